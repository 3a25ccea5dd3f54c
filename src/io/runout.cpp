#include "io/runout.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace rktsph::io {

namespace {

// A uniform cell grid over the cloud for neighbour queries within `cell`.
struct Grid {
  double cell = 1.0, xmin = 0.0, ymin = 0.0;
  long nx = 1, ny = 1;
  std::vector<long> start;  // CSR over the cells
  std::vector<long> items;
  Grid(const std::vector<Vec<2>>& x, double c) : cell(c) {
    double xmax = -std::numeric_limits<double>::infinity(), ymax = xmax;
    xmin = ymin = std::numeric_limits<double>::infinity();
    for (const auto& p : x) {
      xmin = std::min(xmin, p[0]), ymin = std::min(ymin, p[1]);
      xmax = std::max(xmax, p[0]), ymax = std::max(ymax, p[1]);
    }
    if (x.empty()) xmin = ymin = xmax = ymax = 0.0;
    nx = static_cast<long>((xmax - xmin) / cell) + 1;
    ny = static_cast<long>((ymax - ymin) / cell) + 1;
    start.assign(static_cast<std::size_t>(nx * ny + 1), 0);
    for (const auto& p : x) ++start[static_cast<std::size_t>(index(p)) + 1];
    for (std::size_t k = 1; k < start.size(); ++k) start[k] += start[k - 1];
    items.resize(x.size());
    std::vector<long> fill(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < x.size(); ++i) items[static_cast<std::size_t>(fill[static_cast<std::size_t>(index(x[i]))]++)] = static_cast<long>(i);
  }
  long ix(double v) const { return std::clamp(static_cast<long>((v - xmin) / cell), 0L, nx - 1); }
  long iy(double v) const { return std::clamp(static_cast<long>((v - ymin) / cell), 0L, ny - 1); }
  long index(const Vec<2>& p) const { return ix(p[0]) + nx * iy(p[1]); }
  // Calls f(j) for every particle in the cells around p (the 3 x 3 block).
  template <class F>
  void around(const Vec<2>& p, F&& f) const {
    const long cx = static_cast<long>(std::floor((p[0] - xmin) / cell));
    const long cy = static_cast<long>(std::floor((p[1] - ymin) / cell));
    for (long b = std::max(0L, cy - 1); b <= std::min(ny - 1, cy + 1); ++b) {
      for (long a = std::max(0L, cx - 1); a <= std::min(nx - 1, cx + 1); ++a) {
        const auto c = static_cast<std::size_t>(a + nx * b);
        for (long k = start[c]; k < start[c + 1]; ++k) f(static_cast<std::size_t>(items[static_cast<std::size_t>(k)]));
      }
    }
  }
};

}  // namespace

DepositProfile deposit_profile(const std::vector<Vec<2>>& x, double x0, double x1, double column, double base_y,
                               int gap_columns) {
  DepositProfile p;
  p.x0 = x0;
  p.column = column;
  const auto n = static_cast<std::size_t>(std::max(1L, std::lround(std::ceil((x1 - x0) / column - 1e-9))));
  p.h.assign(n, 0.0);
  p.count.assign(n, 0);
  std::vector<double> right(n, -std::numeric_limits<double>::infinity());
  std::vector<long> column_of(x.size(), -1);
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double c = std::floor((x[i][0] - x0) / column);
    if (c < 0.0 || c >= static_cast<double>(n)) continue;
    const auto k = static_cast<std::size_t>(c);
    column_of[i] = static_cast<long>(k);
    p.h[k] = std::max(p.h[k], x[i][1] - base_y);
    ++p.count[k];
    right[k] = std::max(right[k], x[i][0]);
  }
  // The connected body: columns from the first occupied one until gap_columns empty in a row.
  long last = -1, empty = 0;
  for (std::size_t k = 0; k < n; ++k) {
    if (p.count[k] > 0) {
      if (last >= 0 && empty >= gap_columns) break;
      last = static_cast<long>(k);
      empty = 0;
    } else if (last >= 0) {
      ++empty;
    }
  }
  p.front_column = static_cast<int>(last);
  if (last >= 0) p.front = right[static_cast<std::size_t>(last)];
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (column_of[i] < 0 || column_of[i] > last) ++p.detached;
  }
  for (long k = 0; k <= last; ++k) p.area += p.h[static_cast<std::size_t>(k)] * column;
  return p;
}

double profile_slope(const DepositProfile& p, std::size_t k, double half_width) {
  double sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0;
  int m = 0;
  const double xc = p.centre(k);
  for (std::size_t j = 0; j < p.h.size(); ++j) {
    const double xj = p.centre(j);
    if (std::abs(xj - xc) > half_width + 1e-9 * p.column) continue;
    sx += xj - xc, sy += p.h[j], sxx += (xj - xc) * (xj - xc), sxy += (xj - xc) * p.h[j];
    ++m;
  }
  if (m < 3) return NAN;
  return (m * sxy - sx * sy) / (m * sxx - sx * sx);
}

std::vector<char> alpha_boundary(const std::vector<Vec<2>>& x, double r,
                                 const std::function<bool(const Vec<2>&)>& solid, int samples) {
  std::vector<char> out(x.size(), 0);
  if (x.empty()) return out;
  const Grid grid(x, 2.0 * r);  // a disk covering a circle point lies within 2r of the centre
  const double r2 = r * r * (1.0 - 1e-9);
  std::vector<Vec<2>> pts(static_cast<std::size_t>(samples));
  for (std::size_t i = 0; i < x.size(); ++i) {
    for (int s = 0; s < samples; ++s) {
      const double a = 2.0 * std::numbers::pi * (s + 0.5) / samples;
      pts[static_cast<std::size_t>(s)] = x[i] + r * Vec<2>(std::cos(a), std::sin(a));
    }
    std::vector<char> covered(pts.size(), 0);
    grid.around(x[i], [&](std::size_t j) {
      if (j == i) return;
      for (std::size_t s = 0; s < pts.size(); ++s) {
        if (covered[s] == 0 && (pts[s] - x[j]).squaredNorm() < r2) covered[s] = 1;
      }
    });
    for (std::size_t s = 0; s < pts.size(); ++s) {
      if (covered[s] == 0 && !(solid && solid(pts[s]))) {
        out[i] = 1;
        break;
      }
    }
  }
  return out;
}

Disorder particle_disorder(const std::vector<Vec<2>>& x, double dx) {
  Disorder d;
  if (x.size() < 2) return d;
  const Grid grid(x, 2.0 * dx);
  std::vector<double> nn(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    double best = std::numeric_limits<double>::infinity();
    grid.around(x[i], [&](std::size_t j) {
      if (j != i) best = std::min(best, (x[j] - x[i]).squaredNorm());
    });
    // Beyond the 3 x 3 block (more than 2 dx away): report it as 2 dx + (isolated anyway).
    nn[i] = std::isfinite(best) ? std::sqrt(best) / dx : 4.0;
  }
  d.min = *std::min_element(nn.begin(), nn.end());
  d.max = *std::max_element(nn.begin(), nn.end());
  double s = 0.0, s2 = 0.0;
  for (double v : nn) {
    s += v, s2 += v * v;
    d.clustered += v < 0.5 ? 1 : 0;
    d.isolated += v > 2.0 ? 1 : 0;
  }
  const auto n = static_cast<double>(nn.size());
  d.mean = s / n;
  d.cv = std::sqrt(std::max(0.0, s2 / n - d.mean * d.mean)) / d.mean;
  return d;
}

}  // namespace rktsph::io
