#pragma once
// Modified Cam-Clay surface (method-notes §1.8, docs/cases.md §1.2 C3). Scalar form used in the
// overstress: F = p' + q^2/(M^2 p') (the "equivalent size" P_y), Y = p_c. The flow vector is
// the gradient of the ellipse f = q^2 + M^2 p'(p' - p_c), scaled by 1/p_c (dimensionless).
//
// Optional Lode dependence M(theta) = 6 sin(phi_c)/(3 - sin(phi_c) sin(3 theta)), with
// sin(phi_c) = 3 M_c/(6 + M_c) so that M = M_c in triaxial compression (theta = +30 deg,
// tension-positive stress). Its gradient is taken through x = sin(3 theta) directly:
//   dx/dsigma = -(3 sqrt3/2) J2^(-3/2) [t - 3 J3/(2 J2) s],  t = s.s - 2/3 J2 1,
// which is the lineage form of method-notes §1.8 times 3 cos(3 theta): the cos(3 theta) cancels, so the
// Owen–Hinton cut-off at |theta| > 29 deg is not needed. Only J2 -> 0 is guarded (the
// deviatoric direction is undefined there, and q^2 -> 0 removes M from F anyway).
#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/types.hpp"
#include "materials/lode_form.hpp"
#include "materials/pq_form.hpp"
#include "materials/tensor.hpp"

namespace rktsph {

struct CamClaySurface {
  double M_c = 1.0;             // critical-state slope in triaxial compression
  bool lode_dependent = false;  // M(theta) instead of constant M_c

  /// With M(theta) the return moves in the coaxial deviatoric plane (method-notes §2.5).
  bool lode_depends() const { return lode_dependent; }
  /// M(theta) is smooth in sin 3 theta: no stop at the triaxial corners (method-notes eq. (2.5.16)).
  bool sharp_corners() const { return false; }

  /// Tension guard (method-notes §1.8): for p' <= kTensionGuard * p_c, F = p' (no q term).
  static constexpr double kTensionGuard = 1e-6;
  /// Below q = kLodeGuard * p_c the Lode angle is undefined and M = M_c is used.
  static constexpr double kLodeGuard = 1e-9;

  struct Slope {
    double M;  // M(theta)
    Sym6 dM;   // dM/dsigma, tensor components (zero for constant M)
  };

  Slope slope(const Sym6& s, double J2, double Y) const {
    if (!lode_dependent || 3.0 * J2 <= kLodeGuard * kLodeGuard * Y * Y) return {M_c, {}};
    const double sphi = 3.0 * M_c / (6.0 + M_c);
    const double J3 = tensor::determinant(s);
    const double c = 1.5 * std::sqrt(3.0);
    const double x = std::clamp(-c * J3 / std::pow(J2, 1.5), -1.0, 1.0);
    const double den = 3.0 - sphi * x;
    const double M = 6.0 * sphi / den;
    const double dMdx = 6.0 * sphi * sphi / (den * den);
    Sym6 t = tensor::square(s);
    for (std::size_t i = 0; i < 3; ++i) t[i] -= 2.0 / 3.0 * J2;
    const double a = -c / std::pow(J2, 1.5);
    const double b = 1.5 * J3 / J2;
    Sym6 dM;
    for (std::size_t i = 0; i < 6; ++i) dM[i] = dMdx * a * (t[i] - b * s[i]);
    return {M, dM};
  }

  /// F = p' + q^2/(M^2 p'), in Pa; Y = p_c is used only by the tension guard.
  double value(const Sym6& sigma, double Y) const {
    const double p = -tensor::trace(sigma) / 3.0;
    if (p <= kTensionGuard * Y) return p;
    const Sym6 s = tensor::deviator(sigma);
    const double J2 = 0.5 * tensor::ddot(s, s);
    const double M = slope(s, J2, Y).M;
    return p + 3.0 * J2 / (M * M * p);
  }

  /// dF/dsigma (tensor components), for the relaxation-rate estimate and the tests.
  Sym6 gradient(const Sym6& sigma, double Y) const {
    const double p = -tensor::trace(sigma) / 3.0;
    if (p <= kTensionGuard * Y) return {-1.0 / 3.0, -1.0 / 3.0, -1.0 / 3.0, 0.0, 0.0, 0.0};
    const Sym6 s = tensor::deviator(sigma);
    const double J2 = 0.5 * tensor::ddot(s, s);
    const Slope sl = slope(s, J2, Y);
    const double q2 = 3.0 * J2;
    const double M2 = sl.M * sl.M;
    const double dp = -(1.0 - q2 / (M2 * p * p)) / 3.0;  // dF/dp' times dp'/dsigma = -1/3
    Sym6 g;
    for (std::size_t i = 0; i < 6; ++i) {
      g[i] = 3.0 * s[i] / (M2 * p) - 2.0 * q2 / (M2 * sl.M * p) * sl.dM[i];
    }
    for (std::size_t i = 0; i < 3; ++i) g[i] += dp;
    return g;
  }

