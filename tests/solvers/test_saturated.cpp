// V3 saturated solver (method-notes §2.4, §5.3; docs/cases.md C4): the pressure matrix is symmetric
// positive definite with a Dirichlet row, the PCG reaches the requested tolerance with both
// preconditioners, the undrained limit (k -> 0) gives p0 = q Q/(M+Q) and the undrained
// settlement, the time step is the drained skeleton's, and the drained limit (k -> infinity)
// reduces to the V1 solver.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <random>
#include <string>
#include <utility>

#include <fmt/format.h>
#include <Eigen/Dense>

#include "../support/test_util.hpp"
#include "../support/node_lattice.hpp"
#include "core/error.hpp"
#include "core/kernel.hpp"
#include "linear_solvers/pore_pressure.hpp"
#include "operators/laplacian.hpp"
#include "schemes/simulation.hpp"
#include "validation/analytic_saturated.hpp"

namespace rktsph {
namespace {

ParticleSet<2> grid(int n, int m, double dx) { return test::node_lattice(n, m, dx); }

PorePressureSolver::Settings settings(double inv_q_dt, PressurePreconditioner pc) {
  PorePressureSolver::Settings s;
  s.inv_q_dt = inv_q_dt;
  s.k_eff = 3e-7;
  s.tolerance = 1e-10;
  s.preconditioner = pc;
  s.deferred_correction = false;
  return s;
}

TEST(PorePressure, MatrixIsSymmetricPositiveDefiniteWithADirichletRow) {
  const auto s = grid(10, 8, 0.1);
  const auto lap = build_node_laplacian<2>(s, CubicSplineKernel<2>(0.12));
  std::vector<bool> drained(static_cast<std::size_t>(s.size()), false);
  for (std::size_t i = 0; i < drained.size(); ++i) drained[i] = s.position[i][1] > 0.8 - 1e-9;  // top row
  // Incompressible fluid (1/Q* = 0): only the Dirichlet row makes K definite.
  for (double inv_q_dt : {0.0, 1e-5}) {
    PorePressureSolver solver(lap.full, lap.symmetric, drained, settings(inv_q_dt, PressurePreconditioner::diagonal));
    EXPECT_EQ(solver.unknowns(), 11 * 8);
    const Eigen::MatrixXd K = Eigen::MatrixXd(solver.matrix());
    // K = I/(Q dt) - k_eff S on the free nodes (method-notes eq. (2.4.13)); S is symmetric
    // without mirror walls, so the solver's symmetrisation from the lower triangle changes
    // nothing and K equals the assembled matrix (to the row patterns' sharing tolerance).
    const Eigen::MatrixXd S = Eigen::MatrixXd(lap.symmetric);
    Eigen::MatrixXd expected(solver.unknowns(), solver.unknowns());
    for (int a = 0, ra = 0; a < S.rows(); ++a) {
      if (drained[static_cast<std::size_t>(a)]) continue;
      for (int b = 0, rb = 0; b < S.cols(); ++b) {
        if (drained[static_cast<std::size_t>(b)]) continue;
        expected(ra, rb++) = (a == b ? inv_q_dt : 0.0) - 3e-7 * S(a, b);
      }
      ++ra;
    }
    EXPECT_LT((K - expected).norm(), 1e-12 * K.norm());
    EXPECT_LT((K - K.transpose()).norm(), 1e-14 * K.norm());
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(K);
    EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0) << "1/(Q dt) = " << inv_q_dt;
    const Eigen::LLT<Eigen::MatrixXd> llt(K);
    EXPECT_EQ(llt.info(), Eigen::Success);
  }
  // Without any Dirichlet row and with 1/Q* = 0, K is singular (constant null vector): the
  // check above can fail.
  std::vector<bool> none(drained.size(), false);
  PorePressureSolver floating(lap.full, lap.symmetric, none, settings(0.0, PressurePreconditioner::diagonal));
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Eigen::MatrixXd(floating.matrix()));
  EXPECT_LT(std::abs(eig.eigenvalues().minCoeff()), 1e-10 * eig.eigenvalues().maxCoeff());
}

TEST(PorePressure, AnUnsymmetricAssembledMatrixIsSymmetrisedFromItsLowerTriangle) {
  // Mirror walls seen by some nodes only (as near a drained corner, method-notes §2.4 "Storage"):
  // the assembled S, hence K, is unsymmetric; the solver keeps K's lower triangle and mirrors it.
  const auto s = grid(10, 8, 0.1);
  const std::vector<MirrorPlane> walls = {{0, 0.0, -1}};
  std::vector<std::uint8_t> mask(static_cast<std::size_t>(s.size()), 0);
  for (std::size_t i = 0; i < mask.size(); ++i) mask[i] = s.position[i][1] < 0.35 ? 1 : 0;
  const auto lap = build_node_laplacian<2>(s, CubicSplineKernel<2>(0.12), {}, walls, mask);
  const Eigen::MatrixXd S = Eigen::MatrixXd(lap.symmetric);
  ASSERT_GT((S - S.transpose()).norm(), 1e-3 * S.norm());  // the case this test is about
  std::vector<bool> drained(static_cast<std::size_t>(s.size()), false);
  for (std::size_t i = 0; i < drained.size(); ++i) drained[i] = s.position[i][1] > 0.8 - 1e-9;
  PorePressureSolver solver(lap.full, lap.symmetric, drained, settings(1e-5, PressurePreconditioner::diagonal));
  const Eigen::MatrixXd K = Eigen::MatrixXd(solver.matrix());
  EXPECT_LT((K - K.transpose()).norm(), 1e-14 * K.norm());
  for (int a = 0, ra = 0; a < S.rows(); ++a) {
    if (drained[static_cast<std::size_t>(a)]) continue;
    for (int b = 0, rb = 0; b <= a; ++b) {
      if (drained[static_cast<std::size_t>(b)]) continue;
      EXPECT_NEAR(K(ra, rb++), (a == b ? 1e-5 : 0.0) - 3e-7 * S(a, b), 1e-12 * K.norm());
    }
    ++ra;
  }
}

