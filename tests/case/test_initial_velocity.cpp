// Initial velocity per body or region (docs/case-format.md "[initial_velocity]"): entries
// selected by material and box, a later entry replacing an earlier one, rigid rotation and a
// function of position; bad entries name the file, the line and the key.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include <Eigen/Geometry>

#include "../support/test_util.hpp"
#include "core/error.hpp"
#include "schemes/simulation.hpp"

namespace rktsph {
namespace {

// Two blocks of two materials side by side: "left" on x in [0, 1], "right" on [1, 2].
constexpr const char* kTwoBodies = R"(
[geometry]
dimension = 2
spacing = 0.25

[[geometry.block]]
min = [0.0, 0.0]
max = [1.0, 1.0]
material = "left"

[[geometry.block]]
min = [1.0, 0.0]
max = [2.0, 1.0]
material = "right"

[materials.left]
model = "elastic"
E = 1.0e7
nu = 0.3
density = 2000.0

[materials.right]
model = "elastic"
E = 1.0e7
nu = 0.3
density = 2000.0

[time]
end = 0.001

[solver]
version = "v2"
)";

Simulation<2> simulation(const test::TempDir& dir, const std::string& entries) {
  return Simulation<2>(test::case_from_string<2>(dir, std::string(kTwoBodies) + entries));
}

TEST(InitialVelocity, EntriesSelectByMaterialAndBoxAndTheLaterWins) {
  const test::TempDir dir;
  const Simulation<2> sim = simulation(dir, R"(
[[initial_velocity]]
material = "left"
velocity = [3.0, 0.0]

[[initial_velocity]]
material = "right"
angular_velocity = 2.0
centre = [1.5, 0.5]

[[initial_velocity]]
x = [0.0, 0.25]
y = [0.75, 1.0]
function = { x = "-x", y = "10*y + x^2" }
)");
  const auto& nodes = sim.nodes();
  const auto v = sim.node_velocity();
  int in_box = 0;
  for (Index i = 0; i < static_cast<Index>(nodes.size()); ++i) {
    const Vec<2> x = nodes.position[static_cast<std::size_t>(i)];
    Vec<2> expected;
    if (x[0] <= 0.25 && x[1] >= 0.75) {
      expected = {-x[0], 10.0 * x[1] + x[0] * x[0]};  // the last entry, whatever the material
      ++in_box;
    } else if (nodes.material[static_cast<std::size_t>(i)] == 0) {
      expected = {3.0, 0.0};
    } else {
      expected = {-2.0 * (x[1] - 0.5), 2.0 * (x[0] - 1.5)};
    }
    EXPECT_NEAR(v(i, 0), expected[0], 1e-14) << x.transpose();
    EXPECT_NEAR(v(i, 1), expected[1], 1e-14) << x.transpose();
  }
  EXPECT_EQ(in_box, 4) << "2 x 2 lattice nodes in the corner box";
}

// 3D: a rigid rotation about an axis through a centre, v = omega x (x - c), and a function of
// x, y, z added to it.
TEST(InitialVelocity, ARigidRotationIn3DIsTheCrossProduct) {
  const test::TempDir dir;
  const Simulation<3> sim(test::case_from_string<3>(dir, R"(
[geometry]
dimension = 3
spacing = 0.25
[[geometry.block]]
min = [0.0, 0.0, 0.0]
max = [1.0, 0.5, 0.75]
[material]
model = "elastic"
E = 1.0e7
nu = 0.3
density = 2000.0
[time]
end = 0.001
[solver]
version = "v2"
[initial_velocity]
angular_velocity = [0.5, -1.0, 2.0]
centre = [0.5, 0.25, 0.25]
velocity = [0.1, 0.0, 0.0]
function = { z = "x*y*z" }
)"));
  const Vec<3> omega(0.5, -1.0, 2.0), centre(0.5, 0.25, 0.25);
  const auto v = sim.node_velocity();
  ASSERT_EQ(sim.nodes().size(), 5 * 3 * 4);
  for (Index i = 0; i < static_cast<Index>(sim.nodes().size()); ++i) {
    const Vec<3> x = sim.nodes().position[static_cast<std::size_t>(i)];
    Vec<3> expected = Vec<3>(0.1, 0.0, 0.0) + omega.cross(x - centre);
    expected[2] += x[0] * x[1] * x[2];
    for (int d = 0; d < 3; ++d) EXPECT_NEAR(v(i, d), expected[d], 1e-14) << x.transpose();
  }
}

TEST(InitialVelocity, NodesNoEntrySelectsStartAtRest) {
  const test::TempDir dir;
  const Simulation<2> sim = simulation(dir, "[[initial_velocity]]\nmaterial = \"right\"\nvelocity = [0.0, -1.0]\n");
  const auto v = sim.node_velocity();
  for (Index i = 0; i < static_cast<Index>(sim.nodes().size()); ++i) {
    const bool right = sim.nodes().material[static_cast<std::size_t>(i)] == 1;
    EXPECT_EQ(v(i, 1), right ? -1.0 : 0.0);
  }
}

TEST(InitialVelocity, ASingleTableIsTheWholeBody) {
  const test::TempDir dir;
  const Simulation<2> sim = simulation(dir, "[initial_velocity]\nvelocity = [0.5, 0.25]\n");
  const auto v = sim.node_velocity();
  for (Index i = 0; i < static_cast<Index>(sim.nodes().size()); ++i) {
    EXPECT_EQ(v(i, 0), 0.5);
    EXPECT_EQ(v(i, 1), 0.25);
  }
}

void expect_input_error(const std::string& entries, const std::string& key, const std::string& fragment) {
  const test::TempDir dir;
  const std::string text = std::string(kTwoBodies) + entries;
  try {
    test::case_from_string<2>(dir, text);
    ADD_FAILURE() << "no error for " << entries;
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("case.toml, line"), std::string::npos) << message;
    EXPECT_NE(message.find(key), std::string::npos) << message;
    EXPECT_NE(message.find(fragment), std::string::npos) << message;
  }
}

TEST(InitialVelocity, BadEntriesNameTheFileTheLineAndTheKey) {
  expect_input_error("[[initial_velocity]]\nfunction = { x = \"2*\" }\n", "initial_velocity[0].function.x",
                     "cannot evaluate '2*'");
  expect_input_error("[[initial_velocity]]\nfunction = { x = \"z\" }\n", "initial_velocity[0].function.x",
                     "variables: x, y");
  expect_input_error("[[initial_velocity]]\nfunction = { w = \"1\" }\n", "initial_velocity[0].function.w",
                     "unknown velocity component");
  expect_input_error("[[initial_velocity]]\nmaterial = \"clay\"\n", "initial_velocity[0].material",
                     "no material named 'clay'");
  expect_input_error("[[initial_velocity]]\nx = [1.0, 0.0]\n", "initial_velocity[0].x", "min <= max");
  expect_input_error("[[initial_velocity]]\nspeed = 1.0\n", "speed", "");
}

TEST(InitialVelocity, ANonFiniteValueAtANodeIsAnError) {
  const test::TempDir dir;
  // Finite at the origin (where the expression is checked on reading), infinite at x = 1.
  EXPECT_THROW(simulation(dir, "[[initial_velocity]]\nfunction = { y = \"1/(x-1)\" }\n"), InputError);
}

}  // namespace
}  // namespace rktsph
