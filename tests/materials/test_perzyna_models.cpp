// Perzyna models against closed forms, through the material-point path integrator
// (materials/material_point_path.hpp) and the RK4 batch source integrator.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "material_test_util.hpp"
#include "materials/material_point_path.hpp"
#include "materials/source_integrator.hpp"
#include "materials/tensor.hpp"
#include "materials/yield_drucker_prager.hpp"
#include "materials/yield_mohr_coulomb.hpp"

namespace rktsph {
namespace {

using test::material_from_toml;

// E = 1e7, nu = 0.3: G = 1e7/2.6.
constexpr double kG = 1.0e7 / 2.6;
constexpr double kY = 1.0e5;

double q_of(const Sym6& s) { return invariants(s).q; }

TEST(VonMisesPerzyna, NoFlowInsideTheSurface) {
  auto m = material_from_toml(test::von_mises(1.0));
  // Simple shear to gamma = 0.01: tau = G gamma = 38.5 kPa, q = 66.6 kPa < Y.
  LoadPath path = LoadPath::simple_shear(1.0);
  path.duration = 0.01;
  path.dt = 1e-3;
  const PathResult r = integrate_path(*m, {}, path);
  const PathPoint& end = r.points.back();
  EXPECT_NEAR(end.stress[3], kG * 0.01, 1e-9 * kG * 0.01);
  EXPECT_EQ(end.state[0], 0.0);
  EXPECT_EQ(m->relaxation_rate(end.stress, end.state.data()), 0.0);
  Sym6 ds;
  double dk[1];
  m->source_rate(end.stress, end.state.data(), ds, dk);
  for (double v : ds) EXPECT_EQ(v, 0.0);
}

TEST(VonMisesPerzyna, CohesionGivesPlaneStrainShearStrength) {
  // docs/cases.md §1.2 C2: sigma_Y = sqrt(3) c, so pure shear yields at tau = c.
  auto m = material_from_toml(
      "model = 'perzyna_von_mises'\nE = 1e7\nnu = 0.3\ndensity = 2000\ncohesion = 5e4\n"
      "fluidity = 1.0\n");
  const double k[1] = {0.0};
  EXPECT_EQ(m->relaxation_rate({0, 0, 0, 5e4 * (1 - 1e-9), 0, 0}, k), 0.0);
  EXPECT_GT(m->relaxation_rate({0, 0, 0, 5e4 * (1 + 1e-6), 0, 0}, k), 0.0);
}

// Constant deviatoric strain rate: at steady state all the deviatoric rate is viscoplastic,
// so gamma Phi = eps_eq_dot with eps_eq_dot = sqrt(2/3 e_dot:e_dot). For simple shear at the
// engineering rate g (eps_xy_dot = g/2) this is g/sqrt(3). Hence
//   power:       q = Y (1 + (eps_eq_dot/gamma)^(1/N)),
//   exponential: q = Y (1 + ln(1 + eps_eq_dot/gamma)/N).
TEST(VonMisesPerzyna, SteadyStateUnderConstantDeviatoricStrainRate) {
  const double g = 1.0, gamma = 1.0;
  const double rate_eq = g / std::sqrt(3.0);
  struct Variant {
    const char* keys;
    double q_expected;
  };
  const Variant variants[] = {
      {"exponent = 1.0\n", kY * (1.0 + rate_eq / gamma)},
      {"exponent = 2.0\n", kY * (1.0 + std::sqrt(rate_eq / gamma))},
      {"exponent = 2.0\noverstress = 'exponential'\n", kY * (1.0 + std::log1p(rate_eq / gamma) / 2.0)},
  };
  for (const Variant& v : variants) {
    auto m = material_from_toml(test::von_mises(gamma, v.keys));
    LoadPath path = LoadPath::simple_shear(g);
    path.duration = 0.3;
    path.dt = 1e-3;
    const PathResult r = integrate_path(*m, {}, path);
    const PathPoint& a = r.points[r.points.size() - 2];
    const PathPoint& b = r.points.back();
    EXPECT_NEAR(q_of(b.stress), v.q_expected, 1e-6 * v.q_expected) << v.keys;
    // Accumulated viscoplastic strain grows at eps_eq_dot.
    EXPECT_NEAR((b.state[0] - a.state[0]) / (b.t - a.t), rate_eq, 1e-6) << v.keys;
    // The stress stays pure shear.
    EXPECT_NEAR(b.stress[0], 0.0, 1e-6);
  }
}

// Fixed strain, N = 1, H = 0: q_dot = -3 G gamma (q - Y)/Y, so the overstress decays as
// exp(-3 G gamma t / Y), the rate quoted in method-notes §4.3.
TEST(VonMisesPerzyna, StressRelaxationDecaysAtTheMethodRate) {
  auto m = material_from_toml(test::von_mises(1.0));
  const double gamma = 1.0, rate = 3.0 * kG * gamma / kY;  // 115.4 1/s
  const double q0 = 1.5 * kY;
  const Sym6 s0{0, 0, 0, q0 / std::sqrt(3.0), 0, 0};
  const double k0[1] = {0.0};
  EXPECT_NEAR(m->relaxation_rate(s0, k0), rate, 1e-9 * rate);
  LoadPath path;  // every strain rate zero
  path.duration = 0.02;
  path.dt = 1e-4;
  const PathResult r = integrate_path(*m, s0, path);
  for (const PathPoint& p : r.points) {
    const double exact = (q0 - kY) * std::exp(-rate * p.t);
    EXPECT_NEAR(q_of(p.stress) - kY, exact, 1e-7 * (q0 - kY)) << "t = " << p.t;
  }
  const PathPoint& a = r.points[50];
  const PathPoint& b = r.points[150];
  const double measured = std::log((q_of(a.stress) - kY) / (q_of(b.stress) - kY)) / (b.t - a.t);
  EXPECT_NEAR(measured, rate, 1e-5 * rate);
  // The relaxed stress went into eps_vp_eq: q0 - q = 3 G eps_vp_eq.
  EXPECT_NEAR(r.points.back().state[0], (q0 - q_of(r.points.back().stress)) / (3.0 * kG), 1e-12);
}

// Independent rate-independent reference: incremental radial return (backward Euler) for von
// Mises with linear hardening, many small increments along the same strain path.
Sym6 radial_return_reference(const Sym6& sigma0, const Sym6& eps_rate, double duration, double E, double nu, double Y0,
                             double H, int increments) {
  const double G = E / (2 * (1 + nu)), K = E / (3 * (1 - 2 * nu));
  const double dt = duration / increments;
  Sym6 s = sigma0;
  double ebar = 0.0;
  for (int n = 0; n < increments; ++n) {
    const Sym6 de = tensor::scaled(eps_rate, dt);
    const double dv = tensor::trace(de);
    Sym6 tr = s;
    for (std::size_t i = 0; i < 6; ++i) tr[i] += 2 * G * de[i];
    for (std::size_t i = 0; i < 3; ++i) tr[i] += (K - 2 * G / 3) * dv;
    const double p = -tensor::trace(tr) / 3;
    const Sym6 dev = tensor::deviator(tr);
    const double q = std::sqrt(1.5 * tensor::ddot(dev, dev));
    const double Y = Y0 + H * ebar;
    if (q > Y) {
      const double dl = (q - Y) / (3 * G + H);
      const double f = 1 - 3 * G * dl / q;
      for (std::size_t i = 0; i < 6; ++i) tr[i] = f * dev[i] - (i < 3 ? p : 0.0);
      ebar += dl;
    }
    s = tr;
  }
  return s;
}

TEST(VonMisesPerzyna, FastLimitApproachesRateIndependentReturnMapping) {
  // Non-proportional: an anisotropic initial stress, then a mixed normal + shear strain rate.
  const Sym6 s0{-50e3, -100e3, -50e3, 0, 0, 0};
  const Sym6 rate{0.004, -0.01, 0.0, 0.003, 0.0, 0.0};
  const double duration = 2.0, H = 1.0e6;
  const Sym6 ref = radial_return_reference(s0, rate, duration, 1e7, 0.3, kY, H, 40000);
  double err[2];
  const double gammas[2] = {50.0, 500.0};
  for (int i = 0; i < 2; ++i) {
    auto m = material_from_toml(test::von_mises(gammas[i], "hardening_modulus = 1.0e6\n"));
    LoadPath path;
    path.rate = rate;
    path.duration = duration;
    // A step small enough that the path's discretisation (backward Euler: O(dt)) stays below
    // the O(1/gamma) difference measured here.
    path.dt = 1e-4;
    const PathResult r = integrate_path(*m, s0, path);
    double e = 0.0;
    for (std::size_t c = 0; c < 6; ++c) e = std::max(e, std::abs(r.points.back().stress[c] - ref[c]));
    err[i] = e / kY;
  }
  // The Perzyna stress approaches the rate-independent one as O(1/gamma).
  EXPECT_LT(err[1], 2e-4);
  EXPECT_GT(err[0] / err[1], 7.0);
  EXPECT_LT(err[0] / err[1], 13.0);
  // Sanity: the reference did yield well beyond Y0.
  EXPECT_GT(q_of(ref), 1.05 * kY);
}

// One particle advanced by the batch integrator (the solver's entry point).
Sym6 advance(const Material& m, const Sym6& s0, const Sym6& flux, double tau, SourceCoupling coupling,
             std::vector<double>& k, SourceStats* stats = nullptr) {
  Sym6 out{};
  std::vector<double> kend(k.size());
  SourceBatch b;
  b.count = 1;
  b.stress_components = 6;
  b.sigma_start = s0.data();
  b.flux_rate = flux.data();
  b.sigma_end = out.data();
  b.state_start = k.data();
  b.state_end = kend.data();
  b.coupling = coupling;
  const SourceStats st = m.advance_source(tau, b);
  if (stats != nullptr) *stats = st;
  k = kend;
  return out;
}

// One particle through the RK4 batch integrator alone (no implicit return), with the model's
// rate and relaxation rate, or a relaxation rate next to zero (one RK4 step, no sub-stepping).
Sym6 advance_rk4(const Material& m, const Sym6& s0, double tau, double* k, SourceStats* stats, bool substep = true) {
  SourceBatch b;
  Sym6 out{};
  double k1[1];
  b.count = 1;
  b.sigma_start = s0.data();
  b.sigma_end = out.data();
  b.state_start = k;
  b.state_end = k1;
  const SourceStats st = detail::integrate_source_batch(
      tau, b, 1, [&m](const Sym6& a, const double* kk, Sym6& ds, double* dk) { m.source_rate(a, kk, ds, dk); },
      [&m, substep](const Sym6& a, const double* kk) { return substep ? m.relaxation_rate(a, kk) : 1e-300; });
  if (stats != nullptr) *stats = st;
  k[0] = k1[0];
  return out;
}

TEST(PerzynaSource, SubSteppingKeepsStiffSourceBoundedAndAccurate) {
  auto m = material_from_toml(test::von_mises(1.0e4));
  const Sym6 s0{0, 0, 0, 2.0 * kY / std::sqrt(3.0), 0, 0};  // q = 2 Y
  const double tau = 0.01;
  const double lam = 3.0 * kG * 1.0e4 / kY;  // 1.15e6 1/s: lam tau = 1.15e4 >> 2.78
  // RK4 sub-stepped against the relaxation rate (method-notes eq. (2.2.6)).
  double k[1] = {0.0};
  SourceStats stats;
  const Sym6 coarse = advance_rk4(*m, s0, tau, k, &stats);
  EXPECT_GE(stats.max_substeps, static_cast<long>(lam * tau / 1.0) - 1);
  // Exact: q - Y = Y exp(-lam t), i.e. Y to round-off after tau.
  EXPECT_NEAR(q_of(coarse), kY, 1e-9 * kY);
  // Fine run: 100 calls of tau/100.
  double kf[1] = {0.0};
  Sym6 s = s0;
  for (int i = 0; i < 100; ++i) s = advance_rk4(*m, s, tau / 100, kf, nullptr);
  for (std::size_t c = 0; c < 6; ++c) EXPECT_NEAR(coarse[c], s[c], 1e-9 * kY);
  EXPECT_NEAR(k[0], kf[0], 1e-12);
  // Without sub-stepping one RK4 step of this size explodes: the guard above is what matters.
  double k0[1] = {0.0};
  EXPECT_GT(std::abs(q_of(advance_rk4(*m, s0, tau, k0, nullptr, false)) - kY), 1e3 * kY);
  // The solver's entry point integrates this source by backward Euler (method-notes §2.5):
  // bounded, one particle, a few Newton iterations, the overstress x_0/(1 + lam tau) left.
  std::vector<double> kb{0.0};
  const Sym6 be = advance(*m, s0, {}, tau, SourceCoupling::additive, kb, &stats);
  EXPECT_EQ(stats.implicit_points, 1);
  EXPECT_EQ(stats.max_substeps, 0);
  EXPECT_LE(stats.max_newton_iterations, 5);
  EXPECT_NEAR(q_of(be), kY * (1.0 + 1.0 / (1.0 + lam * tau)), 1e-6 * kY);
}

TEST(PerzynaSource, FrozenFluxAndAdditiveAgreeToSecondOrder) {
  auto m = material_from_toml(test::von_mises(10.0));
  const Sym6 s0{-20e3, 10e3, 0, 1.2 * kY / std::sqrt(3.0), 0, 0};
  const Sym6 flux = m->elastic().apply({0.005, 0.0, 0.0, 0.01, 0.0, 0.0});
  double diff[3];
  const double taus[3] = {1e-4, 5e-5, 2.5e-5};
  for (int i = 0; i < 3; ++i) {
    std::vector<double> ka{0.0}, kf{0.0};
    const Sym6 a = advance(*m, s0, flux, taus[i], SourceCoupling::additive, ka);
    const Sym6 f = advance(*m, s0, flux, taus[i], SourceCoupling::frozen_flux, kf);
    double d = 0.0;
    for (std::size_t c = 0; c < 6; ++c) d = std::max(d, std::abs(a[c] - f[c]));
    diff[i] = d;
  }
  EXPECT_GT(diff[0], 0.0);
  EXPECT_NEAR(diff[0] / diff[1], 4.0, 0.4);
  EXPECT_NEAR(diff[1] / diff[2], 4.0, 0.4);
}

// ---------------------------------------------------------------------------------------
// Modified Cam-Clay

// docs/cases.md Case 3 closed form: plane-strain compression from isotropic p0 with constant
// lateral stress; s = sigma_1 - sigma_3 (compression positive).
struct Case3Closed {
  double nu = 0.3, E = 2.0e7, p0 = 50e3, pc = 400e3;
  double s_yield(double M) const {
    const double A = (1 - nu + nu * nu) / (M * M), B = (1 + nu) / 3;
    const double a = A + B * B, b = B * (2 * p0 - pc), c = p0 * (p0 - pc);
    return (-b + std::sqrt(b * b - 4 * a * c)) / (2 * a);
  }
};

struct YieldPoint {
  double s, q, p, eps_a;
};

YieldPoint first_yield(const PathResult& r, double M) {
  // Independent of the model code: F = p' + q^2/(M^2 p') crosses p_c (state index 2).
  auto excess = [&](const PathPoint& pt) {
    const Invariants inv = invariants(pt.stress);
    return inv.p + inv.q * inv.q / (M * M * inv.p) - pt.state[2];
  };
  for (std::size_t i = 1; i < r.points.size(); ++i) {
    const double f0 = excess(r.points[i - 1]), f1 = excess(r.points[i]);
    if (f0 <= 0.0 && f1 > 0.0) {
      const double w = -f0 / (f1 - f0);
      auto lerp = [&](double a, double b) { return a + w * (b - a); };
      const PathPoint &a = r.points[i - 1], &b = r.points[i];
      const double s = lerp(a.stress[0] - a.stress[1], b.stress[0] - b.stress[1]);
      const Invariants ia = invariants(a.stress), ib = invariants(b.stress);
      return {s, lerp(ia.q, ib.q), lerp(ia.p, ib.p), -lerp(a.strain[1], b.strain[1])};
    }
  }
  return {0, 0, 0, 0};
}

TEST(CamClayPerzyna, Case3ElasticPathAndFirstYield) {
  const Case3Closed cf;
  auto m = material_from_toml(test::kCamClayCase3);
  LoadPath path = LoadPath::plane_strain_compression(-0.05);  // docs/cases.md: 0.05 1/s
  path.duration = 0.8;                                        // 4 % axial strain
  path.dt = 2e-4;
  const Sym6 s0{-cf.p0, -cf.p0, -cf.p0, 0, 0, 0};
  const PathResult r = integrate_path(*m, s0, path);
  // Elastic path at 1 % axial strain (t = 0.2 s).
  const PathPoint& e = r.points[1000];
  ASSERT_NEAR(e.t, 0.2, 1e-12);
  const double s = cf.E * 0.01 / (1 - cf.nu * cf.nu);
  const Invariants inv = invariants(e.stress);
  EXPECT_NEAR(e.stress[0] - e.stress[1], s, 1e-9 * s);
  EXPECT_NEAR(-e.stress[2], cf.p0 + cf.nu * s, 1e-9 * s);
  EXPECT_NEAR(inv.p, cf.p0 + (1 + cf.nu) * s / 3, 1e-9 * s);
  EXPECT_NEAR(inv.q, s * std::sqrt(1 - cf.nu + cf.nu * cf.nu), 1e-9 * s);
  EXPECT_EQ(e.state[0], 0.0);
  // First yield: the closed-form root and the docs/cases.md numbers.
  const YieldPoint y = first_yield(r, 1.2);
  EXPECT_NEAR(y.s, cf.s_yield(1.2), 1e-6 * y.s);
  EXPECT_NEAR(y.s, 265.9e3, 0.1e3);
  EXPECT_NEAR(y.q, 236.3e3, 0.1e3);
  EXPECT_NEAR(y.p, 165.2e3, 0.1e3);
  EXPECT_NEAR(y.eps_a, 0.0121, 0.00005);
  // Dry side: the peak is within +0/+4 % of q_y at 0.05 1/s, then softening. At a material
  // point the peak is flat (q within 0.5 % of q_y from 1.21 % to about 1.6 % strain), so the
  // viscous delay moves the strain at the peak to about 1.34 %.
  double qpk = 0.0, eps_pk = 0.0;
  for (const PathPoint& p : r.points) {
    if (q_of(p.stress) > qpk) {
      qpk = q_of(p.stress);
      eps_pk = -p.strain[1];
    }
  }
  EXPECT_GE(qpk, y.q);
  EXPECT_LE(qpk, 1.04 * y.q);
  EXPECT_GE(eps_pk, y.eps_a);
  EXPECT_LE(eps_pk, 1.2 * y.eps_a);
  EXPECT_LT(q_of(r.points.back().stress), 0.99 * qpk);
  EXPECT_LT(r.points.back().state[2], cf.pc);  // dilation shrank p_c
}

TEST(CamClayPerzyna, Case3FirstYieldWithLodeDependentM) {
  const Case3Closed cf;
  auto m = material_from_toml(test::kCamClayCase3 + "lode_dependent_M = true\n");
  LoadPath path = LoadPath::plane_strain_compression(-0.05);
  path.duration = 0.3;
  path.dt = 2e-4;
  const PathResult r = integrate_path(*m, {-cf.p0, -cf.p0, -cf.p0, 0, 0, 0}, path);
  // M(theta) on this path, from sin 3 theta of the elastic stress (constant along it).
  const double M = 1.117;
  const YieldPoint y = first_yield(r, M);
  EXPECT_NEAR(y.s, 245.3e3, 0.3e3);
  EXPECT_NEAR(y.q, 218.0e3, 0.3e3);
  EXPECT_NEAR(y.p, 156.3e3, 0.3e3);
  EXPECT_NEAR(y.eps_a, 0.0112, 0.00005);
}

TEST(CamClayPerzyna, InitialStateFromOcrUsesEquivalentSize) {
  auto m = material_from_toml(
      "model = 'perzyna_cam_clay'\nE = 2e7\nnu = 0.3\ndensity = 2000\nM = 1.2\nlambda = 0.2\n"
      "kappa = 0.02\ne0 = 1.0\nocr = 8\nfluidity = 10\n");
  double k[3];
  m->initial_state({-50e3, -50e3, -50e3, 0, 0, 0}, k);
  EXPECT_DOUBLE_EQ(k[2], 400e3);
  // Anisotropic: p' = 60 kPa, q = 30 kPa -> P_y = 60 + 900/(1.44*60) kPa.
  m->initial_state({-50e3, -80e3, -50e3, 0, 0, 0}, k);
  EXPECT_NEAR(k[2], 8.0 * (60e3 + 30e3 * 30e3 / (1.44 * 60e3)), 1e-6);
  ASSERT_EQ(m->state_size(), 3);
  const auto names = m->state_names();
  EXPECT_EQ(std::vector<std::string>(names.begin(), names.end()),
            (std::vector<std::string>{"eps_vp_eq", "eps_vp_vol", "p_c"}));
}

// Normally consolidated sample (p_c0 = p0): both triaxial paths end on the critical state
// line. At the end the flow is purely deviatoric, so p' = p_c/2 and, with the overstress x,
// q/p' = M sqrt(1 + 2x): x ~ eps_eq_dot/(gamma M) ~ 1e-3 here.
const std::string kCamClayNC =
    "model = 'perzyna_cam_clay'\nE = 2.0e7\nnu = 0.3\ndensity = 2000.0\nM = 1.2\n"
    "lambda = 0.2\nkappa = 0.02\ne0 = 1.0\np_c0 = 1.0e5\nfluidity = 10.0\n";

TEST(CamClayPerzyna, DrainedTriaxialNormallyConsolidatedEndsOnCriticalState) {
  auto m = material_from_toml(kCamClayNC);
  LoadPath path = LoadPath::drained_triaxial(-0.01);
  path.duration = 80.0;          // 80 % axial strain (small-strain model): the approach is exponential
  path.dt = 0.05;                // in strain with a scale of about 12 %
  path.relaxation_target = 2.0;  // stable for RK4 (2.78); the stiff mode only tracks the surface
  const Sym6 s0{-1e5, -1e5, -1e5, 0, 0, 0};
  const PathResult r = integrate_path(*m, s0, path);
  const PathPoint& end = r.points.back();
  const Invariants inv = invariants(end.stress);
  // Lateral stress held; drained total stress path q = 3 (p' - p0).
  EXPECT_NEAR(end.stress[0], -1e5, 1e-6);
  EXPECT_NEAR(end.stress[2], -1e5, 1e-6);
  EXPECT_NEAR(inv.q, 3.0 * (inv.p - 1e5), 1e-6 * inv.q);
  // Critical state: q = M p' = 200 kPa at p' = p0/(1 - M/3) = 166.7 kPa.
  EXPECT_NEAR(inv.q / inv.p, 1.2, 0.002 * 1.2);
  EXPECT_NEAR(inv.p, 1e5 / 0.6, 0.002 * 1e5 / 0.6);
  EXPECT_NEAR(end.state[2], 2.0 * inv.p, 0.002 * 2.0 * inv.p);
  EXPECT_LT(end.state[1], 0.0);  // compaction
}

TEST(CamClayPerzyna, UndrainedTriaxialEndsOnCriticalStateIsochorically) {
  auto m = material_from_toml(kCamClayNC);
  LoadPath path = LoadPath::undrained_triaxial(-0.01);
  path.duration = 20.0;
  path.dt = 0.01;
  const PathResult r = integrate_path(*m, {-1e5, -1e5, -1e5, 0, 0, 0}, path);
  for (const PathPoint& p : r.points) {
    ASSERT_NEAR(tensor::trace(p.strain), 0.0, 1e-14) << "t = " << p.t;
  }
  const PathPoint& end = r.points.back();
  const Invariants inv = invariants(end.stress);
  EXPECT_NEAR(inv.q / inv.p, 1.2, 0.005 * 1.2);
  EXPECT_NEAR(end.state[2], 2.0 * inv.p, 0.01 * 2.0 * inv.p);
  // Isochoric: the elastic volume change cancels the viscoplastic one, so p' dropped by
  // K eps_vp_vol (eps_vp_vol < 0, compaction).
  const double K = 2.0e7 / (3 * (1 - 0.6));
  EXPECT_LT(inv.p, 1e5);
  EXPECT_NEAR(inv.p, 1e5 + K * end.state[1], 1e-6 * 1e5);
}

}  // namespace
}  // namespace rktsph

