#pragma once
// Constitutive models (METHOD.md §1.5–1.9).
//
// Every model is isotropic hypo-elastic (E, nu constant) plus an optional pointwise
// viscoplastic source. The solver applies the elastic part through the flux (D^e : sym grad v)
// and calls the model only for the source ODE of the Runge–Kutta split (METHOD.md §2.2):
//     d sigma/dt = -D^e : eps_vp_dot(sigma, kappa),   d kappa/dt = h(sigma, kappa).
// History variables kappa are declared by name so that output can write any of them.
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/types.hpp"

namespace rktsph {
namespace io {
class Section;
}

/// Isotropic elastic constants (METHOD.md §1.5). lambda and G are the Lamé constants.
struct ElasticConstants {
  double E = 0.0;        // Young's modulus, Pa
  double nu = 0.0;       // Poisson's ratio
  double density = 0.0;  // kg/m^3
  double lambda = 0.0;   // Pa
  double G = 0.0;        // shear modulus, Pa
  double K = 0.0;        // bulk modulus, Pa
  double M = 0.0;        // constrained (P-wave) modulus lambda + 2G, Pa

  static ElasticConstants from_E_nu(double E, double nu, double density);
  /// Fastest elastic wave speed sqrt((K + 4G/3)/rho), m/s (METHOD.md §4.3).
  double p_wave_speed() const;
  /// sigma = D^e : eps for a full symmetric tensor (tensor shear components).
  Sym6 apply(const Sym6& strain) const;
  /// eps = C^e : sigma (the inverse of apply).
  Sym6 apply_inverse(const Sym6& stress) const;
};

/// How the source increment is combined with the flux increment (METHOD.md §2.2).
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

  /// Names of the history variables carried per particle, in storage order.
  virtual std::span<const std::string> state_names() const { return {}; }
  int state_size() const { return static_cast<int>(state_names().size()); }
  /// Initial history variables for an initial stress (e.g. p_c from the OCR for Cam-Clay).
  virtual void initial_state(const Sym6& /*sigma*/, double* /*state*/) const {}

  /// False for a purely elastic model: the solver then skips the source integration.
  virtual bool has_source() const { return false; }
  /// Pointwise source rate: dsigma = -D^e : eps_vp_dot, dstate = d kappa / dt.
  virtual void source_rate(const Sym6& sigma, const double* state, Sym6& dsigma,
                           double* dstate) const;
  /// Estimate (1/s) of the largest relaxation rate of the source at this state, used to
  /// sub-step RK4 (METHOD.md §4.3). Zero when no flow occurs.
  virtual double relaxation_rate(const Sym6& sigma, const double* state) const;

  /// Advance the source ODE of a batch over tau by classical RK4 (METHOD.md §2.2), with
  /// automatic sub-stepping so that relaxation_rate * substep <= rk4_stability_target.
  virtual SourceStats advance_source(double tau, const SourceBatch& batch) const;

  /// Sub-stepping target for lambda_vp * dt in one RK4 step (RK4's real-axis limit is 2.78).
  static constexpr double rk4_stability_target = 1.0;
  /// A sub-step count above this means the case is hopelessly stiff for an explicit scheme.
  static constexpr long max_substeps = 100000;

 private:
  ElasticConstants elastic_;
};

/// Read E, nu and density from a material table, with the physical checks
/// (E > 0, -1 < nu < 0.5, density > 0).
ElasticConstants read_elastic_constants(const io::Section& section);

/// Purely elastic model (METHOD.md §1.5).
class ElasticMaterial final : public Material {
 public:
  using Material::Material;
  std::string_view model() const override { return "elastic"; }
};

/// Build a model by its `model` key through the one registry (materials/registry.cpp).
/// An unknown name is an input error listing the known ones.
std::unique_ptr<Material> create_material(const io::Section& section);
/// Names and one-line descriptions of the registered models.
std::vector<std::pair<std::string, std::string>> registered_materials();

}  // namespace rktsph
