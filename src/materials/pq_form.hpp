#pragma once
// The (p', q) form of a Lode-independent yield surface and flow rule, for the backward-Euler
// return (method-notes §2.5, eqs. (2.5.8)–(2.5.10)): with p' = -tr(sigma)/3 (compression
// positive) and q = sqrt(3 J2), the flow vector is
//   m = dQ/dsigma = -(Q_p/3) 1 + Q_q (3/2) s/q,
// so that D^e : m = -K Q_p 1 + 3 G Q_q s/q: the return keeps the deviator's direction and moves
// p' by K dl Q_p and q by -3 G dl Q_q. The second derivatives are those of the exact Newton
// Jacobian.

namespace rktsph {

struct PQForm {
  double F = 0.0, F_p = 0.0, F_q = 0.0, F_Y = 0.0;  // yield function, Pa, and its derivatives
  double Q_p = 0.0, Q_q = 0.0;                      // flow components (dimensionless)
  double Q_pp = 0.0, Q_pq = 0.0, Q_qq = 0.0;        // their derivatives, 1/Pa
  double Q_pY = 0.0, Q_qY = 0.0;                    // and along the size Y, 1/Pa
};

}  // namespace rktsph
