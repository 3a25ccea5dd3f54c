// A traction on part of a face (a footing): the node where the load ends takes the traction
// averaged over its face segment, and a damped run comes to rest with displacements that stay
// put (they follow the stress points' velocity, not the nodal velocity, which keeps an O(dt)
// steady component at a load jump: docs/method-notes.md, "Displacements").
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "../support/test_util.hpp"
#include "schemes/simulation.hpp"

namespace rktsph {
namespace {

std::string footing_case(const std::string& loads) {
  return R"(
[geometry]
dimension = 2
spacing = 0.5
[[geometry.block]]
min = [0.0, 0.0]
max = [5.0, 5.0]
[material]
model = "elastic"
E = 3.0e7
nu = 0.2
density = 1700.0
[damping]
coefficient = 20.0
[[boundary]]
name = "symmetry"
x = [0.0, 0.0]
velocity = { x = 0.0 }
[[boundary]]
name = "far_side"
x = [5.0, 5.0]
velocity = { x = 0.0 }
[[boundary]]
name = "base"
y = [0.0, 0.0]
velocity = { y = 0.0 }
)" + loads +
         R"(
[time]
end = 10.0
cfl = 0.5
)";
}

const char* kFooting = R"(
[[boundary]]
name = "footing"
x = [0.0, 2.5]
y = [5.0, 5.0]
stress = { yy = -1.0e4, xy = 0.0 }
)";

std::size_t node_at(const Simulation<2>& s, double x, double y) {
  const auto& p = s.nodes().position;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (std::abs(p[i][0] - x) < 1e-9 && std::abs(p[i][1] - y) < 1e-9) return i;
  }
  ADD_FAILURE() << "no node at " << x << ", " << y;
  return 0;
}

TEST(PartialLoad, NodeWhereTheLoadEndsTakesTheAverageTraction) {
  const test::ThreadCount threads(1);
  test::TempDir dir;
  auto setup = test::case_from_string<2>(dir, footing_case(kFooting));
  Simulation<2> solver(setup);
  solver.step();
  const auto stress = solver.node_stress();
  EXPECT_DOUBLE_EQ(stress(node_at(solver, 2.0, 5.0), StressComponent::yy), -1.0e4);
  EXPECT_DOUBLE_EQ(stress(node_at(solver, 2.5, 5.0), StressComponent::yy), -0.5e4);  // half its segment loaded
  EXPECT_DOUBLE_EQ(stress(node_at(solver, 3.0, 5.0), StressComponent::yy), 0.0);
  EXPECT_DOUBLE_EQ(stress(node_at(solver, 0.0, 5.0), StressComponent::yy), -1.0e4);  // corner: its whole segment
}

TEST(PartialLoad, TwoLoadsMeetingAtANodeAdd) {
  const test::ThreadCount threads(1);
  test::TempDir dir;
  auto setup = test::case_from_string<2>(dir, footing_case(std::string(kFooting) + R"(
[[boundary]]
name = "surcharge"
x = [2.5, 5.0]
y = [5.0, 5.0]
stress = { yy = -2.0e4 }
)"));
  Simulation<2> solver(setup);
  solver.step();
  const auto stress = solver.node_stress();
  EXPECT_DOUBLE_EQ(stress(node_at(solver, 2.5, 5.0), StressComponent::yy), -1.5e4);
  EXPECT_DOUBLE_EQ(stress(node_at(solver, 3.0, 5.0), StressComponent::yy), -2.0e4);
}

// Damped footing: at rest, the displacements must stop moving (the nodal-velocity integration
// drifted at ~1e-3 m/s at the footing edge) and the base reactions must carry the load.
TEST(PartialLoad, DampedFootingComesToRestWithoutDrift) {
  const test::ThreadCount threads(1);
  test::TempDir dir;
  auto setup = test::case_from_string<2>(dir, footing_case(kFooting));
  Simulation<2> solver(setup);
  while (solver.time() < 3.0) solver.step();
  const auto edge = node_at(solver, 2.5, 5.0);
  const auto centre = node_at(solver, 0.0, 5.0);
  const double u_edge = solver.node_displacement()(edge, 1);
  const double u_centre = solver.node_displacement()(centre, 1);
  const double t0 = solver.time();
  while (solver.time() < t0 + 2.0) solver.step();
  const double drift_edge = solver.node_displacement()(edge, 1) - u_edge;
  const double drift_centre = solver.node_displacement()(centre, 1) - u_centre;
  EXPECT_LT(u_centre, -1e-4);
  // Integrating the nodal velocity, the edge node drifted by about 4 |u_centre| per second.
  // What is left is the slow approach to the steady state (the centre still settles by about
  // 1e-3 of itself in these 2 s, independently of c_d).
  EXPECT_LT(std::abs(drift_edge), 1e-5 * std::abs(u_centre)) << "edge settlement still moving";
  EXPECT_LT(std::abs(drift_centre), 3e-3 * std::abs(u_centre));
  // Vertical equilibrium: the base reactions sum to the load, sigma0 x 2.5 m.
  const auto& disc = solver.model();
  double reaction = 0.0;
  for (std::size_t i = 0; i < disc.nodes.position.size(); ++i) {
    if (std::abs(disc.nodes.position[i][1]) > 1e-9) continue;
    const double x = disc.nodes.position[i][0];
    const double length = (x < 1e-9 || x > 5.0 - 1e-9) ? 0.25 : 0.5;
    reaction += solver.node_stress()(i, StressComponent::yy) * length;
  }
  EXPECT_NEAR(reaction / (-1.0e4 * 2.5), 1.0, 0.01);
}

}  // namespace
}  // namespace rktsph
