#pragma once
// Drucker–Prager cone with a hyperbolic apex and a non-associated potential (method-notes
// §1.10). In q–p′ form (p′ = −tr σ/3, compression positive):
//   F = sqrt(q^2 + delta_F^2) − eta p′,   Y = xi c,   delta_F = eps sin(phi) Y        (1.10.1)
//   Q = sqrt(q^2 + delta_Q^2) − eta_Q p′,           delta_Q = eps sin(psi) Y        (1.10.3)
// The rounding makes F and Q smooth at the apex (q = 0): no NaN at or beyond it. With
// phi = psi = 0 both are q exactly (von Mises), with Y = sqrt(3) c for the plane-strain match.
#include <cmath>

#include "core/types.hpp"
#include "materials/pq_form.hpp"
#include "materials/tensor.hpp"

namespace rktsph {

/// How the cone is fitted to the Mohr–Coulomb pyramid of the same c, phi (method-notes §1.10).
enum class DruckerPragerMatch {
  plane_strain,  // same plane-strain limit load as Mohr–Coulomb for the given dilatancy (eq. 1.10.5)
  outer,         // through the triaxial-compression corners (eq. 1.10.6)
  inner,         // through the triaxial-extension corners (eq. 1.10.7)
};

/// The cone's slopes: F-slope eta, cohesion factor xi (Y = xi c) and potential slope eta_Q.
struct DruckerPragerCone {
  double eta = 0.0;
  double xi = 0.0;
  double eta_flow = 0.0;

  /// eqs. (1.10.5)–(1.10.7); angles in radians.
  static DruckerPragerCone matched(DruckerPragerMatch match, double phi, double psi) {
    const double sf = std::sin(phi), cf = std::cos(phi), sp = std::sin(psi);
    switch (match) {
      case DruckerPragerMatch::plane_strain: {
        const double root = std::sqrt(3.0 + sp * sp);
        const double den = 3.0 + sf * sp;
        return {3.0 * sf * root / den, 3.0 * cf * root / den, 3.0 * sp / root};
      }
      case DruckerPragerMatch::outer:
        return {6.0 * sf / (3.0 - sf), 6.0 * cf / (3.0 - sf), 6.0 * sp / (3.0 - sp)};
      case DruckerPragerMatch::inner:
        return {6.0 * sf / (3.0 + sf), 6.0 * cf / (3.0 + sf), 6.0 * sp / (3.0 + sp)};
    }
    return {};
  }
};

struct DruckerPragerSurface {
  double eta = 0.0;       // friction slope of F
  double eta_flow = 0.0;  // slope of the potential Q (eta_flow = eta: associated)
  double round_F = 0.0;   // eps sin(phi): delta_F = round_F * Y
  double round_Q = 0.0;   // eps sin(psi): delta_Q = round_Q * Y

  /// F and Q depend on p and q alone (method-notes §2.5).
  bool lode_depends() const { return false; }

  /// F of eq. (1.10.1), Pa.
  double value(const Sym6& sigma, double Y) const {
    const Invariants inv = invariants(sigma);
    const double d = round_F * Y;
    return std::sqrt(inv.q * inv.q + d * d) - eta * inv.p;
  }

  /// dF/dsigma = 3 s / (2 sqrt(q^2 + delta_F^2)) + (eta/3) 1, tensor components (eq. 1.10.2).
  Sym6 gradient(const Sym6& sigma, double Y) const { return cone_gradient(sigma, Y, round_F * Y, eta); }

  /// m = dQ/dsigma (eq. 1.10.4): its deviatoric part has sqrt(2/3 e:e) = q/sqrt(q^2 + delta_Q^2),
  /// 1 away from the apex, as for von Mises.
  Sym6 flow(const Sym6& sigma, double Y) const { return cone_gradient(sigma, Y, round_Q * Y, eta_flow); }

  /// F and Q of eqs. (1.10.1), (1.10.3) in the (p', q) plane (method-notes eq. (2.5.8)). Without
  /// rounding, Q_q is 1 on the axis too (its limit along the deviator; the apex of §2.5).
  PQForm pq(double p, double q, double Y) const {
    PQForm f;
    const double dF = round_F * Y, dQ = round_Q * Y;
    const double RF = std::sqrt(q * q + dF * dF), RQ = std::sqrt(q * q + dQ * dQ);
    f.F = RF - eta * p;
    f.F_p = -eta;
    f.F_q = RF > 0.0 ? q / RF : 1.0;
    f.F_Y = RF > 0.0 ? round_F * dF / RF : 0.0;
    f.Q_p = -eta_flow;
    f.Q_q = RQ > 0.0 ? q / RQ : 1.0;
    if (RQ > 0.0) {
      const double RQ3 = RQ * RQ * RQ;
      f.Q_qq = dQ * dQ / RQ3;
      f.Q_qY = -q * round_Q * dQ / RQ3;
    }
    return f;
  }

  /// The potential Q of eq. (1.10.3), for the tests.
  double potential(const Sym6& sigma, double Y) const {
    const Invariants inv = invariants(sigma);
    const double d = round_Q * Y;
    return std::sqrt(inv.q * inv.q + d * d) - eta_flow * inv.p;
  }

 private:
  /// Without rounding, below q = kAxisGuard * Y the deviatoric direction is round-off.
  static constexpr double kAxisGuard = 1e-9;

  // Gradient of sqrt(q^2 + delta^2) − slope p′. With delta = 0 (phi or psi = 0) on the axis the
  // deviatoric direction is undefined; its part is set to zero there (no flow for von Mises).
  static Sym6 cone_gradient(const Sym6& sigma, double Y, double delta, double slope) {
    const Sym6 s = tensor::deviator(sigma);
    const double q2 = 1.5 * tensor::ddot(s, s);
    const bool on_axis = delta == 0.0 && q2 <= kAxisGuard * kAxisGuard * Y * Y;
    Sym6 g = on_axis ? Sym6{} : tensor::scaled(s, 1.5 / std::sqrt(q2 + delta * delta));
    for (std::size_t i = 0; i < 3; ++i) g[i] += slope / 3.0;
    return g;
  }
};

}  // namespace rktsph
