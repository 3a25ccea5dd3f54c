// The backward-Euler integration of the Perzyna source (method-notes §2.5): closed forms for
// von Mises, the discrete equations checked on every model at every fluidity and cohesion, the
// rate-independent limit, the tension cut-off's corner and the batch integrator's choice.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "case/case_builder.hpp"
#include "core/error.hpp"
#include "material_test_util.hpp"
#include "materials/perzyna_models.hpp"
#include "schemes/simulation.hpp"
#include "materials/material_point_path.hpp"
#include "materials/tensor.hpp"

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
      // On the surface: the source rate's overstress is zero (round-off).
      for (std::size_t i = 0; i < 6; ++i) EXPECT_NEAR(rate[i], 0.0, 1e-6) << i;
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

}  // namespace
}  // namespace rktsph
