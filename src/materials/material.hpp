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
#include <algorithm>
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
  /// From the bulk and shear moduli K, G (Pa).
  static ElasticConstants from_K_G(double K, double G, double density);
  /// Fastest elastic wave speed sqrt((K + 4G/3)/rho), m/s (method-notes §4.3).
  double p_wave_speed() const;
  /// sigma = D^e : eps for a full symmetric tensor (tensor shear components).
  Sym6 apply(const Sym6& strain) const;
  /// eps = C^e : sigma (the inverse of apply).
  Sym6 apply_inverse(const Sym6& stress) const;
};

/// Pressure-dependent isotropic moduli of modified Cam-Clay (method-notes eqs. (1.8.8)–(1.8.9)):
///   K = (1 + e0)/kappa * clamp(p', p_min, p_max),
///   G = G_over_K K (constant Poisson's ratio)  or  G = G_constant (constant shear modulus),
/// with p' = -tr(sigma)/3 positive in compression. Inactive (the moduli are constant) when
/// v0_over_kappa is 0, the default.
struct PressureDependentModuli {
  double v0_over_kappa = 0.0;   // (1 + e0)/kappa, dimensionless
  bool constant_shear = false;  // G = G_constant instead of a constant Poisson's ratio
  double G_over_K = 0.0;        // 3(1 - 2 nu)/(2(1 + nu)), constant Poisson's ratio
  double G_constant = 0.0;      // Pa, constant shear modulus
  double p_min = 0.0;           // Pa: floor of p' in K (stiffness at and beyond zero stress)
  double p_max = 0.0;           // Pa: cap of p' in K (the stiffness the time step is set for)

  bool active() const { return v0_over_kappa > 0.0; }
  /// K at the mean effective stress p' (Pa), eq. (1.8.8).
  double bulk_modulus(double p) const { return v0_over_kappa * std::clamp(p, p_min, p_max); }
  /// G for the bulk modulus K, eq. (1.8.9).
  double shear_modulus(double K) const { return constant_shear ? G_constant : G_over_K * K; }

  /// p' after a plastic volumetric strain ev (positive in dilation) from p0 at fixed total strain:
  /// dp' = K(p') ev integrated exactly, exponential within [p_min, p_max] and linear beyond
  /// (method-notes eq. (2.5.7)); the backward-Euler return uses it so that the swelling line
  /// ln p' = (v0/kappa) eps_vp_vol + const holds to round-off.
  double pressure_after_plastic_volume(double p0, double ev) const {
    double p = p0, rest = ev;
    for (int piece = 0; piece < 3 && rest != 0.0; ++piece) {
      if (p < p_min || (p == p_min && rest < 0.0) || p > p_max || (p == p_max && rest > 0.0)) {
        const double edge = p <= p_min ? p_min : p_max;
        const double slope = v0_over_kappa * edge;
        const double to_edge = (edge - p) / slope;  // ev that reaches the clamp's edge
        const bool reaches = (rest > 0.0 && p < p_min && rest > to_edge) || (rest < 0.0 && p > p_max && rest < to_edge);
        if (!reaches) return p + slope * rest;
        p = edge;
        rest -= to_edge;
        continue;
      }
      const double next = p * std::exp(v0_over_kappa * rest);
      if (next >= p_min && next <= p_max) return next;
      const double edge = next > p_max ? p_max : p_min;
      rest -= std::log(edge / p) / v0_over_kappa;
      p = edge;
    }
    return p;
  }
};

/// The elastic part of the stress rate (method-notes eq. (1.2.2)):
///   d sigma/dt = lambda tr(d) 1 + 2 G d,   d = sym grad v,
/// with the full stress whatever the dimension (szz in plane strain; syy, szz in 1D).
/// With pressure-dependent moduli (eq. (1.8.8)) lambda and G are the values at p_max (the
/// stiffest, for the time step) and the rate of a particle uses the moduli at its own stress.
struct ElasticRate {
  double lambda = 0.0;  // Pa
  double G = 0.0;       // Pa
  PressureDependentModuli pressure{};

  /// The constant moduli at a stress (per-dimension layout: the first three slots are the
  /// normal stresses in every dimension); *this when the moduli are constant.
  ElasticRate at(const double* sigma) const {
    if (!pressure.active()) return *this;
    const double K = pressure.bulk_modulus(-(sigma[0] + sigma[1] + sigma[2]) / 3.0);
    const double shear = pressure.shear_modulus(K);
    return {K - 2.0 / 3.0 * shear, shear, {}};
  }

  /// sigma = D^e : eps for a full symmetric tensor (tensor shear components), constant moduli.
  Sym6 apply(const Sym6& e) const {
    const double tr = e[0] + e[1] + e[2];
    return {lambda * tr + 2.0 * G * e[0],
            lambda * tr + 2.0 * G * e[1],
            lambda * tr + 2.0 * G * e[2],
            2.0 * G * e[3],
            2.0 * G * e[4],
            2.0 * G * e[5]};
  }

