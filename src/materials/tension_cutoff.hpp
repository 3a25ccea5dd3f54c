#pragma once
// Tension cut-off on the mean stress, a second Perzyna mechanism beside the yield surface
// (method-notes §1.12). With sigma_m = tr(sigma)/3 (tension positive) and the cut-off T:
//   F_t = sigma_m,   x_t = (sigma_m − T)/Y,   m_t = dF_t/dsigma = 1/3 (associated)   (1.12.1)
// normalised by the same size Y as the shear surface so that one overstress function Phi and
// one fluidity gamma serve both; the viscoplastic strain rates add (eq. 1.12.2).
// The mean stress (not the largest principal stress) is cut because it is smooth everywhere,
// in particular on the isotropic axis where the relief is needed (three equal principal
// stresses are a corner of a Rankine cut-off).
#include <cmath>

#include "core/types.hpp"
#include "materials/tensor.hpp"

namespace rktsph {

struct TensionCutoff {
  bool active = false;  // absent key: no cut-off
  double limit = 0.0;   // T, Pa: the largest mean stress tr(sigma)/3 allowed

  /// F_t of eq. (1.12.1): the mean stress, Pa (tension positive).
  static double value(const Sym6& sigma) { return tensor::trace(sigma) / 3.0; }
  /// x_t of eq. (1.12.1).
  double overstress(const Sym6& sigma, double Y) const { return (value(sigma) - limit) / Y; }
  /// dF_t/dsigma = m_t = 1/3 (the identity over three), tensor components.
  static Sym6 gradient() { return {1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0, 0.0, 0.0, 0.0}; }
};

}  // namespace rktsph
