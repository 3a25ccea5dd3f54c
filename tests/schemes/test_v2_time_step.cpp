// V2's step from the current state (time.dt_rule = "current", method-notes eq. (4.3.3)):
// dt^n = C dx / max_i c_i(rho_i^n), c_i = c_m (rho_m / rho_i)^(1/2), recomputed before every step,
// the last step cut to end on time.end. Case 7's bar pulled at v0 = 0.2 C0 stretches to
// lambda ~ 1.5 once the fan has reflected from the fixed end, and its wave speed grows with it:
// at C = 1.3 the fixed step goes unstable there, the step from the current state does not.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "../support/test_util.hpp"
#include "case/case_builder.hpp"
#include "core/error.hpp"
#include "schemes/simulation.hpp"

namespace rktsph {
namespace {

constexpr double kE = 1.0e7, kRho = 2000.0, kLength = 10.0;
const double kC0 = std::sqrt(kE / kRho);

// Case 7 (cases.md): a 1D elastic bar, nu = 0 (M = E), the end X = 0 driven at v0, X = L held.
CaseSetup<1> bar(double v0, double end, double cfl, bool current, double gradient_floor = 0.05) {
  CaseBuilder<1> b("v2 bar, step from the current state");
  b.spacing(0.05)
      .block(Vec<1>(0.0), Vec<1>(kLength))
      .elastic(kE, 0.0, kRho)
      .prescribe_velocity(Region<1>::plane(0, 0.0), {{0, v0}})
      .fix_velocity(Region<1>::plane(0, kLength), {0})
      .scheme("v2")
      .time(end, cfl);
  if (current) b.step_from_current_state();
  b.gradient_floor(gradient_floor);
  return b.build();
}

// The fastest wave over both sets at their densities, independently of the model's own sum.
double fastest_wave(const Simulation<1>& sim) {
  double rho_min = kRho;
  for (const ParticleSet<1>* set : {&sim.nodes(), &sim.stress_points()}) {
    for (double rho : set->density) rho_min = std::min(rho_min, rho);
  }
  return std::sqrt(kE / rho_min);
}

TEST(V2TimeStep, EachStepFollowsTheCurrentDensityAndTheRunEndsOnTime) {
  const double end = 0.2, cfl = 0.8;
  Simulation<1> sim(bar(-0.2 * kC0, end, cfl, true));
  const double dx = 0.05;
  EXPECT_DOUBLE_EQ(sim.clock().initial_dt(), cfl * dx / kC0);
  double last_dt = 0.0;
  long steps = 0;
  while (sim.time() < end * (1.0 - 1e-12)) {
    const double expected = std::min(cfl * dx / fastest_wave(sim), end - sim.time());
    EXPECT_NEAR(sim.model().current_wave_speed(), fastest_wave(sim), 1e-12 * kC0);
    const double t0 = sim.time();
    sim.step();
    ++steps;
    ASSERT_NEAR(sim.dt(), expected, 1e-15 * expected) << "step " << steps;
    EXPECT_DOUBLE_EQ(sim.time(), t0 + sim.dt());
    last_dt = sim.dt();
    ASSERT_LT(steps, 10000);
  }
  // The pull stretches the bar (lambda = 1.21 behind the fan, cases.md Case 7, about 1.45 once
  // the fan has reflected from the fixed end at 0.14 s): the step falls by 1/sqrt(lambda) to
  // about 0.83 of the initial one, and the run ends exactly on time.end.
  EXPECT_DOUBLE_EQ(sim.time(), end);
  EXPECT_LT(sim.clock().dt_min(), 0.9 * sim.clock().initial_dt());
  EXPECT_GT(sim.clock().dt_min(), 0.75 * sim.clock().initial_dt());
  EXPECT_EQ(sim.clock().dt_max(), sim.clock().initial_dt());
  EXPECT_GT(last_dt, 0.0);
}

TEST(V2TimeStep, ThePulledBarAtCourant13IsStableOnlyWithTheStepFromTheCurrentState) {
  const double end = 0.5, cfl = 1.3;
  // Fixed step without the gradient floor: the reflected fan stretches the bar to lambda ~ 1.5,
  // the local Courant number C (lambda)^(1/2) passes the scheme's limit and the growth guard
  // stops the run (at 0.46 s).
  {
    Simulation<1> sim(bar(-0.2 * kC0, end, cfl, false, 0.0));
    EXPECT_THROW(
        {
          while (sim.time() < end * (1.0 - 1e-12)) sim.step();
        },
        SolverError);
    EXPECT_GT(sim.time(), 0.3);
  }
  // With it (V2's default) the stretched bar's rows (1.5 dx apart under h = 1.2 dx) are
  // regularised (method-notes eq. (3.2.6)) and the guard may not catch the growth before 0.5 s,
  // but the fixed step is no better: the velocities are not bounded by the waves (0.57 C0 at
  // 0.5 s, 2026-12-05, against 0.20 C0 with the step from the current state).
  {
    Simulation<1> sim(bar(-0.2 * kC0, end, cfl, false));
    bool stopped = false;
    try {
      while (sim.time() < end * (1.0 - 1e-12)) sim.step();
    } catch (const SolverError&) {
      stopped = true;
    }
    double vmax = 0.0;
    for (Index i = 0; i < sim.nodes().size(); ++i) vmax = std::max(vmax, std::abs(sim.node_velocity()(i, 0)));
    EXPECT_TRUE(stopped || vmax > 0.5 * kC0) << "vmax / C0 = " << vmax / kC0;
  }
  // From the current state: the same run completes, its steps shortened where it stretched.
  Simulation<1> sim(bar(-0.2 * kC0, end, cfl, true));
  while (sim.time() < end * (1.0 - 1e-12)) sim.step();
  EXPECT_DOUBLE_EQ(sim.time(), end);
  EXPECT_LT(sim.clock().dt_min(), 0.85 * sim.clock().initial_dt());
  double vmax = 0.0;
  for (Index i = 0; i < sim.nodes().size(); ++i) vmax = std::max(vmax, std::abs(sim.node_velocity()(i, 0)));
  EXPECT_LT(vmax, 0.5 * kC0);  // bounded: the piston's 0.2 C0 and the reflected waves
}

TEST(V2TimeStep, BitIdenticalOnOneAndTwoThreads) {
  auto run = [](int threads) {
    const test::ThreadCount count(threads);
    Simulation<1> sim(bar(0.2 * kC0, 0.1, 1.0, true));
    while (sim.time() < 0.1 * (1.0 - 1e-12)) sim.step();
    std::vector<double> state(sim.nodes().position.size());
    for (std::size_t i = 0; i < state.size(); ++i) state[i] = sim.nodes().position[i][0];
    state.push_back(sim.dt());
    state.push_back(static_cast<double>(sim.step_count()));
    return state;
  };
  EXPECT_EQ(run(1), run(2));
}

TEST(V2TimeStep, NeedsV2AndACourantNumber) {
  CaseBuilder<1> b("v1 with a step from the current state");
  b.spacing(0.05).block(Vec<1>(0.0), Vec<1>(1.0)).elastic(kE, 0.0, kRho).time(0.01, 0.5).step_from_current_state();
  EXPECT_THROW(b.build(), InputError);
  b.scheme("v2").time_step(0.01, 1e-5);
  EXPECT_THROW(b.build(), InputError);
}

}  // namespace
}  // namespace rktsph