TEST(PorePressure, ConjugateGradientReachesTheRequestedTolerance) {
  const auto s = grid(20, 16, 0.05);
  const auto lap = build_node_laplacian<2>(s, CubicSplineKernel<2>(0.06));
  std::vector<bool> drained(static_cast<std::size_t>(s.size()), false);
  for (std::size_t i = 0; i < drained.size(); ++i) drained[i] = s.position[i][1] > 0.8 - 1e-9;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> source(drained.size()), p_old(drained.size(), 0.0);
  for (double& v : source) v = u(rng);
  for (auto pc : {PressurePreconditioner::diagonal, PressurePreconditioner::incomplete_cholesky}) {
    PorePressureSolver solver(lap.full, lap.symmetric, drained, settings(1e-6, pc));
    std::vector<double> p(drained.size(), 0.0);  // drained value 0
    solver.solve(source, p_old, p);
    // Independent residual over the free nodes: K x - b with b = source (drained values 0).
    Eigen::VectorXd x(solver.unknowns()), b(solver.unknowns());
    Index r = 0;
    for (std::size_t i = 0; i < drained.size(); ++i) {
      if (drained[i]) continue;
      x[r] = p[i];
      b[r] = source[i];
      ++r;
    }
    const double rel = (Eigen::VectorXd(solver.matrix() * x) - b).norm() / b.norm();
    EXPECT_LE(rel, 1e-10 * 1.01);
    EXPECT_GT(solver.stats().last_iterations, 0);
    EXPECT_LE(solver.stats().last_error, 1e-10);
  }
}

// The 1D column of docs/cases.md Case 13 (H = 10 m unless given), as a V3 case.
std::string column(double H, double dx, double conductivity, const std::string& load, double end,
                   const std::string& top_pressure = "pore_pressure = 0.0",
                   const std::string& base_pressure = "impermeable = true") {
  return fmt::format(R"(
[geometry]
dimension = 1
spacing = {dx}
[[geometry.block]]
min = [0.0]
max = [{H}]
[material]
model = "elastic"
E = 3.0e7
nu = 0.2
density = 1700.0
[fluid]
porosity = 0.3
density = 1000.0
bulk_modulus = 1.0e8
conductivity = {k}
[solver]
version = "v3"
[functions.load]
{load}
[[boundary]]
name = "base"
x = [0.0, 0.0]
velocity = {{ x = 0.0 }}
{base}
[[boundary]]
name = "top"
x = [{H}, {H}]
stress = {{ xx = -5.0e3 }}
{top}
function = "load"
[time]
end = {end}
cfl = 0.5
)",
                     fmt::arg("dx", dx), fmt::arg("H", H), fmt::arg("k", conductivity), fmt::arg("load", load),
                     fmt::arg("end", end), fmt::arg("top", top_pressure), fmt::arg("base", base_pressure));
}

constexpr double kM = 3.0e7 * 0.8 / (1.2 * 0.6), kQ = 1.0e8 / 0.3, kRho = 1700.0;

// k = 0 and no drained face: the load, a total stress on the (impermeable) top, is carried by
// the pore pressure p0 = q Q/(M+Q) and the skeleton q M/(M+Q) (docs/cases.md Case 13). (A drained
// top with k = 0 is singular: p jumps from p0 to 0 there, and the scheme spreads the jump
// over a few dx.) Means over 2-3 s (after a 2 s load ramp) remove the free vibration.
struct UndrainedColumn {
  double dt = 0.0, wave_speed = 0.0;
  double p_mid = 0.0, settlement = 0.0, p_top = 0.0, sigma_mid = 0.0;  // p, u: means over 2-3 s
};

UndrainedColumn run_undrained_column(const std::vector<std::string>& overrides) {
  test::ThreadCount one(1);
  test::TempDir dir;
  auto setup = test::case_from_string<1>(
      dir, column(10.0, 0.1, 0.0, "type = \"ramp\"\nduration = 2.0", 3.0, "impermeable = true"), overrides);
  Simulation<1> solver(setup);
  UndrainedColumn out;
  out.dt = solver.dt();
  out.wave_speed = solver.max_wave_speed();
  const auto& nodes = solver.nodes();
  std::size_t mid = 0, top = 0;
  for (std::size_t i = 0; i < static_cast<std::size_t>(nodes.size()); ++i) {
    if (std::abs(nodes.position[i][0] - 5.0) < 1e-9) mid = i;
    if (std::abs(nodes.position[i][0] - 10.0) < 1e-9) top = i;
  }
  long count = 0;
  while (solver.time() < 3.0 - 1e-9) {
    solver.step();
    if (solver.time() >= 2.0) {
      out.p_mid += solver.node_pore_pressure()[mid];
      out.settlement += -solver.node_displacement()(top, 0);
      ++count;
    }
  }
  out.p_mid /= static_cast<double>(count);
  out.settlement /= static_cast<double>(count);
  out.p_top = solver.node_pore_pressure()[top];
  out.sigma_mid = solver.node_stress()(mid, StressComponent::xx);
  return out;
}

