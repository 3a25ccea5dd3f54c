#pragma once
// Mohr–Coulomb with the Abbo & Sloan (1995) hyperbolic and Lode-angle rounding (method-notes
// §1.11), in the q–p′ form of the Drucker–Prager part (p′ = −tr σ/3, compression positive):
//   F = sqrt(q^2 K_phi(theta)^2 + delta_F^2) − sqrt(3) sin(phi) p′,   Y = sqrt(3) c cos(phi)   (1.11.1)
//   Q = sqrt(q^2 K_psi(theta)^2 + delta_Q^2) − sqrt(3) sin(psi) p′                             (1.11.4)
// with delta = eps sin(angle) Y as in §1.10. K(theta) is the exact Mohr–Coulomb
// cos(theta) − sin(angle) sin(theta)/sqrt(3) for |theta| <= theta_T and A − B sin(3 theta) beyond
// (eq. 1.11.2), so F is smooth at the corners theta = ±30 deg. theta_T is the material key
// lode_transition, default 29.7 deg (the triaxial peak within 0.7 % of the sharp pyramid up to
// phi = 40 deg; method-notes §1.11). The Lode derivative is
// taken through x = sin(3 theta) (as for Cam-Clay, method-notes §1.8): no cos(3 theta) -> 0.
// With phi = psi = 0 this is a rounded Tresca with Y = sqrt(3) c (equal to von Mises at theta = 0).
#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/types.hpp"
#include "materials/lode_form.hpp"
#include "materials/tensor.hpp"

namespace rktsph {

/// The Lode factor K(x), x = sin(3 theta), of eqs. (1.11.2)–(1.11.3) for one angle (phi or psi).
struct LodeFactor {
  /// Default theta_T and its admissible range, degrees (the key lode_transition). The rounding's
  /// curvature d2K/dtheta2 = 9 B sin(3 theta) grows like 1/cos(3 theta_T): 19 at 29 deg, 64 at
  /// the default 29.7 deg, 191 at the upper end 29.9 deg.
  static constexpr double kDefaultTransitionDegrees = 29.7;
  static constexpr double kMinTransitionDegrees = 20.0;
  static constexpr double kMaxTransitionDegrees = 29.9;
  static constexpr double kDefaultTransition = kDefaultTransitionDegrees * std::numbers::pi / 180.0;

  double sin_angle = 0.0;
  double transition = kDefaultTransition;  // theta_T, radians
  double A_plus = 0.0, B_plus = 0.0;       // rounding for theta > theta_T
  double A_minus = 0.0, B_minus = 0.0;     // rounding for theta < −theta_T
  double cos_transition = std::cos(kDefaultTransition);  // cos(theta_T), for along()

  /// A and B from continuity of K and dK/dtheta at ±theta_T (eq. 1.11.3).
  static LodeFactor of(double sin_angle, double transition = kDefaultTransition) {
    LodeFactor f;
    f.sin_angle = sin_angle;
    f.transition = transition;
    f.cos_transition = std::cos(transition);
    const double t = transition, r3 = std::sqrt(3.0);
    for (double sign : {1.0, -1.0}) {
      const double B = (sign * std::sin(t) + sin_angle * std::cos(t) / r3) / (3.0 * std::cos(3.0 * t));
      const double A = std::cos(t) - sign * sin_angle * std::sin(t) / r3 + B * sign * std::sin(3.0 * t);
      (sign > 0 ? f.A_plus : f.A_minus) = A;
      (sign > 0 ? f.B_plus : f.B_minus) = B;
    }
    return f;
  }

  struct Value {
    double K;     // K(x)
    double dKdx;  // dK/dx
  };

  Value operator()(double x) const {
    x = std::clamp(x, -1.0, 1.0);
    const double theta = std::asin(x) / 3.0;
    if (theta > transition) return {A_plus - B_plus * x, -B_plus};
    if (theta < -transition) return {A_minus - B_minus * x, -B_minus};
    const double r3 = std::sqrt(3.0);
    const double K = std::cos(theta) - sin_angle * std::sin(theta) / r3;
    const double dKdtheta = -std::sin(theta) - sin_angle * std::cos(theta) / r3;
    return {K, dKdtheta / (3.0 * std::cos(3.0 * theta))};  // cos(3 theta) >= cos(3 theta_T) > 0 here
  }

