// Unit tests of the Perzyna parts: yield surfaces (value, gradient, flow vector against
// central finite differences), overstress functions and hardening laws.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numbers>
#include <vector>

#include "materials/hardening.hpp"
#include "materials/overstress.hpp"
#include "materials/perzyna.hpp"
#include "materials/tension_cutoff.hpp"
#include "materials/tensor.hpp"
#include "materials/yield_cam_clay.hpp"
#include "materials/yield_drucker_prager.hpp"
#include "materials/yield_mohr_coulomb.hpp"
#include "materials/yield_von_mises.hpp"

namespace rktsph {
namespace {

// Derivative of a scalar function of a symmetric tensor in TENSOR components: the Sym6 shear
// entry stands for both sigma_ij and sigma_ji, so d/dSym6[i] is twice the tensor derivative.
Sym6 fd_gradient(const std::function<double(const Sym6&)>& f, const Sym6& s, double h) {
  Sym6 g;
  for (std::size_t i = 0; i < 6; ++i) {
    Sym6 a = s, b = s;
    a[i] += h;
    b[i] -= h;
    g[i] = (f(a) - f(b)) / (2.0 * h) * (i < 3 ? 1.0 : 0.5);
  }
  return g;
}

const Sym6 kGeneral{-120e3, -80e3, -95e3, 15e3, -7e3, 4e3};  // Pa, all components non-zero

TEST(PerzynaParts, VonMisesValueAndGradientMatchFiniteDifferences) {
  const VonMisesSurface vm;
  // Uniaxial compression of 3 kPa: q = 3 kPa regardless of the pressure.
  EXPECT_NEAR(vm.value({-3e3, 0, 0, 0, 0, 0}, 1.0), 3e3, 1e-9);
  const Sym6 g = vm.gradient(kGeneral, 1.0);
  const Sym6 fd = fd_gradient([&](const Sym6& s) { return vm.value(s, 1.0); }, kGeneral, 1.0);
  for (std::size_t i = 0; i < 6; ++i) EXPECT_NEAR(g[i], fd[i], 1e-7) << "component " << i;
  // Flow: deviatoric, unit equivalent norm sqrt(2/3 m:m) = 1 (method-notes §1.7).
  const Sym6 m = vm.flow(kGeneral, 1.0);
  EXPECT_NEAR(tensor::trace(m), 0.0, 1e-14);
  EXPECT_NEAR(tensor::equivalent_strain(m), 1.0, 1e-12);
}

TEST(PerzynaParts, CamClayValueGradientAndFlowMatchFiniteDifferences) {
  for (bool lode : {false, true}) {
    const CamClaySurface cc{1.2, lode};
    const double pc = 200e3;
    const Sym6 g = cc.gradient(kGeneral, pc);
    const Sym6 fd = fd_gradient([&](const Sym6& s) { return cc.value(s, pc); }, kGeneral, 1.0);
    for (std::size_t i = 0; i < 6; ++i) {
      EXPECT_NEAR(g[i], fd[i], 1e-6 * (1.0 + std::abs(fd[i]))) << "lode " << lode << " i " << i;
    }
    // m = (df/dsigma)/p_c with the ellipse f = q^2 + M(theta)^2 p'(p' - p_c) (method-notes §1.8).
    auto f = [&](const Sym6& s) {
      const Invariants inv = invariants(s);
      const Sym6 d = tensor::deviator(s);
      const double M = cc.slope(d, 0.5 * tensor::ddot(d, d), pc).M;
      return (inv.q * inv.q + M * M * inv.p * (inv.p - pc)) / pc;
    };
    const Sym6 m = cc.flow(kGeneral, pc);
    const Sym6 fdm = fd_gradient(f, kGeneral, 1.0);
    for (std::size_t i = 0; i < 6; ++i) {
      EXPECT_NEAR(m[i], fdm[i], 1e-6 * (1.0 + std::abs(fdm[i]))) << "lode " << lode << " i " << i;
    }
  }
}

TEST(PerzynaParts, CamClayFlowDirection) {
  const CamClaySurface cc{1.2, false};
  const double pc = 100e3;
  // Isotropic at p' = p_c: m = -(M^2/3) 1, i.e. compaction (tr m = -M^2 < 0).
  const Sym6 iso = cc.flow({-pc, -pc, -pc, 0, 0, 0}, pc);
  EXPECT_NEAR(iso[0], -1.44 / 3.0, 1e-12);
  EXPECT_NEAR(iso[3], 0.0, 1e-15);
  // Critical state (p' = p_c/2, q = M p'): purely deviatoric flow.
  const double p = 0.5 * pc, q = 1.2 * p;  // triaxial compression along y
  const Sym6 cs{-(p - q / 3.0), -(p + 2.0 * q / 3.0), -(p - q / 3.0), 0, 0, 0};
  EXPECT_NEAR(cc.value(cs, pc), pc, 1e-9);
  EXPECT_NEAR(tensor::trace(cc.flow(cs, pc)), 0.0, 1e-12);
  // Dry side (p' < p_c/2) dilates, wet side compacts.
  const Sym6 dry{-20e3, -20e3 - 60e3, -20e3, 0, 0, 0};  // p' = 40 kPa < p_c/2
  const Sym6 wet{-80e3, -80e3 - 60e3, -80e3, 0, 0, 0};  // p' = 100 kPa > p_c/2
  EXPECT_GT(tensor::trace(cc.flow(dry, pc)), 0.0);
  EXPECT_LT(tensor::trace(cc.flow(wet, pc)), 0.0);
  // Tension guard: F = p' for p' <= 0, no division by p'.
  EXPECT_DOUBLE_EQ(cc.value({10e3, 10e3, 10e3, 5e3, 0, 0}, pc), -10e3);
}

TEST(PerzynaParts, CamClayLodeDependentM) {
  const double Mc = 1.2;
  const CamClaySurface cc{Mc, true};
  const double sphi = 3.0 * Mc / (6.0 + Mc);
  auto M_of = [&](const Sym6& s) {
    const Sym6 d = tensor::deviator(s);
    return cc.slope(d, 0.5 * tensor::ddot(d, d), 1e5).M;
  };
  // Triaxial compression along y (theta = +30 deg in the tension-positive convention): M = M_c.
  EXPECT_NEAR(M_of({-50e3, -150e3, -50e3, 0, 0, 0}), Mc, 1e-12);
  // Triaxial extension: M = 6 sin(phi)/(3 + sin(phi)).
  EXPECT_NEAR(M_of({-150e3, -50e3, -150e3, 0, 0, 0}), 6.0 * sphi / (3.0 + sphi), 1e-12);
  // docs/cases.md Case 3: plane-strain elastic path, nu = 0.3, has sin 3theta = 0.629, M = 1.117.
  const double s = 100e3, nu = 0.3, p0 = 50e3;
  EXPECT_NEAR(M_of({-p0, -(p0 + s), -(p0 + nu * s), 0, 0, 0}), 1.117, 5e-4);
  EXPECT_NEAR(CamClaySurface::M_from_friction_angle(30.0), 1.2, 1e-12);
}

TEST(PerzynaParts, OverstressFunctions) {
  Overstress pw{OverstressKind::power, 2.0, 0.0};
  EXPECT_DOUBLE_EQ(pw.value(-0.1), 0.0);  // Macaulay bracket
  EXPECT_DOUBLE_EQ(pw.value(0.0), 0.0);
  EXPECT_NEAR(pw.value(0.3), 0.09, 1e-15);
  EXPECT_NEAR(pw.slope(0.3), 0.6, 1e-15);
  Overstress ex{OverstressKind::exponential, 2.0, 0.0};
  EXPECT_NEAR(ex.value(0.3), std::exp(0.6) - 1.0, 1e-15);
  EXPECT_NEAR(ex.slope(0.3), 2.0 * std::exp(0.6), 1e-14);
  EXPECT_DOUBLE_EQ(ex.value(-0.3), 0.0);
  // No dead band by default: any positive overstress flows.
  EXPECT_GT(Overstress{}.value(1e-6), 0.0);
  // A requested dead band suppresses flow below it and does not shift Phi above it.
  Overstress db{OverstressKind::power, 1.0, 0.01};
  EXPECT_DOUBLE_EQ(db.value(0.005), 0.0);
  EXPECT_DOUBLE_EQ(db.value(0.02), 0.02);
  // Slopes against central differences.
  for (const Overstress& o : {pw, ex, Overstress{OverstressKind::power, 0.5, 0.0}}) {
    const double x = 0.4, h = 1e-6;
    EXPECT_NEAR(o.slope(x), (o.value(x + h) - o.value(x - h)) / (2 * h), 1e-6);
  }
}

TEST(PerzynaParts, LinearHardeningWithResidualFloor) {
  const LinearHardening h{100e3, -1e6, 10e3};
  double k[1] = {0.05};
  EXPECT_DOUBLE_EQ(h.size(k), 50e3);
  k[0] = 0.2;  // 100e3 - 200e3 < floor
  EXPECT_DOUBLE_EQ(h.size(k), 10e3);
  EXPECT_DOUBLE_EQ(h.size_rate_per_flow({0, 0, 0, 1.0, 0, 0}, k), 0.0);  // on the floor
  // Rate: accumulated strain sqrt(2/3 e:e); pure tensor shear e_xy = a gives 2a/sqrt(3).
  double dk[1];
  h.rate({0, 0, 0, 3e-3, 0, 0}, k, dk);
  EXPECT_NEAR(dk[0], 2.0 * 3e-3 / std::sqrt(3.0), 1e-15);
  // Volumetric strain rate does not count.
  h.rate({1e-3, 1e-3, 1e-3, 0, 0, 0}, k, dk);
  EXPECT_NEAR(dk[0], 0.0, 1e-18);
}

TEST(PerzynaParts, CamClayHardeningLaw) {
  // (1 + e0)/(lambda - kappa) = 2/0.18.
  CamClayHardening h{2.0 / 0.18, 300e3, 0.0};
  double k[3];
  h.initial_state(123.0, k);
  EXPECT_DOUBLE_EQ(k[2], 300e3);
  double dk[3];
  const Sym6 compaction{-1e-3, -1e-3, -1e-3, 0, 0, 0};  // tr = -3e-3 (compression)
  h.rate(compaction, k, dk);
  EXPECT_NEAR(dk[1], -3e-3, 1e-18);
  EXPECT_NEAR(dk[2], 300e3 * 2.0 / 0.18 * 3e-3, 1e-6);  // compaction hardens
  h.rate(tensor::scaled(compaction, -1.0), k, dk);
  EXPECT_LT(dk[2], 0.0);  // dilation softens
  // OCR: p_c = OCR * (p' + q^2/(M^2 p')) of the initial stress.
  CamClayHardening o{1.0, 0.0, 4.0};
  o.initial_state(50e3, k);
  EXPECT_DOUBLE_EQ(k[2], 200e3);
}

constexpr double kDeg = std::numbers::pi / 180.0;

// A Drucker–Prager surface as the registry builds it (perzyna_models.cpp), rounding eps.
DruckerPragerSurface drucker_prager(DruckerPragerMatch match, double phi_deg, double psi_deg, double eps) {
  const DruckerPragerCone cone = DruckerPragerCone::matched(match, phi_deg * kDeg, psi_deg * kDeg);
  return {cone.eta, cone.eta_flow, eps * std::sin(phi_deg * kDeg), eps * std::sin(psi_deg * kDeg)};
}

bool all_finite(const Sym6& a) {
  return std::all_of(a.begin(), a.end(), [](double v) { return std::isfinite(v); });
}

TEST(PerzynaParts, DruckerPragerValueGradientAndFlowMatchFiniteDifferences) {
  const double Y = 30e3;  // xi c, Pa; delta_F = 0.1 sin(30 deg) Y = 1.5 kPa
  const double p_apex = -Y / drucker_prager(DruckerPragerMatch::plane_strain, 30, 10, 0.1).eta;
  const std::vector<Sym6> states{
      kGeneral,
      {-50e3, -50e3, -50e3, 300.0, 0, 0},                           // near the axis, q = 520 Pa < delta_F
      {-50e3, -50e3, -50e3, 0, 0, 0},                               // on the axis (q = 0)
      {p_apex, p_apex, p_apex, 0, 0, 0},                            // at the sharp cone's apex
      {-3 * p_apex, -3 * p_apex + 100.0, -3 * p_apex, 0, 50.0, 0},  // far beyond the apex, in tension
  };
  double worst_grad = 0.0, worst_flow = 0.0;
  for (DruckerPragerMatch match :
       {DruckerPragerMatch::plane_strain, DruckerPragerMatch::outer, DruckerPragerMatch::inner}) {
    const DruckerPragerSurface dp = drucker_prager(match, 30, 10, 0.1);
    for (std::size_t k = 0; k < states.size(); ++k) {
      const Sym6& s = states[k];
      const Sym6 g = dp.gradient(s, Y);
      const Sym6 fd = fd_gradient([&](const Sym6& t) { return dp.value(t, Y); }, s, 0.5);
      const Sym6 m = dp.flow(s, Y);
      const Sym6 fdm = fd_gradient([&](const Sym6& t) { return dp.potential(t, Y); }, s, 0.5);
      for (std::size_t i = 0; i < 6; ++i) {
        EXPECT_NEAR(g[i], fd[i], 1e-6 * (1.0 + std::abs(fd[i]))) << "state " << k << " i " << i;
        EXPECT_NEAR(m[i], fdm[i], 1e-6 * (1.0 + std::abs(fdm[i]))) << "state " << k << " i " << i;
        worst_grad = std::max(worst_grad, std::abs(g[i] - fd[i]));
        worst_flow = std::max(worst_flow, std::abs(m[i] - fdm[i]));
      }
    }
  }
  std::printf("[ figures  ] Drucker-Prager max |dF/dsigma - FD| = %.2e, max |m - dQ/dsigma FD| = %.2e\n", worst_grad,
              worst_flow);
  // The flow slope is the potential's, not the surface's (non-associated): tr m = eta_Q.
  const DruckerPragerSurface dp = drucker_prager(DruckerPragerMatch::plane_strain, 30, 10, 0.1);
  EXPECT_NEAR(tensor::trace(dp.flow(kGeneral, Y)), dp.eta_flow, 1e-14);
  EXPECT_NEAR(tensor::trace(dp.gradient(kGeneral, Y)), dp.eta, 1e-14);
  EXPECT_LT(dp.eta_flow, dp.eta);
}

// The cone against the Mohr–Coulomb strength of the matched meridian (no rounding): on the
// compression meridian for the outer cone, the extension meridian for the inner one.
TEST(PerzynaParts, DruckerPragerMatchesMohrCoulombOnItsMeridian) {
  const double phi = 30 * kDeg, c = 20e3, sf = std::sin(phi), cf = std::cos(phi);
  const double confining = 80e3;                                                 // sigma_3, compression positive
  const double major = confining * (1 + sf) / (1 - sf) + 2 * c * cf / (1 - sf);  // sigma_1 on MC
  struct Case {
    DruckerPragerMatch match;
    Sym6 stress;
  };
  const Case cases[] = {
      {DruckerPragerMatch::outer, {-confining, -major, -confining, 0, 0, 0}},  // triaxial compression
      {DruckerPragerMatch::inner, {-major, -confining, -major, 0, 0, 0}},      // triaxial extension
  };
  for (const Case& k : cases) {
    const DruckerPragerCone cone = DruckerPragerCone::matched(k.match, phi, 0.0);
    const DruckerPragerSurface dp{cone.eta, 0.0, 0.0, 0.0};
    EXPECT_NEAR(dp.value(k.stress, cone.xi * c), cone.xi * c, 1e-9 * cone.xi * c);
  }
  // Plane-strain match, associated: the classical sqrt(J2) = k + 3 alpha p' with
  // alpha = tan(phi)/sqrt(9 + 12 tan^2 phi), k = 3c/sqrt(9 + 12 tan^2 phi); eta = 3 sqrt3 alpha, xi c = sqrt3 k.
  const DruckerPragerCone ps = DruckerPragerCone::matched(DruckerPragerMatch::plane_strain, phi, phi);
  const double t = std::tan(phi);
  EXPECT_NEAR(ps.eta, std::sqrt(3.0) * 3 * t / std::sqrt(9 + 12 * t * t), 1e-14);
  EXPECT_NEAR(ps.xi, std::sqrt(3.0) * 3 / std::sqrt(9 + 12 * t * t), 1e-14);
  EXPECT_NEAR(ps.eta_flow, ps.eta, 1e-14);
  // Plane-strain match with psi = 0: alpha = sin(phi)/3, k = c cos(phi) (sqrt(J2) form).
  const DruckerPragerCone ps0 = DruckerPragerCone::matched(DruckerPragerMatch::plane_strain, phi, 0.0);
  EXPECT_NEAR(ps0.eta, std::sqrt(3.0) * sf, 1e-14);
  EXPECT_NEAR(ps0.xi, std::sqrt(3.0) * cf, 1e-14);
  EXPECT_EQ(ps0.eta_flow, 0.0);
  // phi = 0: von Mises with Y = sqrt(3) c (plane strain) or 2 c (through the Tresca corners).
  EXPECT_NEAR(DruckerPragerCone::matched(DruckerPragerMatch::plane_strain, 0, 0).xi, std::sqrt(3.0), 1e-15);
  EXPECT_NEAR(DruckerPragerCone::matched(DruckerPragerMatch::outer, 0, 0).xi, 2.0, 1e-15);
  EXPECT_NEAR(DruckerPragerCone::matched(DruckerPragerMatch::inner, 0, 0).xi, 2.0, 1e-15);
}

TEST(PerzynaParts, DruckerPragerApexAndTensionStatesAreFinite) {
  const double Y = 30e3;
  for (double eps : {0.1, 0.0}) {
    for (double psi : {0.0, 20.0}) {
      const DruckerPragerSurface dp = drucker_prager(DruckerPragerMatch::plane_strain, 35, psi, eps);
      const double p_apex = -Y / dp.eta;
      for (double p : {0.0, 0.5 * p_apex, p_apex, 10.0 * p_apex, -1e6}) {
        const Sym6 s{-p, -p, -p, 0, 0, 0};
        EXPECT_TRUE(std::isfinite(dp.value(s, Y))) << eps << " " << psi << " " << p;
        EXPECT_TRUE(all_finite(dp.gradient(s, Y))) << eps << " " << psi << " " << p;
        EXPECT_TRUE(all_finite(dp.flow(s, Y))) << eps << " " << psi << " " << p;
      }
      // Unstressed: inside (F = delta_F < Y).
      EXPECT_LT(dp.value({}, Y), Y);
      // On the axis the gradient is volumetric, eta/3 1; beyond the apex F > Y.
      const Sym6 beyond{-2 * p_apex, -2 * p_apex, -2 * p_apex, 0, 0, 0};
      EXPECT_GT(dp.value(beyond, Y), Y);
      const Sym6 g = dp.gradient(beyond, Y);
      EXPECT_NEAR(g[0], dp.eta / 3, 1e-15);
      EXPECT_EQ(g[3], 0.0);
      // With psi > 0 the flow there dilates (relieves the tension); with psi = 0 it is zero.
      const Sym6 m = dp.flow(beyond, Y);
      if (psi > 0) {
        EXPECT_GT(tensor::trace(m), 0.0);
      } else {
        EXPECT_EQ(tensor::trace(m), 0.0);
      }
    }
  }
  // The rounded apex: F(q = 0) = Y at p' = -(1 - eps sin(phi)) Y/eta (eq. 1.10.1).
  const DruckerPragerSurface dp = drucker_prager(DruckerPragerMatch::outer, 30, 0, 0.1);
  const double p_round = -(1 - 0.05) * Y / dp.eta;
  EXPECT_NEAR(dp.value({-p_round, -p_round, -p_round, 0, 0, 0}, Y), Y, 1e-9 * Y);
}

TEST(PerzynaParts, DruckerPragerWithoutFrictionIsVonMises) {
  const VonMisesSurface vm;
  const DruckerPragerSurface dp = drucker_prager(DruckerPragerMatch::plane_strain, 0, 0, 0.1);
  EXPECT_EQ(dp.eta, 0.0);
  EXPECT_EQ(dp.round_F, 0.0);
  for (const Sym6& s : {kGeneral, Sym6{-1e5, -1e5, -1e5, 0, 0, 0}, Sym6{3e4, 0, -2e4, 0, 1e4, 0}}) {
    EXPECT_NEAR(dp.value(s, 1e5), vm.value(s, 1e5), 1e-15 * vm.value(s, 1e5));
    const Sym6 g = dp.gradient(s, 1e5), gv = vm.gradient(s, 1e5);
    const Sym6 m = dp.flow(s, 1e5), mv = vm.flow(s, 1e5);
    for (std::size_t i = 0; i < 6; ++i) {
      EXPECT_NEAR(g[i], gv[i], 1e-15);
      EXPECT_NEAR(m[i], mv[i], 1e-15);
    }
  }
}

// A stress of mean pressure p (compression positive), von Mises stress q and Lode angle theta
// (eq. (1.1.3); +30 deg is triaxial compression), its principal axes turned by a (about z)
// and b (about x) so that every component is non-zero.
Sym6 lode_state(double p, double q, double theta_deg, double a = 0.4, double b = 0.7) {
  const double t = theta_deg * kDeg, third = 2.0 * std::numbers::pi / 3.0;
  const double d[3] = {-p + 2.0 * q / 3.0 * std::sin(t + third), -p + 2.0 * q / 3.0 * std::sin(t),
                       -p + 2.0 * q / 3.0 * std::sin(t - third)};
  const double ca = std::cos(a), sa = std::sin(a), cb = std::cos(b), sb = std::sin(b);
  // R = Rx(b) Rz(a); sigma = R diag(d) R^T.
  const double R[3][3] = {{ca, -sa, 0.0}, {cb * sa, cb * ca, -sb}, {sb * sa, sb * ca, cb}};
  auto c = [&](int i, int j) {
    double v = 0.0;
    for (int k = 0; k < 3; ++k) v += R[i][k] * d[k] * R[j][k];
    return v;
  };
  return {c(0, 0), c(1, 1), c(2, 2), c(0, 1), c(1, 2), c(0, 2)};
}

// Sharp Mohr–Coulomb in the form of eq. (1.11.1): sqrt3 [(s1 - s3)/2 - (s1 + s3)/2 sin(phi)]
// with s1 >= s2 >= s3 the principal stresses, compression positive (from the same p, q, theta).
double sharp_mohr_coulomb(double p, double q, double theta_deg, double phi_deg) {
  const double t = theta_deg * kDeg, third = 2.0 * std::numbers::pi / 3.0;
  double c[3] = {p - 2.0 * q / 3.0 * std::sin(t + third), p - 2.0 * q / 3.0 * std::sin(t),
                 p - 2.0 * q / 3.0 * std::sin(t - third)};
  std::sort(c, c + 3);
  return std::sqrt(3.0) * (0.5 * (c[2] - c[0]) - 0.5 * (c[2] + c[0]) * std::sin(phi_deg * kDeg));
}

TEST(PerzynaParts, MohrCoulombLodeStateHelperHasTheRequestedInvariants) {
  const Sym6 s = lode_state(80e3, 50e3, 20.0);
  const Sym6 d = tensor::deviator(s);
  const double J2 = 0.5 * tensor::ddot(d, d);
  EXPECT_NEAR(invariants(s).p, 80e3, 1e-8);
  EXPECT_NEAR(invariants(s).q, 50e3, 1e-8);
  EXPECT_NEAR(MohrCoulombSurface::lode_x(d, J2, 1.0), std::sin(60.0 * kDeg), 1e-12);
}

TEST(PerzynaParts, MohrCoulombValueGradientAndFlowMatchFiniteDifferences) {
  const double Y = 30e3;  // sqrt3 c cos(phi)
  const MohrCoulombSurface mc = MohrCoulombSurface::make(30 * kDeg, 10 * kDeg, 0.1);
  const double p_apex = -Y / (std::sqrt(3.0) * 0.5);
  std::vector<Sym6> states{kGeneral,
                           lode_state(80e3, 500.0, 13.0),
                           {-50e3, -50e3, -50e3, 0, 0, 0},
                           {p_apex, p_apex, p_apex, 0, 0, 0},
                           lode_state(-3 * p_apex, 200.0, -17.0)};
  // The Lode extremes, both sides of the default transition theta_T = 29.7 deg, and inside.
  for (double theta : {30.0, -30.0, 29.85, -29.85, 29.5, -29.5, 28.4, -28.4, 10.0, 0.0, -20.0}) {
    states.push_back(lode_state(80e3, 50e3, theta));
  }
  double worst_grad = 0.0, worst_flow = 0.0;
  for (std::size_t k = 0; k < states.size(); ++k) {
    const Sym6& s = states[k];
    // The step resolves the Lode variation at small q; on the axis the Lode factor of the
    // perturbed state depends on the direction of the step, so the difference is only O(h).
    const double h = std::clamp(1e-4 * invariants(s).q, 1e-3, 0.5);
    const Sym6 g = mc.gradient(s, Y);
    const Sym6 fd = fd_gradient([&](const Sym6& t) { return mc.value(t, Y); }, s, h);
    const Sym6 m = mc.flow(s, Y);
    const Sym6 fdm = fd_gradient([&](const Sym6& t) { return mc.potential(t, Y); }, s, h);
    for (std::size_t i = 0; i < 6; ++i) {
      EXPECT_NEAR(g[i], fd[i], 1e-6 * (1.0 + std::abs(fd[i]))) << "state " << k << " i " << i;
      EXPECT_NEAR(m[i], fdm[i], 1e-6 * (1.0 + std::abs(fdm[i]))) << "state " << k << " i " << i;
      worst_grad = std::max(worst_grad, std::abs(g[i] - fd[i]));
      worst_flow = std::max(worst_flow, std::abs(m[i] - fdm[i]));
    }
  }
  std::printf("[ figures  ] Mohr-Coulomb max |dF/dsigma - FD| = %.2e, max |m - dQ/dsigma FD| = %.2e\n", worst_grad,
              worst_flow);
  EXPECT_NEAR(tensor::trace(mc.flow(kGeneral, Y)), std::sqrt(3.0) * std::sin(10 * kDeg), 1e-14);
}

TEST(PerzynaParts, MohrCoulombLodeRoundingIsSmoothAndIsAbboSloans) {
  EXPECT_NEAR(LodeFactor::kDefaultTransition, 29.7 * kDeg, 1e-15);
  EXPECT_NEAR(LodeFactor::of(0.5).transition, 29.7 * kDeg, 1e-15);
  for (double tT_deg : {20.0, 29.0, 29.7, 29.9}) {
    const double tT = tT_deg * kDeg;
    for (double phi : {0.0, 20.0, 30.0, 40.0}) {
      const double sf = std::sin(phi * kDeg);
      const LodeFactor K = LodeFactor::of(sf, tT);
      // Abbo & Sloan (1995): A = cos(tT)/3 [3 + tan(tT) tan(3tT) + sign/sqrt3 (tan(3tT) - 3 tan(tT)) sin(phi)],
      // B = [sign sin(tT) + sin(phi) cos(tT)/sqrt3] / (3 cos(3tT)).
      for (double sign : {1.0, -1.0}) {
        const double A =
            std::cos(tT) / 3 *
            (3 + std::tan(tT) * std::tan(3 * tT) + sign / std::sqrt(3.0) * (std::tan(3 * tT) - 3 * std::tan(tT)) * sf);
        const double B = (sign * std::sin(tT) + sf * std::cos(tT) / std::sqrt(3.0)) / (3 * std::cos(3 * tT));
        EXPECT_NEAR(sign > 0 ? K.A_plus : K.A_minus, A, 1e-12 * std::abs(A)) << phi << " " << tT_deg;
        EXPECT_NEAR(sign > 0 ? K.B_plus : K.B_minus, B, 1e-12 * std::abs(B)) << phi << " " << tT_deg;
        // K and dK/dtheta continuous at +-theta_T.
        const double x_in = std::sin(3 * (sign * tT - sign * 1e-9)), x_out = std::sin(3 * (sign * tT + sign * 1e-9));
        EXPECT_NEAR(K(x_in).K, K(x_out).K, 1e-8);
        EXPECT_NEAR(K(x_in).dKdx, K(x_out).dKdx, 1e-6 * std::abs(K(x_out).dKdx));
      }
      // Inside the transition K is the exact Mohr–Coulomb factor.
      const double th = 19 * kDeg;
      EXPECT_NEAR(K(std::sin(3 * th)).K, std::cos(th) - sf * std::sin(th) / std::sqrt(3.0), 1e-14);
    }
  }
}

// The rounding's departure from the exact pyramid, |K/K_MC - 1| over theta_T <= |theta| <= 30 deg,
// is within the bound of method-notes eq. (1.11.7), (30 deg - theta_T)/2 sqrt3 (1 + sin phi)/(3 - sin phi)
// (its first-order value at the compression corner; 2 % margin for the second order).
TEST(PerzynaParts, MohrCoulombRoundingDepartsFromThePyramidWithinItsBound) {
  for (double tT_deg : {20.0, 29.0, 29.5, 29.7, 29.9}) {
    const double tT = tT_deg * kDeg;
    for (double phi : {0.0, 20.0, 30.0, 40.0, 45.0}) {
      const double sf = std::sin(phi * kDeg);
      const LodeFactor K = LodeFactor::of(sf, tT);
      const double bound = 0.5 * (30 * kDeg - tT) * std::sqrt(3.0) * (1 + sf) / (3 - sf);
      double worst = 0.0;
      for (int i = 0; i <= 400; ++i) {
        const double th = tT + (30 * kDeg - tT) * i / 400.0;
        for (double sign : {1.0, -1.0}) {
          const double exact = std::cos(th) - sign * sf * std::sin(th) / std::sqrt(3.0);
          worst = std::max(worst, std::abs(K(std::sin(3 * sign * th)).K / exact - 1));
        }
      }
      EXPECT_LE(worst, 1.02 * bound) << tT_deg << " " << phi;
      EXPECT_GE(worst, 0.9 * bound) << tT_deg << " " << phi;  // the bound is the departure, not a loose cap
      if (tT_deg == 29.7) {
        std::printf("[ figures  ] theta_T = 29.7, phi = %2.0f: max |K/K_MC - 1| = %.3e, bound %.3e\n", phi, worst,
                    bound);
        // The default meets the 1 % triaxial-peak criterion of issue 16 up to phi = 45 deg (eq. 1.11.8).
        const double peak_error =
            (std::cos(30 * kDeg) - 1.5 * sf / std::sqrt(3.0)) / (K(1.0).K - sf / std::sqrt(3.0)) - 1;
        EXPECT_LT(std::abs(peak_error), 0.01) << phi;
        EXPECT_NEAR(peak_error, -(30 * kDeg - tT) * (1 + sf) / (2 * std::sqrt(3.0) * (1 - sf)),
                    0.02 * std::abs(peak_error));
      }
    }
  }
}

TEST(PerzynaParts, MohrCoulombIsTheSharpPyramidOnItsFaces) {
  const MohrCoulombSurface mc = MohrCoulombSurface::make(30 * kDeg, 0.0, 0.0);
  for (double theta : {-28.0, -15.0, 0.0, 20.0, 28.9}) {
    const double F = mc.value(lode_state(90e3, 70e3, theta), 1.0);
    EXPECT_NEAR(F, sharp_mohr_coulomb(90e3, 70e3, theta, 30), 1e-9 * 70e3) << theta;
  }
  // At the corners the rounding is within 1 % (of the deviatoric part).
  for (double theta : {30.0, -30.0}) {
    const double F = mc.value(lode_state(90e3, 70e3, theta), 1.0);
    const double sharp = sharp_mohr_coulomb(90e3, 70e3, theta, 30);
    EXPECT_NEAR(F, sharp, 1e-2 * 70e3) << theta;
    EXPECT_NE(F, sharp);
  }
}

TEST(PerzynaParts, MohrCoulombWithoutFrictionIsRoundedTresca) {
  const MohrCoulombSurface mc = MohrCoulombSurface::make(0.0, 0.0, 0.1);
  const VonMisesSurface vm;
  EXPECT_EQ(mc.round_F, 0.0);
  // Pure shear (theta = 0): F = q, the gradient is von Mises'.
  const Sym6 shear{0, 0, 0, 3e4, 0, 0};
  EXPECT_NEAR(mc.value(shear, 1e5), vm.value(shear, 1e5), 1e-10);
  for (std::size_t i = 0; i < 6; ++i) EXPECT_NEAR(mc.gradient(shear, 1e5)[i], vm.gradient(shear, 1e5)[i], 1e-14);
  // Inside the transition: Tresca, sqrt3 (sigma_1 - sigma_3)/2, whatever the pressure.
  for (double theta : {-25.0, 10.0, 28.0}) {
    EXPECT_NEAR(mc.value(lode_state(-4e4, 6e4, theta), 1e5), sharp_mohr_coulomb(-4e4, 6e4, theta, 0), 1e-9 * 6e4);
  }
  // Hydrostatic (q = 0, no rounding at phi = 0) and the corners: finite, no NaN.
  for (const Sym6& s :
       {Sym6{-1e5, -1e5, -1e5, 0, 0, 0}, Sym6{}, lode_state(1e5, 5e4, 30.0), lode_state(1e5, 5e4, -30.0)}) {
    EXPECT_TRUE(std::isfinite(mc.value(s, 1e5)));
    EXPECT_TRUE(all_finite(mc.gradient(s, 1e5)));
    EXPECT_TRUE(all_finite(mc.flow(s, 1e5)));
  }
  const Sym6 g = mc.gradient({-1e5, -1e5, -1e5, 0, 0, 0}, 1e5);
  for (double v : g) EXPECT_EQ(v, 0.0);
}

TEST(PerzynaParts, MohrCoulombApexAndTensionStatesAreFinite) {
  const double Y = 30e3;
  for (double eps : {0.1, 0.0}) {
    for (double psi : {0.0, 20.0}) {
      const MohrCoulombSurface mc = MohrCoulombSurface::make(35 * kDeg, psi * kDeg, eps);
      const double p_apex = -Y / (std::sqrt(3.0) * std::sin(35 * kDeg));
      for (double p : {0.0, 0.5 * p_apex, p_apex, 10.0 * p_apex, -1e6}) {
        for (const Sym6& s : {Sym6{-p, -p, -p, 0, 0, 0}, lode_state(p, 1e-3, 30.0), lode_state(p, 1e-3, -30.0)}) {
          EXPECT_TRUE(std::isfinite(mc.value(s, Y))) << eps << " " << psi << " " << p;
          EXPECT_TRUE(all_finite(mc.gradient(s, Y))) << eps << " " << psi << " " << p;
          EXPECT_TRUE(all_finite(mc.flow(s, Y))) << eps << " " << psi << " " << p;
        }
      }
      EXPECT_LT(mc.value({}, Y), Y);
      const Sym6 beyond{-2 * p_apex, -2 * p_apex, -2 * p_apex, 0, 0, 0};
      EXPECT_GT(mc.value(beyond, Y), Y);
      EXPECT_NEAR(tensor::trace(mc.flow(beyond, Y)), std::sqrt(3.0) * std::sin(psi * kDeg), 1e-12);
    }
  }
}

// The tension cut-off (method-notes §1.12) beside the Mohr–Coulomb surface: E = 100 MPa,
// nu = 0.3, c = 10 kPa, phi = 30 (or 0), psi = 0, T = 5 kPa, gamma = 20 1/s, Phi = x.
using MohrCoulombCutoff = PerzynaMaterial<MohrCoulombSurface, LinearHardening>;
MohrCoulombCutoff mohr_coulomb_with_cutoff(double phi_deg, double T) {
  const double phi = phi_deg * kDeg;
  LinearHardening h;
  h.Y0 = std::sqrt(3.0) * std::cos(phi) * 1e4;
  h.Y_residual = 0.1 * h.Y0;
  return MohrCoulombCutoff("perzyna_mohr_coulomb", ElasticConstants::from_E_nu(1e8, 0.3, 2000.0),
                           MohrCoulombSurface::make(phi, 0.0, 0.1), h, Overstress{}, 20.0, PressureDependentModuli{},
                           TensionCutoff{true, T});
}

TEST(PerzynaParts, TensionCutoffValueAndGradientMatchFiniteDifferencesAcrossTheCutoff) {
  const double T = 5e3, Y = 1.5e4;
  const TensionCutoff cut{true, T};
  // States below, at and beyond the cut-off, isotropic and sheared.
  for (double sm : {-5e4, 0.0, T - 1.0, T, T + 1.0, 2 * T, 1e5}) {
    for (const Sym6& s : {Sym6{sm, sm, sm, 0, 0, 0}, Sym6{sm + 3e3, sm - 1e3, sm - 2e3, 4e3, -2e3, 1e3}}) {
      EXPECT_NEAR(TensionCutoff::value(s), sm, 1e-9 * (1 + std::abs(sm)));
      EXPECT_NEAR(cut.overstress(s, Y), (sm - T) / Y, 1e-12 * (1 + std::abs(sm)));
      const Sym6 fd = fd_gradient([&](const Sym6& t) { return TensionCutoff::value(t); }, s, 1.0);
      const Sym6 fdx = fd_gradient([&](const Sym6& t) { return Y * cut.overstress(t, Y); }, s, 1.0);
      for (std::size_t i = 0; i < 6; ++i) {
        EXPECT_NEAR(TensionCutoff::gradient()[i], fd[i], 1e-9) << sm << " " << i;
        EXPECT_NEAR(TensionCutoff::gradient()[i], fdx[i], 1e-9) << sm << " " << i;
      }
    }
  }
}

// On the isotropic axis beyond the apex with psi = 0 the shear flow vanishes (m = 0), so the
// rate is the cut-off's alone: dsigma = -gamma <x_t> K 1 (eq. 1.12.2), continuous across sigma_m = T.
TEST(PerzynaParts, TensionCutoffRateOnTheIsotropicAxis) {
  for (double phi : {30.0, 0.0}) {
    const MohrCoulombCutoff m = mohr_coulomb_with_cutoff(phi, 5e3);
    const double K = 1e8 / (3 * (1 - 2 * 0.3)), Y = m.hardening().Y0;
    const double k[1] = {0.0};
    for (double sm : {5e3 - 1e-3, 5e3, 5e3 + 1e-3, 1e4, 3e4, 1e6}) {
      const Sym6 s{sm, sm, sm, 0, 0, 0};
      Sym6 ds;
      double dk[1];
      m.source_rate(s, k, ds, dk);
      const double x_t = std::max(0.0, (sm - 5e3) / Y);
      for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(ds[i], -20.0 * x_t * K, 1e-9 * K * (1 + x_t)) << phi << " " << sm;
      for (std::size_t i = 3; i < 6; ++i) EXPECT_EQ(ds[i], 0.0);
      EXPECT_NEAR(dk[0], 0.0, 1e-12);  // volumetric flow: no equivalent (deviatoric) plastic strain
      EXPECT_TRUE(all_finite(m.surface().gradient(s, Y)));
      EXPECT_TRUE(all_finite(m.surface().flow(s, Y)));
      // Relaxation-rate estimate: gamma K/Y beyond the cut-off (eq. 1.12.3), 0 inside.
      EXPECT_NEAR(m.relaxation_rate(s, k), sm > 5e3 ? 20.0 * K / Y : 0.0, 1e-9 * 20.0 * K / Y) << phi << " " << sm;
    }
  }
}

// phi = 0 (rounded Tresca) with the cut-off: no apex, no NaN on the axis or at the corners,
// and the shear part of the rate is Tresca's (the cut-off adds only to the normal components).
TEST(PerzynaParts, TensionCutoffWithoutFrictionIsTrescaPlusCutoff) {
  const MohrCoulombCutoff with = mohr_coulomb_with_cutoff(0.0, 5e3);
  const MohrCoulombSurface tresca = MohrCoulombSurface::make(0.0, 0.0, 0.1);
  const double Y = with.hardening().Y0, k[1] = {0.0};
  for (const Sym6& s : {Sym6{}, Sym6{1e4, 1e4, 1e4, 0, 0, 0}, lode_state(-2e4, 3e4, 30.0), lode_state(-2e4, 3e4, -30.0),
                        lode_state(-2e4, 3e4, 12.0), lode_state(-1e4, 1e3, 30.0)}) {
    Sym6 ds;
    double dk[1];
    with.source_rate(s, k, ds, dk);
    EXPECT_TRUE(all_finite(ds));
    EXPECT_TRUE(std::isfinite(dk[0]));
    EXPECT_TRUE(std::isfinite(with.relaxation_rate(s, k)));
    // Deviatoric part: -2 G gamma <(F - Y)/Y> dev(m) of the Tresca surface alone.
    const double x = std::max(0.0, (tresca.value(s, Y) - Y) / Y);
    const Sym6 dev = tensor::deviator(tresca.flow(s, Y));
    const Sym6 dds = tensor::deviator(ds);
    const double G = 1e8 / 2.6;
    for (std::size_t i = 0; i < 6; ++i) EXPECT_NEAR(dds[i], -2 * G * 20.0 * x * dev[i], 1e-6 * G) << i;
  }
}

}  // namespace
}  // namespace rktsph
