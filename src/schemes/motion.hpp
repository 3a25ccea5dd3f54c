#pragma once
// How the particles of a staggered scheme move, as policies of its stages (method-notes §1.3,
// §2.3, §5.2):
//   FixedParticles   V1, V3: small deformation, the particles stay at their positions;
//   MovingParticles  V2: updated Lagrangian. The stress rate gets the Jaumann term with the
//                    spin frozen over the interval, integrated exactly as a rotation
//                    sigma <- Q sigma Q^T, Q = exp(W tau); the density follows the continuity
//                    equation and the volume the mass; the positions move with the material.
// and how step 2 updates the nodal velocity:
//   TaylorGalerkinVelocity  V1's step 2: v^{n+1} = v^n + dt (div sigma^{n+1/2} / rho + b);
//   SimpleVelocity          V2's "simple scheme" (method-notes §2.3):
//                           v^{n+1} = P_NE v^{n+1/2} + (dt/2)(div sigma^{n+1/2} / rho + b),
//                           which forgets the nodal history and with it the modes the stress
//                           points cannot see.
#include <cmath>

#include <Eigen/Dense>

#include "core/types.hpp"

namespace rktsph {

struct FixedParticles {
  static constexpr bool kMoving = false;
};
struct MovingParticles {
  static constexpr bool kMoving = true;
};

struct TaylorGalerkinVelocity {
  static constexpr bool kSimple = false;
};
struct SimpleVelocity {
  static constexpr bool kSimple = true;
};

/// sin and cos of an angle; below 0.1 rad (every step's rotation but in a violent flow) by
/// their Taylor series, whose truncation (theta^13 / 13! and theta^14 / 14!, below 2e-22 of the
/// values there) is far under a unit in the last place: the results agree with libm's within
/// one (rounding), at a fraction of its cost (test V2.SinCosSeriesAgreesWithLibm).
inline void sin_cos(double theta, double& sn, double& c) {
  if (std::abs(theta) >= 0.1) {
    sn = std::sin(theta);
    c = std::cos(theta);
    return;
  }
  // Horner in theta^2 with the coefficients as constants: written with divisions (t2 / 6.0 ...),
  // which GCC keeps without -ffast-math, they were a third of step 1 in a perf profile.
  const double t2 = theta * theta;
  constexpr double s3 = -1.0 / 6.0, s5 = 1.0 / 120.0, s7 = -1.0 / 5040.0, s9 = 1.0 / 362880.0, s11 = -1.0 / 39916800.0;
  constexpr double c2 = -0.5, c4 = 1.0 / 24.0, c6 = -1.0 / 720.0, c8 = 1.0 / 40320.0, c10 = -1.0 / 3628800.0,
                   c12 = 1.0 / 479001600.0;
  sn = theta + theta * t2 * (s3 + t2 * (s5 + t2 * (s7 + t2 * (s9 + t2 * s11))));
  c = 1.0 + t2 * (c2 + t2 * (c4 + t2 * (c6 + t2 * (c8 + t2 * (c10 + t2 * c12)))));
}

/// The Jaumann term d sigma/dt = W sigma - sigma W over tau with the spin W = skew(grad v)
/// frozen, integrated exactly: sigma <- Q sigma Q^T, Q = exp(W tau) (method-notes eq. (1.3.1)).
/// grad_v[d][k] = d v_k / d x_d; s in the per-dimension stress layout. A rigid rotation thus
/// rotates the stress exactly, whatever the step.
template <int Dim>
inline void jaumann_rotate(const double (&grad_v)[Dim][Dim], double tau, double* s) {
  if constexpr (Dim == 2) {
    // W_xy = 1/2 (dv_x/dy - dv_y/dx); Q = [[c, sn], [-sn, c]] with the angle W_xy tau.
    const double theta = 0.5 * (grad_v[1][0] - grad_v[0][1]) * tau;
    if (theta == 0.0) return;
    double c, sn;
    sin_cos(theta, sn, c);
    const double a = s[0], d = s[1], b = s[3];
    s[0] = c * c * a + 2.0 * c * sn * b + sn * sn * d;
    s[1] = sn * sn * a - 2.0 * c * sn * b + c * c * d;
    s[3] = c * sn * (d - a) + (c * c - sn * sn) * b;
  } else if constexpr (Dim == 3) {
    Eigen::Matrix3d W;
    for (int k = 0; k < 3; ++k) {
      for (int d = 0; d < 3; ++d) W(k, d) = 0.5 * (grad_v[d][k] - grad_v[k][d]);  // W_kd
    }
    const Eigen::Vector3d axis(W(2, 1), W(0, 2), W(1, 0));  // W = [axis]_x
    const double angle = axis.norm() * tau;
    if (angle == 0.0) return;
    const Eigen::Matrix3d K = W / axis.norm();  // unit skew
    double sn, c;
    sin_cos(angle, sn, c);
    const Eigen::Matrix3d Q = Eigen::Matrix3d::Identity() + sn * K + (1.0 - c) * K * K;
    Eigen::Matrix3d S;
    S << s[0], s[3], s[5], s[3], s[1], s[4], s[5], s[4], s[2];
    const Eigen::Matrix3d R = Q * S * Q.transpose();
    s[0] = R(0, 0);
    s[1] = R(1, 1);
    s[2] = R(2, 2);
    s[3] = R(0, 1);
    s[4] = R(1, 2);
    s[5] = R(0, 2);
  } else {
    (void)grad_v;  // 1D: no spin
    (void)tau;
    (void)s;
  }
}

}  // namespace rktsph