namespace rktsph {
namespace {

// The Cam-Clay relaxation estimate is the actual decay rate on the isotropic axis: with
// x = p'/p_c - 1 at fixed strain, x_dot = -gamma M^2 (K + p_c (1+e0)/(lambda-kappa)) x / p_c.
TEST(CamClayPerzyna, RelaxationRateMatchesIsotropicDecay) {
  auto m = test::material_from_toml(test::kCamClayCase3);
  const double pc = 4.0e5, K = 2.0e7 / (3 * (1 - 0.6)), M2 = 1.44, h = 2.0 / 0.18, gamma = 10.0;
  const double expected = gamma * M2 * (K + pc * h) / pc;
  const double p0 = pc * (1 + 1e-4);
  const Sym6 s0{-p0, -p0, -p0, 0, 0, 0};
  const double k0[3] = {0, 0, pc};
  EXPECT_NEAR(m->relaxation_rate(s0, k0), expected, 1e-3 * expected);
  LoadPath path;  // fixed strain
  path.duration = 2.0 / expected;
  path.dt = path.duration / 200;
  const PathResult r = integrate_path(*m, s0, path);
  auto x = [](const PathPoint& p) { return invariants(p.stress).p / p.state[2] - 1.0; };
  const double measured = std::log(x(r.points.front()) / x(r.points.back())) / path.duration;
  EXPECT_NEAR(measured, expected, 1e-3 * expected);
}

// The batch integrator honours a state stride (several materials sharing one state array).
TEST(PerzynaSource, BatchHonoursStateStride) {
  auto m = test::material_from_toml(test::von_mises(10.0));
  const double tau1 = 2.0 * 1.0e5 / std::sqrt(3.0);
  const double sig[2][6] = {{0, 0, 0, 0.4 * tau1, 0, 0}, {0, 0, 0, tau1, 0, 0}};
  double out[2][6] = {};
  double k0[8] = {0, -1, -1, -1, 0, -1, -1, -1};
  double k1[8] = {-1, -1, -1, -1, -1, -1, -1, -1};
  SourceBatch b;
  b.count = 2;
  b.stress_components = 6;
  b.sigma_start = &sig[0][0];
  b.sigma_start_stride = 6;
  b.sigma_end = &out[0][0];
  b.sigma_end_stride = 6;
  b.state_start = k0;
  b.state_end = k1;
  b.state_stride = 4;
  m->advance_source(1e-3, b);
  EXPECT_EQ(k1[0], 0.0);   // particle 0 is inside the surface: no flow
  EXPECT_GT(k1[4], 0.0);   // particle 1 flowed
  EXPECT_EQ(k1[1], -1.0);  // slots between particles untouched
  EXPECT_EQ(k1[5], -1.0);
  EXPECT_DOUBLE_EQ(out[0][3], 0.4 * tau1);
  EXPECT_LT(out[1][3], tau1);
}

// Drucker–Prager, E = 100 MPa, nu = 0.3, c = 10 kPa, default rounding 0.1 (method-notes §1.10).
std::string drucker_prager(const std::string& match, double phi, double psi, double fluidity,
                           const std::string& extra = "") {
  return "model = 'perzyna_drucker_prager'\nE = 1.0e8\nnu = 0.3\ndensity = 2000.0\ncohesion = 1.0e4\n"
         "friction_angle = " +
         std::to_string(phi) + "\ndilatancy = " + std::to_string(psi) + "\ndp_match = '" + match +
         "'\nfluidity = " + std::to_string(fluidity) + "\n" + extra;
}

constexpr double kDegree = std::numbers::pi / 180.0;

DruckerPragerMatch match_of(const std::string& name) {
  if (name == "outer") return DruckerPragerMatch::outer;
  if (name == "inner") return DruckerPragerMatch::inner;
  return DruckerPragerMatch::plane_strain;
}

double peak_q(const PathResult& r) {
  double q = 0.0;
  for (const PathPoint& p : r.points) q = std::max(q, q_of(p.stress));
  return q;
}

TEST(DruckerPragerPerzyna, WithoutFrictionIsTheVonMisesModel) {
  // phi = 0 with the plane-strain match: von Mises with Y = sqrt(3) c (method-notes eq. (1.7.5)).
  auto dp = material_from_toml(drucker_prager("plane_strain", 0.0, 0.0, 3.0));
  auto vm = material_from_toml(
      "model = 'perzyna_von_mises'\nE = 1.0e8\nnu = 0.3\ndensity = 2000.0\ncohesion = 1.0e4\nfluidity = 3.0\n");
  ASSERT_EQ(dp->state_size(), 1);
  EXPECT_EQ(dp->state_names()[0], "eps_vp_eq");
  const double k[1] = {0.0};
  for (const Sym6& s :
       {Sym6{-120e3, -80e3, -95e3, 15e3, -7e3, 4e3}, Sym6{2e4, -1e4, 0, 0, 0, 9e3}, Sym6{-1e5, -1e5, -1e5, 0, 0, 0}}) {
    Sym6 d1, d2;
    double k1[1], k2[1];
    dp->source_rate(s, k, d1, k1);
    vm->source_rate(s, k, d2, k2);
    for (std::size_t i = 0; i < 6; ++i) EXPECT_NEAR(d1[i], d2[i], 1e-12 * (1.0 + std::abs(d2[i]))) << i;
    EXPECT_NEAR(k1[0], k2[0], 1e-12 * (1.0 + k2[0]));
    EXPECT_NEAR(dp->relaxation_rate(s, k), vm->relaxation_rate(s, k), 1e-12 * vm->relaxation_rate(s, k));
  }
  // Pure shear yields at tau = c, as cohesion does for von Mises.
  EXPECT_EQ(dp->relaxation_rate({0, 0, 0, 1e4 * (1 - 1e-9), 0, 0}, k), 0.0);
  EXPECT_GT(dp->relaxation_rate({0, 0, 0, 1e4 * (1 + 1e-6), 0, 0}, k), 0.0);
}

// Drained triaxial compression from p0 (sigma_xx = sigma_zz = -p0 held): the rate-independent
// peak is on the cone, q = eta p' + xi c with p' = p0 + q/3, so q = (eta p0 + xi c)/(1 - eta/3)
// (method-notes eq. (1.10.9)); for the outer cone this is the Mohr–Coulomb
// q = 2 (p0 sin(phi) + c cos(phi))/(1 - sin(phi)).
TEST(DruckerPragerPerzyna, FastLimitDrainedTriaxialPeakMatchesTheCone) {
  const double p0 = 1e5, c = 1e4, phi = 30.0;
  double worst = 0.0;
  for (const char* match : {"plane_strain", "outer", "inner"}) {
    for (double psi : {0.0, 30.0}) {
      auto m = material_from_toml(drucker_prager(match, phi, psi, 20.0));
      LoadPath path = LoadPath::drained_triaxial(-0.01);
      path.duration = 1.0;  // 1 % axial strain; the peak is reached at about 0.25 %
      path.dt = 1e-3;
      const PathResult r = integrate_path(*m, {-p0, -p0, -p0, 0, 0, 0}, path);
      const DruckerPragerCone cone = DruckerPragerCone::matched(match_of(match), phi * kDegree, psi * kDegree);
      const double expected = (cone.eta * p0 + cone.xi * c) / (1.0 - cone.eta / 3.0);
      const double q_end = q_of(r.points.back().stress);
      const double err = std::abs(peak_q(r) - expected) / expected;
      worst = std::max(worst, err);
      EXPECT_LT(err, 1e-3) << match << " psi " << psi << ": peak " << peak_q(r) << " expected " << expected;
      EXPECT_NEAR(q_end, peak_q(r), 1e-4 * expected) << match << " psi " << psi;  // perfectly plastic
      EXPECT_NEAR(r.points.back().stress[0], -p0, 1e-6);
      if (std::string(match) == "outer") {
        const double sf = std::sin(phi * kDegree), cf = std::cos(phi * kDegree);
        EXPECT_NEAR(expected, 2.0 * (p0 * sf + c * cf) / (1.0 - sf), 1e-9 * expected);
      }
      // Dilatancy: tr(eps_vp) > 0 for psi > 0; zero for psi = 0 (volume change only elastic).
      const Sym6& e = r.points.back().strain;
      const double elastic_volume = -(invariants(r.points.back().stress).p - p0) / m->elastic().K;
      const double plastic_volume = tensor::trace(e) - elastic_volume;
      if (psi > 0.0) {
        EXPECT_GT(plastic_volume, 1e-3) << match;
      } else {
        EXPECT_NEAR(plastic_volume, 0.0, 1e-9) << match;
      }
    }
  }
  std::printf("[ figures  ] Drucker-Prager drained triaxial peak, worst relative error to the cone: %.2e\n", worst);
}

// Without the apex rounding the only departure from the cone is the overstress, O(1/gamma):
// the Perzyna peak approaches the rate-independent one as the fluidity grows.
TEST(DruckerPragerPerzyna, FastLimitConvergesAsOneOverFluidity) {
  const double p0 = 1e5, c = 1e4;
  const DruckerPragerCone cone = DruckerPragerCone::matched(DruckerPragerMatch::outer, 30.0 * kDegree, 0.0);
  const double expected = (cone.eta * p0 + cone.xi * c) / (1.0 - cone.eta / 3.0);
  double err[2];
  const double gammas[2] = {5.0, 50.0};
  for (int i = 0; i < 2; ++i) {
    auto m = material_from_toml(drucker_prager("outer", 30.0, 0.0, gammas[i], "apex_rounding = 0.0\n"));
    LoadPath path = LoadPath::drained_triaxial(-0.01);
    path.duration = 1.0;
    path.dt = 1e-3;
    const PathResult r = integrate_path(*m, {-p0, -p0, -p0, 0, 0, 0}, path);
    err[i] = (q_of(r.points.back().stress) - expected) / expected;
  }
  std::printf("[ figures  ] Drucker-Prager peak excess over the cone: %.2e (gamma = 5), %.2e (gamma = 50)\n", err[0],
              err[1]);
  EXPECT_GT(err[1], 0.0);  // the overstress is positive
  EXPECT_LT(err[1], 1e-4);
  EXPECT_GT(err[0] / err[1], 8.0);
  EXPECT_LT(err[0] / err[1], 12.0);
}

// Plane-strain compression from the isotropic p0 to the end of `duration` s: the relative error
// of the peak -sigma_yy against `expected` (below 1e-3), with sigma_zz the intermediate
// principal stress (sigma_yy < sigma_zz < sigma_xx).
double plane_strain_peak_error(const Material& m, double p0, double expected, double duration, double psi) {
  LoadPath path = LoadPath::plane_strain_compression(-0.01);
  path.duration = duration;
  path.dt = 1e-3;
  const PathResult r = integrate_path(m, {-p0, -p0, -p0, 0, 0, 0}, path);
  const Sym6& end = r.points.back().stress;
  const double err = std::abs(-end[1] - expected) / expected;
  EXPECT_LT(err, 1e-3) << "psi " << psi << ": sigma_yy " << end[1];
  EXPECT_LT(end[1], end[2]);
  EXPECT_LT(end[2], end[0]);
  return err;
}

// Plane-strain compression (sigma_xx = -p0 held, eps_zz = 0): with the plane-strain match of
// eq. (1.10.5) the steady peak is the Mohr–Coulomb one, sigma_1 = p0 (1 + sin)/(1 - sin) +
// 2 c cos/(1 - sin) (compression positive), for any dilatancy (method-notes eq. (1.10.10)).
TEST(DruckerPragerPerzyna, PlaneStrainPeakMatchesMohrCoulomb) {
  const double p0 = 1e5, c = 1e4, phi = 30.0;
  const double sf = std::sin(phi * kDegree), cf = std::cos(phi * kDegree);
  const double expected = p0 * (1 + sf) / (1 - sf) + 2 * c * cf / (1 - sf);  // 334.6 kPa
  double worst = 0.0;
  for (double psi : {0.0, 15.0, 30.0}) {
    auto m = material_from_toml(drucker_prager("plane_strain", phi, psi, 20.0));
    worst = std::max(worst, plane_strain_peak_error(*m, p0, expected, 3.0, psi));
  }
  std::printf("[ figures  ] Drucker-Prager plane-strain peak, worst relative error to Mohr-Coulomb: %.2e\n", worst);
}

// Linear softening of c (eq. (1.10.8)): the drained triaxial strength drops to the residual cone.
TEST(DruckerPragerPerzyna, CohesionSofteningEndsOnTheResidualCone) {
  const double p0 = 1e5, c = 1e4, c_res = 2e3;
  auto m = material_from_toml(
      drucker_prager("outer", 30.0, 0.0, 5.0, "hardening_modulus = -2.0e5\nresidual_cohesion = 2.0e3\n"));
  LoadPath path = LoadPath::drained_triaxial(-0.05);
  path.duration = 2.0;  // 10 % axial strain; c reaches the floor at eps_vp_eq = 0.04
  path.dt = 1e-3;
  const PathResult r = integrate_path(*m, {-p0, -p0, -p0, 0, 0, 0}, path);
  const DruckerPragerCone cone = DruckerPragerCone::matched(DruckerPragerMatch::outer, 30.0 * kDegree, 0.0);
  const double peak = (cone.eta * p0 + cone.xi * c) / (1.0 - cone.eta / 3.0);
  const double residual = (cone.eta * p0 + cone.xi * c_res) / (1.0 - cone.eta / 3.0);
  EXPECT_NEAR(peak_q(r), peak, 1e-2 * peak);
  EXPECT_NEAR(q_of(r.points.back().stress), residual, 2e-3 * residual);
  EXPECT_GT(r.points.back().state[0], 0.04);
}

// Mohr–Coulomb (Abbo–Sloan), E = 100 MPa, nu = 0.3, c = 10 kPa, default rounding 0.1 (method-notes §1.11).
std::string mohr_coulomb(double phi, double psi, double fluidity) {
  return "model = 'perzyna_mohr_coulomb'\nE = 1.0e8\nnu = 0.3\ndensity = 2000.0\ncohesion = 1.0e4\n"
         "friction_angle = " +
         std::to_string(phi) + "\ndilatancy = " + std::to_string(psi) + "\nfluidity = " + std::to_string(fluidity) +
         "\n";
}

// Drained triaxial compression (theta = +30 deg, p' = p0 + q/3) and extension (theta = -30 deg,
// p' = p0 - q/3), lateral stress held: the rate-independent peaks of the rounded surface are
// q = sqrt3 (c cos + p0 sin)/(K(+-1) -+ sin/sqrt3) (method-notes eq. (1.11.6)); the sharp pyramid
// gives 2 (c cos + p0 sin)/(1 -+ sin).
TEST(MohrCoulombPerzyna, FastLimitTriaxialPeaks) {
  const double p0 = 1e5, c = 1e4, phi = 30.0;
  const double sf = std::sin(phi * kDegree), cf = std::cos(phi * kDegree), r3 = std::sqrt(3.0);
  const LodeFactor K = LodeFactor::of(sf);
  double worst_rounded = 0.0, sharp_error[2] = {0.0, 0.0};
  for (int side = 0; side < 2; ++side) {
    const double sign = side == 0 ? 1.0 : -1.0;  // compression, extension
    const double rounded = r3 * (c * cf + p0 * sf) / (K(sign).K - sign * sf / r3);
    const double sharp = 2.0 * (c * cf + p0 * sf) / (1.0 - sign * sf);
    for (double psi : {0.0, 30.0}) {
      auto m = material_from_toml(mohr_coulomb(phi, psi, 20.0));
      LoadPath path = LoadPath::drained_triaxial(-sign * 0.01);
      path.duration = 1.0;
      path.dt = 1e-3;
      const PathResult r = integrate_path(*m, {-p0, -p0, -p0, 0, 0, 0}, path);
      const double q = peak_q(r);
      const double err = std::abs(q - rounded) / rounded;
      worst_rounded = std::max(worst_rounded, err);
      sharp_error[side] = std::max(sharp_error[side], std::abs(q - sharp) / sharp);
      EXPECT_LT(err, 1e-3) << "side " << side << " psi " << psi << ": q " << q << " expected " << rounded;
      EXPECT_NEAR(q_of(r.points.back().stress), q, 1e-4 * q);
      // The path stays on its meridian: sigma_yy is the major (compression) or minor principal stress.
      const Sym6& e = r.points.back().stress;
      EXPECT_NEAR(e[0], -p0, 1e-6);
      EXPECT_NEAR(e[2], -p0, 1e-6);
      EXPECT_NEAR(e[3], 0.0, 1e-9);
    }
  }
  std::printf(
      "[ figures  ] Mohr-Coulomb triaxial peaks: worst error to the rounded closed form %.2e; to the sharp "
      "pyramid %.2e (compression), %.2e (extension)\n",
      worst_rounded, sharp_error[0], sharp_error[1]);
  // theta_T = 29.7 deg rounds the corners: the compression peak is 0.45 % below the sharp one at
  // phi = 30 (eq. (1.11.8); 1.5 % with the former 29 deg).
  EXPECT_LT(sharp_error[0], 6e-3);
  EXPECT_LT(sharp_error[1], 3e-3);
}

// Plane-strain compression (sigma_xx = -p0 held, eps_zz = 0): sigma_zz stays intermediate, on a
// face of the pyramid (|theta| < theta_T), where the rounded surface is the sharp one, so the
// peak is eq. (1.10.10) for any dilatancy.
TEST(MohrCoulombPerzyna, PlaneStrainPeakIsTheMohrCoulombOne) {
  const double p0 = 1e5, c = 1e4, phi = 30.0;
  const double sf = std::sin(phi * kDegree), cf = std::cos(phi * kDegree);
  const double expected = p0 * (1 + sf) / (1 - sf) + 2 * c * cf / (1 - sf);
  double worst = 0.0;
  for (double psi : {0.0, 30.0}) {
    auto m = material_from_toml(mohr_coulomb(phi, psi, 20.0));
    worst = std::max(worst, plane_strain_peak_error(*m, p0, expected, 1.5, psi));
  }
  std::printf("[ figures  ] Mohr-Coulomb plane-strain peak, worst relative error: %.2e\n", worst);
}

// phi = 0 in simple shear (theta = 0 throughout): the same path as von Mises with cohesion c.
TEST(MohrCoulombPerzyna, WithoutFrictionShearsLikeVonMises) {
  auto mc = material_from_toml(mohr_coulomb(0.0, 0.0, 2.0));
  auto vm = material_from_toml(
      "model = 'perzyna_von_mises'\nE = 1.0e8\nnu = 0.3\ndensity = 2000.0\ncohesion = 1.0e4\nfluidity = 2.0\n");
  LoadPath path = LoadPath::simple_shear(0.02);
  path.duration = 0.5;
  path.dt = 1e-3;
  const Sym6 s0{-1e5, -1e5, -1e5, 0, 0, 0};
  const PathResult a = integrate_path(*mc, s0, path);
  const PathResult b = integrate_path(*vm, s0, path);
  ASSERT_EQ(a.points.size(), b.points.size());
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_NEAR(a.points.back().stress[i], b.points.back().stress[i], 1e-9 * 1e5) << i;
  }
  EXPECT_NEAR(a.points.back().state[0], b.points.back().state[0], 1e-12);
  EXPECT_GT(a.points.back().state[0], 1e-3);  // it did flow
}

// Tension cut-off (method-notes §1.12). Isotropic extension at eps_dot per normal component,
// psi = 0: beyond the apex the shear surface has no flow on the axis, so without a cut-off
// the mean stress grows elastically; with one it settles where the cut-off's viscoplastic
// volumetric rate takes all of 3 eps_dot: sigma_m = T + Y 3 eps_dot/gamma (Phi = x), which
// tends to the rate-independent return sigma_m = T as gamma grows.
TEST(TensionCutoff, IsotropicTensionIsRelievedToTheCutoff) {
  const double T = 5e3, rate = 0.01, K = 1e8 / (3 * (1 - 2 * 0.3));
  LoadPath path;
  path.rate = {rate, rate, rate, 0, 0, 0};
  path.duration = 0.2;
  path.dt = 1e-3;
  const std::string dp = drucker_prager("plane_strain", 30.0, 0.0, 20.0);
  const std::string mc0 = mohr_coulomb(0.0, 0.0, 20.0), mc30 = mohr_coulomb(30.0, 0.0, 20.0);
  // Without the key nothing relieves the isotropic tension (the behaviour kept by default).
  const PathResult free = integrate_path(*material_from_toml(mc30), {}, path);
  EXPECT_NEAR(free.points.back().stress[0], 3 * K * rate * 0.2, 1e-6 * K);
  struct Model {
    std::string toml;
    double Y;  // xi c
  };
  const double sf = std::sin(30 * kDegree), cf = std::cos(30 * kDegree), sp = 0.0;
  const double xi_dp = 3 * cf * std::sqrt(3 + sp * sp) / (3 + sf * sp);
  for (const Model& model :
       {Model{dp, xi_dp * 1e4}, Model{mc30, std::sqrt(3.0) * cf * 1e4}, Model{mc0, std::sqrt(3.0) * 1e4}}) {
    double excess[2];
    const double gammas[2] = {20.0, 200.0};
    for (int g = 0; g < 2; ++g) {
      std::string toml = model.toml;
      toml.replace(toml.find("fluidity = "), std::string::npos, "fluidity = " + std::to_string(gammas[g]) + "\n");
      auto m = material_from_toml(toml + "tension_cutoff = 5.0e3\n");
      const PathResult r = integrate_path(*m, {}, path);
      const Sym6& e = r.points.back().stress;
      const double expected = T + model.Y * 3 * rate / gammas[g];
      for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(e[i], expected, 1e-6 * expected) << model.toml << " i " << i;
      for (std::size_t i = 3; i < 6; ++i) EXPECT_EQ(e[i], 0.0);
      EXPECT_LT(r.points.back().state[0], 1e-12);  // no deviatoric plastic strain
      excess[g] = (e[0] - T) / T;
      for (const PathPoint& p : r.points) EXPECT_LE(p.stress[0], 3 * K * rate * 0.2);  // bounded
    }
    std::printf("[ figures  ] cut-off excess (sigma_m - T)/T: %.2e (gamma = 20), %.2e (gamma = 200)\n", excess[0],
                excess[1]);
    EXPECT_NEAR(excess[0] / excess[1], 10.0, 1e-3);
  }
}

// Both mechanisms at once: Mohr–Coulomb, phi = 30, psi = 10, T = 5 kPa in uniaxial-strain
// extension (eps_yy grows, the others held). The cut-off acts first (sigma_m = T while the
// shear surface needs about 8 kPa), then q grows along sigma_m = T to the shear surface: the
// end state sits on the intersection. As gamma grows the state converges (the differences
// shrink like 1/gamma) to a point that satisfies both surfaces: the rate-independent limit.
TEST(TensionCutoff, FastLimitOnTheIntersectionOfBothSurfaces) {
  const double T = 5e3, Y = std::sqrt(3.0) * std::cos(30 * kDegree) * 1e4;
  LoadPath path = LoadPath::oedometric(0.02);
  path.duration = 0.1;
  path.dt = 1e-3;
  const double gammas[3] = {2.0, 20.0, 200.0};
  Sym6 end[3];
  for (int g = 0; g < 3; ++g) {
    std::string toml = mohr_coulomb(30.0, 10.0, gammas[g]) + "tension_cutoff = 5.0e3\n";
    auto m = material_from_toml(toml);
    const PathResult r = integrate_path(*m, {}, path);
    end[g] = r.points.back().stress;
    EXPECT_TRUE(std::all_of(end[g].begin(), end[g].end(), [](double v) { return std::isfinite(v); }));
    const MohrCoulombSurface surf = MohrCoulombSurface::make(30 * kDegree, 10 * kDegree, 0.1);
    const double x = (surf.value(end[g], Y) - Y) / Y, x_t = (tensor::trace(end[g]) / 3 - T) / Y;
    std::printf("[ figures  ] gamma = %5.0f: shear overstress %.2e, cut-off overstress %.2e, sigma_yy %.1f Pa\n",
                gammas[g], x, x_t, end[g][1]);
    EXPECT_GT(x, 0.0);  // both act
    EXPECT_GT(x_t, 0.0);
    EXPECT_LT(x, 0.5 / gammas[g]);
    EXPECT_LT(x_t, 0.5 / gammas[g]);
  }
  const double d1 = std::abs(end[0][1] - end[1][1]), d2 = std::abs(end[1][1] - end[2][1]);
  EXPECT_GT(d1 / d2, 7.0);
  EXPECT_LT(d1 / d2, 13.0);
}

}  // namespace
}  // namespace rktsph
