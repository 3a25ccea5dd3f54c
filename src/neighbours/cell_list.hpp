#pragma once
// Cell list (method-notes §3.8, the cell linked list stored as sorted arrays): the bounding box is
// split into square cells of side equal to the search radius (or a fraction of it), and a query
// scans its own cell and the 3^Dim (5^Dim, ...) around it. Built once in the small-deformation solvers; cheap enough to
// rebuild every step when particles move.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "core/error.hpp"
#include "core/types.hpp"

namespace rktsph {

template <int Dim>
class CellList {
 public:
  /// The largest grid built: kMaxCellsPerPoint cells per point, at least kMaxCellsFloor (64 MiB
  /// of cell starts); beyond it the constructor throws SolverError.
  static constexpr double kMaxCellsPerPoint = 64.0;
  static constexpr std::size_t kMaxCellsFloor = std::size_t{1} << 24;
  /// Cells of side radius / subdivisions; a query scans the (2 subdivisions + 1)^Dim cells
  /// around its own. Finer cells test fewer candidates (2D: 9 r^2 of area with 1, 6.25 r^2 with
  /// 2) for more, shorter ranges.
  CellList(const std::vector<Vec<Dim>>& points, double radius, int subdivisions = 1);

  /// Call f(j, x_query - x_j, r) for every point j with |x_query - x_j| < radius. Cells are
  /// visited in a fixed order (x fastest) and each cell's points in increasing index, so the
  /// order of the calls is reproducible.
  template <class F>
  void for_each_neighbour(const Vec<Dim>& x, F&& f) const;

  /// One neighbour found by collect(): index, x_query - x_j and the squared distance.
  struct Hit {
    Index j;
    Vec<Dim> x_ij;
    double r2;
  };

  /// Write to buf[0, count) every point j with |x_query - x_j|^2 < r2 (r2 <= radius^2), in the
  /// order of for_each_neighbour, and return count. Branch-free: every candidate is written and
  /// the distance test only advances the count, which avoids a mispredicted branch per
  /// candidate (about a third of the candidates are hits, in no predictable pattern). `buf`
  /// only grows (to the largest candidate count), so a reused buffer allocates nothing.
  std::size_t collect(const Vec<Dim>& x, double r2, std::vector<Hit>& buf) const;

  double radius() const { return radius_; }

