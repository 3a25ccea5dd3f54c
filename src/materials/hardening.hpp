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

  double size(const double* k) const { return std::max(Y0 + H * k[0], Y_residual); }
  void rate(const Sym6& eps_vp_dot, const double* /*k*/, double* dk) const {
    dk[0] = tensor::equivalent_strain(eps_vp_dot);
  }
  /// dY/dt per unit gamma*Phi along the flow vector m (for the relaxation-rate estimate).
  double size_rate_per_flow(const Sym6& m, const double* k) const {
    return Y0 + H * k[0] > Y_residual ? H * tensor::equivalent_strain(m) : 0.0;
  }
  void initial_state(double /*F0*/, double* k) const { k[0] = 0.0; }
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
  /// F0 is the equivalent size p' + q^2/(M^2 p') of the initial stress: with an OCR the
  /// initial surface passes through OCR times it (equal to OCR p'0 for isotropic stress).
  void initial_state(double F0, double* k) const {
    k[0] = 0.0;
    k[1] = 0.0;
    k[2] = p_c0 > 0.0 ? p_c0 : ocr * F0;
  }
};

}  // namespace rktsph
