// The nodal velocity checkerboard is a zero-energy mode of the staggered scheme in 2D
// (METHOD.md §0.3 item 3): the elements, at the cell centres, see a zero interpolated value
// and zero gradient of it. Without the velocity filter it survives; with it, it is removed.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include <fmt/format.h>

#include "../support/test_util.hpp"
#include "solvers/staggered_solver.hpp"

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
double checkerboard_amplitude(const StaggeredSolver<2>& s) {
  constexpr int NV = StaggeredSolver<2>::NV;
  const auto& idx = s.particles().node_lattice_index;
  double num = 0.0, den = 0.0;
  for (std::size_t i = 0; i < idx.size(); ++i) {
    const double sign = (idx[i][0] + idx[i][1]) % 2 == 0 ? 1.0 : -1.0;
    for (int d = 0; d < 2; ++d) {
      num += sign * s.node_phi()[i * NV + static_cast<std::size_t>(d)];
      den += 1.0;
    }
  }
  return num / den;
}

double run_checkerboard(bool filter, int steps) {
  const test::ThreadCount threads(1);
  test::TempDir dir;
  auto setup = test::case_from_string<2>(dir, free_block(filter));
  StaggeredSolver<2> solver(setup);
  constexpr int NV = StaggeredSolver<2>::NV;
  auto& phi = solver.mutable_node_phi();
  const auto& idx = solver.particles().node_lattice_index;
  for (std::size_t i = 0; i < idx.size(); ++i) {
    const double sign = (idx[i][0] + idx[i][1]) % 2 == 0 ? 1.0 : -1.0;
    phi[i * NV + 0] = kAmplitude * sign;
    phi[i * NV + 1] = kAmplitude * sign;
  }
  const double a0 = checkerboard_amplitude(solver);
  EXPECT_NEAR(a0, kAmplitude, 1e-15);
  // Sanity: the elements cannot see the mode (their interpolated velocity is ~0 after step 1).
  solver.step();
  double emax = 0.0;
  for (std::size_t e = 0; e < solver.element_phi().size() / NV; ++e) {
    emax = std::max(emax, std::abs(solver.element_phi()[e * NV]));
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
