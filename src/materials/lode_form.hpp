#pragma once
// The (p', q, theta) form of a Lode-dependent yield surface and flow rule, for the backward-Euler
// return (method-notes §2.5, eqs. (2.5.11)–(2.5.15)): the analogue of PQForm for Mohr–Coulomb and
// Cam-Clay with M(theta). With theta the Lode angle of eq. (1.1.3) the flow vector is
//   m = dQ/dsigma = -(Q_p/3) 1 + Q_q (3/2) s/q + Q_theta dtheta/dsigma,
// and dtheta/dsigma lies in the coaxial deviatoric plane, normal to s, of size 1/|s|. The second
// derivatives (along p', q, theta and the size Y) are those of the exact Newton Jacobian.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>

#include "core/types.hpp"
#include "materials/tensor.hpp"

namespace rktsph {

/// A Lode angle theta in [-pi/6, pi/6] by its sines and cosines, all the forms use: the return
/// turns it by the angle-addition formulas, without sin, cos or atan2.
struct LodeAngle {
  double cos1 = 1.0, sin1 = 0.0;  // cos(theta), sin(theta)
  double cos3 = 1.0, sin3 = 0.0;  // cos(3 theta), sin(3 theta)

  /// From theta itself (tests and set-up).
  static LodeAngle of(double theta) {
    return {std::cos(theta), std::sin(theta), std::cos(3.0 * theta), std::sin(3.0 * theta)};
  }
  /// From cos(theta) and sin(theta): the triple angles by c3 = 4c^3 - 3c, s3 = 3s - 4s^3.
  static LodeAngle of(double c, double s) { return {c, s, c * (4.0 * c * c - 3.0), s * (3.0 - 4.0 * s * s)}; }
};

/// An angle on the unfolded deviatoric plane, given by its cosine and sine, folded into the Lode
/// range [-pi/6, pi/6]: the angle of the same invariants, and dtheta/dangle (+1, or -1 after
/// an odd number of mirrorings at the triaxial corners, where the plane's sectors mirror).
/// Valid for angles within +-2 pi/3 (the return keeps q_a >= 0, so |b| <= pi/2).
struct FoldedLodeAngle {
  LodeAngle lode;
  double sign = 1.0;

  static FoldedLodeAngle of(double c, double s) {
    const double sin60 = std::sqrt(3.0) / 2.0;
    double sign = 1.0;
    for (int mirror = 0; mirror < 2; ++mirror) {
      const double c0 = c, s0 = s;
      if (sin60 * s0 - 0.5 * c0 > 0.0) {  // sin(theta - pi/6) > 0: theta -> pi/3 - theta
        c = 0.5 * c0 + sin60 * s0;
        s = sin60 * c0 - 0.5 * s0;
      } else if (sin60 * s0 + 0.5 * c0 < 0.0) {  // sin(theta + pi/6) < 0: theta -> -pi/3 - theta
        c = 0.5 * c0 - sin60 * s0;
        s = -sin60 * c0 - 0.5 * s0;
      } else {
        break;
      }
      sign = -sign;
    }
    return {LodeAngle::of(c, s), sign};
  }
};

/// The coaxial deviatoric plane of a trial deviator s_tr (method-notes eqs. (2.5.3), (2.5.11)):
/// e1 = s_tr/|s_tr|, e2 the unit part of dev(s_tr^2) normal to e1. The deviator
/// sqrt(2/3) q (cos b e1 + sin b e2) has the size q and the Lode angle theta_tr - b: along e2
/// J3 grows at fixed J2, and sin 3 theta falls.
struct CoaxialPlane {
  Sym6 e1{}, e2{};
  double cos_theta = 1.0, sin_theta = 0.0;  // the trial's Lode angle
  bool has_e1 = false;                      // s_tr is not round-off
  bool has_e2 = false;                      // s_tr is off the triaxial corners

  double theta() const { return std::atan2(sin_theta, cos_theta); }

