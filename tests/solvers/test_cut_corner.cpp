// Boundary closure of a cut (method-notes §0.3 item 8) and the damped equilibrium:
//  - at the toe, where a fixed base meets a free face, the face tractions sigma_xx and sigma_xy
//    are held at zero while sigma_yy (the base reaction) is free; at the corner of a roller side
//    and a free top, sigma_xy = 0;
//  - a state in static equilibrium stays at rest under the velocity damping whatever c_d dt
//    (the damping acts on the whole velocity increment, not on the body force alone).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "../support/test_util.hpp"
#include "schemes/simulation.hpp"

namespace rktsph {
namespace {

const char* kCut = R"(
[geometry]
dimension = 2
spacing = 0.5
[[geometry.block]]
min = [0.0, 0.0]
max = [5.0, 5.0]
[material]
model = "elastic"
E = 8.0e7
nu = 0.3
density = 2000.0
[body_force]
gravity = [0.0, -9.81]
[damping]
coefficient = 50.0
[[boundary]]
name = "base"
y = [0.0, 0.0]
velocity = { x = 0.0, y = 0.0 }
[[boundary]]
name = "left_rollers"
x = [0.0, 0.0]
velocity = { x = 0.0 }
[time]
end = 1.0
dt = 1.0e-3
)";

std::size_t node_at(const Simulation<2>& s, double x, double y) {
  const auto& p = s.nodes().position;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (std::abs(p[i][0] - x) < 1e-9 && std::abs(p[i][1] - y) < 1e-9) return i;
  }
  ADD_FAILURE() << "no node at " << x << ", " << y;
  return 0;
}

TEST(CutCorner, ToeHoldsTheFaceTractionsAndLeavesTheBaseReaction) {
  const test::ThreadCount threads(1);
  test::TempDir dir;
  auto setup = test::case_from_string<2>(dir, kCut);
  Simulation<2> solver(setup);
  for (int n = 0; n < 300; ++n) solver.step();
  const auto toe = node_at(solver, 5.0, 0.0);
  const auto v = solver.node_velocity();
  const auto s = solver.node_stress();
  EXPECT_EQ(v(toe, 0), 0.0);  // v_x, v_y fixed by the base
  EXPECT_EQ(v(toe, 1), 0.0);
  EXPECT_EQ(s(toe, StressComponent::xx), 0.0);  // sigma_xx: normal traction of the free face
  EXPECT_EQ(s(toe, StressComponent::xy), 0.0);  // sigma_xy: shear traction of the free face
  EXPECT_LT(s(toe, StressComponent::yy), -1.0e4) << "sigma_yy at the toe is the base reaction and must carry load";
  // Corner of the left rollers and the free top: sigma_xy = 0 (both faces are smooth/free).
  const auto tl = node_at(solver, 0.0, 5.0);
  EXPECT_EQ(solver.node_stress()(tl, StressComponent::xy), 0.0);
  EXPECT_EQ(solver.node_stress()(tl, StressComponent::yy), 0.0);
  // Base interior node: both base reactions free.
  const auto b = node_at(solver, 2.5, 0.0);
  EXPECT_LT(solver.node_stress()(b, StressComponent::yy), -1.0e4);
  EXPECT_NE(solver.node_stress()(b, StressComponent::xy), 0.0);
}

// A 1-D column state (lateral rollers on both sides, smooth base, geostatic stress with
// K0 = nu/(1-nu)) is an exact discrete equilibrium; with c_d dt = 0.05 it must stay at rest.
TEST(DampedEquilibrium, GeostaticColumnStaysAtRestUnderStrongDamping) {
  const test::ThreadCount threads(1);
  test::TempDir dir;
  auto setup = test::case_from_string<2>(dir, R"(
[geometry]
dimension = 2
spacing = 0.5
[[geometry.block]]
min = [0.0, 0.0]
max = [2.0, 5.0]
[material]
model = "elastic"
E = 8.0e7
nu = 0.3
density = 2000.0
[body_force]
gravity = [0.0, -9.81]
[damping]
coefficient = 50.0
[initial_stress]
type = "geostatic"
[[boundary]]
name = "base"
y = [0.0, 0.0]
velocity = { y = 0.0 }
[[boundary]]
name = "left"
x = [0.0, 0.0]
velocity = { x = 0.0 }
[[boundary]]
name = "right"
x = [2.0, 2.0]
velocity = { x = 0.0 }
[time]
end = 1.0
dt = 1.0e-3
)");
  Simulation<2> solver(setup);
  for (int n = 0; n < 200; ++n) solver.step();
  double vmax = 0.0;
  for (std::size_t i = 0; i < static_cast<std::size_t>(solver.nodes().size()); ++i) {
    vmax = std::max(vmax, std::abs(solver.node_velocity()(i, 1)));
  }
  std::printf("geostatic column, c_d dt = 0.05, 200 steps: max |v_y| = %.3g m/s\n", vmax);
  // Damping only the body force would leave 2.5 % of g unbalanced: |v| ~ 0.025 g / c_d = 5e-3 m/s.
  EXPECT_LT(vmax, 1e-9);
}

}  // namespace
}  // namespace rktsph