constexpr double kP0 = 5.0e3 * kQ / (kM + kQ), kS0 = 5.0e3 * 10.0 / (kM + kQ);

TEST(Saturated, UndrainedLimitGivesTheUndrainedResponse) {
  const UndrainedColumn r = run_undrained_column({});
  // The time step is the drained skeleton's: C dx / sqrt(M/rho), not the undrained sqrt((M+Q)/rho).
  EXPECT_NEAR(r.dt, 0.5 * 0.1 / std::sqrt(kM / kRho), 1e-12);
  EXPECT_NEAR(r.wave_speed, std::sqrt(kM / kRho), 1e-9);
  EXPECT_NEAR(r.p_mid, kP0, 0.01 * kP0);
  EXPECT_NEAR(r.settlement, kS0, 0.03 * kS0);
  EXPECT_NEAR(r.p_top, kP0, 0.05 * kP0);
  // The effective stress carries the rest, q M/(M+Q).
  EXPECT_NEAR(r.sigma_mid, -5.0e3 * kM / (kM + kQ), 0.1 * 5.0e3 * kM / (kM + kQ));
}

// With water's bulk modulus (K_f = 2.2 GPa: C c_u/c_d = 7.4 at C = 0.5) the impermeable loaded
// top was unstable within 8 steps with the explicit face condition; with the implicit one it runs
// the 3 s (about 600 transits of the undrained wave) to the undrained response.
TEST(Saturated, StiffWaterUnderAnImpermeableLoadedFaceRunsAtTheDrainedStep) {
  const UndrainedColumn r = run_undrained_column({"fluid.bulk_modulus=2.2e9"});
  const double q = 2.2e9 / 0.3, p0 = 5.0e3 * q / (kM + q);
  EXPECT_NEAR(r.dt, 0.5 * 0.1 / std::sqrt(kM / kRho), 1e-12);
  EXPECT_NEAR(r.p_mid, p0, 0.001 * p0);
  EXPECT_NEAR(r.p_top, p0, 0.01 * p0);
  EXPECT_NEAR(r.settlement, 5.0e3 * 10.0 / (kM + q), 0.05 * 5.0e3 * 10.0 / (kM + q));
  EXPECT_THROW(run_undrained_column({"fluid.bulk_modulus=2.2e9", "solver.pressure_faces=explicit"}), SolverError);
}

// The same column with the storage equation driven by the stress points' velocity
// (solver.pressure_divergence = "stress_points", half the stabilisation): stable at k = 0 with
// the drained skeleton's time step, and the same undrained response.
TEST(Saturated, StressPointDivergenceKeepsTheUndrainedResponse) {
  const UndrainedColumn r = run_undrained_column({"solver.pressure_divergence=stress_points"});
  EXPECT_NEAR(r.dt, 0.5 * 0.1 / std::sqrt(kM / kRho), 1e-12);
  EXPECT_NEAR(r.p_mid, kP0, 0.01 * kP0);
  EXPECT_NEAR(r.settlement, kS0, 0.03 * kS0);
  EXPECT_NEAR(r.p_top, kP0, 0.05 * kP0);
}

// Why the reader rejects pressure_incremental with pressure_divergence = "stress_points": the
// undrained column of the test above, with the combination forced past the reader, diverges
// (the growth guard stops it) well before the 3 s the stable forms run.
TEST(Saturated, IncrementalProjectionWithStressPointDivergenceIsUnstable) {
  test::ThreadCount one(1);
  test::TempDir dir;
  auto setup = test::case_from_string<1>(
      dir, column(10.0, 0.1, 0.0, "type = \"ramp\"\nduration = 2.0", 3.0, "impermeable = true"),
      {"solver.pressure_divergence=stress_points"});
  ASSERT_FALSE(setup.fluid.incremental);  // the reader's default with that divergence
  setup.fluid.incremental = true;
  Simulation<1> solver(setup);
  double stopped_at = -1.0;
  try {
    while (solver.time() < 3.0 - 1e-9) solver.step();
  } catch (const SolverError&) {
    stopped_at = solver.time();
  }
  EXPECT_GT(stopped_at, 0.0) << "the combination ran to the end: the reader's rejection needs revisiting";
  EXPECT_LT(stopped_at, 1.0);
}

