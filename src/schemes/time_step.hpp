#pragma once
// The one time-step rule of the explicit schemes (method-notes §4.3, §0.3 item 4):
//   dt = C dx / c_max,  c_max the fastest wave speed over the materials,  C <= kMaxCourant.
// The case reader checks it where the key's line is known; the schemes check it again for
// cases built in code.
#include <cmath>
#include <memory>
#include <optional>
#include <vector>

#include "materials/material.hpp"

namespace rktsph {

/// The largest Courant number accepted: the staggered scheme is unstable beyond it.
inline constexpr double kMaxCourant = 1.3;

/// The fastest wave the flux carries over the materials, m/s.
inline double max_wave_speed(const std::vector<std::shared_ptr<const Material>>& materials) {
  double c = 0.0;
  for (const auto& m : materials) c = std::max(c, m->wave_speed());
  return c;
}

struct TimeStep {
  double dt = 0.0;          // s
  double courant = 0.0;     // c_max dt / dx
  double wave_speed = 0.0;  // c_max, m/s
};

/// The step from a Courant number or a fixed dt (exactly one of them given).
inline TimeStep time_step_from(double dx, double wave_speed, std::optional<double> cfl, std::optional<double> dt) {
  TimeStep s;
  s.wave_speed = wave_speed;
  if (dt) {
    s.dt = *dt;
    s.courant = s.dt * wave_speed / dx;
  } else {
    s.courant = cfl.value_or(0.5);
    s.dt = s.courant * dx / wave_speed;
  }
  return s;
}

}  // namespace rktsph
