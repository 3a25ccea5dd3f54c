// The nodal velocity checkerboard is a zero-energy mode of the staggered scheme in 2D
// (method-notes §0.3 item 3): the stress points, at the cell centres, see a zero interpolated value
// and zero gradient of it. Without the velocity filter it survives; with it, it is removed.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include <fmt/format.h>

#include "../support/test_util.hpp"
#include "schemes/simulation.hpp"

namespace rktsph {
namespace {

constexpr double kAmplitude = 1e-3;  // m/s

std::string free_block(bool filter) {
  return fmt::format(R"(
[geometry]
dimension = 2
spacing = 0.25
[[geometry.block]]
min = [0.0, 0.0]
max = [4.0, 4.0]
[material]
model = "elastic"
E = 1.0e7
nu = 0.3
density = 2000.0
[time]
end = 1.0
cfl = 0.9
[solver]
filter = {}
)",
                     filter);
}

// Projection of the nodal velocity onto the checkerboard (-1)^(i+j), per component, over all
// nodes: the amplitude of the mode that was seeded.
// The sign (-1)^(i+j) of the node at lattice coordinates (i, j).
double parity(const Simulation<2>& s, std::size_t node) {
  const auto& x = s.nodes().position[node];
  const long i = std::lround(x[0] / s.setup().dx), j = std::lround(x[1] / s.setup().dx);
  return (i + j) % 2 == 0 ? 1.0 : -1.0;
}

double checkerboard_amplitude(const Simulation<2>& s) {
  double num = 0.0, den = 0.0;
  const auto v = s.node_velocity();
  for (std::size_t i = 0; i < s.nodes().position.size(); ++i) {
    const double sign = parity(s, i);
    for (int d = 0; d < 2; ++d) {
      num += sign * v(i, d);
      den += 1.0;
    }
  }
  return num / den;
}

double run_checkerboard(bool filter, int steps) {
  const test::ThreadCount threads(1);
  test::TempDir dir;
  auto setup = test::case_from_string<2>(dir, free_block(filter));
  Simulation<2> solver(setup);
  auto v = solver.mutable_node_velocity();
  for (std::size_t i = 0; i < solver.nodes().position.size(); ++i) {
    const double sign = parity(solver, i);
    v(i, 0) = kAmplitude * sign;
    v(i, 1) = kAmplitude * sign;
  }
  const double a0 = checkerboard_amplitude(solver);
  EXPECT_NEAR(a0, kAmplitude, 1e-15);
  // Sanity: the stress points cannot see the mode (their interpolated velocity is ~0 after step 1).
  solver.step();
  double emax = 0.0;
  for (Index e = 0; e < solver.stress_points().size(); ++e) {
    emax = std::max(emax, std::abs(solver.stress_point_velocity()(e, 0)));
  }
  if (!filter) {
    EXPECT_LT(emax, 0.5 * kAmplitude);
  }
  for (int n = 1; n < steps; ++n) solver.step();
  return checkerboard_amplitude(solver) / a0;
}

TEST(Checkerboard, FilterRemovesTheNodalMode) {
  const double left = run_checkerboard(true, 500);
  std::printf("checkerboard with filter: %.3g of the seeded amplitude left after 500 steps\n", left);
  EXPECT_LT(std::abs(left), 1e-3);
}

TEST(Checkerboard, WithoutFilterTheModeSurvives) {
  const double left = run_checkerboard(false, 500);
  std::printf("checkerboard without filter: %.3g of the seeded amplitude left after 500 steps\n", left);
  EXPECT_GT(left, 0.5);
}

}  // namespace
}  // namespace rktsph
