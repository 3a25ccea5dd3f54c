#include "core/types.hpp"

#include <cmath>

namespace rktsph {

Invariants invariants(const Sym6& s) {
  const double p = -(s[0] + s[1] + s[2]) / 3.0;
  const double dxx = s[0] + p, dyy = s[1] + p, dzz = s[2] + p;
  const double j2 = 0.5 * (dxx * dxx + dyy * dyy + dzz * dzz) + s[3] * s[3] + s[4] * s[4] + s[5] * s[5];
  return {p, std::sqrt(3.0 * j2)};
}

}  // namespace rktsph
