// V2's nodal stress update with the stress points' share beta (solver.simple_stress_weight,
// method-notes eq. (2.3.3)): sigma_I = (1 - beta) [the node's own full step] + beta [the stress
// points' stress at t^{n+1/2} interpolated to the node, rotated over the second half step, plus
// half a step's flux]. A nodal stress checkerboard, which no stress point sees on a lattice, is
// kept by the nodes' own step and loses the factor 1 - beta a step with the blend; a rigid
// rotation still rotates a uniform stress objectively.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "../support/test_util.hpp"
#include "../support/v2_block.hpp"
#include "case/case_builder.hpp"
#include "schemes/simulation.hpp"

namespace rktsph {
namespace {

// The interior amplitude of a nodal sigma_xx checkerboard (+-1 kPa) seeded in the V2 test block
// (2 m, elastic, free faces), over the nodes 0.5 m or more inside the faces, after each step.
std::vector<double> interior_stress_checkerboard(double beta, int steps) {
  CaseSetup<2> c = test::simple_scheme(test::v2_block("v2 block, nodal stress checkerboard").build());
  c.simple_stress_weight = beta;
  Simulation<2> sim(c);
  const std::vector<double> sign = test::lattice_checkerboard(sim.nodes().position);
  auto s = sim.mutable_node_stress();
  for (std::size_t i = 0; i < sign.size(); ++i) s(i, 0) = sign[i] * 1.0e3;
  const std::vector<Vec<2>> start = sim.nodes().position;
  std::vector<double> amplitude;
  auto measure = [&] {
    amplitude.push_back(test::interior_checkerboard_amplitude(sim, sign, start, StressComponent::xx, 1.0e3));
  };
  measure();
  for (int n = 0; n < steps; ++n) {
    sim.step();
    measure();
  }
  return amplitude;
}

TEST(V2StressBlend, ANodalStressCheckerboardLosesTheWeightEachStep) {
  const test::ThreadCount threads(1);
  // The nodes' own step keeps the mode: deep inside, the stress points see neither its value
  // nor its divergence, so nothing acts on it (what eq. (2.3.3) is for).
  const std::vector<double> kept = interior_stress_checkerboard(0.0, 20);
  std::printf("beta = 0: checkerboard left after 20 steps %.6f\n", kept[20]);
  EXPECT_GT(kept[20], 0.99);
  for (const double beta : {0.2, 0.5}) {
    const std::vector<double> a = interior_stress_checkerboard(beta, 20);
    // The stress points' part is zero deep inside: sigma <- (1 - beta) sigma.
    EXPECT_NEAR(a[1] / a[0], 1.0 - beta, 1e-6) << "beta = " << beta;
    std::printf("beta = %.2f: checkerboard left after 1 / 20 steps %.6f / %.3e (exact (1 - beta)^n: %.6f / %.3e)\n",
                beta, a[1] / a[0], a[20] / a[0], 1.0 - beta, std::pow(1.0 - beta, 20));
    // Until the little that the faces' rows, which do see the mode, send in.
    for (int n = 1; n <= 20; ++n)
      EXPECT_LT(a[n] / a[0], 1.05 * std::pow(1.0 - beta, n) + 1e-3) << "beta = " << beta << ", n = " << n;
  }
}

// Rigid rotation at omega about the origin, the velocity reset to omega x x before every step, a
// quarter turn in 8 steps of a 10 m block (the V2 test of the Jaumann rate, tests/schemes/
// test_v2.cpp, with the blend): the stress of the nodes within 0.5 m of the centre, which the
// faces' traction-free stress cannot reach in 8 steps (each step's interpolations spread it by at
// most 4.8 dx), is the initial one rotated by the angle turned, to round-off. The stress points'
// half step and the node's second half rotation compose to the node's full rotation.
TEST(V2StressBlend, AUniformStressStillRotatesObjectively) {
  const test::ThreadCount threads(1);
  const int steps = 8;
  CaseSetup<2> c = test::simple_scheme(test::rotation_block("v2 block, rigid rotation with the stress blend", steps).build());
  c.simple_stress_weight = 0.3;
  Simulation<2> sim(c);
  const test::RotationCheck r = test::spin_rigidly(sim, steps);
  ASSERT_NEAR(sim.time(), 1.0, 1e-12);  // a quarter turn
  ASSERT_GT(r.nodes, 80);
  EXPECT_LT(r.worst / 3.0e4, 1e-11) << "max stress error " << r.worst << " Pa";
}

}  // namespace
}  // namespace rktsph
