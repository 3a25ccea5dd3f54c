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
