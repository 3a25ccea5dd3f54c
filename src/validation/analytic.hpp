#pragma once
// Closed-form reference solutions used by the validation cases (docs/cases.md).
#include <cmath>

namespace rktsph::analytic {

/// Quintic smooth step S(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5 on [0, 1] (docs/cases.md Case 1,
/// revised acceptance); a rise time of zero gives the Heaviside step.
inline double smooth_step(double t, double rise_time) {
  if (t < 0.0) return 0.0;
  if (rise_time <= 0.0) return 1.0;
  const double tau = std::min(t / rise_time, 1.0);
  return tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau);
}

/// 1D elastic bar 0 <= x <= L, fixed at x = 0, traction sigma0 S(t) at x = L: stress and
/// velocity by the method of images (docs/cases.md Case 1).
struct ElasticBar {
  double length;      // m
  double wave_speed;  // m/s
  double density;     // kg/m^3
  double sigma0;      // Pa, tension positive
  double rise_time;   // s; 0 for a step load

  double stress(double x, double t) const { return sigma0 * images(x, t, +1.0); }
  double velocity(double x, double t) const { return sigma0 / (density * wave_speed) * images(x, t, -1.0); }

  /// sum_k (-1)^k [S(t - (2kL + L - x)/c) + reflected * S(t - (2kL + L + x)/c)]: the incident and
  /// reflected image waves; stress adds them (reflected = +1), velocity subtracts them (-1).
  double images(double x, double t, double reflected) const {
    double sum = 0.0;
    const double L = length, c = wave_speed;
    for (int k = 0;; ++k) {
      const double a = (2.0 * k * L + (L - x)) / c;
      if (a > t) break;
      const double sign = (k % 2 == 0) ? 1.0 : -1.0;
      sum +=
          sign * (smooth_step(t - a, rise_time) + reflected * smooth_step(t - (2.0 * k * L + (L + x)) / c, rise_time));
    }
    return sum;
  }

  /// Distance from x to the nearest wave front of the step solution at time t.
  double distance_to_front(double x, double t) const {
    const double L = length, c = wave_speed;
    double best = 1e300;
    for (int k = 0; 2.0 * k * L <= c * t + 2.0 * L; ++k) {
      const double travelled = c * t - 2.0 * k * L;
      const double f1 = L - travelled;  // incoming front from the loaded end
      const double f2 = travelled - L;  // front reflected at the fixed end
      if (f1 >= 0.0 && f1 <= L) best = std::min(best, std::abs(x - f1));
      if (f2 >= 0.0 && f2 <= L) best = std::min(best, std::abs(x - f2));
    }
    return best;
  }
};

}  // namespace rktsph::analytic

namespace rktsph::analytic {

/// A 1D bar 0 <= X in large deformation: the Jaumann hypoelastic law in uniaxial strain gives
/// sigma = M ln(lambda), lambda = dx/dX, and the p-system rho0 v_t = sigma_X, lambda_t = v_X
/// with the Lagrangian wave speed C(lambda) = sqrt(M / (rho0 lambda)) (docs/cases.md Case 7).
/// The end X = 0 is driven at v(0, t) = v0 from t = 0 into the bar at rest: v0 > 0 pushes (one
/// shock), v0 < 0 pulls (a rarefaction fan).
struct LargeStrainBar {
  double M;     // constrained modulus, Pa
  double rho0;  // reference density, kg/m^3
  double v0;    // m/s

  double c0() const { return std::sqrt(M / rho0); }
  double wave_speed(double lambda) const { return std::sqrt(M / (rho0 * lambda)); }
  /// The state behind the wave: rho0 v0^2 / M = (-ln l)(1 - l) for the shock (push), and
  /// l = (1 + |v0| / (2 C0))^2 behind the fan (pull).
  double lambda_behind() const {
    if (v0 <= 0.0) {
      const double r = 1.0 + std::abs(v0) / (2.0 * c0());
      return r * r;
    }
    const double target = rho0 * v0 * v0 / M;
    double lo = 1e-6, hi = 1.0 - 1e-15;  // f decreases from +inf to 0 on (0, 1)
    for (int k = 0; k < 200; ++k) {
      const double mid = 0.5 * (lo + hi);
      if ((-std::log(mid)) * (1.0 - mid) > target) lo = mid;
      else hi = mid;
    }
    return 0.5 * (lo + hi);
  }
  /// Lagrangian speed of the shock (push).
  double shock_speed() const { return v0 / (1.0 - lambda_behind()); }
  /// The fan's head and tail speeds (pull).
  double fan_head() const { return c0(); }
  double fan_tail() const { return wave_speed(lambda_behind()); }

  double lambda(double X, double t) const {
    if (t <= 0.0) return 1.0;
    if (v0 > 0.0) return X < shock_speed() * t ? lambda_behind() : 1.0;
    const double xi = X / t;
    if (xi >= fan_head()) return 1.0;
    if (xi <= fan_tail()) return lambda_behind();
    return M * t * t / (rho0 * X * X);  // inside the fan: C(lambda) = X / t
  }
  double velocity(double X, double t) const {
    if (v0 > 0.0) return X < shock_speed() * t ? v0 : 0.0;
    return -2.0 * c0() * (std::sqrt(lambda(X, t)) - 1.0);
  }
  double stress(double X, double t) const { return M * std::log(lambda(X, t)); }
};

}  // namespace rktsph::analytic
