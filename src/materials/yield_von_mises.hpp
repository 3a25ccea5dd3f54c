#pragma once
// von Mises yield surface F = q = sqrt(3 J2) with Y the current yield stress (method-notes §1.7).
#include "core/types.hpp"
#include "materials/pq_form.hpp"
#include "materials/tensor.hpp"

namespace rktsph {

struct VonMisesSurface {
  /// F depends on q alone: the return keeps the deviator's direction (method-notes §2.5).
  bool lode_depends() const { return false; }

  /// F(sigma) in Pa; Y (the current size) is not needed by this surface.
  double value(const Sym6& sigma, double /*Y*/) const { return invariants(sigma).q; }

  /// dF/dsigma = 3 s/(2q), tensor components (method-notes §1.7). Zero at q = 0, where the
  /// direction is undefined but no flow can occur (Y > 0).
  Sym6 gradient(const Sym6& sigma, double /*Y*/) const {
    const Sym6 s = tensor::deviator(sigma);
    const double q = std::sqrt(1.5 * tensor::ddot(s, s));
    if (!(q > 0.0)) return {};
    return tensor::scaled(s, 1.5 / q);
  }

  /// Flow vector m (associated). With this normalisation sqrt(2/3 m:m) = 1, so the
  /// accumulated strain rate equals gamma <Phi>.
  Sym6 flow(const Sym6& sigma, double Y) const { return gradient(sigma, Y); }

  /// F = q, m = dq/dsigma in the (p', q) plane (method-notes eq. (2.5.8)).
  PQForm pq(double /*p*/, double q, double /*Y*/) const {
    PQForm f;
    f.F = q;
    f.F_q = 1.0;
    f.Q_q = 1.0;
    return f;
  }
};

}  // namespace rktsph