  struct AlongTheta {
    double K, dK, d2K;  // K and its first two derivatives along theta
  };
  /// K(theta) of eq. (1.11.2) and dK/dtheta, d2K/dtheta2 (method-notes eq. (2.5.12)), for the
  /// (p', q, theta) return: from the angle's sines and cosines, without asin.
  AlongTheta along(const LodeAngle& lode) const {
    if (lode.cos1 < cos_transition) {  // |theta| > theta_T
      const double A = lode.sin1 > 0.0 ? A_plus : A_minus, B = lode.sin1 > 0.0 ? B_plus : B_minus;
      return {A - B * lode.sin3, -3.0 * B * lode.cos3, 9.0 * B * lode.sin3};
    }
    const double r3 = std::sqrt(3.0);
    const double K = lode.cos1 - sin_angle * lode.sin1 / r3;
    return {K, -lode.sin1 - sin_angle * lode.cos1 / r3, -K};
  }
};

struct MohrCoulombSurface {
  /// Below q = kLodeGuard * Y the Lode angle is undefined: theta = 0 (K = 1) and no Lode term.
  static constexpr double kLodeGuard = 1e-9;

  LodeFactor lode_F;     // K_phi
  LodeFactor lode_Q;     // K_psi
  double round_F = 0.0;  // eps sin(phi): delta_F = round_F * Y
  double round_Q = 0.0;  // eps sin(psi)

  /// K(theta): the return moves in the coaxial deviatoric plane (method-notes §2.5).
  bool lode_depends() const { return true; }
  /// The flow turns by 60 deg within the rounding, 2 (30 deg - theta_T) wide, at the triaxial
  /// corners: the (p', q, theta) return stops a Newton step there (method-notes eq. (2.5.16)).
  bool sharp_corners() const { return true; }

  /// theta_T in radians, in [kMinTransitionDegrees, kMaxTransitionDegrees] degrees.
  static MohrCoulombSurface make(double phi, double psi, double eps,
                                 double transition = LodeFactor::kDefaultTransition) {
    return {LodeFactor::of(std::sin(phi), transition), LodeFactor::of(std::sin(psi), transition), eps * std::sin(phi),
            eps * std::sin(psi)};
  }

  /// F of eq. (1.11.1), Pa.
  double value(const Sym6& sigma, double Y) const { return function(sigma, Y, lode_F, round_F * Y); }
  /// dF/dsigma, tensor components (eq. 1.11.5 with phi).
  Sym6 gradient(const Sym6& sigma, double Y) const { return derivative(sigma, Y, lode_F, round_F * Y); }
  /// m = dQ/dsigma (eq. 1.11.5 with psi).
  Sym6 flow(const Sym6& sigma, double Y) const { return derivative(sigma, Y, lode_Q, round_Q * Y); }
  /// Q of eq. (1.11.4), for the tests.
  double potential(const Sym6& sigma, double Y) const { return function(sigma, Y, lode_Q, round_Q * Y); }

