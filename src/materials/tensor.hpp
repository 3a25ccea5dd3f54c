#pragma once
// Small helpers on full symmetric tensors (core/types.hpp Sym6: xx, yy, zz, xy, yz, xz with
// TENSOR shear components). A double contraction counts each shear component twice.
#include <array>
#include <cmath>
#include <numbers>

#include "core/types.hpp"

namespace rktsph::tensor {

inline double trace(const Sym6& a) { return a[0] + a[1] + a[2]; }

inline Sym6 deviator(const Sym6& a) {
  const double m = trace(a) / 3.0;
  return {a[0] - m, a[1] - m, a[2] - m, a[3], a[4], a[5]};
}

/// a : b for symmetric tensors (shear entries appear twice in the full tensor).
inline double ddot(const Sym6& a, const Sym6& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + 2.0 * (a[3] * b[3] + a[4] * b[4] + a[5] * b[5]);
}

inline Sym6 scaled(const Sym6& a, double c) { return {c * a[0], c * a[1], c * a[2], c * a[3], c * a[4], c * a[5]}; }

/// Matrix product a·a of a symmetric tensor with itself.
inline Sym6 square(const Sym6& a) {
  const double xx = a[0], yy = a[1], zz = a[2], xy = a[3], yz = a[4], xz = a[5];
  return {xx * xx + xy * xy + xz * xz, xy * xy + yy * yy + yz * yz, xz * xz + yz * yz + zz * zz,
          xx * xy + xy * yy + xz * yz, xy * xz + yy * yz + yz * zz, xx * xz + xy * yz + xz * zz};
}

inline double determinant(const Sym6& a) {
  const double xx = a[0], yy = a[1], zz = a[2], xy = a[3], yz = a[4], xz = a[5];
  return xx * (yy * zz - yz * yz) - xy * (xy * zz - yz * xz) + xz * (xy * yz - yy * xz);
}

/// Equivalent strain (rate) sqrt(2/3 e:e) of the deviatoric part e (method-notes §1.7).
inline double equivalent_strain(const Sym6& eps) {
  const Sym6 e = deviator(eps);
  return std::sqrt(2.0 / 3.0 * ddot(e, e));
}

/// The stress of mean stress -p, deviator q and Lode angle theta (0 in shear, pi/6 in triaxial
/// compression), its principal axes turned away from x, y, z by R = Rz(turn) Rx(0.7 turn):
/// R diag(s1, s2, s3) R^T - p 1. For checks and benchmarks of the returns on general states.
inline Sym6 from_invariants(double p, double q, double theta, double turn) {
  constexpr double third = 2.0 * std::numbers::pi / 3.0;
  const double d[3] = {2.0 * q / 3.0 * std::sin(theta + third), 2.0 * q / 3.0 * std::sin(theta),
                       2.0 * q / 3.0 * std::sin(theta - third)};
  const double c = std::cos(turn), s = std::sin(turn), cx = std::cos(0.7 * turn), sx = std::sin(0.7 * turn);
  const double R[3][3] = {{c, -s * cx, s * sx}, {s, c * cx, -c * sx}, {0.0, sx, cx}};
  double m[3][3];
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      m[i][j] = 0.0;
      for (int k = 0; k < 3; ++k) m[i][j] += R[i][k] * d[k] * R[j][k];
    }
  }
  return {m[0][0] - p, m[1][1] - p, m[2][2] - p, m[0][1], m[1][2], m[0][2]};
}

}  // namespace rktsph::tensor