  /// m = (1/p_c)[-(M^2/3)(2p' - p_c) 1 + 3 s + 2 M p'(p' - p_c) dM/dsigma] (method-notes §1.8).
  Sym6 flow(const Sym6& sigma, double Y) const {
    const double p = -tensor::trace(sigma) / 3.0;
    const Sym6 s = tensor::deviator(sigma);
    const double J2 = 0.5 * tensor::ddot(s, s);
    const Slope sl = slope(s, J2, Y);
    const double iso = -sl.M * sl.M / 3.0 * (2.0 * p - Y);
    const double dfdM = 2.0 * sl.M * p * (p - Y);
    Sym6 m;
    for (std::size_t i = 0; i < 6; ++i) m[i] = (3.0 * s[i] + dfdM * sl.dM[i]) / Y;
    for (std::size_t i = 0; i < 3; ++i) m[i] += iso / Y;
    return m;
  }

  /// F and the flow in the (p', q) plane with constant M (method-notes eq. (2.5.8)):
  /// Q_p = M^2 (2p' - p_c)/p_c, Q_q = 2q/p_c, the flow() above; F with its tension guard.
  PQForm pq(double p, double q, double Y) const {
    PQForm f;
    pq_parts(M_c * M_c, p, q, Y, f);
    return f;
  }

  /// F and the flow in (p', q, theta) with M(theta) (method-notes eq. (2.5.13)): Q_p and Q_q as
  /// in pq() with M(theta), Q_theta = 2 M M' p'(p' - p_c)/p_c, and their derivatives. Below the
  /// Lode guard M = M_c with no Lode term, as slope() gives.
  LodeForm pq_theta(double p, double q, const LodeAngle& lode, double Y) const {
    double M = M_c, dM = 0.0, d2M = 0.0;  // M and its derivatives along theta
    if (lode_dependent && q > kLodeGuard * Y) {
      // M(x) = 6 s/(3 - s x), x = sin(3 theta): dM/dx = 6 s^2/den^2, d2M/dx2 = 12 s^3/den^3.
      const double sphi = 3.0 * M_c / (6.0 + M_c);
      const double den = 3.0 - sphi * lode.sin3;
      M = 6.0 * sphi / den;
      const double M_x = M * sphi / den, M_xx = 2.0 * M_x * sphi / den;
      dM = 3.0 * lode.cos3 * M_x;
      d2M = 9.0 * (lode.cos3 * lode.cos3 * M_xx - lode.sin3 * M_x);
    }
    LodeForm f;
    const double M2 = M * M;
    pq_parts(M2, p, q, Y, f);
    if (p > kTensionGuard * Y) f.F_theta = -2.0 * q * q * dM / (M2 * M * p);
    const double ell = p * (p - Y);  // f = q^2 + M^2 p'(p' - p_c)
    f.Q_theta = 2.0 * M * dM * ell / Y;
    f.Q_ptheta = 2.0 * M * dM * (2.0 * p - Y) / Y;
    f.Q_thetatheta = 2.0 * (dM * dM + M * d2M) * ell / Y;
    f.Q_thetaY = -2.0 * M * dM * p * p / (Y * Y);
    return f;
  }

 private:
  /// The (p', q) parts of pq() and pq_theta() at a given M^2: F with its tension guard, the flow
  /// Q_p, Q_q and their derivatives along p', q and the size Y (method-notes eq. (2.5.8)).
  template <class Form>
  static void pq_parts(double M2, double p, double q, double Y, Form& f) {
    if (p <= kTensionGuard * Y) {
      f.F = p;
      f.F_p = 1.0;
    } else {
      f.F = p + q * q / (M2 * p);
      f.F_p = 1.0 - q * q / (M2 * p * p);
      f.F_q = 2.0 * q / (M2 * p);
    }
    f.Q_p = M2 * (2.0 * p - Y) / Y;
    f.Q_q = 2.0 * q / Y;
    f.Q_pp = 2.0 * M2 / Y;
    f.Q_qq = 2.0 / Y;
    f.Q_pY = -2.0 * M2 * p / (Y * Y);
    f.Q_qY = -2.0 * q / (Y * Y);
  }

 public:

  /// sin(phi_c) -> M_c in triaxial compression (docs/cases.md §1.2 C3).
  static double M_from_friction_angle(double phi_deg) {
    const double s = std::sin(phi_deg * std::numbers::pi / 180.0);
    return 6.0 * s / (3.0 - s);
  }
};

}  // namespace rktsph