  /// F and Q of eqs. (1.11.1), (1.11.4) in (p', q, theta) with the derivatives of the exact
  /// Jacobian (method-notes eq. (2.5.12)). Below the guard theta is taken as 0 with no Lode
  /// term, as value() and flow() do; without rounding, Q_q = K on the axis (its limit along the
  /// deviator, for the apex of §2.5).
  LodeForm pq_theta(double p, double q, const LodeAngle& lode, double Y) const {
    const bool lode_defined = q > kLodeGuard * Y;
    const LodeFactor::AlongTheta kF = lode_defined ? lode_F.along(lode) : LodeFactor::AlongTheta{1.0, 0.0, 0.0};
    const LodeFactor::AlongTheta kQ = lode_defined ? lode_Q.along(lode) : LodeFactor::AlongTheta{1.0, 0.0, 0.0};
    const double r3 = std::sqrt(3.0);
    LodeForm f;
    const double dF = round_F * Y, dQ = round_Q * Y;
    const double RF = std::sqrt(q * q * kF.K * kF.K + dF * dF);
    f.F = RF - r3 * lode_F.sin_angle * p;
    f.F_p = -r3 * lode_F.sin_angle;
    if (RF > 0.0) {
      f.F_q = q * kF.K * kF.K / RF;
      f.F_theta = q * q * kF.K * kF.dK / RF;
      f.F_Y = round_F * dF / RF;
    } else {
      f.F_q = kF.K;
    }
    const double RQ = std::sqrt(q * q * kQ.K * kQ.K + dQ * dQ);
    f.Q_p = -r3 * lode_Q.sin_angle;
    if (!(RQ > 0.0)) {
      f.Q_q = kQ.K;
      return f;
    }
    // Q_q = q K^2/R, Q_theta = q^2 K K'/R with R = sqrt(q^2 K^2 + delta^2), and R^2 - q^2 K^2 = delta^2.
    const double K2 = kQ.K * kQ.K, KdK = kQ.K * kQ.dK;
    const double RQ3 = RQ * RQ * RQ;
    f.Q_q = q * K2 / RQ;
    f.Q_theta = q * q * KdK / RQ;
    f.Q_qq = K2 * dQ * dQ / RQ3;
    f.Q_qtheta = q * KdK * (q * q * K2 + 2.0 * dQ * dQ) / RQ3;
    f.Q_thetatheta = q * q * (kQ.K * kQ.d2K * RQ * RQ + kQ.dK * kQ.dK * dQ * dQ) / RQ3;
    f.Q_qY = -q * K2 * round_Q * dQ / RQ3;
    f.Q_thetaY = -q * q * KdK * round_Q * dQ / RQ3;
    return f;
  }

  /// x = sin(3 theta) of eq. (1.1.3), 0 below the guard.
  static double lode_x(const Sym6& s, double J2, double Y) {
    if (3.0 * J2 <= kLodeGuard * kLodeGuard * Y * Y) return 0.0;
    return std::clamp(-1.5 * std::sqrt(3.0) * tensor::determinant(s) / std::pow(J2, 1.5), -1.0, 1.0);
  }

 private:
  static double function(const Sym6& sigma, double Y, const LodeFactor& lode, double delta) {
    const Sym6 s = tensor::deviator(sigma);
    const double J2 = 0.5 * tensor::ddot(s, s);
    const double K = lode(lode_x(s, J2, Y)).K;
    const double p = -tensor::trace(sigma) / 3.0;
    return std::sqrt(3.0 * J2 * K * K + delta * delta) - std::sqrt(3.0) * lode.sin_angle * p;
  }

  // d/dsigma of sqrt(q^2 K^2 + delta^2) − sqrt3 sin(angle) p′:
  //   (1.5 K^2 s + q^2 K dK/dx dx/dsigma)/R + (sin(angle)/sqrt3) 1,
  //   q^2 dx/dsigma = −(9 sqrt3/2) J2^(−1/2) [t − 3 J3/(2 J2) s],  t = s.s − 2/3 J2 1.
  static Sym6 derivative(const Sym6& sigma, double Y, const LodeFactor& lode, double delta) {
    const Sym6 s = tensor::deviator(sigma);
    const double J2 = 0.5 * tensor::ddot(s, s);
    const bool lode_defined = 3.0 * J2 > kLodeGuard * kLodeGuard * Y * Y;
    const LodeFactor::Value k = lode(lode_x(s, J2, Y));
    const double R = std::sqrt(3.0 * J2 * k.K * k.K + delta * delta);
    Sym6 g{};
    // Without rounding (delta = 0) on the axis the deviatoric direction is round-off: none.
    if (R > 0.0 && (lode_defined || delta > 0.0)) {
      for (std::size_t i = 0; i < 6; ++i) g[i] = 1.5 * k.K * k.K * s[i] / R;
      if (lode_defined) {
        Sym6 t = tensor::square(s);
        for (std::size_t i = 0; i < 3; ++i) t[i] -= 2.0 / 3.0 * J2;
        const double b = 1.5 * tensor::determinant(s) / J2;
        const double a = -4.5 * std::sqrt(3.0) / std::sqrt(J2) * k.K * k.dKdx / R;
        for (std::size_t i = 0; i < 6; ++i) g[i] += a * (t[i] - b * s[i]);
      }
    }
    for (std::size_t i = 0; i < 3; ++i) g[i] += lode.sin_angle / std::sqrt(3.0);
    return g;
  }
};

}  // namespace rktsph
