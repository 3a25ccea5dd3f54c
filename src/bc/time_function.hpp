#pragma once
// Time functions that scale loads, prescribed values and body forces (method-notes §4.1).
#include <string>
#include <vector>

namespace rktsph {

class TimeFunction {
 public:
  enum class Kind { constant, ramp, step, smoothstep, sine, table };

  /// f(t), dimensionless.
  double operator()(double t) const;

  static TimeFunction constant(double value = 1.0);
  /// 0 before `start`, rising linearly (ramp) or by the quintic smoothstep to 1 over `duration`.
  static TimeFunction ramp(double duration, double start = 0.0);
  static TimeFunction smoothstep(double duration, double start = 0.0);

  Kind kind = Kind::constant;
  double value = 1.0;                 // constant level (all kinds scale by it)
  double start = 0.0;                 // s: step and ramp begin here
  double duration = 0.0;              // s: ramp and smoothstep rise time
  double offset = 0.0;                // sine: a0
  double amplitude = 0.0;             // sine: a1
  double frequency = 0.0;             // sine: Hz
  double phase = 0.0;                 // sine: rad
  double rise_time = 0.0;             // sine: ramp factor (1 - exp(-t/T)), 0 for none
  std::vector<double> times, values;  // table: piecewise linear, held constant outside
};

}  // namespace rktsph