 private:
  std::array<int, Dim> cell_of(const Vec<Dim>& x) const;
  /// Call f(first, last) for each contiguous range [first, last) of cell-ordered points that a
  /// query at x scans (one x-row of cells each), in the fixed order of for_each_neighbour.
  template <class F>
  void for_each_range(const Vec<Dim>& x, F&& f) const;
  std::size_t cell_index(const std::array<int, Dim>& c) const {
    std::size_t idx = 0;
    for (int d = Dim - 1; d >= 0; --d)
      idx = idx * static_cast<std::size_t>(n_[static_cast<std::size_t>(d)]) +
            static_cast<std::size_t>(c[static_cast<std::size_t>(d)]);
    return idx;
  }
  double radius_;
  double side_;  // cell side
  int reach_;    // cells scanned on each side of the query's cell
  Vec<Dim> lo_;
  std::array<int, Dim> n_{};
  // The points sorted by cell (counting sort, stable: increasing index within a cell), with a
  // copy of their positions in that order. The cells of one x-row are consecutive, so a query
  // scans 3^(Dim-1) contiguous ranges instead of chasing a linked list through the particles.
  std::vector<Index> cell_start_;   // points of cell c: [cell_start_[c], cell_start_[c+1])
  std::vector<Index> index_;        // particle index, in cell order
  std::vector<Vec<Dim>> position_;  // its position, in cell order
};

template <int Dim>
CellList<Dim>::CellList(const std::vector<Vec<Dim>>& points, double radius, int subdivisions)
    : radius_(radius), side_(radius / subdivisions), reach_(subdivisions) {
  Vec<Dim> hi;
  lo_.setConstant(0.0);
  hi.setConstant(0.0);
  if (!points.empty()) {
    lo_ = points.front();
    hi = points.front();
    for (const auto& p : points) {
      if (!p.allFinite()) {
        throw SolverError(fmt::format("neighbour search: particle {} has a non-finite position (the run has gone "
                                      "unstable)",
                                      &p - points.data()));
      }
      lo_ = lo_.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
  // A grid far larger than the particle count means particles flung far apart (a run gone
  // unstable) or non-finite positions: stop with a diagnosis instead of allocating it (or
  // overflowing the cell counts).
  const double limit = std::max(static_cast<double>(kMaxCellsFloor), kMaxCellsPerPoint * static_cast<double>(points.size()));
  double cells = 1.0;
  for (int d = 0; d < Dim; ++d) {
    const double along = std::floor((hi[d] - lo_[d]) / side_) + 1.0;
    cells *= std::isfinite(along) ? std::max(1.0, along) : std::numeric_limits<double>::infinity();
  }
  if (!(cells <= limit)) {
    std::string span;
    for (int d = 0; d < Dim; ++d) span += fmt::format("{}{:.3g}", d > 0 ? " x " : "", hi[d] - lo_[d]);
    throw SolverError(fmt::format(
        "neighbour search: the {} particles span {} m, a cell grid of {:.3g} cells of side {:.3g} m: particles "
        "have been flung far apart or have non-finite positions (the run has gone unstable)",
        points.size(), span, cells, side_));
  }
  std::size_t total = 1;
  for (int d = 0; d < Dim; ++d) {
    n_[static_cast<std::size_t>(d)] = std::max(1, static_cast<int>(std::floor((hi[d] - lo_[d]) / side_)) + 1);
    total *= static_cast<std::size_t>(n_[static_cast<std::size_t>(d)]);
  }
  std::vector<Index> cell(points.size());
  cell_start_.assign(total + 1, 0);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto c = cell_index(cell_of(points[i]));
    cell[i] = static_cast<Index>(c);
    ++cell_start_[c + 1];
  }
  for (std::size_t c = 0; c < total; ++c) cell_start_[c + 1] += cell_start_[c];
  index_.resize(points.size());
  position_.resize(points.size());
  std::vector<Index> fill(cell_start_.begin(), cell_start_.end() - 1);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto k = static_cast<std::size_t>(fill[static_cast<std::size_t>(cell[i])]++);
    index_[k] = static_cast<Index>(i);
    position_[k] = points[i];
  }
}

template <int Dim>
std::array<int, Dim> CellList<Dim>::cell_of(const Vec<Dim>& x) const {
  std::array<int, Dim> c;
  for (int d = 0; d < Dim; ++d) {
    const auto du = static_cast<std::size_t>(d);
    c[du] = std::clamp(static_cast<int>(std::floor((x[d] - lo_[d]) / side_)), 0, n_[du] - 1);
  }
  return c;
}

template <int Dim>
template <class F>
void CellList<Dim>::for_each_range(const Vec<Dim>& x, F&& f) const {
  // A query outside the box is clamped to the border cells; points further than one cell
  // away from the box cannot have neighbours, which the callers' distance tests enforce.
  const auto c = cell_of(x);
  std::array<int, Dim> lo, hi;
  for (std::size_t d = 0; d < Dim; ++d) {
    lo[d] = std::max(0, c[d] - reach_);
    hi[d] = std::min(n_[d] - 1, c[d] + reach_);
  }
  // k runs over the cells in the dimensions above x; along x the cells lo..hi are one range.
  std::array<int, Dim> k = lo;
  while (true) {
    k[0] = lo[0];
    const auto first = static_cast<std::size_t>(cell_start_[cell_index(k)]);
    k[0] = hi[0];
    const auto last = static_cast<std::size_t>(cell_start_[cell_index(k) + 1]);
    f(first, last);
    std::size_t d = 1;
    while (d < Dim) {
      if (++k[d] <= hi[d]) break;
      k[d] = lo[d];
      ++d;
    }
    if (d >= Dim) return;
  }
}

template <int Dim>
template <class F>
void CellList<Dim>::for_each_neighbour(const Vec<Dim>& x, F&& f) const {
  const double r2 = radius_ * radius_;
  for_each_range(x, [&](std::size_t first, std::size_t last) {
    for (std::size_t q = first; q < last; ++q) {
      const Vec<Dim> xij = x - position_[q];
      const double d2 = xij.squaredNorm();
      if (d2 < r2) f(index_[q], xij, std::sqrt(d2));
    }
  });
}

template <int Dim>
std::size_t CellList<Dim>::collect(const Vec<Dim>& x, double r2, std::vector<Hit>& buf) const {
  std::size_t count = 0;
  for_each_range(x, [&](std::size_t first, std::size_t last) {
    if (buf.size() < count + (last - first)) buf.resize(count + (last - first));
    Hit* o = buf.data();
    for (std::size_t q = first; q < last; ++q) {
      const Vec<Dim> xij = x - position_[q];
      const double d2 = xij.squaredNorm();
      o[count] = {index_[q], xij, d2};
      count += d2 < r2 ? 1 : 0;
    }
  });
  return count;
}

}  // namespace rktsph