TEST(Saturated, DrainedLimitReducesToV1) {
  test::ThreadCount one(1);
  test::TempDir dir;
  // A 1 m column drained at both ends, smooth load; V1 with the same (mixture) density.
  const std::string load = "type = \"smoothstep\"\nduration = 0.02";
  const double end = 0.05;
  auto run = [&](const std::string& text, bool v3) {
    auto setup = test::case_from_string<1>(dir, text, {}, v3 ? "v3.toml" : "v1.toml");
    Simulation<1> solver(setup);
    while (solver.time() < end - 1e-12) solver.step();
    std::vector<double> out;
    for (std::size_t i = 0; i < static_cast<std::size_t>(solver.nodes().size()); ++i) {
      out.push_back(solver.node_stress()(i, StressComponent::xx));  // sigma'_xx (V3) or sigma_xx (V1)
    }
    return out;
  };
  std::string v1 = column(1.0, 0.05, 0.0, load, end, "", "");
  v1.replace(v1.find("[fluid]"), v1.find("[functions.load]") - v1.find("[fluid]"), "");
  // (the [fluid] and [solver] tables are gone: a V1 case)
  const auto ref = run(v1, false);
  double scale = 0.0;
  for (double v : ref) scale = std::max(scale, std::abs(v));
  double previous = 1e300;
  for (double k : {0.1, 1.0, 10.0}) {
    const auto sat = run(column(1.0, 0.05, k, load, end, "pore_pressure = 0.0", "pore_pressure = 0.0"), true);
    double diff = 0.0;
    for (std::size_t i = 0; i < ref.size(); ++i) diff = std::max(diff, std::abs(sat[i] - ref[i]));
    diff /= scale;
    EXPECT_LT(diff, previous) << "k = " << k;  // the difference falls as k grows
    previous = diff;
  }
  EXPECT_LT(previous, 0.01);
}

// The Terzaghi reference of Case 13 under a smoothstep load: each mode's convolution with the
// load history (both branches: Gauss-Legendre for a ramp < 1, integration by parts above)
// against a fine composite Simpson sum, during and after the rise; and the linear ramp against
// its own closed form the same way.
TEST(Saturated, TerzaghiReferenceConvolvesTheLoadHistoryExactly) {
  analytic::SaturatedColumn col;
  col.constrained = 3.0e7 * 0.8 / (1.2 * 0.6);
  col.storage = 1.0e8 / 0.3;
  col.permeability = 1.0e-3 / (1000.0 * 9.81);
  col.density = 1700.0;
  for (const auto rise : {TimeFunction::Kind::ramp, TimeFunction::Kind::smoothstep}) {
    const analytic::Terzaghi ref{col, 5.0e3, 0.5, rise};
    for (double a : {1e-3, 0.0762, 1.0, 1.99, 2.01, 7.0, 60.0, 4.9e4}) {
      for (double t : {0.1, 0.25, 0.49, 0.5, 0.8, 3.0}) {
        // Simpson over tau in [0, min(t, ramp)] of f'(tau) exp(-a (t - tau)), f' by central differences
        // of the load fraction is not accurate enough: use its closed form.
        auto dfdt = [&](double tau) {
          const double s = tau / 0.5;
          return rise == TimeFunction::Kind::ramp ? 1.0 / 0.5 : 30.0 * s * s * (1.0 - s) * (1.0 - s) / 0.5;
        };
        const double end = std::min(t, 0.5);
        const int n = 200000;
        const double h = end / n;
        double sum = 0.0;
        for (int i = 0; i <= n; ++i) {
          const double w = (i == 0 || i == n) ? 1.0 : (i % 2 == 1 ? 4.0 : 2.0);
          const double tau = i * h;
          sum += w * dfdt(tau) * std::exp(-a * (t - tau));
        }
        sum *= h / 3.0;
        EXPECT_NEAR(ref.ramp_factor(a, t), sum, 1e-10 * std::max(1.0, std::abs(sum)))
            << "rise " << static_cast<int>(rise) << ", a = " << a << ", t = " << t;
      }
    }
    // Fully loaded and fully drained: no pressure, the final settlement; at a = 0 the history's
    // weight is the load fraction.
    EXPECT_NEAR(ref.ramp_factor(1e-12, 0.3), ref.fraction(0.3), 1e-9);
    EXPECT_NEAR(ref.pressure(5.0, 1e4), 0.0, 1e-9);
    EXPECT_NEAR(ref.settlement(1e4) / ref.final_settlement(), 1.0, 1e-9);
  }
  const analytic::Terzaghi smooth{col, 5.0e3, 0.5, TimeFunction::Kind::smoothstep};
  EXPECT_DOUBLE_EQ(smooth.fraction(0.25), 0.5);
  EXPECT_DOUBLE_EQ(smooth.fraction(0.6), 1.0);
}

// A 4 m column of the mixture above (any dimension, the last axis vertical, a drained top
// loaded by 5 kPa over a 0.5 s ramp) run to 3 s: the largest |p_w - Terzaghi| over its nodes,
// walls and corners included, over p0.
template <int Dim>
double consolidate_against_terzaghi(const test::TempDir& dir, const std::string& text) {
  Simulation<Dim> solver(test::case_from_string<Dim>(dir, text));
  while (solver.time() < 3.0 - 1e-9) solver.step();
  analytic::SaturatedColumn col;
  col.height = 4.0;
  col.constrained = kM;
  col.storage = kQ;
  col.permeability = 1.0e-3 / (1000.0 * 9.81);
  col.density = kRho;
  const analytic::Terzaghi ref{col, 5.0e3, 0.5};
  const double p0 = 5.0e3 * col.skempton();
  double worst = 0.0;
  const auto& nodes = solver.nodes();
  for (std::size_t i = 0; i < static_cast<std::size_t>(nodes.size()); ++i) {
    const double depth = 4.0 - nodes.position[i][Dim - 1];
    worst = std::max(worst, std::abs(solver.node_pore_pressure()[i] - ref.pressure(depth, solver.time())) / p0);
  }
  return worst;
}

