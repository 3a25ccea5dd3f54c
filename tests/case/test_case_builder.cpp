// CaseBuilder (case/case_builder.hpp): a case made in code is the case the reader makes from the
// equivalent file (the same run bit for bit), and its checks name what is wrong.
#include <gtest/gtest.h>

#include <cstring>

#include "../support/test_util.hpp"
#include "case/case_builder.hpp"
#include "schemes/simulation.hpp"

namespace rktsph {
namespace {

const char* kFile = R"(
[geometry]
dimension = 2
spacing = 0.25
[[geometry.block]]
min = [0.0, 0.0]
max = [3.0, 2.0]
[material]
model = "elastic"
E = 1.0e7
nu = 0.3
density = 2000.0
[body_force]
gravity = [0.0, -9.81]
function = "ramp"
[functions.ramp]
type = "ramp"
duration = 0.05
[[boundary]]
y = [0.0, 0.0]
velocity = { x = 0.0, y = 0.0 }
[[boundary]]
x = [0.0, 0.0]
velocity = { x = 0.0 }
[[boundary]]
y = [2.0, 2.0]
x = [0.0, 1.0]
stress = { yy = -5.0e3 }
function = "ramp"
[time]
end = 0.2
cfl = 0.6
)";

CaseBuilder<2> equivalent() {
  Region<2> footing = Region<2>::plane(1, 2.0);
  footing.lo[0] = 0.0;
  footing.hi[0] = 1.0;
  footing.bounded[0] = true;
  CaseBuilder<2> b("equivalent");
  b.spacing(0.25)
      .block(Vec<2>(0.0, 0.0), Vec<2>(3.0, 2.0))
      .elastic(1.0e7, 0.3, 2000.0)
      .function("ramp", TimeFunction::ramp(0.05))
      .gravity(Vec<2>(0.0, -9.81), "ramp")
      .fix_velocity(Region<2>::plane(1, 0.0), {0, 1})
      .fix_velocity(Region<2>::plane(0, 0.0), {0})
      .prescribe_stress(footing, StressComponent::yy, -5.0e3, "ramp")
      .time(0.2, 0.6);
  return b;
}

TEST(CaseBuilder, ACaseMadeInCodeRunsAsTheSameFile) {
  const test::ThreadCount threads(1);
  test::TempDir dir;
  Simulation<2> from_file(test::case_from_string<2>(dir, kFile));
  Simulation<2> in_code(equivalent().build());
  ASSERT_EQ(from_file.nodes().size(), in_code.nodes().size());
  EXPECT_EQ(from_file.dt(), in_code.dt());
  for (int n = 0; n < 100; ++n) {
    from_file.step();
    in_code.step();
  }
  const auto a = values_of(from_file.model().nodes.view(from_file.model().fields.stress));
  const auto b = values_of(in_code.model().nodes.view(in_code.model().fields.stress));
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)), 0);
  EXPECT_LT(in_code.node_stress()(0, StressComponent::yy), -1.0e3) << "gravity and the load reached the base";
}

TEST(CaseBuilder, ChecksNameWhatIsWrong) {
  auto message = [](const CaseBuilder<2>& b) {
    try {
      (void)b.build();
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(message(CaseBuilder<2>("x").spacing(0.1).block(Vec<2>(0, 0), Vec<2>(1, 1)).time(1.0)).find("no material"),
            std::string::npos);
  EXPECT_NE(message(equivalent().block(Vec<2>(0, 0), Vec<2>(1, 1), "clay")).find("no material named 'clay'"),
            std::string::npos);
  EXPECT_NE(message(equivalent().gravity(Vec<2>(0, -9.81), "nope")).find("no time function named 'nope'"),
            std::string::npos);
  EXPECT_NE(message(equivalent().time(0.2, 1.5)).find("Courant"), std::string::npos);
  EXPECT_NE(message(equivalent().scheme("v3")).find("pore fluid"), std::string::npos);
  EXPECT_NE(message(equivalent().scheme("v9")).find("no scheme 'v9'"), std::string::npos);
}

}  // namespace
}  // namespace rktsph
