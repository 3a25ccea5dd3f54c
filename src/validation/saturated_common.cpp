#include "validation/saturated_common.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace rktsph::validation {

double checkerboard_amplitude(const std::vector<double>& x, const std::vector<double>& y, const std::vector<double>& f,
                              double dx, double* rms, const std::vector<bool>* skip) {
  std::map<std::pair<long, long>, double> grid;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (skip != nullptr && (*skip)[i]) continue;
    grid[{std::lround(x[i] / dx), std::lround(y[i] / dx)}] = f[i];
  }
  auto at = [&](long i, long j, double& v) {
    const auto it = grid.find({i, j});
    if (it == grid.end()) return false;
    v = it->second;
    return true;
  };
  double worst = 0.0, sum2 = 0.0;
  long count = 0;
  for (const auto& [ij, f0] : grid) {
    const auto [i, j] = ij;
    double a = 0.0;
    bool ok = true;
    for (int axis = 0; axis < 2 && ok; ++axis) {
      double v[5];
      for (int k = -2; k <= 2 && ok; ++k) ok = at(axis == 0 ? i + k : i, axis == 0 ? j : j + k, v[k + 2]);
      if (ok) a = std::max(a, std::abs(v[0] - 4.0 * v[1] + 6.0 * v[2] - 4.0 * v[3] + v[4]) / 16.0);
    }
    if (!ok) continue;
    worst = std::max(worst, a);
    sum2 += a * a;
    ++count;
  }
  if (rms != nullptr) *rms = count > 0 ? std::sqrt(sum2 / static_cast<double>(count)) : 0.0;
  return worst;
}

}  // namespace rktsph::validation