TEST(Saturated, TwoDimensionalStripConsolidatesLikeTerzaghi) {
  // A 2D strip (0.6 m wide, 4 m high, lateral rollers and impermeable walls) is a 1D column:
  // the mirror images at the side walls (laplacian.hpp) must leave the consolidation 1D.
  // Without them the wall rows over-estimate the Laplacian by half (Schwaiger's isotropic
  // normalisation on a one-sided support) and the strip drained ~25 % too fast.
  test::ThreadCount one(1);
  test::TempDir dir;
  const std::string text = R"(
[geometry]
dimension = 2
spacing = 0.2
[[geometry.block]]
min = [0.0, 0.0]
max = [0.6, 4.0]
[material]
model = "elastic"
E = 3.0e7
nu = 0.2
density = 1700.0
[fluid]
porosity = 0.3
density = 1000.0
bulk_modulus = 1.0e8
conductivity = 1.0e-3
[solver]
version = "v3"
[functions.load]
type = "ramp"
duration = 0.5
[[boundary]]
name = "left"
x = [0.0, 0.0]
velocity = { x = 0.0 }
[[boundary]]
name = "right"
x = [0.6, 0.6]
velocity = { x = 0.0 }
[[boundary]]
name = "base"
y = [0.0, 0.0]
velocity = { x = 0.0, y = 0.0 }
impermeable = true
[[boundary]]
name = "top"
y = [4.0, 4.0]
stress = { yy = -5.0e3, xy = 0.0 }
pore_pressure = 0.0
function = "load"
[time]
end = 3.0
cfl = 0.5
)";
  const double worst = consolidate_against_terzaghi<2>(dir, text);
  // T_v = 0.58: every node, walls and corners included, within 2 % of p0.
  EXPECT_LT(worst, 0.02);
}

// The same strip as a 3D prism (0.6 m x 0.6 m x 4 m, rollers and impermeable walls on all four
// sides): still a 1D column, in the mirror images of two pairs of walls and along their edges.
TEST(Saturated, ThreeDimensionalPrismConsolidatesLikeTerzaghi) {
  test::ThreadCount one(1);
  test::TempDir dir;
  const std::string text = R"(
[geometry]
dimension = 3
spacing = 0.2
[[geometry.block]]
min = [0.0, 0.0, 0.0]
max = [0.6, 0.6, 4.0]
[material]
model = "elastic"
E = 3.0e7
nu = 0.2
density = 1700.0
[fluid]
porosity = 0.3
density = 1000.0
bulk_modulus = 1.0e8
conductivity = 1.0e-3
[solver]
version = "v3"
[functions.load]
type = "ramp"
duration = 0.5
[[boundary]]
name = "x_walls"
x = [0.0, 0.0]
velocity = { x = 0.0 }
[[boundary]]
name = "x_walls_far"
x = [0.6, 0.6]
velocity = { x = 0.0 }
[[boundary]]
name = "y_walls"
y = [0.0, 0.0]
velocity = { y = 0.0 }
[[boundary]]
name = "y_walls_far"
y = [0.6, 0.6]
velocity = { y = 0.0 }
[[boundary]]
name = "base"
z = [0.0, 0.0]
velocity = { x = 0.0, y = 0.0, z = 0.0 }
impermeable = true
[[boundary]]
name = "top"
z = [4.0, 4.0]
stress = { zz = -5.0e3, xz = 0.0, yz = 0.0 }
pore_pressure = 0.0
function = "load"
[time]
end = 3.0
cfl = 0.5
)";
  const double worst = consolidate_against_terzaghi<3>(dir, text);
  std::printf("3D prism at T_v = 0.58: largest |p_w - Terzaghi| / p0 = %.4f\n", worst);
  EXPECT_LT(worst, 0.02);
}

// An undrained strip (0.6 m wide, 4 m high, lateral rollers, fixed base, every face
// impermeable, k = 0) loaded by its own weight: p_w must carry Q/(M+Q) of the total vertical
// stress, -gamma (H - y), and keep it while the weight is held. The non-incremental projection
// imposes dp/dn = 0 at the walls on the stabilisation (dt/rho) L p as well, while the load needs
// dp/dy = -gamma Q/(M+Q) there: the mismatch leaks pore pressure through the "impermeable" base
// whatever k is (docs/cases.md Case 17 showed it). The incremental variant (solver.pressure_incremental)
// puts the stabilisation on p^{n+1} - p^n only and removes most of the leak; what is left
// (base p_w 0.97 -> 0.94 of the undrained value from 1 to 3 s at dx = 0.2 m, against 0.81 ->
// 0.66 non-incremental) is not explained yet.
// The elastic mixture of the column tests with k = 0, and the pressure options.
// rate: solver.pressure_divergence ("nodes" unless named: the projection variants of these
// tests are those of the nodal storage rate, method-notes §2.4).
std::string undrained_mixture(bool incremental, double filter, double odd_even = 0.0, const char* rate = "nodes") {
  return fmt::format(R"([material]
model = "elastic"
E = 3.0e7
nu = 0.2
density = 1700.0
[fluid]
porosity = 0.3
density = 1000.0
bulk_modulus = 1.0e8
conductivity = 0.0
[solver]
version = "v3"
pressure_incremental = {}
pressure_filter = {}
pressure_odd_even_filter = {}
pressure_divergence = "{}")",
                     incremental ? "true" : "false", filter, odd_even, rate);
}