  /// cos theta and sin theta of theta in [-pi/6, pi/6] from c3 = cos 3 theta >= 0 and
  /// s3 = sin 3 theta, without atan2, sin and cos: Newton on 4c^3 - 3c = c3, convex with a slope
  /// of 6 to 9 on [cos 30 deg, 1], from the right (c0 = 1 - (1 - c3)/9, the second-order
  /// expansion, lies above the root), then s = s3/(4c^2 - 1), as 3 - 4s^2 = 4c^2 - 1 in [2, 3].
  static void third_angle(double c3, double s3, double& c, double& s) {
    c = 1.0 - (1.0 - c3) / 9.0;
    for (int it = 0; it < 5; ++it) c -= (c * (4.0 * c * c - 3.0) - c3) / (12.0 * c * c - 3.0);
    s = s3 / (4.0 * c * c - 1.0);
  }

  /// The plane of s (deviatoric); no e1 below |s| = floor.
  static CoaxialPlane of(const Sym6& s, double floor) {
    CoaxialPlane c;
    const double ns = std::sqrt(tensor::ddot(s, s));
    if (ns > floor) {
      c.has_e1 = true;
      c.e1 = tensor::scaled(s, 1.0 / ns);
      Sym6 t = tensor::deviator(tensor::square(s));
      const double along = tensor::ddot(t, c.e1);
      for (std::size_t i = 0; i < 6; ++i) t[i] -= along * c.e1[i];
      const double nt = std::sqrt(tensor::ddot(t, t));
      // sin 3 theta = -3 sqrt6 det(e1) and cos 3 theta = sqrt6 dev(e1^2) : e2 >= 0, the latter
      // from d(sin 3 theta)/db = -3 cos 3 theta: exact near the corners, where asin is not.
      const double root6 = std::sqrt(6.0);
      const double s3 = std::clamp(-3.0 * root6 * tensor::determinant(c.e1), -1.0, 1.0);
      const double c3 = std::min(root6 * nt / (ns * ns), 1.0);
      const double norm = 1.0 / std::sqrt(s3 * s3 + c3 * c3);  // round-off off the unit circle
      third_angle(c3 * norm, s3 * norm, c.cos_theta, c.sin_theta);
      if (nt > 1e-8 * ns * ns) {  // the generic return's test (implicit_source.hpp)
        c.has_e2 = true;
        c.e2 = tensor::scaled(t, 1.0 / nt);
      }
    }
    return c;
  }

  /// sqrt(2/3) q (cos b e1 + sin b e2).
  Sym6 deviator(double q, double b) const {
    const double rho = std::sqrt(2.0 / 3.0) * q, a = rho * std::cos(b), c = rho * std::sin(b);
    Sym6 s{};
    for (std::size_t i = 0; i < 6; ++i) s[i] = a * e1[i] + c * e2[i];
    return s;
  }

  /// The Lode angle after the rotation b, theta_tr - b, with cb = cos b and sb = sin b: by the
  /// angle-addition formulas, folded into the Lode range.
  FoldedLodeAngle lode_angle(double cb, double sb) const {
    return FoldedLodeAngle::of(cos_theta * cb + sin_theta * sb, sin_theta * cb - cos_theta * sb);
  }
};

struct LodeForm {
  double F = 0.0, F_p = 0.0, F_q = 0.0, F_theta = 0.0, F_Y = 0.0;  // yield function, Pa, and its derivatives
  double Q_p = 0.0, Q_q = 0.0, Q_theta = 0.0;                      // flow components (Q_theta in Pa)
  double Q_pp = 0.0, Q_pq = 0.0, Q_ptheta = 0.0;                   // their derivatives
  double Q_qq = 0.0, Q_qtheta = 0.0, Q_thetatheta = 0.0;
  double Q_pY = 0.0, Q_qY = 0.0, Q_thetaY = 0.0;  // and along the size Y
};

}  // namespace rktsph
