// The scheme registry (schemes/registry.hpp): the built-in schemes are lists of named stages,
// and a new scheme is registered from existing stages without touching the others.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "../support/test_util.hpp"
#include "core/error.hpp"
#include "schemes/registry.hpp"
#include "schemes/simulation.hpp"
#include "schemes/staggered_stages.hpp"

namespace rktsph {
namespace {

const char* kBlock = R"(
[geometry]
dimension = 2
spacing = 0.25
[[geometry.block]]
min = [0.0, 0.0]
max = [2.0, 2.0]
[material]
model = "elastic"
E = 1.0e7
nu = 0.3
density = 2000.0
[[boundary]]
y = [0.0, 0.0]
velocity = { x = 0.0, y = 0.0 }
[[boundary]]
y = [2.0, 2.0]
stress = { yy = -1.0e4 }
function = "load"
[functions.load]
type = "ramp"
duration = 0.01
[time]
end = 0.1
cfl = 0.5
)";

std::vector<std::string> stage_names(const Scheme& s) {
  std::vector<std::string> out;
  for (const auto& st : s.stages()) out.emplace_back(st->name());
  return out;
}

TEST(SchemeRegistry, BuiltInSchemesAreListsOfNamedStages) {
  const test::ThreadCount threads(1);
  test::TempDir dir;
  Simulation<2> v1(test::case_from_string<2>(dir, kBlock));
  EXPECT_EQ(v1.scheme().name(), "v1");
  EXPECT_EQ(stage_names(v1.scheme()), (std::vector<std::string>{"stress_points_half_step", "nodes_full_step",
                                                                "constraints", "velocity_filter", "constraints"}));
  const auto names = scheme_names<2>();
  EXPECT_NE(std::find(names.begin(), names.end(), "v1"), names.end());
  EXPECT_NE(std::find(names.begin(), names.end(), "v3"), names.end());
  EXPECT_TRUE(find_scheme<2>("v3")->pore_fluid);
  EXPECT_FALSE(find_scheme<1>("v1")->pore_fluid);
  EXPECT_EQ(find_scheme<2>("no_such_scheme"), nullptr);
  StaggeredModel<2> model(test::case_from_string<2>(dir, kBlock));
  EXPECT_THROW(create_scheme<2>("no_such_scheme", model), InputError);
}

// A scheme made here from V1's stages, without the velocity filter: registered by name, chosen
// by solver.version in the case file, it must give bit for bit what V1 gives with
// solver.filter = false (the same stages in the same order).
TEST(SchemeRegistry, ANewSchemeIsRegisteredFromExistingStages) {
  const test::ThreadCount threads(1);
  register_scheme<2>({"test_unfiltered", "V1 without the velocity filter (a test)", false},
                     [](StaggeredModel<2>& model) {
                       auto scheme = std::make_unique<Scheme>("test_unfiltered");
                       auto sources = std::make_shared<ViscoplasticSources<2>>(model);
                       scheme->add(std::make_unique<StressPointHalfStep<2>>(model, sources));
                       scheme->add(std::make_unique<NodeFullStep<2>>(model, sources));
                       scheme->add(std::make_unique<ApplyConstraints<2>>(model));
                       return scheme;
                     });
  EXPECT_THROW(register_scheme<2>({"test_unfiltered", "twice", false}, make_v1_scheme<2>), SolverError);
  test::TempDir dir;
  Simulation<2> custom(test::case_from_string<2>(dir, kBlock, {"solver.version=test_unfiltered"}, "custom.toml"));
  Simulation<2> v1(test::case_from_string<2>(dir, kBlock, {"solver.filter=false"}, "v1.toml"));
  EXPECT_EQ(custom.scheme().name(), "test_unfiltered");
  EXPECT_EQ(custom.scheme().stages().size(), 3u);
  for (int n = 0; n < 200; ++n) {
    custom.step();
    v1.step();
  }
  const auto a = values_of(custom.model().nodes.view(custom.model().fields.velocity));
  const auto b = values_of(v1.model().nodes.view(v1.model().fields.velocity));
  double vmax = 0.0;
  for (double v : a) vmax = std::max(vmax, std::abs(v));
  EXPECT_GT(vmax, 1e-4) << "the load reached the block";
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)), 0);
  EXPECT_EQ(custom.energy().external_work, v1.energy().external_work);
  // The 1D registry is separate: the name is not known there.
  EXPECT_EQ(find_scheme<1>("test_unfiltered"), nullptr);
}

}  // namespace
}  // namespace rktsph
