#include "materials/uniaxial_stress.hpp"

#include <cmath>
#include <utility>

#include <fmt/format.h>

#include "core/error.hpp"

namespace rktsph {

UniaxialStressMaterial::UniaxialStressMaterial(std::shared_ptr<const Material> inner)
    : Material(inner->elastic()), inner_(std::move(inner)) {
  if (inner_->pressure_moduli().active()) {
    throw InputError(
        fmt::format("{}: pressure-dependent elasticity is not available with the 1D uniaxial-stress "
                    "bar condition (it uses the constant E); use elasticity = \"constant\"",
                    inner_->model()));
  }
}

double UniaxialStressMaterial::wave_speed() const { return std::sqrt(elastic().E / density()); }

void UniaxialStressMaterial::initial_state(const Sym6& sigma, double* state) const {
  inner_->initial_state(uniaxial(sigma), state);
}

void UniaxialStressMaterial::source_rate(const Sym6& sigma, const double* state, Sym6& dsigma, double* dstate) const {
  Sym6 inner_rate;
  inner_->source_rate(uniaxial(sigma), state, inner_rate, dstate);
  // eps_vp_dot = -C^e : dsigma_inner; the bar's stress rate is -E eps_vp_xx.
  const Sym6 minus_evp = elastic().apply_inverse(inner_rate);
  dsigma.fill(0.0);
  dsigma[0] = elastic().E * minus_evp[0];
}

double UniaxialStressMaterial::relaxation_rate(const Sym6& sigma, const double* state) const {
  // The wrapped model's estimate (3 G gamma / Y for von Mises) bounds the uniaxial one
  // (E gamma / Y) for nu >= 0: a conservative sub-stepping (method-notes §4.3).
  return inner_->relaxation_rate(uniaxial(sigma), state);
}

}  // namespace rktsph
