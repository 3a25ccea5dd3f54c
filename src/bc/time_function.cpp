#include "bc/time_function.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "io/section.hpp"

namespace rktsph {

double TimeFunction::operator()(double t) const {
  switch (kind) {
    case Kind::constant: return value;
    case Kind::step: return t >= start ? value : 0.0;
    case Kind::ramp:
      if (t <= start) return 0.0;
      if (t >= start + duration) return value;
      return value * (t - start) / duration;
    case Kind::smoothstep: {
      // Quintic S(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5: C2-continuous rise (CASES.md Case 1).
      const double tau = std::clamp((t - start) / duration, 0.0, 1.0);
      return value * tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau);
    }
    case Kind::sine: {
      // METHOD.md §4.1: a0 + a1 sin(omega t - phi), times a ramp (1 - exp(-t/T)).
      const double ramp = rise_time > 0.0 ? 1.0 - std::exp(-t / rise_time) : 1.0;
      return value * ramp *
             (offset + amplitude * std::sin(2.0 * std::numbers::pi * frequency * t - phase));
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

TimeFunction TimeFunction::constant(double v) {
  TimeFunction f;
  f.value = v;
  return f;
}

TimeFunction TimeFunction::read(const io::Section& s) {
  TimeFunction f;
  const std::string type = s.string("type");
  f.value = s.number("scale", 1.0);
  if (type == "constant") {
    f.kind = Kind::constant;
  } else if (type == "step") {
    f.kind = Kind::step;
    f.start = s.non_negative("start", 0.0);
  } else if (type == "ramp" || type == "smoothstep") {
    f.kind = type == "ramp" ? Kind::ramp : Kind::smoothstep;
    f.start = s.non_negative("start", 0.0);
    f.duration = s.positive("duration");
  } else if (type == "sine") {
    f.kind = Kind::sine;
    f.offset = s.number("offset", 0.0);
    f.amplitude = s.number("amplitude", 1.0);
    f.frequency = s.positive("frequency");
    f.phase = s.number("phase", 0.0);
    f.rise_time = s.non_negative("rise_time", 0.0);
  } else if (type == "table") {
    f.kind = Kind::table;
    f.times = s.numbers("times");
    f.values = s.numbers("values");
    s.require(!f.times.empty(), "times", "needs at least one point");
    s.require(f.times.size() == f.values.size(), "values",
              fmt::format("must have as many entries as 'times' ({}), got {}", f.times.size(),
                          f.values.size()));
    for (std::size_t i = 1; i < f.times.size(); ++i) {
      s.require(f.times[i] > f.times[i - 1], "times", "must be strictly increasing");
    }
  } else {
    s.fail("type", fmt::format("unknown time function type '{}' (known: constant, step, ramp, "
                               "smoothstep, sine, table)",
                               type));
  }
  s.finish();
  return f;
}

}  // namespace rktsph
