#pragma once
// Uniaxial-stress decorator for 1D bars (docs/cases.md Case 2: scalar sigma, lateral stresses zero).
//
// The solver carries (sxx, syy, szz) in 1D; with this condition the elastic rate uses the
// modulus E (lambda = 0, 2G = E, so the lateral stress rates vanish), the lateral stresses stay
// 0 and the wave speed is the bar speed sqrt(E/rho).
// The source of the wrapped model is evaluated at sigma = (sxx, 0, 0, ...); its viscoplastic
// strain rate is recovered from its stress rate, eps_vp_dot = -C^e : dsigma_inner, and the
// uniaxial stress rate is dsigma_xx = -E eps_vp_xx, other components 0. For von Mises
// (method-notes §1.7) this gives q = |sxx|, eps_vp_xx = gamma <Phi> sign(sxx) and
// d eps_vp_eq/dt = gamma <Phi>, i.e. the 1D Perzyna law of docs/cases.md Case 2 (Variant B).
#include <memory>

#include "materials/material.hpp"

namespace rktsph {

class UniaxialStressMaterial final : public Material {
 public:
  explicit UniaxialStressMaterial(std::shared_ptr<const Material> inner);

  std::string_view model() const override { return inner_->model(); }
  ElasticRate elastic_rate() const override { return {0.0, 0.5 * elastic().E, {}}; }
  double wave_speed() const override;
  std::span<const std::string> state_names() const override { return inner_->state_names(); }
  void initial_state(const Sym6& sigma, double* state) const override;
  bool has_source() const override { return inner_->has_source(); }
  void source_rate(const Sym6& sigma, const double* state, Sym6& dsigma, double* dstate) const override;
  double relaxation_rate(const Sym6& sigma, const double* state) const override;

  const Material& inner() const { return *inner_; }
  /// The stress the wrapped model sees: (sxx, 0, 0, 0, 0, 0).
  static Sym6 uniaxial(const Sym6& sigma) { return {sigma[0], 0.0, 0.0, 0.0, 0.0, 0.0}; }

 private:
  std::shared_ptr<const Material> inner_;
};

}  // namespace rktsph
