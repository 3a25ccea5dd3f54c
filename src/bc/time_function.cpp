#include "bc/time_function.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

namespace rktsph {

double TimeFunction::operator()(double t) const {
  switch (kind) {
    case Kind::constant:
      return value;
    case Kind::step:
      return t >= start ? value : 0.0;
    case Kind::ramp:
      if (t <= start) return 0.0;
      if (t >= start + duration) return value;
      return value * (t - start) / duration;
    case Kind::smoothstep: {
      // Quintic S(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5: C2-continuous rise (docs/cases.md Case 1).
      const double tau = std::clamp((t - start) / duration, 0.0, 1.0);
      return value * tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau);
    }
    case Kind::sine: {
      // method-notes §4.1: a0 + a1 sin(omega t - phi), times a ramp (1 - exp(-t/T)).
      const double ramp = rise_time > 0.0 ? 1.0 - std::exp(-t / rise_time) : 1.0;
      return value * ramp * (offset + amplitude * std::sin(2.0 * std::numbers::pi * frequency * t - phase));
    }
    case Kind::table: {
      if (t <= times.front()) return value * values.front();
      if (t >= times.back()) return value * values.back();
      const auto it = std::upper_bound(times.begin(), times.end(), t);
      const auto i = static_cast<std::size_t>(it - times.begin());
      const double w = (t - times[i - 1]) / (times[i] - times[i - 1]);
      return value * ((1.0 - w) * values[i - 1] + w * values[i]);
    }
  }
  return value;
}

TimeFunction TimeFunction::ramp(double duration, double start) {
  TimeFunction f;
  f.kind = Kind::ramp;
  f.duration = duration;
  f.start = start;
  return f;
}

TimeFunction TimeFunction::smoothstep(double duration, double start) {
  TimeFunction f = ramp(duration, start);
  f.kind = Kind::smoothstep;
  return f;
}

TimeFunction TimeFunction::constant(double v) {
  TimeFunction f;
  f.value = v;
  return f;
}

}  // namespace rktsph
