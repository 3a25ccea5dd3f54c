#pragma once
// Cell linked list (METHOD.md §3.8): the bounding box is split into square cells of side equal
// to the search radius, and a query scans its own cell and the 3^Dim around it. Built once in
// the small-deformation solvers; cheap enough to rebuild every step when particles move.
#include <array>
#include <cmath>
#include <vector>

#include "core/types.hpp"

namespace rktsph {

template <int Dim>
class CellList {
 public:
  CellList(const std::vector<Vec<Dim>>& points, double radius);

  /// Call f(j, x_query - x_j, r) for every point j with |x_query - x_j| < radius.
  template <class F>
  void for_each_neighbour(const Vec<Dim>& x, F&& f) const;

  double radius() const { return radius_; }

 private:
  std::array<int, Dim> cell_of(const Vec<Dim>& x) const;
  const std::vector<Vec<Dim>>* points_;
  double radius_;
  Vec<Dim> lo_;
  std::array<int, Dim> n_{};
  std::vector<Index> head_;  // first point of each cell, -1 if empty
  std::vector<Index> next_;  // next point in the same cell, -1 at the end
};

template <int Dim>
CellList<Dim>::CellList(const std::vector<Vec<Dim>>& points, double radius)
    : points_(&points), radius_(radius) {
  Vec<Dim> hi;
  lo_.setConstant(0.0);
  hi.setConstant(0.0);
  if (!points.empty()) {
    lo_ = points.front();
    hi = points.front();
    for (const auto& p : points) {
      lo_ = lo_.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
  std::size_t total = 1;
  for (int d = 0; d < Dim; ++d) {
    n_[static_cast<std::size_t>(d)] = std::max(1, static_cast<int>(std::floor((hi[d] - lo_[d]) / radius)) + 1);
    total *= static_cast<std::size_t>(n_[static_cast<std::size_t>(d)]);
  }
  head_.assign(total, -1);
  next_.assign(points.size(), -1);
  // Insert in reverse so that each cell's list runs in increasing index order: neighbour
  // lists then come out in a fixed, reproducible order.
  for (std::size_t i = points.size(); i-- > 0;) {
    const auto c = cell_of(points[i]);
    std::size_t idx = 0;
    for (int d = Dim - 1; d >= 0; --d) idx = idx * static_cast<std::size_t>(n_[static_cast<std::size_t>(d)]) + static_cast<std::size_t>(c[static_cast<std::size_t>(d)]);
    next_[i] = head_[idx];
    head_[idx] = static_cast<Index>(i);
  }
}

template <int Dim>
std::array<int, Dim> CellList<Dim>::cell_of(const Vec<Dim>& x) const {
  std::array<int, Dim> c;
  for (int d = 0; d < Dim; ++d) {
    const auto du = static_cast<std::size_t>(d);
    c[du] = std::clamp(static_cast<int>(std::floor((x[d] - lo_[d]) / radius_)), 0, n_[du] - 1);
  }
  return c;
}

template <int Dim>
template <class F>
void CellList<Dim>::for_each_neighbour(const Vec<Dim>& x, F&& f) const {
  // A query outside the box is clamped to the border cells; points further than one cell
  // away from the box cannot have neighbours, which the distance test below enforces.
  const auto c = cell_of(x);
  std::array<int, Dim> lo, hi;
  for (std::size_t d = 0; d < Dim; ++d) {
    lo[d] = std::max(0, c[d] - 1);
    hi[d] = std::min(n_[d] - 1, c[d] + 1);
  }
  std::array<int, Dim> k = lo;
  const double r2 = radius_ * radius_;
  while (true) {
    std::size_t idx = 0;
    for (int d = Dim - 1; d >= 0; --d) idx = idx * static_cast<std::size_t>(n_[static_cast<std::size_t>(d)]) + static_cast<std::size_t>(k[static_cast<std::size_t>(d)]);
    for (Index j = head_[idx]; j >= 0; j = next_[static_cast<std::size_t>(j)]) {
      const Vec<Dim> xij = x - (*points_)[static_cast<std::size_t>(j)];
      const double d2 = xij.squaredNorm();
      if (d2 < r2) f(j, xij, std::sqrt(d2));
    }
    std::size_t d = 0;
    while (d < Dim) {
      if (++k[d] <= hi[d]) break;
      k[d] = lo[d];
      ++d;
    }
    if (d == Dim) return;
  }
}

}  // namespace rktsph
