// V2's mode-selective hourglass control (solver.velocity_update = "hourglass", method-notes
// §2.6): no work on a linear velocity field on a disordered moving set, and the nodal velocity
// and stress checkerboards that no stress point sees decay.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "../support/test_util.hpp"
#include "../support/v2_block.hpp"
#include "case/case_builder.hpp"
#include "schemes/hourglass_control.hpp"
#include "schemes/simulation.hpp"
#include "schemes/staggered_stages.hpp"

namespace rktsph {
namespace {

const HourglassControl<2>* control_of(const Simulation<2>& sim) {
  const auto* step = sim.scheme().find<NodeFullStep<2, MovingParticles, TaylorGalerkinVelocity>>();
  return step == nullptr ? nullptr : step->hourglass();
}

CaseSetup<2> hourglass_block(const std::string& name, double jitter = 0.0, bool stressed = false) {
  CaseBuilder<2> b = test::v2_block(name);
  if (jitter > 0.0) b.jitter(jitter, 7);
  if (stressed) b.initial_stress({-2.0e4, -1.0e4, -1.5e4, 3.0e3, 0.0, 0.0});
  b.gradient_floor(0.0);
  CaseSetup<2> c = b.build();
  c.simple_velocity = false;
  c.hourglass = true;
  c.detect_free_surface = false;
  return c;
}

TEST(V2Hourglass, DoesNoWorkOnALinearVelocityField) {
  const test::ThreadCount threads(1);
  // A disordered set (nodes and stress points jittered by 0.2 dx), uniform stress, a general
  // linear velocity (stretch, shear and spin). The free faces are not in equilibrium with the
  // stress, and a step carries their disturbance 4 h in (steps 1 and 2 each reach 2 h): after
  // one step the field is still linear beyond 6 h of the faces (4 h, and a pair's 2 h).
  Simulation<2> sim(hourglass_block("v2 block, linear velocity", 0.2, true));
  auto v = sim.mutable_node_velocity();
  const auto& x = sim.nodes().position;
  for (std::size_t i = 0; i < x.size(); ++i) {
    v(static_cast<Index>(i), 0) = 0.3 + 0.02 * x[i][0] + 0.05 * x[i][1];
    v(static_cast<Index>(i), 1) = -0.1 - 0.04 * x[i][0] + 0.01 * x[i][1];
  }
  const HourglassControl<2>* hg = control_of(sim);
  ASSERT_NE(hg, nullptr);
  double worst = 0.0, typical = 0.0;
  int inside = 0;
  const std::vector<Vec<2>> at_n = sim.nodes().position;
  sim.step();
  for (std::size_t i = 0; i < at_n.size(); ++i) {
    const double a = std::hypot(hg->acceleration(static_cast<Index>(i), 0), hg->acceleration(static_cast<Index>(i), 1));
    if (std::max(std::abs(at_n[i][0]), std::abs(at_n[i][1])) < 1.0 - 6.0 * 0.12) {
      worst = std::max(worst, a);
      ++inside;
    } else {
      typical = std::max(typical, a);
    }
  }
  std::printf("[ figures  ] linear velocity, jittered set: largest control acceleration inside %.2e m/s^2 (%d node-steps); "
              "beside the faces' waves %.2e\n",
              worst, inside, typical);
  EXPECT_GE(inside, 25);
  EXPECT_LT(worst, 1e-10 * typical);
}

TEST(V2Hourglass, LeavesARigidRotationAlone) {
  const test::ThreadCount threads(1);
  // No stress, a rigid spin about the centre on the jittered set: every field stays linear, so
  // the control does nothing anywhere and the kinetic energy is kept.
  CaseBuilder<2> b = test::v2_block("v2 block, spinning");
  b.jitter(0.2, 11).initial_velocity(Vec<2>(0.1, 0.0), 0.5, Vec<2>(0.0, 0.0)).gradient_floor(0.0);
  CaseSetup<2> c = b.build();
  c.simple_velocity = false;
  c.hourglass = true;
  c.detect_free_surface = false;
  Simulation<2> sim(c);
  const HourglassControl<2>* hg = control_of(sim);
  double worst = 0.0;
  const double k0 = sim.energy().kinetic;
  for (int n = 0; n < 20; ++n) {
    sim.step();
    worst = std::max(worst, std::abs(hg->kinetic_change()));
  }
  std::printf("[ figures  ] rigid rotation: the control's largest kinetic change a step %.2e of the kinetic energy\n",
              worst / k0);
  EXPECT_LT(worst, 1e-8 * k0);
}

// The interior amplitude of the node lattice's velocity checkerboard (seeded at 1e-6 m/s) after
// each step, with the hourglass control.
std::vector<double> checkerboard_history(int steps) {
  Simulation<2> sim(hourglass_block("v2 block, nodal checkerboard"));
  const std::vector<double> sign = test::lattice_checkerboard(sim.nodes().position);
  auto v = sim.mutable_node_velocity();
  for (std::size_t i = 0; i < sign.size(); ++i) {
    v(static_cast<Index>(i), 0) = sign[i] * 1e-6;
    v(static_cast<Index>(i), 1) = -sign[i] * 1e-6;
  }
  const std::vector<Vec<2>> start = sim.nodes().position;
  std::vector<double> amplitude;
  auto measure = [&] {
    const auto u = sim.node_velocity();
    const std::vector<Index> at = sim.nodes_by_id();
    double sum = 0.0;
    long count = 0;
    for (std::size_t k = 0; k < start.size(); ++k) {
      if (std::abs(start[k][0]) > 0.5 + 1e-9 || std::abs(start[k][1]) > 0.5 + 1e-9) continue;
      const Index i = at[k];
      sum += sign[k] * (u(i, 0) - u(i, 1));
      count += 2;
    }
    amplitude.push_back(std::abs(sum) / static_cast<double>(count));
  };
  measure();
  for (int n = 0; n < steps; ++n) {
    sim.step();
    measure();
  }
  return amplitude;
}

TEST(V2Hourglass, ANodalVelocityCheckerboardDecays) {
  const test::ThreadCount threads(1);
  const std::vector<double> a = checkerboard_history(60);
  // Taylor–Galerkin alone keeps the mode (the stress points see none of it); the control takes a
  // fixed share θ = ξ K (h/dx) C of it every step (method-notes §2.6: K = 2.00 on the 2D
  // lattice, ξ = 0.1, h = 1.2 dx, C = 0.5: θ = 0.12).
  const double first = a[1] / a[0];
  std::printf("[ figures  ] nodal velocity checkerboard: %.3f left after one step, %.2e after 60\n", first, a[60] / a[0]);
  EXPECT_NEAR(first, 1.0 - 0.12, 0.01);
  for (int n = 1; n <= 60; ++n) EXPECT_LE(a[n], a[n - 1] * (1.0 + 1e-9)) << n;
  EXPECT_LT(a[60] / a[0], 1e-3);
}

}  // namespace
}  // namespace rktsph

