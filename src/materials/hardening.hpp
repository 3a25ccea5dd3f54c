#pragma once
// Hardening parts of the Perzyna models: they own the history variables, give the current
// yield size Y, and their rates from the viscoplastic strain rate (method-notes §1.7–1.9).
#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "core/types.hpp"
#include "materials/tensor.hpp"

namespace rktsph {

/// Y = max(Y0 + H eps_vp_eq, Y_res) (method-notes §1.7, §1.9); H < 0 softens. State:
/// eps_vp_eq = int sqrt(2/3 e_vp:e_vp) dt (dimensionless).
struct LinearHardening {
  double Y0 = 0.0;        // initial yield stress, Pa
  double H = 0.0;         // hardening modulus, Pa (negative = softening)
  double Y_residual = 0;  // floor of Y, Pa (method-notes §6 item 12: a parameter, default 0.1 Y0)

  static constexpr int kSize = 1;
  static std::array<std::string, kSize> names() { return {"eps_vp_eq"}; }
  /// The state that sets Y (an unknown of the implicit return, method-notes §2.5) and its scale.
  static constexpr int kDriver = 0;
  static constexpr double kDriverScale = 1e-6;

  double size(const double* k) const { return std::max(Y0 + H * k[0], Y_residual); }
  void rate(const Sym6& eps_vp_dot, const double* /*k*/, double* dk) const {
    dk[0] = tensor::equivalent_strain(eps_vp_dot);
  }
  /// The state after a viscoplastic strain increment e from k0, exact for a fixed direction
  /// (the backward-Euler return, method-notes eq. (2.5.1)).
  void increment(const Sym6& e, const double* k0, double* k) const { k[0] = k0[0] + tensor::equivalent_strain(e); }
  /// dY/dt per unit gamma*Phi along the flow vector m (for the relaxation-rate estimate).
  double size_rate_per_flow(const Sym6& m, const double* k) const {
    return Y0 + H * k[0] > Y_residual ? H * tensor::equivalent_strain(m) : 0.0;
  }
  void initial_state(double /*F0*/, double* k) const { k[0] = 0.0; }

  /// The (p', q) return's driver (method-notes eq. (2.5.9)): Y and dY/d eps at eps, and eps
  /// after dl along a flow of deviatoric size Q_q (its derivatives along dl and Q_q; the
  /// volumetric parts add nothing).
  double size_of(double eps) const { return std::max(Y0 + H * eps, Y_residual); }
  double size_slope(double eps) const { return Y0 + H * eps > Y_residual ? H : 0.0; }
  struct DriverEnd {
    double value, d_dl, d_Qp, d_Qq, d_dlt;
  };
  DriverEnd driver_end(double eps0, double dl, double /*Q_p*/, double Q_q, double /*dl_t*/) const {
    return {eps0 + dl * Q_q, Q_q, 0.0, dl, 0.0};
  }
  /// Every state after that flow (the p-q form of increment()).
  static void pq_states(const double* k0, double dl, double /*Q_p*/, double Q_q, double /*dl_t*/, double* k) {
    k[0] = k0[0] + dl * Q_q;
  }
};

/// Cam-Clay: p_c_dot = -p_c (1 + e0)/(lambda - kappa) tr(eps_vp_dot), tr positive in dilation
/// (method-notes §1.8), so compaction hardens and dilation softens. State: eps_vp_eq,
/// eps_vp_vol = tr(eps_vp) (positive in dilation, like every strain here), p_c (Pa).
struct CamClayHardening {
  double v0_over_lambda_kappa = 0.0;  // (1 + e0)/(lambda - kappa)
  double p_c0 = 0.0;                  // Pa; used when > 0
  double ocr = 0.0;                   // used when p_c0 == 0: p_c = OCR * F(sigma0)

  static constexpr int kSize = 3;
  static std::array<std::string, kSize> names() { return {"eps_vp_eq", "eps_vp_vol", "p_c"}; }
  /// p_c sets Y; the strains only accumulate (method-notes §2.5).
  static constexpr int kDriver = 2;
  static constexpr double kDriverScale = 1.0;  // Pa

  double size(const double* k) const { return k[2]; }
  void rate(const Sym6& eps_vp_dot, const double* k, double* dk) const {
    const double tr = tensor::trace(eps_vp_dot);
    dk[0] = tensor::equivalent_strain(eps_vp_dot);
    dk[1] = tr;
    dk[2] = -k[2] * v0_over_lambda_kappa * tr;
  }
  double size_rate_per_flow(const Sym6& m, const double* k) const {
    return -k[2] * v0_over_lambda_kappa * tensor::trace(m);
  }
  /// The state after a viscoplastic strain increment e from k0: the rate integrated exactly for
  /// a fixed direction, p_c = p_c0 exp(-(1 + e0)/(lambda - kappa) tr e) (method-notes eq. (2.5.1)).
  void increment(const Sym6& e, const double* k0, double* k) const {
    const double tr = tensor::trace(e);
    k[0] = k0[0] + tensor::equivalent_strain(e);
    k[1] = k0[1] + tr;
    k[2] = k0[2] * std::exp(-v0_over_lambda_kappa * tr);
  }
  /// The (p', q) return's driver (method-notes eq. (2.5.9)): Y = p_c, and p_c after dl along a
  /// flow with volumetric part -Q_p plus dl_t of the tension cut-off: p_c0 exp(c (dl Q_p - dl_t)).
  static double size_of(double pc) { return pc; }
  static double size_slope(double /*pc*/) { return 1.0; }
  struct DriverEnd {
    double value, d_dl, d_Qp, d_Qq, d_dlt;
  };
  DriverEnd driver_end(double pc0, double dl, double Q_p, double /*Q_q*/, double dl_t) const {
    const double c = v0_over_lambda_kappa;
    const double v = pc0 * std::exp(c * (dl * Q_p - dl_t));
    return {v, c * Q_p * v, c * dl * v, 0.0, -c * v};
  }
  /// Every state after that flow (the p-q form of increment()).
  void pq_states(const double* k0, double dl, double Q_p, double Q_q, double dl_t, double* k) const {
    const double ev = -dl * Q_p + dl_t;
    k[0] = k0[0] + dl * Q_q;
    k[1] = k0[1] + ev;
    k[2] = k0[2] * std::exp(-v0_over_lambda_kappa * ev);
  }

  /// F0 is the equivalent size p' + q^2/(M^2 p') of the initial stress: with an OCR the
  /// initial surface passes through OCR times it (equal to OCR p'0 for isotropic stress).
  void initial_state(double F0, double* k) const {
    k[0] = 0.0;
    k[1] = 0.0;
    k[2] = p_c0 > 0.0 ? p_c0 : ocr * F0;
  }
};

}  // namespace rktsph