std::vector<double> undrained_strip_base_pressure(bool incremental, double filter = 0.0, double odd_even = 0.0,
                                                  const char* rate = "nodes") {
  test::ThreadCount one(1);
  test::TempDir dir;
  const std::string text = fmt::format(R"(
[geometry]
dimension = 2
spacing = 0.2
[[geometry.block]]
min = [0.0, 0.0]
max = [0.6, 4.0]
{mixture}
[functions.ramp]
type = "ramp"
duration = 0.5
[body_force]
gravity = [0.0, -9.81]
function = "ramp"
[damping]
coefficient = 20.0
[[boundary]]
name = "left"
x = [0.0, 0.0]
velocity = {{ x = 0.0 }}
[[boundary]]
name = "right"
x = [0.6, 0.6]
velocity = {{ x = 0.0 }}
[[boundary]]
name = "base"
y = [0.0, 0.0]
velocity = {{ x = 0.0, y = 0.0 }}
[time]
end = 3.0
cfl = 0.5
)",
                                       fmt::arg("mixture", undrained_mixture(incremental, filter, odd_even, rate)));
  auto setup = test::case_from_string<2>(dir, text);
  Simulation<2> solver(setup);
  const auto& nodes = solver.nodes();
  std::size_t base = 0;
  for (std::size_t i = 0; i < static_cast<std::size_t>(nodes.size()); ++i) {
    if (std::abs(nodes.position[i][0] - 0.2) < 1e-9 && nodes.position[i][1] < 1e-9) base = i;
  }
  std::vector<double> out;  // p_w at the base at t = 1, 2, 3 s
  for (double t : {1.0, 2.0, 3.0}) {
    while (solver.time() < t - 1e-9) solver.step();
    out.push_back(solver.node_pore_pressure()[base]);
  }
  return out;
}

TEST(Saturated, IncrementalProjectionReducesTheUndrainedPressureLeakUnderGravity) {
  const double p_ref = kQ / (kM + kQ) * kRho * 9.81 * 4.0;  // undrained p_w at the base
  const auto inc = undrained_strip_base_pressure(true);
  const auto non = undrained_strip_base_pressure(false);  // the non-incremental form, method-notes §2.4
  for (double p : inc) EXPECT_NEAR(p, p_ref, 0.07 * p_ref);
  // Over the hold (1 -> 3 s) the incremental variant loses about a fifth of what the
  // non-incremental one loses (measured: 3.1 % against 14.8 % of the reference).
  EXPECT_LT(inc[0] - inc[2], 0.25 * (non[0] - non[2]));
  EXPECT_GT(non[0] - non[2], 0.1 * p_ref);  // the leak of the default, on record
  RecordProperty("non_incremental_base_pw_over_ref_at_3s", std::to_string(non[2] / p_ref));
  std::cerr << fmt::format(
      "undrained strip, base p_w / reference at t = 1, 2, 3 s: incremental {:.4f} {:.4f} {:.4f}, "
      "non-incremental {:.4f} {:.4f} {:.4f}\n",
      inc[0] / p_ref, inc[1] / p_ref, inc[2] / p_ref, non[0] / p_ref, non[1] / p_ref, non[2] / p_ref);
}

TEST(Saturated, PressureFilterKeepsTheUndrainedPressureUnderGravity) {
  // The linear-exact filter (solver.pressure_filter) vanishes on the linear p_w that self-weight
  // imposes at the impermeable base, so it adds no leak to the incremental projection.
  const double p_ref = kQ / (kM + kQ) * kRho * 9.81 * 4.0;
  const auto inc = undrained_strip_base_pressure(true);
  const auto fil = undrained_strip_base_pressure(true, 1.0);
  for (std::size_t k = 0; k < fil.size(); ++k) EXPECT_NEAR(fil[k], inc[k], 0.01 * p_ref);
  std::cerr << fmt::format(
      "undrained strip, base p_w / reference at t = 1, 2, 3 s: incremental + filter {:.4f} {:.4f} {:.4f}\n",
      fil[0] / p_ref, fil[1] / p_ref, fil[2] / p_ref);
}

TEST(Saturated, OddEvenFilterKeepsTheUndrainedPressureUnderGravity) {
  // The odd-even filter (solver.pressure_odd_even_filter, method-notes eq. (2.4.19)) is zero on
  // every quadratic field, so it adds no leak at the impermeable base either.
  const double p_ref = kQ / (kM + kQ) * kRho * 9.81 * 4.0;
  const auto inc = undrained_strip_base_pressure(true);
  const auto oe = undrained_strip_base_pressure(true, 0.0, 0.5);
  for (std::size_t k = 0; k < oe.size(); ++k) EXPECT_NEAR(oe[k], inc[k], 0.01 * p_ref);
}

// The consistent storage rate (the default, method-notes eq. (2.4.20)) is built on the
// incremental projection and keeps its cure of the wall leak: the base p_w of the undrained strip
// under self-weight holds over the hold as the nodal form's does.
TEST(Saturated, ConsistentStorageRateKeepsTheUndrainedPressureUnderGravity) {
  const double p_ref = kQ / (kM + kQ) * kRho * 9.81 * 4.0;
  const auto consistent = undrained_strip_base_pressure(true, 0.0, 1.0, "consistent");
  const auto nodes = undrained_strip_base_pressure(true, 0.0, 1.0, "nodes");
  for (double p : consistent) EXPECT_NEAR(p, p_ref, 0.03 * p_ref);
  EXPECT_LT(std::abs(consistent[0] - consistent[2]), 0.01 * p_ref);
  std::cerr << fmt::format(
      "undrained strip, base p_w / reference at t = 1, 2, 3 s: consistent {:.4f} {:.4f} {:.4f}, nodes {:.4f} "
      "{:.4f} {:.4f}\n",
      consistent[0] / p_ref, consistent[1] / p_ref, consistent[2] / p_ref, nodes[0] / p_ref, nodes[1] / p_ref,
      nodes[2] / p_ref);
}