namespace rktsph {
namespace {

// Two elastic blocks of different sizes, one thrown at 2 m/s at the other at rest and offset
// sideways, under V2's default step, free: once their particles are within a kernel's reach they
// are one continuum (there is no contact between deformable bodies). The run must complete
// (the simple scheme's blew up, issue 49). The total momentum is not kept: it is printed
// (docs/VALIDATION.md, "V2's default step": 4.8 times the initial over 0.6 s; with the test
// edited, 0.1 with the free-surface detection off, 9 with the simple scheme): the corrected operators are not
// pair-antisymmetric (method-notes §3.2) and the faces that meet across a gap narrower than the
// kernel's reach are flagged and made traction-free while the other body's stress points still
// act on them.
TEST(V2Hourglass, CollidingBlocksRunThroughTheirCollision) {
  const test::ThreadCount threads(1);
  CaseBuilder<2> b("two blocks colliding");
  b.spacing(0.1)
      .origin(Vec<2>(0.0, 0.0))
      .block(Vec<2>(0.0, 0.0), Vec<2>(1.0, 1.0))
      .block(Vec<2>(1.2, 0.3), Vec<2>(1.8, 1.5))
      .elastic(1.0e7, 0.3, 2000.0)
      .scheme("v2")
      .time(0.6, 0.5);
  Simulation<2> sim(b.build());
  auto v = sim.mutable_node_velocity();
  double p0 = 0.0;
  for (Index i = 0; i < sim.nodes().size(); ++i) {
    const bool thrown = sim.nodes().position[static_cast<std::size_t>(i)][0] < 1.1;
    v(i, 0) = thrown ? 2.0 : 0.0;
    v(i, 1) = 0.0;
    p0 += sim.nodes().mass(i) * v(i, 0);
  }
  double worst = 0.0;
  while (sim.time() < 0.6) {
    sim.step();
    const auto u = sim.node_velocity();
    double px = 0.0, py = 0.0;
    for (Index i = 0; i < sim.nodes().size(); ++i) {
      px += sim.nodes().mass(i) * u(i, 0);
      py += sim.nodes().mass(i) * u(i, 1);
    }
    worst = std::max(worst, std::hypot(px - p0, py) / p0);
  }
  std::printf("[ figures  ] colliding blocks: largest |total momentum - initial| / initial %.3e over 0.6 s\n", worst);
  EXPECT_NEAR(sim.time(), 0.6, 1e-3);  // completed: a SolverError above fails the test first
}

}  // namespace
}  // namespace rktsph
