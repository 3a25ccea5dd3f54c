#pragma once
// Perzyna viscoplasticity composed of parts (method-notes §1.6):
//   eps_vp_dot = gamma <Phi((F - Y)/Y)> m,   dsigma/dt = -D^e : eps_vp_dot,
// with a yield-surface part (F, dF/dsigma, flow vector m), an overstress part (Phi) and a
// hardening part (history variables, Y and their rates). A new surface is one small header
// with value/gradient/flow plus one registry entry (materials/perzyna_models.cpp). An optional
// tension cut-off (materials/tension_cutoff.hpp, method-notes §1.12) adds a second mechanism
// with the same Phi and gamma: eps_vp_dot = gamma (<Phi(x)> m + <Phi(x_t)> m_t).
#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "core/error.hpp"
#include "materials/material.hpp"
#include "materials/implicit_source.hpp"
#include "materials/overstress.hpp"
#include "materials/source_integrator.hpp"
#include "materials/tension_cutoff.hpp"
#include "materials/tensor.hpp"

namespace rktsph {

template <class Surface, class Hardening>
class PerzynaMaterial final : public Material {
 public:
  PerzynaMaterial(std::string model, ElasticConstants elastic, Surface surface, Hardening hardening,
                  Overstress overstress, double fluidity, PressureDependentModuli pressure = {},
                  TensionCutoff tension = {})
      : Material(elastic, pressure),
        model_(std::move(model)),
        names_(Hardening::names()),
        surface_(surface),
        hardening_(hardening),
        overstress_(overstress),
        fluidity_(fluidity),
        tension_(tension) {}

  std::string_view model() const override { return model_; }
  std::span<const std::string> state_names() const override { return names_; }
  bool has_source() const override { return true; }

  void initial_state(const Sym6& sigma, double* state) const override {
    hardening_.initial_state(surface_.value(sigma, 1.0), state);
    const double Y = hardening_.size(state);
    if (!(Y > 0.0)) {
      throw InputError(
          fmt::format("{}: the initial stress gives a non-positive yield size {} Pa (with an OCR the "
                      "initial stress must be compressive; give p_c0 instead)",
                      model_, Y));
    }
  }

  void source_rate(const Sym6& sigma, const double* state, Sym6& dsigma, double* dstate) const override {
    rate(sigma, state, dsigma, dstate);
  }

  /// Linearised relaxation rate of the normalised overstress x = (F - Y)/Y along the flow
  /// (method-notes §4.3): gamma Phi'(x) [dF/dsigma : D^e : m + (1 + x)|dY/d(gamma Phi)|] / Y.
  /// von Mises, N = 1, H = 0 gives 3 G gamma / Y; Cam-Clay gives gamma K M^2/p_c on the
  /// isotropic axis (plus the hardening term gamma M^2 (1+e0)/(lambda-kappa)) and about
  /// 6 G gamma/p_c at the critical state. Zero inside the surface. With the tension cut-off
  /// its own term, gamma Phi'(x_t) K/Y, is added (eq. 1.12.3): a bound when both act.
  double relaxation_rate(const Sym6& sigma, const double* state) const override {
    const double Y = hardening_.size(state);
    double lambda = 0.0;
    const double x = (surface_.value(sigma, Y) - Y) / Y;
    const double slope = overstress_.slope(x);
    if (slope > 0.0) {
      if (std::isinf(fluidity_)) return fluidity_;  // rate independent: integrated implicitly
      const Sym6 m = surface_.flow(sigma, Y);
      const Sym6 n = surface_.gradient(sigma, Y);
      const double stiff = std::abs(tensor::ddot(n, apply_elastic(sigma, m))) +
                           (1.0 + x) * std::abs(hardening_.size_rate_per_flow(m, state));
      lambda = fluidity_ * slope * stiff / Y;
    }
    if (tension_.active) {
      const double x_t = tension_.overstress(sigma, Y);
      const double slope_t = overstress_.slope(x_t);
      if (slope_t > 0.0) {
        const Sym6 m_t = TensionCutoff::gradient();
        const double stiff_t = std::abs(tensor::ddot(m_t, apply_elastic(sigma, m_t))) +
                               (1.0 + x_t) * std::abs(hardening_.size_rate_per_flow(m_t, state));
        lambda += fluidity_ * slope_t * stiff_t / Y;
      }
    }
    return lambda;
  }

  /// Fast path: the batch integrator with the non-virtual rate and return inlined (RK4 where
  /// the source is mild, backward Euler where it is stiff: method-notes eq. (2.5.6)).
  SourceStats advance_source(double tau, const SourceBatch& batch) const override {
    const detail::PerzynaBackwardEuler<PerzynaMaterial> implicit(*this);
    return detail::integrate_source_batch(
        tau, batch, Hardening::kSize,
        [this](const Sym6& s, const double* k, Sym6& ds, double* dk) { rate(s, k, ds, dk); },
        [this](const Sym6& s, const double* k) { return relaxation_rate(s, k); },
        [&implicit](const Sym6& trial, const double* k0, double h, Sym6& s, double* k) {
          return implicit.solve(trial, k0, h, s, k);
        });
  }

  ImplicitOutcome integrate_implicit(const Sym6& sigma_trial, const double* k0, double tau, Sym6& sigma,
                                     double* k) const override {
    return detail::PerzynaBackwardEuler<PerzynaMaterial>(*this).solve(sigma_trial, k0, tau, sigma, k);
  }
  bool has_implicit_source() const override { return true; }
  /// gamma = +inf: the rate-independent limit, integrated by the return mapping alone.
  bool rate_independent() const { return std::isinf(fluidity_); }

  const Surface& surface() const { return surface_; }
  const Hardening& hardening() const { return hardening_; }
  const Overstress& overstress() const { return overstress_; }
  double fluidity() const { return fluidity_; }
  const TensionCutoff& tension_cutoff() const { return tension_; }

 private:
  void rate(const Sym6& sigma, const double* state, Sym6& dsigma, double* dstate) const {
    const double Y = hardening_.size(state);
    const double phi = overstress_.value((surface_.value(sigma, Y) - Y) / Y);
    const double phi_t = tension_.active ? overstress_.value(tension_.overstress(sigma, Y)) : 0.0;
    if (!(phi > 0.0) && !(phi_t > 0.0)) {
      dsigma.fill(0.0);
      for (int j = 0; j < Hardening::kSize; ++j) dstate[j] = 0.0;
      return;
    }
    // eps_vp_dot in tensor components; D^e.apply gives sigma_xy = 2 G eps_xy (method-notes §1.6),
    // with D^e at this stress when the moduli depend on the pressure (eq. (1.8.8)). The cut-off
    // adds gamma Phi(x_t)/3 to the normal components (eq. 1.12.2).
    Sym6 evp = phi > 0.0 ? tensor::scaled(surface_.flow(sigma, Y), fluidity_ * phi) : Sym6{};
    if (phi_t > 0.0) {
      for (std::size_t i = 0; i < 3; ++i) evp[i] += fluidity_ * phi_t / 3.0;
    }
    const Sym6 d = apply_elastic(sigma, evp);
    for (std::size_t i = 0; i < 6; ++i) dsigma[i] = -d[i];
    hardening_.rate(evp, state, dstate);
  }

  std::string model_;
  std::array<std::string, Hardening::kSize> names_;
  Surface surface_;
  Hardening hardening_;
  Overstress overstress_;
  double fluidity_;  // gamma, 1/s
  TensionCutoff tension_;
};

}  // namespace rktsph