// Largest odd-even (checkerboard) amplitude of p_w over the nodes of a lattice block.
double checkerboard_amplitude(const Simulation<2>& solver, double dx) {
  const auto& nodes = solver.nodes();
  double sum = 0.0;
  for (std::size_t i = 0; i < static_cast<std::size_t>(nodes.size()); ++i) {
    const auto ix = std::lround(nodes.position[i][0] / dx), iy = std::lround(nodes.position[i][1] / dx);
    sum += ((ix + iy) % 2 == 0 ? 1.0 : -1.0) * solver.node_pore_pressure()[i];
  }
  return std::abs(sum) / static_cast<double>(nodes.size());
}

double checkerboard_left_after(bool incremental, double filter, int steps, double odd_even = 0.0,
                               const char* rate = "nodes") {
  test::ThreadCount one(1);
  test::TempDir dir;
  const std::string text = fmt::format(R"(
[geometry]
dimension = 2
spacing = 0.1
[[geometry.block]]
min = [0.0, 0.0]
max = [1.0, 1.0]
{mixture}
[[boundary]]
name = "sides"
x = [0.0, 0.0]
velocity = {{ x = 0.0 }}
[[boundary]]
name = "right"
x = [1.0, 1.0]
velocity = {{ x = 0.0 }}
[[boundary]]
name = "base"
y = [0.0, 0.0]
velocity = {{ y = 0.0 }}
[[boundary]]
name = "top"
y = [1.0, 1.0]
velocity = {{ y = 0.0 }}
[time]
end = 1.0
cfl = 0.5
)",
                                       fmt::arg("mixture", undrained_mixture(incremental, filter, odd_even, rate)));
  auto setup = test::case_from_string<2>(dir, text);
  Simulation<2> solver(setup);
  const auto& nodes = solver.nodes();
  auto pw = solver.mutable_node_pore_pressure();
  for (std::size_t i = 0; i < pw.size(); ++i) {
    const auto ix = std::lround(nodes.position[i][0] / 0.1), iy = std::lround(nodes.position[i][1] / 0.1);
    pw[i] = (ix + iy) % 2 == 0 ? 1.0e3 : -1.0e3;
  }
  const double a0 = checkerboard_amplitude(solver, 0.1);
  for (int n = 0; n < steps; ++n) solver.step();
  return checkerboard_amplitude(solver, 0.1) / a0;
}

TEST(Saturated, OddEvenFilterDampsTheCheckerboardThatTheIncrementalProjectionKeeps) {
  // alpha = 0.5 halves the mode each step on every row, faces and corners included.
  const double left = checkerboard_left_after(true, 0.0, 20, 0.5);
  EXPECT_LT(left, 1e-3);
  std::cerr << fmt::format("checkerboard left after 20 steps with the odd-even filter at 0.5: {:.3g}\n", left);
}

TEST(Saturated, OddEvenFilterDampsTheCheckerboardUnderTheConsistentStorageRate) {
  // Without the filter the consistent form keeps the mode (it exerts no force and the stress
  // points' divergence does not see it); with the default filter it is gone.
  const double kept = checkerboard_left_after(true, 0.0, 20, 0.0, "consistent");
  const double filtered = checkerboard_left_after(true, 0.0, 20, 1.0, "consistent");
  EXPECT_GT(kept, 0.5);
  EXPECT_LT(filtered, 1e-3);  // as the nodal form with alpha = 0.5 (measured 7e-4)
  std::cerr << fmt::format("checkerboard left after 20 steps, consistent rate: no filter {:.3g}, filter 1 {:.3g}\n",
                           kept, filtered);
}

TEST(Saturated, PressureFilterDampsTheCheckerboardThatTheIncrementalProjectionKeeps) {
  // An odd-even p_w mode in a closed, undrained box: the corrected gradient does not see it, so
  // it exerts no force and nothing but the pressure equation's stabilisation can remove it.
  const double incremental = checkerboard_left_after(true, 0.0, 20);
  const double filtered = checkerboard_left_after(true, 1.0, 20);
  const double projection = checkerboard_left_after(false, 0.0, 20);  // method-notes §2.4
  EXPECT_GT(incremental, 0.5);
  EXPECT_LT(filtered, 0.01);
  EXPECT_LT(projection, 0.01);
  std::cerr << fmt::format(
      "checkerboard left after 20 steps: incremental {:.3g}, incremental + filter {:.3g}, "
      "non-incremental {:.3g}\n",
      incremental, filtered, projection);
}

// A plane-strain sample with K_f = 2.2 GPa, impermeable faces, a lateral TOTAL stress (the
// configuration of Case 16), its top driven down. Returns the growth guard's message (empty if
// the run finished), the largest |v| or |sigma|, and the centre's pore pressure at the end.
struct SampleRun {
  std::string message;
  double largest = 0.0;
  double centre_pressure = 0.0;
};

