#pragma once
// Cubic B-spline kernel of Monaghan & Lattanzio (method-notes §3.1), support radius 2h.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/types.hpp"

namespace rktsph {

template <int Dim>
class CubicSplineKernel {
 public:
  explicit CubicSplineKernel(double h) : h_(h), inv_h_(1.0 / h), alpha_(normalisation(h)) {}

  double h() const { return h_; }
  double support_radius() const { return 2.0 * h_; }

  /// W(r, h) (method-notes §3.1).
  double value(double r) const {
    const double q = r / h_;
    if (q < 1.0) return alpha_ * (2.0 / 3.0 - q * q + 0.5 * q * q * q);
    if (q < 2.0) {
      const double t = 2.0 - q;
      return alpha_ * t * t * t / 6.0;
    }
    return 0.0;
  }

  /// dW/dr (method-notes §3.1).
  double derivative(double r) const {
    const double q = r / h_;
    if (q < 1.0) return alpha_ / h_ * (-2.0 * q + 1.5 * q * q);
    if (q < 2.0) {
      const double t = 2.0 - q;
      return -alpha_ / h_ * 0.5 * t * t;
    }
    return 0.0;
  }

  /// W(r) and dW/dr together (one evaluation of q for the hot loops of operator assembly).
  void value_and_derivative(double r, double& w, double& dw) const {
    const double q = r * inv_h_;  // multiplications only: this runs for every pair every step (V2)
    if (q < 1.0) {
      w = alpha_ * (2.0 / 3.0 - q * q + 0.5 * q * q * q);
      dw = alpha_ * inv_h_ * (-2.0 * q + 1.5 * q * q);
    } else if (q < 2.0) {
      const double t = 2.0 - q;
      w = alpha_ * (1.0 / 6.0) * t * t * t;
      dw = -alpha_ * inv_h_ * 0.5 * t * t;
    } else {
      w = 0.0;
      dw = 0.0;
    }
  }

  /// W(r) and h W'(r)/r for 0 <= r < 2h, without branches, so that loops over the pairs of a
  /// row vectorise (`#pragma omp simd`): both pieces are evaluated and one is selected. h W'/r
  /// is finite at r = 0 (-2 alpha/h), where grad W = W'/r x_ab vanishes with x_ab; callers
  /// must keep r < 2h (the second piece is not cut off beyond it).
  static void value_and_scaled_derivative(double r, double inv_h, double alpha, double& w, double& h_dw_over_r) {
    const double q = r * inv_h;
    const double t = 2.0 - q;
    const double w_inner = alpha * (2.0 / 3.0 - q * q + 0.5 * q * q * q);
    const double w_outer = alpha * (1.0 / 6.0) * t * t * t;
    w = q < 1.0 ? w_inner : w_outer;
    h_dw_over_r = scaled_derivative<double>(r, inv_h, alpha);
  }

  /// h W'(r)/r alone, as above, in double or float (the free surface's single-precision
  /// pre-screen, method-notes §3.6).
  template <class Real>
  static Real scaled_derivative(Real r, Real inv_h, Real alpha) {
    const Real q = r * inv_h;
    const Real t = Real(2) - q;
    const Real d_inner = alpha * inv_h * (Real(-2) + Real(1.5) * q);
    const Real d_outer = Real(-0.5) * alpha * inv_h * t * t / std::max(q, Real(1));
    return q < Real(1) ? d_inner : d_outer;
  }
  double inv_h() const { return inv_h_; }
  double alpha() const { return alpha_; }

  /// grad_a W_ab = W'(r) (x_a - x_b) / r, with x_ab = x_a - x_b.
  Vec<Dim> gradient(const Vec<Dim>& x_ab) const {
    const double r = x_ab.norm();
    if (r <= 0.0) return Vec<Dim>::Zero();
    return derivative(r) / r * x_ab;
  }

 private:
  static double normalisation(double h) {
    if constexpr (Dim == 1) return 1.0 / h;
    if constexpr (Dim == 2) return 15.0 / (7.0 * std::numbers::pi * h * h);
    return 3.0 / (2.0 * std::numbers::pi * h * h * h);
  }
  double h_;
  double inv_h_;
  double alpha_;
};

}  // namespace rktsph
