// initial_stress type = "uniform" (case_reader / StaggeredSolver::set_initial_state): an
// isotropic uniform stress with the matching confining tractions stays uniform, and the 1D
// uniaxial-stress condition runs with the bar modulus E.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "case/case_reader.hpp"
#include "core/error.hpp"
#include "schemes/simulation.hpp"

namespace rktsph {
namespace {

template <int Dim>
CaseSetup<Dim> setup_from(const std::string& text, const std::string& tag) {
  const auto path =
      std::filesystem::temp_directory_path() / ("rktsph_uniform_" + tag + "_" + std::to_string(::getpid()) + ".toml");
  {
    std::ofstream f(path);
    f << text;
  }
  const CaseDocument doc = load_case_document(path.string(), {});
  std::filesystem::remove(path);
  return read_case<Dim>(doc);
}

const std::string kSample2D = R"(
[geometry]
dimension = 2
spacing = 0.1
[[geometry.block]]
min = [0.0, 0.0]
max = [1.0, 2.0]
[material]
model = "perzyna_cam_clay"
E = 2.0e7
nu = 0.3
density = 2000.0
M = 1.2
lambda = 0.2
kappa = 0.02
e0 = 1.0
p_c0 = 4.0e5
fluidity = 10.0
[initial_stress]
type = "uniform"
xx = -5.0e4
yy = -5.0e4
zz = -5.0e4
[[boundary]]
name = "bottom"
y = [0.0, 0.0]
velocity = { y = 0.0 }
[[boundary]]
name = "top"
y = [2.0, 2.0]
velocity = { y = 0.0 }
[[boundary]]
name = "pin"
x = [0.5, 0.5]
y = [0.0, 0.0]
velocity = { x = 0.0 }
[[boundary]]
name = "left"
x = [0.0, 0.0]
stress = { xx = -5.0e4 }
[[boundary]]
name = "right"
x = [1.0, 1.0]
stress = { xx = -5.0e4 }
[time]
end = 1.0
cfl = 0.5
)";

TEST(UniformInitialStress, IsotropicConfinementStaysUniform) {
  CaseSetup<2> setup = setup_from<2>(kSample2D, "2d");
  Simulation<2> solver(setup);
  const double s0[4] = {-5.0e4, -5.0e4, -5.0e4, 0.0};
  for (int n = 0; n < 500; ++n) solver.step();
  const auto velocity = solver.node_velocity();
  const auto stress = solver.node_stress();
  const auto nn = solver.nodes().position.size();
  double ds = 0.0, v = 0.0;
  for (std::size_t i = 0; i < nn; ++i) {
    for (int c = 0; c < 2; ++c) v = std::max(v, std::abs(velocity(i, c)));
    for (int c = 0; c < 4; ++c) ds = std::max(ds, std::abs(stress[i][c] - s0[c]));
  }
  EXPECT_LT(ds / 5.0e4, 1e-9);
  EXPECT_LT(v, 1e-12);
  // p_c is the given p_c0 everywhere and no flow occurred inside the surface (OCR 8).
  for (const std::string& name : solver.history_layout().names()) {
    const HistoryView k = solver.node_history(name);
    for (std::size_t i = 0; i < nn; ++i) EXPECT_EQ(k(i), name == "p_c" ? 4.0e5 : 0.0) << name;
  }
}

// Pressure-dependent Cam-Clay elasticity in the flux (method-notes eq. (1.8.8)): a uniform
// dilation v = a x from the uniform initial stress gives the stress rate of the moduli at the
// particles' own p' = 50 kPa, while the time step is set by those at elastic_p_max.
TEST(UniformInitialStress, PressureDependentModuliInTheFlux) {
  std::string text = kSample2D;
  text.replace(text.find("E = 2.0e7"), 9,
               "elasticity = \"pressure_dependent\"\nelastic_p_min = 1.0e3\nelastic_p_max = 1.0e6");
  Simulation<2> solver(setup_from<2>(text, "pd"));
  const double v0_over_kappa = 2.0 / 0.02, ratio = 3.0 * (1 - 0.6) / (2 * 1.3);
  const double K_max = v0_over_kappa * 1.0e6;
  EXPECT_NEAR(solver.max_wave_speed(), std::sqrt((K_max + 4.0 / 3.0 * ratio * K_max) / 2000.0),
              1e-9 * solver.max_wave_speed());
  const double a = 1e-4;
  auto v = solver.mutable_node_velocity();
  const auto& nodes = solver.nodes();
  for (std::size_t i = 0; i < nodes.position.size(); ++i) {
    for (int d = 0; d < 2; ++d) v(i, d) = a * nodes.position[i][d];
  }
  solver.step();
  const double K = v0_over_kappa * 5.0e4, G = ratio * K;
  const double rate_xx = (K - 2.0 / 3.0 * G) * 2.0 * a + 2.0 * G * a;  // plane strain, tr d = 2a
  const double rate_zz = (K - 2.0 / 3.0 * G) * 2.0 * a;
  int checked = 0;
  for (std::size_t i = 0; i < nodes.position.size(); ++i) {
    const auto& x = nodes.position[i];
    if (x[0] < 0.25 || x[0] > 0.75 || x[1] < 0.25 || x[1] > 1.75) continue;  // interior
    EXPECT_NEAR(solver.node_stress()(i, StressComponent::xx), -5.0e4 + rate_xx * solver.dt(),
                1e-6 * rate_xx * solver.dt());
    EXPECT_NEAR(solver.node_stress()(i, StressComponent::zz), -5.0e4 + rate_zz * solver.dt(),
                1e-6 * rate_zz * solver.dt());
    ++checked;
  }
  EXPECT_GT(checked, 20);
}

TEST(UniformInitialStress, UnknownTypeAndConditionIn2DAreErrors) {
  std::string bad = kSample2D;
  bad.replace(bad.find("spacing = 0.1"), 13, "spacing = 0.1\ncondition = \"uniaxial_stress\"");
  EXPECT_THROW(setup_from<2>(bad, "cond2d"), InputError);
}

TEST(UniaxialStressCondition, BarUsesModulusE) {
  const std::string bar = R"(
[geometry]
dimension = 1
spacing = 0.1
condition = "uniaxial_stress"
[[geometry.block]]
min = [0.0]
max = [1.0]
[material]
model = "elastic"
E = 1.0e7
nu = 0.3
density = 2000.0
[[boundary]]
name = "fixed"
x = [0.0, 0.0]
velocity = { x = 0.0 }
[time]
end = 1.0
cfl = 0.5
)";
  CaseSetup<1> setup = setup_from<1>(bar, "bar");
  Simulation<1> solver(setup);
  // Bar wave speed sqrt(E/rho), not the P-wave speed of uniaxial strain.
  EXPECT_NEAR(solver.max_wave_speed(), std::sqrt(1.0e7 / 2000.0), 1e-9);
  // A velocity field v = a x gives sigma_xx rate E a and no lateral stress.
  auto v = solver.mutable_node_velocity();
  const auto& nodes = solver.nodes();
  for (std::size_t i = 0; i < nodes.position.size(); ++i) v(i, 0) = 1e-3 * nodes.position[i][0];
  solver.step();
  for (std::size_t i = 0; i < nodes.position.size(); ++i) {
    EXPECT_EQ(solver.node_stress()(i, StressComponent::yy), 0.0);
    EXPECT_EQ(solver.node_stress()(i, StressComponent::zz), 0.0);
  }
  const std::size_t mid = 5;
  EXPECT_NEAR(solver.node_stress()(mid, StressComponent::xx), 1.0e7 * 1e-3 * solver.dt(),
              1e-6 * 1.0e7 * 1e-3 * solver.dt());
}

// The 1D bar's uniaxial-stress wrapper uses the constant E: pressure-dependent moduli are refused.
TEST(UniaxialStressCondition, RefusesPressureDependentElasticity) {
  const std::string bar = R"(
[geometry]
dimension = 1
spacing = 0.1
condition = "uniaxial_stress"
[[geometry.block]]
min = [0.0]
max = [1.0]
[material]
model = "perzyna_cam_clay"
elasticity = "pressure_dependent"
nu = 0.3
density = 2000.0
M = 1.2
lambda = 0.2
kappa = 0.02
e0 = 1.0
p_c0 = 4.0e5
fluidity = 10.0
elastic_p_min = 1.0e3
elastic_p_max = 1.0e6
[time]
end = 1.0
cfl = 0.5
)";
  try {
    setup_from<1>(bar, "barpd");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("pressure-dependent elasticity"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rktsph