SampleRun run_loaded_impermeable_sample(double cfl, const std::string& faces, double end) {
  {
    test::ThreadCount one(1);
    test::TempDir dir;
    const std::string text = fmt::format(R"(
[geometry]
dimension = 2
spacing = 0.04
[[geometry.block]]
min = [0.0, 0.0]
max = [0.4, 0.4]
[material]
model = "elastic"
E = 2.0e7
nu = 0.3
density = 2000.0
[fluid]
porosity = 0.4
density = 1000.0
bulk_modulus = 2.2e9
conductivity = 1.0e-9
[solver]
version = "v3"
pressure_faces = "{}"
[initial_stress]
type = "uniform"
xx = -5.0e4
yy = -5.0e4
zz = -5.0e4
[[boundary]]
name = "base"
y = [0.0, 0.0]
velocity = {{ y = 0.0 }}
[[boundary]]
name = "top"
y = [0.4, 0.4]
velocity = {{ y = -0.01 }}
[[boundary]]
name = "sides"
x = [0.0, 0.0]
stress = {{ xx = -5.0e4, xy = 0.0 }}
[[boundary]]
name = "right"
x = [0.4, 0.4]
stress = {{ xx = -5.0e4, xy = 0.0 }}
[time]
end = {}
cfl = {}
)",
                                         faces, end, cfl);
    auto setup = test::case_from_string<2>(dir, text);
    Simulation<2> solver(setup);
    std::string message;
    try {
      while (solver.time() < end - 1e-12) solver.step();
    } catch (const SolverError& e) {
      message = e.what();
    }
    double vmax = 0.0;
    for (double v : values_of(solver.model().nodes.view(solver.model().fields.velocity)))
      vmax = std::max(vmax, std::abs(v));
    for (double s : values_of(solver.model().nodes.view(solver.model().fields.stress)))
      vmax = std::max(vmax, std::abs(s));
    std::size_t centre = 0;
    const auto& nodes = solver.nodes();
    for (std::size_t i = 0; i < static_cast<std::size_t>(nodes.size()); ++i) {
      if ((nodes.position[i] - Vec<2>(0.2, 0.2)).norm() < 1e-9) centre = i;
    }
    return SampleRun{message, vmax, solver.node_pore_pressure()[centre]};
  }
}

// The V3 instability of the explicit face condition (solver.pressure_faces = "explicit",
// method-notes eq. (4.3.2)): impermeable faces carrying a total stress, undrained Courant number
// C c_u / c_d above about 2.5 with the default (consistent) storage rate, 3.5 with the nodal one.
// At C = 0.5 (C c_u/c_d = 7.1) the run must stop with a diagnosis while the state is still
// finite (the energy growth guard: the V3 limit, and the fastest node with its neighbours), and at
// C = 0.15 (2.1) it runs.
TEST(Saturated, AnUnstableRunStopsWithADiagnosisWhileTheStateIsFinite) {
  const SampleRun unstable = run_loaded_impermeable_sample(0.5, "explicit", 0.02);
  const std::string& message = unstable.message;
  EXPECT_NE(message.find("kinetic energy"), std::string::npos) << message;
  EXPECT_NE(message.find("unstable"), std::string::npos) << message;
  EXPECT_NE(message.find("C c_u/c_d"), std::string::npos) << message;  // names the V3 limit and a safe cfl
  // and where the growth shows: the fastest node, where it was made, its neighbours in the support
  EXPECT_NE(message.find("The fastest node is at x = ["), std::string::npos) << message;
  EXPECT_NE(message.find("in the body as made"), std::string::npos) << message;
  EXPECT_NE(message.find("stress points and"), std::string::npos) << message;
  EXPECT_TRUE(std::isfinite(unstable.largest));
  const SampleRun stable = run_loaded_impermeable_sample(0.15, "explicit", 0.02);
  EXPECT_TRUE(stable.message.empty()) << stable.message;
}

// The implicit face condition (the default, method-notes eqs. (2.4.15)-(2.4.17)) removes that
// limit: the same sample at C = 0.5 (C c_u/c_d = 7.1) runs 0.2 s, about 800 transits of the
// undrained wave, bounded, and its pore pressure is that of the stable explicit run at C = 0.15.
TEST(Saturated, ImplicitFacesAreStableAtTheDrainedCourantNumber) {
  const SampleRun implicit_run = run_loaded_impermeable_sample(0.5, "implicit", 0.2);
  EXPECT_TRUE(implicit_run.message.empty()) << implicit_run.message;
  EXPECT_LT(implicit_run.largest, 1.0e6);  // |sigma| stays near the 50 kPa confinement
  const SampleRun reference = run_loaded_impermeable_sample(0.15, "explicit", 0.2);
  ASSERT_TRUE(reference.message.empty()) << reference.message;
  EXPECT_GT(reference.centre_pressure, 1.0e3);  // the compression did raise p_w
  EXPECT_NEAR(implicit_run.centre_pressure, reference.centre_pressure, 0.02 * reference.centre_pressure);
  std::printf("centre p_w at 0.2 s: implicit C = 0.5 %.2f Pa, explicit C = 0.15 %.2f Pa\n",
              implicit_run.centre_pressure, reference.centre_pressure);
}

}  // namespace
}  // namespace rktsph
