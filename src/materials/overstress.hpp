#pragma once
// Perzyna overstress functions Phi(x) of the normalised overstress x = (F - Y)/Y
// (method-notes §1.6). The Macaulay bracket is built in: Phi = 0 for x <= dead_band. The dead band
// defaults to 0 (method-notes §6 item 12); when a case asks for one, flow starts once x exceeds
// it and Phi is NOT shifted (the lineage behaviour: Phi jumps from 0 to Phi(dead_band)).
#include <algorithm>
#include <cmath>

namespace rktsph {

enum class OverstressKind { power, exponential };

struct Overstress {
  OverstressKind kind = OverstressKind::power;
  double exponent = 1.0;   // N, dimensionless, > 0
  double dead_band = 0.0;  // x below which no flow occurs, >= 0

  /// Phi(x): power x^N or exponential exp(N x) - 1, zero inside the (dead-banded) surface.
  double value(double x) const {
    if (!(x > dead_band)) return 0.0;
    if (kind == OverstressKind::power) return exponent == 1.0 ? x : std::pow(x, exponent);
    return std::expm1(exponent * x);
  }

  /// dPhi/dx, used only for the relaxation-rate estimate. For a power law with N < 1 the
  /// slope is unbounded as x -> 0 (the ODE is not Lipschitz there); the estimate evaluates it
  /// at max(x, kSlopeFloor) because an explicit overshoot below yield just stops the flow.
  double slope(double x) const {
    if (!(x > dead_band)) return 0.0;
    if (kind == OverstressKind::power) {
      if (exponent == 1.0) return 1.0;
      const double xs = exponent < 1.0 ? std::max(x, kSlopeFloor) : x;
      return exponent * std::pow(xs, exponent - 1.0);
    }
    return exponent * std::exp(exponent * x);
  }

  static constexpr double kSlopeFloor = 1e-2;
};

}  // namespace rktsph
