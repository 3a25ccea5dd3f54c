// The uniaxial-stress decorator (materials/uniaxial_stress.hpp) against the closed-form 1D
// Perzyna law of docs/cases.md Case 2: relaxation at fixed strain and the steady state under a
// constant strain rate; lateral stresses stay zero.
#include <gtest/gtest.h>

#include <cmath>

#include "material_test_util.hpp"
#include "materials/uniaxial_stress.hpp"

namespace rktsph {
namespace {

constexpr double kE = 1.0e7, kY = 1.0e5;

std::unique_ptr<Material> wrapped(double fluidity, const std::string& extra = "") {
  return std::make_unique<UniaxialStressMaterial>(test::material_from_toml(test::von_mises(fluidity, extra)));
}

// Advance one particle (1D layout: sxx, syy, szz) over tau with a constant flux rate r_xx.
double advance(const Material& m, double sxx, double r_xx, double tau, double* state, SourceCoupling coupling) {
  const double s0[3] = {sxx, 0.0, 0.0};
  const double r[3] = {r_xx, 0.0, 0.0};
  double s1[3] = {};
  SourceBatch b;
  b.count = 1;
  b.stress_components = 3;
  b.sigma_start = s0;
  b.sigma_start_stride = 3;
  b.flux_rate = r;
  b.flux_rate_stride = 3;
  b.sigma_end = s1;
  b.sigma_end_stride = 3;
  b.state_start = state;
  b.state_end = state;
  b.coupling = coupling;
  m.advance_source(tau, b);
  EXPECT_EQ(s1[1], 0.0);
  EXPECT_EQ(s1[2], 0.0);
  return s1[0];
}

TEST(UniaxialStress, RateIsTheOneDimensionalPerzynaLaw) {
  const auto m = wrapped(2.0);
  double k[1] = {0.0};
  for (double s : {1.5 * kY, -1.3 * kY}) {
    Sym6 ds;
    double dk[1];
    // Lateral components of the input are ignored: the model sees (sxx, 0, 0).
    m->source_rate({s, 0.3 * kY, -0.2 * kY, 0.0, 0.0, 0.0}, k, ds, dk);
    const double x = (std::abs(s) - kY) / kY;
    EXPECT_NEAR(ds[0], -kE * 2.0 * x * (s > 0 ? 1.0 : -1.0), 1e-6 * kE * x);
    for (std::size_t c = 1; c < 6; ++c) EXPECT_EQ(ds[c], 0.0);
    EXPECT_NEAR(dk[0], 2.0 * x, 1e-12);  // d eps_vp_eq/dt = gamma <Phi>, q = |sigma|
  }
  Sym6 ds;
  double dk[1];
  m->source_rate({0.9 * kY, 0, 0, 0, 0, 0}, k, ds, dk);
  EXPECT_EQ(ds[0], 0.0);
  EXPECT_EQ(dk[0], 0.0);
  EXPECT_EQ(m->state_names().size(), 1u);
  EXPECT_EQ(m->model(), "perzyna_von_mises");
}

TEST(UniaxialStress, RelaxationAtFixedStrain) {
  // d sigma/dt = -E gamma (sigma - Y)/Y with H = 0: sigma = Y + (sigma0 - Y) exp(-E gamma t/Y).
  const double gamma = 2.0;
  const auto m = wrapped(gamma);
  double k[1] = {0.0};
  double s = 1.4 * kY;
  const double tau = 1e-4, rate = kE * gamma / kY;  // 200 1/s
  double t = 0.0;
  for (int n = 0; n < 100; ++n) {
    s = advance(*m, s, 0.0, tau, k, SourceCoupling::additive);
    t += tau;
  }
  const double exact = kY + 0.4 * kY * std::exp(-rate * t);
  EXPECT_NEAR(s, exact, 1e-6 * kY);
  // eps_vp_eq = (sigma0 - sigma)/E in relaxation (all stress lost goes into eps_vp).
  EXPECT_NEAR(k[0], (1.4 * kY - s) / kE, 1e-9);
}

TEST(UniaxialStress, SteadyStateUnderConstantStrainRate) {
  // Constant strain rate eps_dot: steady state sigma = Y (1 + eps_dot/gamma) (H = 0).
  const double gamma = 50.0, eps_dot = 5.0;
  const auto m = wrapped(gamma);
  double k[1] = {0.0};
  double s = 0.0;
  for (int n = 0; n < 20000; ++n) s = advance(*m, s, kE * eps_dot, 1e-5, k, SourceCoupling::frozen_flux);
  EXPECT_NEAR(s, kY * (1.0 + eps_dot / gamma), 1e-6 * kY);
}

TEST(UniaxialStress, SofteningUsesTheCurrentSize) {
  // Variant B of docs/cases.md Case 2: the overstress is normalised by Y(eps), here 0.5 Y0.
  const auto m = wrapped(2.0, "hardening_modulus = -2.0e5\n");
  double k[1] = {0.25};  // Y = 1e5 - 2e5 * 0.25 = 0.5e5
  Sym6 ds;
  double dk[1];
  m->source_rate({0.75e5, 0, 0, 0, 0, 0}, k, ds, dk);
  EXPECT_NEAR(dk[0], 2.0 * 0.5, 1e-12);
  EXPECT_NEAR(ds[0], -kE * 1.0, 1e-6);
}

}  // namespace
}  // namespace rktsph
