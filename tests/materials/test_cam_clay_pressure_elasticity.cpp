// Modified Cam-Clay with pressure-dependent elasticity K = (1 + e0) p'/kappa (method-notes
// eqs. (1.8.8)–(1.8.12)) against its closed forms, through the material-point path integrator.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "material_test_util.hpp"
#include "materials/material_point_path.hpp"
#include "materials/tensor.hpp"

namespace rktsph {
namespace {

using test::material_from_toml;

constexpr double kLambda = 0.2, kKappa = 0.04, kE0 = 1.0, kM = 1.2, kNu = 0.3;
constexpr double kV0 = 1.0 + kE0;

// The keys of a pressure-dependent sample; `shear` is the shear-law lines (poisson or constant_G).
std::string pressure_dependent(double p_c0, double fluidity, const std::string& shear = "nu = 0.3\n") {
  return "model = 'perzyna_cam_clay'\nelasticity = 'pressure_dependent'\n" + shear +
         "density = 2000.0\nM = 1.2\nlambda = 0.2\nkappa = 0.04\ne0 = 1.0\nelastic_p_min = 1.0e3\n"
         "elastic_p_max = 1.0e7\np_c0 = " +
         std::to_string(p_c0) + "\nfluidity = " + std::to_string(fluidity) + "\n";
}
const std::string kConstantG = "shear = 'constant_G'\nG = 3.0e6\n";

Sym6 isotropic(double p) { return {-p, -p, -p, 0, 0, 0}; }
double p_of(const Sym6& s) { return -tensor::trace(s) / 3.0; }
double q_of(const Sym6& s) { return invariants(s).q; }
// Void ratio change from the volumetric strain, e - e0 = (1 + e0) tr(eps) (small strain, the
// relation the hardening law eq. (1.8.6) uses).
double delta_e(const PathPoint& a, const PathPoint& b) {
  return kV0 * (tensor::trace(b.strain) - tensor::trace(a.strain));
}

LoadPath isotropic_strain(double volumetric_rate, double duration) {
  LoadPath path;  // all components strain-controlled
  path.rate = {volumetric_rate / 3, volumetric_rate / 3, volumetric_rate / 3, 0, 0, 0};
  path.duration = duration;
  path.dt = duration / 1000;
  return path;
}

// Eq. (1.8.10): inside the surface, unloading and reloading follow the swelling line
// de = -kappa d ln p' exactly.
TEST(CamClayPressureElasticity, IsotropicUnloadReloadFollowsTheSwellingLine) {
  auto m = material_from_toml(pressure_dependent(4.0e5, 100.0));
  const double p1 = 2.0e5;
  // Unload to p' = 50 kPa: tr(eps) = (kappa/v0) ln 4.
  const double unload = kKappa / kV0 * std::log(4.0);
  const PathResult a = integrate_path(*m, isotropic(p1), isotropic_strain(unload / 10.0, 10.0));
  // Reload from there by 1.2 times the unloading strain (p' = 4^1.2 x 50 kPa = 264 kPa < p_c).
  const PathPoint& turn = a.points.back();
  const PathResult b = integrate_path(*m, turn.stress, isotropic_strain(-1.2 * unload / 10.0, 10.0));
  EXPECT_NEAR(p_of(turn.stress), 5.0e4, 1e-6 * 5.0e4);
  double worst = 0.0;
  for (const PathResult* r : {&a, &b}) {
    const PathPoint& start = r->points.front();
    for (const PathPoint& pt : r->points) {
      ASSERT_EQ(pt.state[1], 0.0) << "no viscoplastic volume change inside the surface";
      EXPECT_NEAR(q_of(pt.stress), 0.0, 1e-9 * p1);
      if (&pt == &start) continue;
      const double expected = -kKappa * std::log(p_of(pt.stress) / p_of(start.stress));
      worst = std::max(worst, std::abs(delta_e(start, pt) / expected - 1.0));
    }
  }
  EXPECT_LT(worst, 1e-3);
  EXPECT_NEAR(p_of(b.points.back().stress), 5.0e4 * std::pow(4.0, 1.2), 1e-3 * 2.64e5);
  std::printf("[ figures  ] swelling line: worst relative error of de = -kappa ln(p2/p1): %.2e\n", worst);
}

// On the normal compression line (a normally consolidated sample, fast viscosity) the elastic
// part kappa and the plastic part lambda - kappa add up to de = -lambda d ln p'.
TEST(CamClayPressureElasticity, NormalCompressionFollowsTheVirginLine) {
  auto m = material_from_toml(pressure_dependent(1.0e5, 100.0));
  // Three times the pressure: tr(eps) = -(lambda/v0) ln 3.
  const double compress = -kLambda / kV0 * std::log(3.0);
  const PathResult r = integrate_path(*m, isotropic(1.0e5), isotropic_strain(compress / 10.0, 10.0));
  const PathPoint& end = r.points.back();
  const double p_end = p_of(end.stress);
  const double slope = -delta_e(r.points.front(), end) / std::log(p_end / 1.0e5);
  EXPECT_NEAR(slope, kLambda, 0.01 * kLambda);
  EXPECT_NEAR(end.state[2], p_end, 0.01 * p_end);  // p_c tracks p' on the isotropic axis
  std::printf("[ figures  ] virgin line: slope %.5f (lambda %.2f), p' %.1f kPa, p_c %.1f kPa\n", slope, kLambda,
              p_end / 1e3, end.state[2] / 1e3);
}

// Eqs. (1.8.11)–(1.8.12): undrained (isochoric) triaxial compression of a lightly
// overconsolidated sample. Inside the surface p' is constant; once yielding,
// p_c p'^(kappa/(lambda-kappa)) stays constant, and the path ends on the critical state
// p'_cs = p'_0 (OCR/2)^((lambda-kappa)/lambda), q_cs = M p'_cs. Both shear laws give it: the
// closed form involves K only.
TEST(CamClayPressureElasticity, UndrainedPathFollowsTheClosedForm) {
  const double p0 = 1.0e5, pc0 = 1.5e5, ocr = pc0 / p0;
  const double exponent = kKappa / (kLambda - kKappa);
  const double p_cs = p0 * std::pow(ocr / 2.0, (kLambda - kKappa) / kLambda);
  for (const std::string& shear : {std::string("nu = 0.3\n"), kConstantG}) {
    SCOPED_TRACE(shear);
    auto m = material_from_toml(pressure_dependent(pc0, 100.0, shear));
    LoadPath path = LoadPath::undrained_triaxial(-0.01);
    path.duration = 30.0;
    path.dt = 0.01;
    const PathResult r = integrate_path(*m, isotropic(p0), path);
    double worst_elastic = 0.0, worst_invariant = 0.0;
    long elastic_points = 0, plastic_points = 0;
    for (const PathPoint& pt : r.points) {
      ASSERT_NEAR(tensor::trace(pt.strain), 0.0, 1e-14);
      const double p = p_of(pt.stress);
      if (pt.state[0] == 0.0) {
        worst_elastic = std::max(worst_elastic, std::abs(p / p0 - 1.0));
        ++elastic_points;
      } else {
        worst_invariant = std::max(worst_invariant, std::abs(pt.state[2] * std::pow(p / p0, exponent) / pc0 - 1.0));
        // The elastic volume change cancels the viscoplastic one: ln(p'/p0) = (v0/kappa) eps_vp_vol.
        EXPECT_NEAR(std::log(p / p0), kV0 / kKappa * pt.state[1], 1e-6);
        ++plastic_points;
      }
    }
    EXPECT_GT(elastic_points, 10);
    EXPECT_GT(plastic_points, 1000);
    EXPECT_LT(worst_elastic, 1e-12);
    EXPECT_LT(worst_invariant, 1e-6);
    const PathPoint& end = r.points.back();
    const double p_end = p_of(end.stress), q_end = q_of(end.stress);
    EXPECT_NEAR(p_end, p_cs, 0.01 * p_cs);
    EXPECT_NEAR(q_end, kM * p_cs, 0.01 * kM * p_cs);
    std::printf(
        "[ figures  ] undrained (%s): p' %.3f kPa (closed %.3f), q %.3f kPa (closed %.3f), elastic |dp/p0| %.1e, "
        "invariant error %.1e\n",
        shear.substr(0, shear.find('\n')).c_str(), p_end / 1e3, p_cs / 1e3, q_end / 1e3, kM * p_cs / 1e3, worst_elastic,
        worst_invariant);
  }
}

// Eqs. (1.8.8)–(1.8.9) at every step of an elastic drained triaxial path (p' and q both grow):
// both shear laws give K = v0 p'/kappa; constant nu gives G = 3K(1-2nu)/(2(1+nu)), constant G
// gives G. Measured from the increments between consecutive points.
TEST(CamClayPressureElasticity, ShearLawsGiveTheirModuliAtEveryStep) {
  for (const bool constant_G : {false, true}) {
    SCOPED_TRACE(constant_G ? "constant_G" : "poisson");
    auto m = material_from_toml(pressure_dependent(1.0e6, 100.0, constant_G ? kConstantG : "nu = 0.3\n"));
    LoadPath path = LoadPath::drained_triaxial(-1e-3);
    path.duration = 10.0;  // 1 % axial strain, well inside the surface (OCR 10)
    path.dt = 0.01;
    const PathResult r = integrate_path(*m, isotropic(1.0e5), path);
    double worst_K = 0.0, worst_G = 0.0;
    for (std::size_t i = 1; i < r.points.size(); ++i) {
      const PathPoint &a = r.points[i - 1], &b = r.points[i];
      ASSERT_EQ(b.state[0], 0.0);
      const double pa = p_of(a.stress), pb = p_of(b.stress);
      // K = v0 p'/kappa integrates to d tr(eps) = -(kappa/v0) d ln p'.
      const double dvol = tensor::trace(b.strain) - tensor::trace(a.strain);
      worst_K = std::max(worst_K, std::abs(dvol / (-kKappa / kV0 * std::log(pb / pa)) - 1.0));
      // dq = 3 G d eps_q with eps_q = (2/3)(eps_xx - eps_yy); G at the mid-step pressure.
      const double deps_q = 2.0 / 3.0 * ((b.strain[0] - b.strain[1]) - (a.strain[0] - a.strain[1]));
      const double G_measured = (q_of(b.stress) - q_of(a.stress)) / (3.0 * deps_q);
      const double K_mid = kV0 * 0.5 * (pa + pb) / kKappa;
      const double G_expected = constant_G ? 3.0e6 : 3.0 * K_mid * (1 - 2 * kNu) / (2 * (1 + kNu));
      worst_G = std::max(worst_G, std::abs(G_measured / G_expected - 1.0));
    }
    EXPECT_LT(worst_K, 1e-6);
    EXPECT_LT(worst_G, 1e-6);
    EXPECT_GT(p_of(r.points.back().stress), 1.1e5);  // the pressure did change along the path
    std::printf("[ figures  ] %s: worst relative error of K %.1e, of G %.1e\n", constant_G ? "constant_G" : "poisson",
                worst_K, worst_G);
  }
}

// The flux (ElasticRate with the particle's stress) uses the same moduli, with p' clamped to
// [elastic_p_min, elastic_p_max]; the reference constants (wave speed) are those at p_max.
TEST(CamClayPressureElasticity, FluxModuliFollowThePressureWithinTheClamp) {
  auto m = material_from_toml(pressure_dependent(4.0e5, 100.0));
  const ElasticRate rate = m->elastic_rate();
  ASSERT_TRUE(rate.pressure.active());
  const double ratio = 3.0 * (1 - 2 * kNu) / (2 * (1 + kNu));
  for (const double p : {-5.0e4, 0.0, 1.0e3, 2.0e5, 1.0e7, 3.0e7}) {
    const double clamped = std::clamp(p, 1.0e3, 1.0e7);
    const double K = kV0 * clamped / kKappa, G = ratio * K;
    const double sigma[6] = {-p - 1e4, -p + 2e4, -p - 1e4, 5e3, 0, 0};  // mean -p, with a deviator
    const double grad_v[3][3] = {{1e-3, 2e-4, 0}, {0, 1e-3, 0}, {0, 0, 1e-3}};
    double dsig[6];
    rate(grad_v, sigma, dsig);
    EXPECT_NEAR(dsig[0], 3e-3 * K, 1e-12 * K) << p;  // (lambda + 2G/3) tr d = K tr d
    EXPECT_NEAR(dsig[3], G * 2e-4, 1e-12 * G) << p;
  }
  const double K_max = kV0 * 1.0e7 / kKappa;
  EXPECT_NEAR(m->elastic().K, K_max, 1e-9 * K_max);
  EXPECT_NEAR(m->elastic().G, ratio * K_max, 1e-9 * K_max);
  EXPECT_NEAR(m->wave_speed(), std::sqrt((K_max + 4.0 / 3.0 * ratio * K_max) / 2000.0), 1e-9 * m->wave_speed());
}

// `elasticity = "constant"` is the default: giving it explicitly changes nothing, bit for bit.
TEST(CamClayPressureElasticity, ExplicitConstantElasticityIsTheDefault) {
  auto a = material_from_toml(test::kCamClayCase3);
  auto b = material_from_toml(test::kCamClayCase3 + "elasticity = 'constant'\n");
  EXPECT_FALSE(a->pressure_moduli().active());
  LoadPath path = LoadPath::plane_strain_compression(-0.05);
  path.duration = 0.4;
  path.dt = 2e-4;
  const PathResult ra = integrate_path(*a, isotropic(2.0e5), path);
  const PathResult rb = integrate_path(*b, isotropic(2.0e5), path);
  ASSERT_EQ(ra.points.size(), rb.points.size());
  for (std::size_t i = 0; i < ra.points.size(); ++i) {
    EXPECT_EQ(ra.points[i].stress, rb.points[i].stress);
    EXPECT_EQ(ra.points[i].state, rb.points[i].state);
  }
  EXPECT_GT(ra.points.back().state[0], 0.0);  // the path did yield
}

}  // namespace
}  // namespace rktsph
