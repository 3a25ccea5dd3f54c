#pragma once
// Constitutive models (method-notes §1.5–1.9).
//
// A material owns the whole stress rate of its particles:
//   * the elastic part, D^e : sym grad v, which the schemes apply in the flux (its constants
//     are hoisted out of the loops: elastic_rate());
//   * the objective rate it needs in large deformation (objective_rate(): none for the small-
//     deformation schemes; Jaumann comes with V2);
//   * an optional pointwise viscoplastic source, integrated by the Runge–Kutta split
//     (method-notes §2.2):  d sigma/dt = -D^e : eps_vp_dot(sigma, kappa),  d kappa/dt = h(sigma, kappa).
// Models are built from plain parameter structs (materials/perzyna_models.hpp); reading them
// from a case file is case/'s business. History variables kappa are declared by name so that
// output can write any of them.
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/types.hpp"

namespace rktsph {

/// Isotropic elastic constants (method-notes §1.5). lambda and G are the Lamé constants.
struct ElasticConstants {
  double E = 0.0;        // Young's modulus, Pa
  double nu = 0.0;       // Poisson's ratio
  double density = 0.0;  // kg/m^3
  double lambda = 0.0;   // Pa
  double G = 0.0;        // shear modulus, Pa
  double K = 0.0;        // bulk modulus, Pa
  double M = 0.0;        // constrained (P-wave) modulus lambda + 2G, Pa

  static ElasticConstants from_E_nu(double E, double nu, double density);
  /// Fastest elastic wave speed sqrt((K + 4G/3)/rho), m/s (method-notes §4.3).
  double p_wave_speed() const;
  /// sigma = D^e : eps for a full symmetric tensor (tensor shear components).
  Sym6 apply(const Sym6& strain) const;
  /// eps = C^e : sigma (the inverse of apply).
  Sym6 apply_inverse(const Sym6& stress) const;
};

/// The elastic part of the stress rate (method-notes eq. (1.2.2)):
///   d sigma/dt = lambda tr(d) 1 + 2 G d,   d = sym grad v,
/// with the full stress whatever the dimension (szz in plane strain; syy, szz in 1D).
struct ElasticRate {
  double lambda = 0.0;  // Pa
  double G = 0.0;       // Pa

  /// grad_v[d][k] = d v_k / d x_d; dsig in the per-dimension stress layout.
  template <int Dim>
  void operator()(const double (&grad_v)[Dim][Dim], double* dsig) const {
    double tr = 0.0;
    for (int k = 0; k < Dim; ++k) tr += grad_v[k][k];
    for (int n = 0; n < 3; ++n) dsig[n] = lambda * tr + (n < Dim ? 2.0 * G * grad_v[n][n] : 0.0);
    for (int k = 0; k < Dim; ++k) {
      for (int d = k + 1; d < Dim; ++d) dsig[stress_slot<Dim>(k, d)] = G * (grad_v[d][k] + grad_v[k][d]);
    }
  }
};

/// The objective stress rate a material needs when particles rotate (large deformation).
enum class ObjectiveRate {
  none,     // small deformation: the stress rate is the material rate
  jaumann,  // d sigma/dt = (constitutive rate) + W sigma - sigma W (V2, method-notes §1.3)
};

/// How the source increment is combined with the flux increment (method-notes §2.2).
enum class SourceCoupling {
  additive,     // Phi_end = Phi0 + tau R + DeltaS(tau; Phi0): increments from the same start
  frozen_flux,  // Phi_end = RK4 of dPhi/dt = S(Phi) + R from Phi0: R held constant
};

/// A batch of particles whose source ODE is advanced over one interval tau.
/// Stress arrays use the per-dimension layout of core/types.hpp (stress_components = 3, 4 or
/// 6) with a stride (in doubles) between consecutive particles; state arrays are dense with
/// state_size() doubles per particle.
struct SourceBatch {
  std::size_t count = 0;
  int stress_components = 6;
  const double* sigma_start = nullptr;
  std::size_t sigma_start_stride = 0;
  const double* flux_rate = nullptr;  // constant stress rate R (D^e : sym grad v); may be null
  std::size_t flux_rate_stride = 0;
  double* sigma_end = nullptr;
  std::size_t sigma_end_stride = 0;
  const double* state_start = nullptr;
  double* state_end = nullptr;
  std::size_t state_stride = 0;  // doubles between particles' states; 0 means state_size()
  SourceCoupling coupling = SourceCoupling::additive;
};

/// Statistics of one source integration, for the log and summary.json.
struct SourceStats {
  long max_substeps = 0;
  long total_substeps = 0;
};

class Material {
 public:
  explicit Material(ElasticConstants elastic) : elastic_(elastic) {}
  virtual ~Material() = default;
  Material(const Material&) = delete;
  Material& operator=(const Material&) = delete;

  /// Registry name of the model, e.g. "elastic", "perzyna_von_mises".
  virtual std::string_view model() const = 0;
  const ElasticConstants& elastic() const { return elastic_; }
  double density() const { return elastic_.density; }

  /// The constants of the elastic part of the stress rate (the flux).
  virtual ElasticRate elastic_rate() const { return {elastic_.lambda, elastic_.G}; }
  /// The fastest wave the flux carries, m/s: it sets the time step (method-notes §4.3).
  virtual double wave_speed() const { return elastic_.p_wave_speed(); }
  /// The objective rate of the stress in large deformation.
  virtual ObjectiveRate objective_rate() const { return ObjectiveRate::none; }

  /// Names of the history variables carried per particle, in storage order.
  virtual std::span<const std::string> state_names() const { return {}; }
  int state_size() const { return static_cast<int>(state_names().size()); }
  /// Initial history variables for an initial stress (e.g. p_c from the OCR for Cam-Clay).
  virtual void initial_state(const Sym6& /*sigma*/, double* /*state*/) const {}

  /// False for a purely elastic model: the solver then skips the source integration.
  virtual bool has_source() const { return false; }
  /// Pointwise source rate: dsigma = -D^e : eps_vp_dot, dstate = d kappa / dt.
  virtual void source_rate(const Sym6& sigma, const double* state, Sym6& dsigma, double* dstate) const;
  /// Estimate (1/s) of the largest relaxation rate of the source at this state, used to
  /// sub-step RK4 (method-notes §4.3). Zero when no flow occurs.
  virtual double relaxation_rate(const Sym6& sigma, const double* state) const;

  /// Advance the source ODE of a batch over tau by classical RK4 (method-notes §2.2), with
  /// automatic sub-stepping so that relaxation_rate * substep <= rk4_stability_target.
  virtual SourceStats advance_source(double tau, const SourceBatch& batch) const;

  /// Sub-stepping target for lambda_vp * dt in one RK4 step (RK4's real-axis limit is 2.78).
  static constexpr double rk4_stability_target = 1.0;
  /// A sub-step count above this means the case is hopelessly stiff for an explicit scheme.
  static constexpr long max_substeps = 100000;

 private:
  ElasticConstants elastic_;
};

/// Purely elastic model (method-notes §1.5).
class ElasticMaterial final : public Material {
 public:
  using Material::Material;
  std::string_view model() const override { return "elastic"; }
};

}  // namespace rktsph
