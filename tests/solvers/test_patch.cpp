// Patch test of the V1 solver (method-notes §0.3 items 1-2): a uniform stress state with the
// matching tractions prescribed on every face is an exact steady state of the discrete
// scheme; it must persist to round-off over many steps, in 1D and 2D.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "../support/test_util.hpp"
#include "schemes/simulation.hpp"

namespace rktsph {
namespace {

constexpr double kSxx = -1.0e4, kSyy = -2.5e4, kSxy = 4.0e3, kSzz = -1.05e4;
constexpr double kRho = 2000.0;

std::string block_2d(double sxx_right) {
  // 8 x 6 cells; every face carries the traction of the uniform state.
  return fmt::format(R"(
[geometry]
dimension = 2
spacing = 0.5
[[geometry.block]]
min = [0.0, 0.0]
max = [4.0, 3.0]
[material]
model = "elastic"
E = 1.0e7
nu = 0.3
density = {rho}
[[boundary]]
name = "left"
x = [0.0, 0.0]
stress = {{ xx = {sxx}, xy = {sxy} }}
[[boundary]]
name = "right"
x = [4.0, 4.0]
stress = {{ xx = {sxx_right}, xy = {sxy} }}
[[boundary]]
name = "bottom"
y = [0.0, 0.0]
stress = {{ yy = {syy}, xy = {sxy} }}
[[boundary]]
name = "top"
y = [3.0, 3.0]
stress = {{ yy = {syy}, xy = {sxy} }}
[time]
end = 1.0
cfl = 0.9
)",
                     fmt::arg("rho", kRho), fmt::arg("sxx", kSxx), fmt::arg("sxx_right", sxx_right),
                     fmt::arg("syy", kSyy), fmt::arg("sxy", kSxy));
}

struct Drift {
  double stress = 0.0;    // max |sigma - sigma0| / |sigma0|
  double velocity = 0.0;  // max |v| / (|sigma0| / (rho c))
};

// Seed the uniform stress at every node (the boundary values already hold it), run, measure.
template <int Dim>
Drift run_patch(Simulation<Dim>& solver, const std::array<double, kStressComponents<Dim>>& s0, int steps) {
  auto stress = solver.mutable_node_stress();
  const auto nn = static_cast<std::size_t>(solver.nodes().size());
  for (std::size_t i = 0; i < nn; ++i) {
    for (int c = 0; c < kStressComponents<Dim>; ++c) stress(i, c) = s0[static_cast<std::size_t>(c)];
  }
  for (int n = 0; n < steps; ++n) solver.step();
  double smax = 0.0;
  for (double s : s0) smax = std::max(smax, std::abs(s));
  const double vscale = smax / (kRho * solver.max_wave_speed());
  Drift d;
  const auto v = solver.node_velocity();
  for (std::size_t i = 0; i < nn; ++i) {
    for (int c = 0; c < Dim; ++c) d.velocity = std::max(d.velocity, std::abs(v(i, c)) / vscale);
    for (int c = 0; c < kStressComponents<Dim>; ++c) {
      d.stress = std::max(d.stress, std::abs(stress(i, c) - s0[static_cast<std::size_t>(c)]) / smax);
    }
  }
  return d;
}

TEST(PatchTest, UniformStressWithMatchingTractions2D) {
  const test::ThreadCount threads(1);
  for (bool filter : {true, false}) {
    test::TempDir dir;
    auto setup = test::case_from_string<2>(dir, block_2d(kSxx), {fmt::format("solver.filter={}", filter)});
    Simulation<2> solver(setup);
    ASSERT_EQ(solver.nodes().size(), 63);
    ASSERT_EQ(solver.degenerate_operator_rows(), 0);
    const Drift d = run_patch<2>(solver, {kSxx, kSyy, kSzz, kSxy}, 2000);
    EXPECT_LT(d.stress, 1e-9) << "filter " << filter;
    EXPECT_LT(d.velocity, 1e-9) << "filter " << filter;
    RecordProperty(filter ? "stress_drift_filter" : "stress_drift_nofilter", fmt::format("{:.3g}", d.stress));
    RecordProperty(filter ? "velocity_drift_filter" : "velocity_drift_nofilter", fmt::format("{:.3g}", d.velocity));
    std::printf("2D patch (filter %d): stress drift %.3g, velocity %.3g (relative)\n", filter, d.stress, d.velocity);
  }
}

TEST(PatchTest, MismatchedTractionIsNotASteadyState) {
  // Control: the same block with a 10 % wrong traction on one face must move.
  const test::ThreadCount threads(1);
  test::TempDir dir;
  auto setup = test::case_from_string<2>(dir, block_2d(1.1 * kSxx));
  Simulation<2> solver(setup);
  const Drift d = run_patch<2>(solver, {kSxx, kSyy, kSzz, kSxy}, 200);
  EXPECT_GT(d.velocity, 1e-3);
  EXPECT_GT(d.stress, 1e-3);
}

TEST(PatchTest, UniformStressWithMatchingTractions1D) {
  const test::ThreadCount threads(1);
  test::TempDir dir;
  auto setup = test::case_from_string<1>(dir, R"(
[geometry]
dimension = 1
spacing = 0.1
[[geometry.block]]
min = [0.0]
max = [2.0]
[material]
model = "elastic"
E = 1.0e7
nu = 0.25
density = 2000.0
[[boundary]]
name = "left"
x = [0.0, 0.0]
stress = { xx = -1.0e4 }
[[boundary]]
name = "right"
x = [2.0, 2.0]
stress = { xx = -1.0e4 }
[time]
end = 1.0
cfl = 1.2
)");
  Simulation<1> solver(setup);
  const Drift d = run_patch<1>(solver, {-1.0e4, -3.0e3, -3.0e3}, 2000);
  EXPECT_LT(d.stress, 1e-9);
  EXPECT_LT(d.velocity, 1e-9);
  std::printf("1D patch: stress drift %.3g, velocity %.3g (relative)\n", d.stress, d.velocity);
}

}  // namespace
}  // namespace rktsph
