// Results do not depend on the number of OpenMP threads: every parallel loop writes its own
// particles and the reductions use fixed blocks, so 1 and 2 threads give bit-identical states.
#include <gtest/gtest.h>

#include <omp.h>

#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "../support/test_util.hpp"
#include "linear_solvers/pore_pressure.hpp"
#include "schemes/pressure_stage.hpp"
#include "schemes/simulation.hpp"

namespace rktsph {
namespace {

// Two materials (an elastic base and a viscoplastic von Mises layer that yields, so the
// Runge-Kutta source runs are exercised), gravity ramp, a loaded top strip, a fixed base.
// 32 x 32 cells: 1089 nodes.
constexpr const char* kCase = R"(
[geometry]
dimension = 2
spacing = 0.5
[[geometry.block]]
min = [0.0, 0.0]
max = [16.0, 8.0]
material = "base"
[[geometry.block]]
min = [0.0, 8.0]
max = [16.0, 16.0]
material = "soft"
[materials.base]
model = "elastic"
E = 2.0e7
nu = 0.3
density = 2000.0
[materials.soft]
model = "perzyna_von_mises"
E = 1.0e7
nu = 0.3
density = 1800.0
cohesion = 2.0e3
fluidity = 0.5
exponent = 1.0
[functions.ramp]
type = "ramp"
duration = 0.05
[body_force]
gravity = [0.0, -9.81]
function = "ramp"
[damping]
coefficient = 5.0
until = 0.02
[[boundary]]
name = "base"
y = [0.0, 0.0]
velocity = { x = 0.0, y = 0.0 }
[[boundary]]
name = "footing"
x = [6.0, 10.0]
y = [16.0, 16.0]
stress = { yy = -5.0e4 }
function = "ramp"
[time]
end = 1.0
cfl = 0.9
)";

struct Result {
  std::vector<double> node_velocity, node_stress, stress_point_velocity, stress_point_stress, displacement, history;
  EnergyBalance energy;
};

Result run(int threads, int steps) {
  const double t0 = omp_get_wtime();
  const test::ThreadCount guard(threads);
  EXPECT_EQ(omp_get_max_threads(), threads);
  test::TempDir dir;
  auto setup = test::case_from_string<2>(dir, kCase);
  Simulation<2> solver(setup);
  EXPECT_EQ(solver.nodes().size(), 33 * 33);
  for (int n = 0; n < steps; ++n) solver.step();
  std::printf("%d thread(s): %d steps in %.3f s, max source sub-steps %ld\n", threads, steps, omp_get_wtime() - t0,
              solver.max_source_substeps());
  const auto& m = solver.model();
  return {values_of(m.nodes.view(m.fields.velocity)),
          values_of(m.nodes.view(m.fields.stress)),
          values_of(m.stress_points.view(m.fields.sp_velocity)),
          values_of(m.stress_points.view(m.fields.sp_stress)),
          values_of(m.nodes.view(m.fields.displacement)),
          values_of(m.nodes.view(m.fields.history)),
          solver.energy()};
}

bool bitwise_equal(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

TEST(Threads, OneAndTwoThreadsGiveBitIdenticalResults) {
  const int steps = 100;
  const Result one = run(1, steps);
  const Result two = run(2, steps);
  // The run did something: the soft layer yielded and the state is far from zero.
  double vmax = 0.0;
  for (std::size_t i = 0; i < one.node_velocity.size(); i += 2)
    vmax = std::max(vmax, std::abs(one.node_velocity[i + 1]));
  EXPECT_GT(vmax, 1e-4);
  double hmax = 0.0;
  for (double h : one.history) hmax = std::max(hmax, std::abs(h));
  EXPECT_GT(hmax, 0.0) << "the viscoplastic layer never yielded: the source path is untested";
  EXPECT_TRUE(bitwise_equal(one.node_velocity, two.node_velocity));
  EXPECT_TRUE(bitwise_equal(one.node_stress, two.node_stress));
  EXPECT_TRUE(bitwise_equal(one.stress_point_velocity, two.stress_point_velocity));
  EXPECT_TRUE(bitwise_equal(one.stress_point_stress, two.stress_point_stress));
  EXPECT_TRUE(bitwise_equal(one.displacement, two.displacement));
  EXPECT_TRUE(bitwise_equal(one.history, two.history));
  EXPECT_EQ(one.energy.external_work, two.energy.external_work);
  EXPECT_EQ(one.energy.damping_loss, two.energy.damping_loss);
  EXPECT_EQ(one.energy.kinetic, two.energy.kinetic);
}

// V3 on a block large enough (151 x 151 = 22 801 nodes) for the pressure PCG to take the full,
// threaded matrix product (solvers/pore_pressure.cpp, kParallelUnknowns): still bit-identical.
constexpr const char* kSaturatedCase = R"(
[geometry]
dimension = 2
spacing = 0.1
[[geometry.block]]
min = [0.0, 0.0]
max = [15.0, 15.0]
[material]
model = "elastic"
E = 2.0e7
nu = 0.3
density = 2000.0
[fluid]
porosity = 0.3
density = 1000.0
bulk_modulus = 1.0e8
conductivity = 1.0e-6
[solver]
version = "v3"
[[boundary]]
name = "base"
y = [0.0, 0.0]
velocity = { x = 0.0, y = 0.0 }
[[boundary]]
name = "top"
y = [15.0, 15.0]
stress = { yy = -1.0e4 }
pore_pressure = 0.0
[time]
end = 1.0
cfl = 0.5
)";

std::pair<std::vector<double>, std::vector<double>> run_saturated(int threads, int steps) {
  const test::ThreadCount guard(threads);
  test::TempDir dir;
  auto setup = test::case_from_string<2>(dir, kSaturatedCase);
  Simulation<2> solver(setup);
  EXPECT_GE(solver.scheme().find<PorePressureStage<2>>()->solver().unknowns(), 20000);
  for (int n = 0; n < steps; ++n) solver.step();
  const auto pw = solver.node_pore_pressure();
  return {values_of(solver.model().nodes.view(solver.model().fields.velocity)),
          std::vector<double>(pw.begin(), pw.end())};
}

TEST(Threads, SaturatedLargeSystemOneAndTwoThreadsGiveBitIdenticalResults) {
  const auto one = run_saturated(1, 5);
  const auto two = run_saturated(2, 5);
  double pmax = 0.0;
  for (double p : one.second) pmax = std::max(pmax, std::abs(p));
  EXPECT_GT(pmax, 1.0);  // the load reached the pore pressure
  EXPECT_TRUE(bitwise_equal(one.first, two.first));
  EXPECT_TRUE(bitwise_equal(one.second, two.second));
}

}  // namespace
}  // namespace rktsph