  /// The rate of a particle at the stress sigma (per-dimension layout): the constant moduli,
  /// or those at its mean effective stress (eq. (1.8.8)).
  template <int Dim>
  void operator()(const double (&grad_v)[Dim][Dim], const double* sigma, double* dsig) const {
    if (pressure.active()) {
      at(sigma)(grad_v, dsig);
    } else {
      (*this)(grad_v, dsig);
    }
  }

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
  long elastic_points = 0;           // particles with no flow over their interval
  long rk4_points = 0;               // particles integrated by RK4
  long max_substeps = 0;             // RK4 sub-steps of one particle, largest
  long total_substeps = 0;           // RK4 sub-steps, all particles
  long implicit_points = 0;          // particles integrated by backward Euler (method-notes §2.5)
  long newton_iterations = 0;        // their Newton iterations, all particles
  long max_newton_iterations = 0;    // of one particle, largest (all its pieces)
  long max_implicit_pieces = 0;      // most pieces one interval was halved into (1: none)

  void add(const SourceStats& o) {
    elastic_points += o.elastic_points;
    rk4_points += o.rk4_points;
    max_substeps = std::max(max_substeps, o.max_substeps);
    total_substeps += o.total_substeps;
    implicit_points += o.implicit_points;
    newton_iterations += o.newton_iterations;
    max_newton_iterations = std::max(max_newton_iterations, o.max_newton_iterations);
    max_implicit_pieces = std::max(max_implicit_pieces, o.max_implicit_pieces);
  }
};

/// Outcome of one backward-Euler integration of a particle's source (method-notes §2.5).
struct ImplicitOutcome {
  bool converged = false;
  int iterations = 0;
};

class Material {
 public:
  /// With pressure-dependent moduli, `elastic` holds the constants at p_max (wave speed, time
  /// step, diagnostics) and the stress rates use those at each particle's stress.
  explicit Material(ElasticConstants elastic, PressureDependentModuli pressure = {})
      : elastic_(elastic), pressure_(pressure) {}
  virtual ~Material() = default;
  Material(const Material&) = delete;
  Material& operator=(const Material&) = delete;

  /// Registry name of the model, e.g. "elastic", "perzyna_von_mises".
  virtual std::string_view model() const = 0;
  const ElasticConstants& elastic() const { return elastic_; }
  double density() const { return elastic_.density; }

  /// Pressure-dependent moduli (method-notes eq. (1.8.8)); inactive for constant elasticity.
  const PressureDependentModuli& pressure_moduli() const { return pressure_; }
  /// D^e(sigma) : eps, the elastic stiffness at the stress sigma applied to eps.
  Sym6 apply_elastic(const Sym6& sigma, const Sym6& eps) const {
    if (!pressure_.active()) return elastic_.apply(eps);
    return ElasticRate{0.0, 0.0, pressure_}.at(sigma.data()).apply(eps);
  }

  /// The constants of the elastic part of the stress rate (the flux).
  virtual ElasticRate elastic_rate() const { return {elastic_.lambda, elastic_.G, pressure_}; }
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

  /// Advance the source ODE of a batch over tau (method-notes §2.2): classical RK4 with
  /// automatic sub-stepping so that relaxation_rate * substep <= rk4_stability_target, or, for a
  /// model that has one, backward Euler (integrate_implicit) where RK4 would need more than
  /// max_explicit_substeps sub-steps (method-notes §2.5, eq. (2.5.6)).
  virtual SourceStats advance_source(double tau, const SourceBatch& batch) const;

  /// Backward Euler of the source of one particle over tau from the trial stress (the start
  /// stress, plus tau R with the frozen flux) and history k0 (method-notes §2.5). Models without
  /// one return converged = false and leave sigma, k untouched.
  virtual ImplicitOutcome integrate_implicit(const Sym6& /*sigma_trial*/, const double* /*k0*/, double /*tau*/,
                                             Sym6& /*sigma*/, double* /*k*/) const {
    return {};
  }
  virtual bool has_implicit_source() const { return false; }

  /// Sub-stepping target for lambda_vp * dt in one RK4 step (RK4's real-axis limit is 2.78).
  static constexpr double rk4_stability_target = 1.0;
  /// A sub-step count above this means the case is hopelessly stiff for an explicit scheme.
  static constexpr long max_substeps = 100000;
  /// RK4 integrates a particle whose source needs at most this many sub-steps; beyond it a model
  /// with an implicit source uses backward Euler, which costs about as much as this many RK4
  /// sub-steps whatever the stiffness (method-notes eq. (2.5.6)).
  static constexpr long max_explicit_substeps = 4;

 private:
  ElasticConstants elastic_;
  PressureDependentModuli pressure_;
};

/// Purely elastic model (method-notes §1.5).
class ElasticMaterial final : public Material {
 public:
  using Material::Material;
  std::string_view model() const override { return "elastic"; }
};

}  // namespace rktsph
