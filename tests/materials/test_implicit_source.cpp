// The backward-Euler integration of the Perzyna source (method-notes §2.5): closed forms for
// von Mises, the discrete equations checked on every model at every fluidity and cohesion, the
// rate-independent limit, the tension cut-off's corner and the batch integrator's choice.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "case/case_builder.hpp"
#include "core/error.hpp"
#include "material_test_util.hpp"
#include "materials/hardening.hpp"
#include "materials/lode_form.hpp"
#include "materials/material_point_path.hpp"
#include "materials/perzyna.hpp"
#include "materials/perzyna_models.hpp"
#include "materials/tensor.hpp"
#include "materials/yield_cam_clay.hpp"
#include "materials/yield_mohr_coulomb.hpp"
#include "schemes/simulation.hpp"

namespace rktsph {
namespace {

using test::material_from_toml;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kE = 1.0e7, kNu = 0.3;
const double kG = kE / (2.0 * (1.0 + kNu));

std::string fluidity_text(double gamma) { return std::isinf(gamma) ? "'inf'" : std::to_string(gamma); }

std::string von_mises(double gamma, double Y, const std::string& extra = "") {
  return "model = 'perzyna_von_mises'\nE = 1.0e7\nnu = 0.3\ndensity = 2000.0\nyield_stress = " + std::to_string(Y) +
         "\nfluidity = " + fluidity_text(gamma) + "\n" + extra;
}
std::string drucker_prager(double gamma, double c, double phi, double psi, const std::string& extra = "") {
  return "model = 'perzyna_drucker_prager'\nE = 1.0e7\nnu = 0.3\ndensity = 2000.0\ncohesion = " + std::to_string(c) +
         "\nfriction_angle = " + std::to_string(phi) + "\ndilatancy = " + std::to_string(psi) +
         "\nfluidity = " + fluidity_text(gamma) + "\n" + extra;
}
std::string mohr_coulomb(double gamma, double c, double phi, double psi) {
  return "model = 'perzyna_mohr_coulomb'\nE = 1.0e7\nnu = 0.3\ndensity = 2000.0\ncohesion = " + std::to_string(c) +
         "\nfriction_angle = " + std::to_string(phi) + "\ndilatancy = " + std::to_string(psi) +
         "\nfluidity = " + fluidity_text(gamma) + "\n";
}
std::string cam_clay(double gamma, double pc, const std::string& extra = "") {
  return "model = 'perzyna_cam_clay'\nE = 1.0e7\nnu = 0.3\ndensity = 2000.0\nM = 1.2\nlambda = 0.2\nkappa = 0.02\n"
         "e0 = 1.0\np_c0 = " +
         std::to_string(pc) + "\nfluidity = " + fluidity_text(gamma) + "\n" + extra;
}

struct Return {
  Sym6 sigma;
  std::vector<double> k;
  ImplicitOutcome outcome;
};

Return implicit_return(const Material& m, const Sym6& trial, double tau, std::vector<double> k0 = {}) {
  if (k0.empty()) {
    k0.assign(static_cast<std::size_t>(m.state_size()), 0.0);
    m.initial_state(trial, k0.data());
  }
  Return r;
  r.k.assign(k0.size(), 0.0);
  r.outcome = m.integrate_implicit(trial, k0.data(), tau, r.sigma, r.k.data());
  return r;
}

double q_of(const Sym6& s) { return invariants(s).q; }

TEST(ImplicitSource, VonMisesRateIndependentIsTheRadialReturn) {
  // Linear hardening: dl = (q_tr - Y0 - H eps0)/(3G + H), s = s_tr (1 - 3 G dl / q_tr).
  const double Y0 = 1e5, H = 2e6;
  auto m = material_from_toml(von_mises(kInf, Y0, "hardening_modulus = 2.0e6\n"));
  const Sym6 trial{-40e3, 120e3, 15e3, 90e3, -20e3, 35e3};
  const double eps0 = 0.003;
  const Return r = implicit_return(*m, trial, 1e-3, {eps0});
  ASSERT_TRUE(r.outcome.converged);
  const double q_tr = q_of(trial);
  const double dl = (q_tr - Y0 - H * eps0) / (3.0 * kG + H);
  const double shrink = 1.0 - 3.0 * kG * dl / q_tr;
  const Sym6 s_tr = tensor::deviator(trial);
  const double mean = tensor::trace(trial) / 3.0;
  for (std::size_t i = 0; i < 6; ++i) {
    const double expected = s_tr[i] * shrink + (i < 3 ? mean : 0.0);
    EXPECT_NEAR(r.sigma[i], expected, 1e-8 * Y0) << i;
  }
  EXPECT_NEAR(r.k[0], eps0 + dl, 1e-12);
  EXPECT_LE(r.outcome.iterations, 4);
}

TEST(ImplicitSource, VonMisesPerzynaIsTheClosedFormBackwardEuler) {
  // N = 1, H = 0: q - Y = Y dl/(gamma tau) and q = q_tr - 3 G dl.
  const double Y = 5e4, gamma = 50.0, tau = 2e-3;
  auto m = material_from_toml(von_mises(gamma, Y));
  const Sym6 trial{0, 0, 0, 80e3, 0, 0};
  const Return r = implicit_return(*m, trial, tau);
  ASSERT_TRUE(r.outcome.converged);
  const double q_tr = q_of(trial);
  const double dl = (q_tr - Y) / (3.0 * kG + Y / (gamma * tau));
  EXPECT_NEAR(q_of(r.sigma), q_tr - 3.0 * kG * dl, 1e-9 * Y);
  EXPECT_NEAR(r.k[0], dl, 1e-14);
}

TEST(ImplicitSource, EveryModelConvergesInFewIterationsAtEveryFluidityAndCohesion) {
  // The cost does not depend on gamma or c: trial states up to 10^4 times the strength.
  const std::vector<double> gammas{1.0, 1e2, 1e4, 1e6, kInf};
  const std::vector<double> cohesions{1.0, 1e2, 1e4, 1e5};
  const std::vector<Sym6> strains{{0.0, -0.01, 0.0, 0.004, 0.0, 0.0},
                                  {-0.002, -0.012, 0.001, 0.0, 0.003, -0.002},
                                  {0.001, 0.001, 0.001, 0.002, 0.0, 0.0},
                                  {-0.01, -0.01, -0.01, 0.0, 0.0, 0.0}};
  const Sym6 p0{-2e4, -2e4, -2e4, 0, 0, 0};
  int worst = 0;
  long total = 0, count = 0;
  for (double gamma : gammas) {
    for (double c : cohesions) {
      std::vector<std::unique_ptr<Material>> models;
      models.push_back(material_from_toml(von_mises(gamma, std::sqrt(3.0) * c)));
      models.push_back(material_from_toml(drucker_prager(gamma, c, 30.0, 0.0)));
      models.push_back(material_from_toml(drucker_prager(gamma, c, 30.0, 30.0)));
      models.push_back(material_from_toml(mohr_coulomb(gamma, c, 30.0, 0.0)));
      models.push_back(material_from_toml(mohr_coulomb(gamma, c, 30.0, 30.0)));
      models.push_back(material_from_toml(cam_clay(gamma, 2.0 * c + 2.1e4)));
      for (const auto& m : models) {
        for (const Sym6& strain : strains) {
          const Sym6 d = m->elastic().apply(strain);
          Sym6 trial;
          for (std::size_t i = 0; i < 6; ++i) trial[i] = p0[i] + d[i];
          const Return r = implicit_return(*m, trial, 1e-3);
          const std::string what =
              fmt::format("{} gamma {} c {} strain {}", m->model(), gamma, c, strain[0] + 10 * strain[3]);
          ASSERT_TRUE(r.outcome.converged) << what;
          for (double v : r.sigma) ASSERT_TRUE(std::isfinite(v)) << what;
          worst = std::max(worst, r.outcome.iterations);
          total += r.outcome.iterations;
          ++count;
        }
      }
    }
  }
  const double mean = static_cast<double>(total) / static_cast<double>(count);
  std::printf("[ figures  ] backward Euler, %ld returns over 5 fluidities x 4 cohesions x 6 models: %.2f Newton "
              "iterations on average, %d at most\n",
              count, mean, worst);
  EXPECT_LE(worst, 25);
  EXPECT_LE(mean, 8.0);
}

TEST(ImplicitSource, ReturnedStateSatisfiesTheDiscreteEquations) {
  // Drucker–Prager, non-associated, with hardening: rebuild the residuals from the model's parts.
  for (double gamma : {10.0, 1e4, kInf}) {
    auto m = material_from_toml(drucker_prager(gamma, 5e3, 35.0, 10.0, "hardening_modulus = 1.0e5\n"));
    const Sym6 trial{-10e3, -90e3, -30e3, 25e3, 0, 0};
    const double tau = 1e-3;
    const Return r = implicit_return(*m, trial, tau, {0.0});
    ASSERT_TRUE(r.outcome.converged);
    const double dl = r.k[0];  // eps_eq of dl m: m's deviatoric part has unit equivalent size off the apex
    // sigma_tr - sigma = D^e : (dl m(sigma))
    const auto* perzyna = m.get();
    Sym6 rate;
    double dk[1];
    const double ks[1] = {r.k[0]};
    perzyna->source_rate(r.sigma, ks, rate, dk);  // = -D^e : (gamma Phi m)
    // With gamma finite: dl = gamma tau Phi(x) (N = 1: Phi = x), so -tau * rate = D^e : (dl m).
    if (!std::isinf(gamma)) {
      for (std::size_t i = 0; i < 6; ++i) {
        EXPECT_NEAR(trial[i] - r.sigma[i], -tau * rate[i], 1e-7 * 1e5) << gamma << " " << i;
      }
      EXPECT_NEAR(dl, tau * dk[0], 1e-10);
    } else {
      // On the surface: the overstress is zero to round-off, read through a finite-fluidity twin
      // (gamma = 1 1/s: its rate is -D^e : (x m), x the overstress).
      auto twin = material_from_toml(drucker_prager(1.0, 5e3, 35.0, 10.0, "hardening_modulus = 1.0e5\n"));
      twin->source_rate(r.sigma, ks, rate, dk);
      for (std::size_t i = 0; i < 6; ++i) EXPECT_NEAR(rate[i], 0.0, 1e-6 * 1e5) << i;
      EXPECT_LT(dk[0], 1e-9);
      EXPECT_GT(dl, 0.0);
    }
  }
}

TEST(ImplicitSource, PerzynaConvergesToTheRateIndependentLimitAsOneOverFluidity) {
  auto limit = material_from_toml(mohr_coulomb(kInf, 1e4, 30.0, 5.0));
  const Sym6 trial{-20e3, -160e3, -50e3, 30e3, 0, 0};
  const double tau = 1e-3;
  const Return ref = implicit_return(*limit, trial, tau, {0.0});
  ASSERT_TRUE(ref.outcome.converged);
  double err[3];
  const double gammas[3] = {1e3, 1e4, 1e5};
  for (int i = 0; i < 3; ++i) {
    auto m = material_from_toml(mohr_coulomb(gammas[i], 1e4, 30.0, 5.0));
    const Return r = implicit_return(*m, trial, tau, {0.0});
    ASSERT_TRUE(r.outcome.converged);
    double e = 0.0;
    for (std::size_t c = 0; c < 6; ++c) e = std::max(e, std::abs(r.sigma[c] - ref.sigma[c]));
    err[i] = e;
  }
  EXPECT_GT(err[0], 0.0);
  EXPECT_NEAR(err[0] / err[1], 10.0, 1.0);
  EXPECT_NEAR(err[1] / err[2], 10.0, 1.0);
}

TEST(ImplicitSource, TensionCutoffReturnsToTheCornerOrTheCutoff) {
  // Isotropic tension beyond the cut-off: only the cut-off acts, the mean stress ends at T.
  auto m = material_from_toml(drucker_prager(kInf, 1e4, 30.0, 0.0, "tension_cutoff = 2.0e3\n"));
  const Return iso = implicit_return(*m, {3e4, 3e4, 3e4, 0, 0, 0}, 1e-3, {0.0});
  ASSERT_TRUE(iso.outcome.converged);
  EXPECT_NEAR(tensor::trace(iso.sigma) / 3.0, 2e3, 1e-6);
  EXPECT_NEAR(q_of(iso.sigma), 0.0, 1e-6);
  // Tension with shear: both surfaces active at the end (the corner).
  const Return both = implicit_return(*m, {4e4, 1e4, 2e4, 3e4, 0, 0}, 1e-3, {0.0});
  ASSERT_TRUE(both.outcome.converged);
  EXPECT_NEAR(tensor::trace(both.sigma) / 3.0, 2e3, 1e-6);
  const double k[1] = {both.k[0]};
  Sym6 rate;
  double dk[1];
  auto finite = material_from_toml(drucker_prager(1.0, 1e4, 30.0, 0.0, "tension_cutoff = 2.0e3\n"));
  finite->source_rate(both.sigma, k, rate, dk);
  for (double v : rate) EXPECT_NEAR(v, 0.0, 1e-3);  // on both surfaces: no overstress left
}

TEST(ImplicitSource, ApexWithoutDilatancyHoldsTheMeanStress) {
  // psi = 0: no volumetric flow; hydrostatic tension beyond the apex cannot return, the deviator
  // goes to zero and the mean stress stays (add a tension cut-off to relieve it).
  auto m = material_from_toml(drucker_prager(kInf, 1e3, 30.0, 0.0));
  const Sym6 trial{2e4, 2.2e4, 1.8e4, 1e3, 0, 0};
  const Return r = implicit_return(*m, trial, 1e-3, {0.0});
  ASSERT_TRUE(r.outcome.converged);
  EXPECT_NEAR(tensor::trace(r.sigma), tensor::trace(trial), 1e-6);
  EXPECT_LT(q_of(r.sigma), 1e-6 * q_of(trial));
}

TEST(ImplicitSource, BatchUsesRungeKuttaWhenMildAndBackwardEulerWhenStiff) {
  // lambda = 3 G gamma / Y (von Mises, N = 1).
  const double Y = 1e5;
  long substeps = 0;
  auto check = [&](double gamma, double tau, bool implicit) {
    auto m = material_from_toml(von_mises(gamma, Y));
    const Sym6 s0{0, 0, 0, 1.5 * Y / std::sqrt(3.0), 0, 0};
    Sym6 out{};
    double k0[1] = {0.0}, k1[1];
    SourceBatch b;
    b.count = 1;
    b.sigma_start = s0.data();
    b.sigma_end = out.data();
    b.state_start = k0;
    b.state_end = k1;
    const SourceStats st = m->advance_source(tau, b);
    EXPECT_EQ(st.implicit_points, implicit ? 1 : 0) << gamma;
    EXPECT_EQ(st.max_substeps > 0, !implicit) << gamma;
    substeps = st.max_substeps;
    return q_of(out);
  };
  const double lam_per_gamma = 3.0 * kG / Y;
  // lambda tau = 2.9 (RK4, 3 sub-steps) and 1e4 (backward Euler).
  const double q_mild = check(2.9 / lam_per_gamma / 1e-3, 1e-3, false);
  ASSERT_EQ(substeps, 3);
  // RK4's amplification of a linear decay, (1 - z + z^2/2 - z^3/6 + z^4/24)^3 at z = 2.9/3.
  const double z = 2.9 / 3.0;
  const double amp = std::pow(1.0 - z + z * z / 2.0 - z * z * z / 6.0 + z * z * z * z / 24.0, 3);
  const double lt = 1e4;
  const double q_stiff = check(lt / lam_per_gamma / 1e-3, 1e-3, true);
  EXPECT_NEAR(q_mild, Y * (1.0 + 0.5 * amp), 1e-8 * Y);
  // Backward Euler's relaxation: x_end = x_0 / (1 + lambda tau).
  EXPECT_NEAR(q_stiff, Y * (1.0 + 0.5 / (1.0 + lt)), 1e-6 * Y);
}

TEST(ImplicitSource, RateIndependentMaterialPointReachesTheConePeak) {
  // Drained triaxial compression, rate independent: the peak q on the outer cone is the
  // Mohr–Coulomb one, 2 (p0 sin(phi) + c cos(phi))/(1 - sin(phi)) (method-notes eq. (1.10.9)).
  const double p0 = 1e5, c = 1e4, phi = 30.0 * std::numbers::pi / 180.0;
  auto m = material_from_toml(drucker_prager(kInf, c, 30.0, 0.0, "dp_match = 'outer'\napex_rounding = 0.0\n"));
  LoadPath path = LoadPath::drained_triaxial(-0.01);
  path.duration = 5.0;  // 5 % axial strain; the peak is reached at about 2.5 %
  path.dt = 1e-3;
  const PathResult r = integrate_path(*m, {-p0, -p0, -p0, 0, 0, 0}, path);
  const double expected = 2.0 * (p0 * std::sin(phi) + c * std::cos(phi)) / (1.0 - std::sin(phi));
  EXPECT_NEAR(q_of(r.points.back().stress), expected, 1e-6 * expected);
  // The lateral stresses held.
  EXPECT_NEAR(r.points.back().stress[0], -p0, 1e-6 * p0);
  EXPECT_NEAR(r.points.back().stress[2], -p0, 1e-6 * p0);
}

TEST(ImplicitSource, FluidityReadsInfinityAndRefusesOtherWords) {
  // The string "inf", and TOML's own inf literal.
  EXPECT_TRUE(std::isinf(material_from_toml(von_mises(kInf, 1e5))->relaxation_rate({0, 0, 0, 1e5, 0, 0},
                                                                                   std::vector<double>{0.0}.data())));
  auto m = material_from_toml(
      "model = 'perzyna_von_mises'\nE = 1.0e7\nnu = 0.3\ndensity = 2000.0\nyield_stress = 1e5\nfluidity = inf\n");
  EXPECT_TRUE(std::isinf(m->relaxation_rate({0, 0, 0, 1e5, 0, 0}, std::vector<double>{0.0}.data())));
  for (const char* bad : {"'infinite'", "-inf", "0.0"}) {
    try {
      material_from_toml(std::string("model = 'perzyna_von_mises'\nE = 1.0e7\nnu = 0.3\ndensity = 2000.0\n"
                                     "yield_stress = 1e5\nfluidity = ") +
                         bad + "\n");
      ADD_FAILURE() << bad << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("material.fluidity"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("line 7"), std::string::npos) << e.what();
    }
  }
}

// The run reports the source's integration whatever the scheme (V2's step 2 is another
// instantiation: summary.json's max_source_substeps read 0 for every V2 run before).
TEST(ImplicitSource, EverySchemeReportsItsSourceCounts) {
  for (const char* scheme : {"v1", "v2"}) {
    DruckerPragerParameters p;
    p.elastic = ElasticConstants::from_E_nu(2.0e7, 0.3, 2000.0);
    p.cohesion = 10.0;
    p.friction_angle = 0.5;
    p.fluidity = 100.0;
    CaseBuilder<2> b("a collapsing block");
    b.spacing(0.1).block(Vec<2>(0.0, 0.0), Vec<2>(1.0, 1.0)).material(make_perzyna_drucker_prager(p));
    b.gravity(Vec<2>(0.0, -9.81)).fix_velocity(Region<2>::plane(1, 0.0), {0, 1}).scheme(scheme).time(0.05, 0.5);
    Simulation<2> solver(b.build());
    for (int i = 0; i < 40; ++i) solver.step();
    const SourceStats s = solver.source_stats();
    EXPECT_GT(s.implicit_points, 0) << scheme;
    EXPECT_GT(s.newton_iterations, s.implicit_points / 2) << scheme;
    EXPECT_GT(s.elastic_points + s.rk4_points + s.implicit_points, 40 * 100) << scheme;
    EXPECT_GE(solver.source_seconds(), 0.0);
  }
}

// ---- the (p', q, theta) return of the Lode-dependent surfaces (method-notes eqs. (2.5.11)–(2.5.15))

constexpr double kDeg = std::numbers::pi / 180.0;

// A stress of mean -p, size q and Lode angle theta (eq. (1.1.3), tension positive: +30 deg is
// triaxial compression), its principal axes turned away from x, y, z by `turn` radians.
Sym6 stress_of(double p, double q, double theta, double turn = 0.4) {
  return tensor::from_invariants(p, q, theta, turn);
}

double lode_sin3(const Sym6& sigma) {
  const Sym6 s = tensor::deviator(sigma);
  return MohrCoulombSurface::lode_x(s, 0.5 * tensor::ddot(s, s), 1.0);
}

TEST(ImplicitSource, CoaxialPlaneTurnsTheLodeAngleAsTheSurfacesMeasureIt) {
  // Along e2 the Lode angle falls: theta = theta_tr - b (eq. (2.5.11)), folded past the corners.
  for (double theta : {-30.0, -29.999, -29.8, -20.0, -3.0, 0.0, 11.0, 29.5, 29.99, 30.0}) {
    const Sym6 trial = stress_of(1e4, 3e4, theta * kDeg);
    const CoaxialPlane plane = CoaxialPlane::of(tensor::deviator(trial), 1e-9);
    ASSERT_TRUE(plane.has_e1);
    EXPECT_NEAR(plane.theta(), theta * kDeg, 1e-12) << theta;
    EXPECT_EQ(plane.has_e2, std::abs(theta) < 29.9999) << theta;
    if (!plane.has_e2) continue;
    // e2 is the part of dev(s^2) normal to s, of size cos(3 theta): its round-off grows near the corners.
    const double tolerance = 1e-12 + 1e-15 / std::cos(3.0 * plane.theta());
    for (double b : {-1.5, -1.0, -0.6, -0.1, -1e-4, 0.0, 2e-3, 0.3, 0.8, 1.04, 1.5}) {
      const Sym6 s = plane.deviator(2.5e4, b);
      const FoldedLodeAngle a = plane.lode_angle(std::cos(b), std::sin(b));
      const double folded = std::atan2(a.lode.sin1, a.lode.cos1);
      EXPECT_NEAR(invariants(s).q, 2.5e4, 1e-10 * 2.5e4);
      EXPECT_NEAR(a.lode.sin3, lode_sin3(s), tolerance) << theta << " " << b;
      EXPECT_NEAR(a.lode.sin3, std::sin(3.0 * (plane.theta() - b)), 1e-12) << theta << " " << b;
      EXPECT_LE(std::abs(folded), std::numbers::pi / 6.0 + 1e-12) << theta << " " << b;
      EXPECT_NEAR(a.lode.sin3, std::sin(3.0 * folded), 1e-12) << theta << " " << b;
      EXPECT_NEAR(a.lode.cos3, std::cos(3.0 * folded), 1e-12) << theta << " " << b;
      // dtheta/db = -sign, by differences (away from the corners, where the fold turns).
      const double h = 1e-7;
      const FoldedLodeAngle up = plane.lode_angle(std::cos(b + h), std::sin(b + h));
      const FoldedLodeAngle down = plane.lode_angle(std::cos(b - h), std::sin(b - h));
      if (std::abs(std::abs(folded) - std::numbers::pi / 6.0) > 1e-5) {
        const double slope =
            (std::atan2(up.lode.sin1, up.lode.cos1) - std::atan2(down.lode.sin1, down.lode.cos1)) / (2 * h);
        EXPECT_NEAR(slope, -a.sign, 1e-6) << theta << " " << b;
      }
    }
  }
}

// The form against the surface's own value() and flow() at (p', q, theta), and its second
// derivatives against central differences of the first.
template <class Surface>
void check_lode_form(const Surface& surface, double p, double q, double theta, double Y, const std::string& what) {
  const Sym6 sigma = stress_of(p, q, theta);
  const LodeForm f = surface.pq_theta(p, q, LodeAngle::of(theta), Y);
  const double scale = std::max({std::abs(f.F), Y, q});
  EXPECT_NEAR(f.F, surface.value(sigma, Y), 1e-12 * scale) << what;
  // m = -(Q_p/3) 1 + sqrt(3/2) (Q_q e1 - (Q_theta/q) e2) in the plane of sigma (eq. (2.5.13)).
  const CoaxialPlane plane = CoaxialPlane::of(tensor::deviator(sigma), 1e-9 * Y);
  const Sym6 m = surface.flow(sigma, Y);
  const double size = std::max({std::abs(f.Q_p), std::abs(f.Q_q), std::abs(f.Q_theta / q), 1.0});
  EXPECT_NEAR(-tensor::trace(m), f.Q_p, 1e-11 * size) << what;
  EXPECT_NEAR(tensor::ddot(m, plane.e1), std::sqrt(1.5) * f.Q_q, 1e-11 * size) << what;
  if (plane.has_e2) {
    EXPECT_NEAR(tensor::ddot(m, plane.e2), -std::sqrt(1.5) * f.Q_theta / q, 1e-9 * size) << what;
  }
  // Second derivatives.
  const double hp = 1e-6 * std::max(std::abs(p), Y), hq = 1e-6 * q, ht = 1e-6, hY = 1e-6 * Y;
  auto at = [&](double dp, double dq, double dt, double dY) {
    return surface.pq_theta(p + dp, q + dq, LodeAngle::of(theta + dt), Y + dY);
  };
  const LodeForm pp = at(hp, 0, 0, 0), pm = at(-hp, 0, 0, 0), qp = at(0, hq, 0, 0), qm = at(0, -hq, 0, 0);
  const LodeForm tp = at(0, 0, ht, 0), tm = at(0, 0, -ht, 0), Yp = at(0, 0, 0, hY), Ym = at(0, 0, 0, -hY);
  auto expect = [&](double analytic, double difference, double unit, const char* name) {
    EXPECT_NEAR(analytic, difference, 1e-6 * std::max(std::abs(analytic), unit)) << what << " " << name;
  };
  expect(f.F_p, (pp.F - pm.F) / (2 * hp), 1.0, "F_p");
  expect(f.F_q, (qp.F - qm.F) / (2 * hq), 1.0, "F_q");
  expect(f.F_theta, (tp.F - tm.F) / (2 * ht), q, "F_theta");
  expect(f.F_Y, (Yp.F - Ym.F) / (2 * hY), 1.0, "F_Y");
  expect(f.Q_pp, (pp.Q_p - pm.Q_p) / (2 * hp), 1.0 / Y, "Q_pp");
  expect(f.Q_pq, (qp.Q_p - qm.Q_p) / (2 * hq), 1.0 / Y, "Q_pq");
  expect(f.Q_ptheta, (tp.Q_p - tm.Q_p) / (2 * ht), 1.0, "Q_ptheta");
  expect(f.Q_ptheta, (pp.Q_theta - pm.Q_theta) / (2 * hp), 1.0, "Q_thetap");
  expect(f.Q_qq, (qp.Q_q - qm.Q_q) / (2 * hq), 1.0 / Y, "Q_qq");
  expect(f.Q_qtheta, (tp.Q_q - tm.Q_q) / (2 * ht), 1.0, "Q_qtheta");
  expect(f.Q_qtheta, (qp.Q_theta - qm.Q_theta) / (2 * hq), 1.0, "Q_thetaq");
  expect(f.Q_thetatheta, (tp.Q_theta - tm.Q_theta) / (2 * ht), q, "Q_thetatheta");
  expect(f.Q_pY, (Yp.Q_p - Ym.Q_p) / (2 * hY), 1.0 / Y, "Q_pY");
  expect(f.Q_qY, (Yp.Q_q - Ym.Q_q) / (2 * hY), 1.0 / Y, "Q_qY");
  expect(f.Q_thetaY, (Yp.Q_theta - Ym.Q_theta) / (2 * hY), 1.0, "Q_thetaY");
}

TEST(ImplicitSource, LodeFormsAreTheSurfacesInInvariants) {
  const std::vector<double> thetas{-29.95, -29.0, -12.0, 0.0, 7.0, 28.0, 29.8, 29.97};
  for (double eps : {0.0, 0.1}) {
    for (double psi : {0.0, 10.0, 30.0}) {
      const MohrCoulombSurface mc = MohrCoulombSurface::make(30.0 * kDeg, psi * kDeg, eps);
      for (double theta : thetas) {
        for (double q : {0.05, 1.0, 20.0}) {
          check_lode_form(mc, 2.0, q, theta * kDeg, 1.0,
                          fmt::format("MC eps {} psi {} theta {} q {}", eps, psi, theta, q));
        }
      }
    }
  }
  CamClaySurface cc;
  cc.M_c = 1.2;
  cc.lode_dependent = true;
  for (double theta : thetas) {
    for (double p : {0.3, 0.7, 1.4}) {
      check_lode_form(cc, p * 1e5, 0.6e5, theta * kDeg, 1e5, fmt::format("CC theta {} p {}", theta, p));
    }
  }
}

using MohrCoulombModel = PerzynaMaterial<MohrCoulombSurface, LinearHardening>;
using CamClayModel = PerzynaMaterial<CamClaySurface, CamClayHardening>;

template <class Model>
Return return_by(const Model& m, const Sym6& trial, double tau, const std::vector<double>& k0,
                 typename detail::PerzynaBackwardEuler<Model>::Path path) {
  const detail::PerzynaBackwardEuler<Model> solver(m, path);
  Return r;
  r.k.assign(k0.size(), 0.0);
  r.outcome = solver.solve(trial, k0.data(), tau, r.sigma, r.k.data());
  return r;
}

struct Agreement {
  int compared = 0, generic_failed = 0, exact_failed = 0, both_failed = 0, at_apex = 0;
  int exact_failed_moderate = 0;         // on trials within 30 times the strength
  double worst = 0.0, worst_apex = 0.0;  // largest stress or history difference, relative
  long exact_iterations = 0, generic_iterations = 0;
  int most_iterations = 0;
};

// The (p', q, theta) return against the generic (mean, a, b) one from one trial. Where the
// exact-Jacobian problem alone fails, the fall-back must give the generic return.
template <class Model>
void compare_returns(const Model& m, const Sym6& trial, const std::vector<double>& k0, double tau, Agreement& a,
                     const std::string& what, bool moderate = false) {
  using Path = typename detail::PerzynaBackwardEuler<Model>::Path;
  const Return slow = return_by(m, trial, tau, k0, Path::generic);
  if (!slow.outcome.converged) {
    ++a.generic_failed;
    if (!return_by(m, trial, tau, k0, Path::fastest).outcome.converged) {
      ++a.both_failed;
      if (std::getenv("RKTSPH_PRINT_FAILED") != nullptr) std::printf("both failed: %s\n", what.c_str());
    }
    return;
  }
  Return fast = return_by(m, trial, tau, k0, Path::exact_only);
  if (!fast.outcome.converged) {
    ++a.exact_failed;
    if (moderate) ++a.exact_failed_moderate;
    if (std::getenv("RKTSPH_PRINT_FAILED") != nullptr) std::printf("exact failed: %s\n", what.c_str());
    fast = return_by(m, trial, tau, k0, Path::fastest);
    ASSERT_TRUE(fast.outcome.converged) << what;
  } else {
    ++a.compared;
    a.exact_iterations += fast.outcome.iterations;
    a.generic_iterations += slow.outcome.iterations;
    a.most_iterations = std::max(a.most_iterations, fast.outcome.iterations);
  }
  const double scale = std::max({m.hardening().size(k0.data()), q_of(trial), std::abs(invariants(trial).p)});
  double worst = 0.0;
  for (std::size_t i = 0; i < 6; ++i) worst = std::max(worst, std::abs(fast.sigma[i] - slow.sigma[i]) / scale);
  for (std::size_t j = 0; j < k0.size(); ++j) {
    worst = std::max(worst, std::abs(fast.k[j] - slow.k[j]) / std::max(std::abs(slow.k[j]), 1e-6));
  }
  // At the apex the generic problem takes the flow at a deviator of 1e-6 of the scale on the
  // mean stress, so its volumetric part carries 1e-10 of round-off, times the multiplier: those
  // returns are checked to 1e-6 (and the exact ones' mean stress below).
  const bool apex = q_of(fast.sigma) == 0.0 && q_of(trial) > 0.0;
  if (apex) {
    ++a.at_apex;
    a.worst_apex = std::max(a.worst_apex, worst);
  } else {
    a.worst = std::max(a.worst, worst);
  }
  EXPECT_LT(worst, apex ? 1e-6 : 1e-9) << what
                                       << fmt::format(" (iterations {} / {})", fast.outcome.iterations,
                                                      slow.outcome.iterations);
}

void print_agreement(const char* model, const Agreement& a) {
  std::printf(
      "[ figures  ] %s: %d returns agree with the generic one to %.1e (%d at the apex, to %.1e), "
      "Newton iterations %.2f on average (generic %.2f), %d at most; the generic one failed on %d (the new "
      "one on %d of them), the exact one alone on %d (the fall-back's)\n",
      model, a.compared, a.worst, a.at_apex, a.worst_apex, static_cast<double>(a.exact_iterations) / a.compared,
      static_cast<double>(a.generic_iterations) / a.compared, a.most_iterations, a.generic_failed, a.both_failed,
      a.exact_failed);
}

TEST(ImplicitSource, LodeReturnIsTheGenericReturnOfMohrCoulomb) {
  // Fluidities, cohesions 1 Pa - 100 kPa, psi = 0 and phi, tension cut-off off and on, trials
  // about the triaxial corners, inside the rounding and at the apex, up to 10^4 times the strength.
  const std::vector<double> thetas{-30.0, -29.99, -29.8, -29.0, -15.0, 0.0, 10.0, 29.5, 29.8, 29.99, 30.0};
  Agreement a;
  for (double gamma : {1.0, 1e2, 1e4, 1e6, kInf}) {
    for (double c : {1.0, 1e2, 1e4, 1e5}) {
      for (double psi : {0.0, 30.0}) {
        for (bool cutoff : {false, true}) {
          MohrCoulombParameters par;
          par.elastic = ElasticConstants::from_E_nu(kE, kNu, 2000.0);
          par.cohesion = c;
          par.friction_angle = 30.0 * kDeg;
          par.dilatancy = psi * kDeg;
          par.fluidity = gamma;
          par.hardening_modulus = -0.1 * c;
          par.residual_cohesion = 0.5 * c;
          if (cutoff) par.tension_cutoff = {true, 0.5 * c};
          const auto material = make_perzyna_mohr_coulomb(par);
          const auto& m = dynamic_cast<const MohrCoulombModel&>(*material);
          const double cot = std::sqrt(3.0);  // cot 30 deg
          for (double theta : thetas) {
            for (double p : {2e4 + c, 5.0 * c, -0.5 * c * cot, -3.0 * c * cot}) {
              for (double q_over : {1.2, 4.0, 30.0, 1e3}) {
                const double q = q_over * (std::abs(p) + c);
                const Sym6 trial = stress_of(p, q, theta * kDeg);
                const std::string what = fmt::format("gamma {} c {} psi {} cutoff {} theta {} p {} q {}", gamma, c, psi,
                                                     cutoff, theta, p, q);
                compare_returns(m, trial, {0.002}, 1e-3, a, what, q_over < 100.0);
              }
            }
            // Near the apex: a small deviator on a hydrostatic tension.
            compare_returns(m, stress_of(-2.0 * c * cot, 0.01 * c, theta * kDeg), {0.0}, 1e-3, a,
                            fmt::format("apex gamma {} c {} psi {} cutoff {} theta {}", gamma, c, psi, cutoff, theta));
          }
          compare_returns(m, stress_of(-2.0 * c * cot, 0.0, 0.0), {0.0}, 1e-3, a, "hydrostatic tension");
        }
      }
    }
  }
  print_agreement("Mohr-Coulomb", a);
  // Newton on (q_a, q_b) alone fails only from trials 10^3 times the strength or in tension
  // beyond the apex, where the fall-back takes the generic path.
  EXPECT_EQ(a.exact_failed_moderate, 0);
  EXPECT_LE(a.exact_failed, a.compared / 50);
  EXPECT_LE(a.both_failed, a.generic_failed / 2);
}

TEST(ImplicitSource, LodeReturnIsTheGenericReturnOfCamClayWithLodeDependentM) {
  const std::vector<double> thetas{-30.0, -29.9, -20.0, 0.0, 17.0, 29.9, 30.0};
  Agreement a;
  for (bool pressure_dependent : {false, true}) {
    for (double gamma : {1.0, 1e2, 1e4, 1e6, kInf}) {
      for (double pc : {2e3, 2e5}) {
        CamClayParameters par;
        par.elastic = ElasticConstants::from_E_nu(kE, kNu, 2000.0);
        par.M = 1.2;
        par.lode_dependent_M = true;
        par.lambda = 0.2;
        par.kappa = 0.02;
        par.e0 = 1.0;
        par.p_c0 = pc;
        par.fluidity = gamma;
        if (pressure_dependent) {
          par.elasticity = CamClayElasticity::pressure_dependent;
          par.elastic_p_min = 1e-3 * pc;
          par.elastic_p_max = 10.0 * pc;
        }
        const auto material = make_perzyna_cam_clay(par);
        const auto& m = dynamic_cast<const CamClayModel&>(*material);
        for (double theta : thetas) {
          for (double p_over : {0.1, 0.4, 0.9, 1.6}) {
            for (double q_over : {0.5, 1.5, 10.0}) {
              const Sym6 trial = stress_of(p_over * pc, q_over * pc, theta * kDeg);
              const std::string what = fmt::format("pressure {} gamma {} pc {} theta {} p/pc {} q/pc {}",
                                                   pressure_dependent, gamma, pc, theta, p_over, q_over);
              compare_returns(m, trial, {0.001, -0.002, pc}, 1e-3, a, what, true);
            }
          }
        }
      }
    }
  }
  print_agreement("Cam-Clay with M(theta)", a);
  EXPECT_EQ(a.exact_failed, 0);
}

}  // namespace
}  // namespace rktsph
