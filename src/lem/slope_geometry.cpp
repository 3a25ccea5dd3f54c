// The soil of a limit-equilibrium analysis: membership, vertical sections and circle crossings
// of a union of polygons with holes (method-notes §9).
#include "lem/slope_geometry.hpp"

#include <algorithm>
#include <cmath>

namespace rktsph::lem {

namespace {

template <class F>
void for_each_ring(const Body& b, F&& f) {
  f(b.outer);
  for (const auto& h : b.holes) f(h);
}

// Even-odd ray cast to +x.
bool ring_parity(const std::vector<Point>& ring, Point p) {
  bool inside = false;
  const std::size_t n = ring.size();
  for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
    const Point a = ring[i], b = ring[j];
    if ((a.y > p.y) != (b.y > p.y)) {
      const double x = a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y);
      if (p.x < x) inside = !inside;
    }
  }
  return inside;
}

bool body_contains(const Body& b, Point p) {
  bool inside = false;
  for_each_ring(b, [&](const std::vector<Point>& r) { inside ^= ring_parity(r, p); });
  return inside;
}

double cross(Point o, Point a, Point b) { return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x); }

bool on_segment(Point a, Point b, Point p) {
  return std::min(a.x, b.x) <= p.x && p.x <= std::max(a.x, b.x) && std::min(a.y, b.y) <= p.y &&
         p.y <= std::max(a.y, b.y);
}

bool segments_meet(Point a, Point b, Point c, Point d) {
  const double d1 = cross(c, d, a), d2 = cross(c, d, b), d3 = cross(a, b, c), d4 = cross(a, b, d);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) return true;
  return (d1 == 0 && on_segment(c, d, a)) || (d2 == 0 && on_segment(c, d, b)) || (d3 == 0 && on_segment(a, b, c)) ||
         (d4 == 0 && on_segment(a, b, d));
}

}  // namespace

double signed_area(const std::vector<Point>& ring) {
  double a = 0.0;
  const std::size_t n = ring.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Point p = ring[i], q = ring[(i + 1) % n];
    a += p.x * q.y - q.x * p.y;
  }
  return 0.5 * a;
}

bool self_intersects(const std::vector<Point>& ring, std::size_t* first, std::size_t* second) {
  const std::size_t n = ring.size();
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      const bool adjacent = j == i + 1 || (i == 0 && j == n - 1);
      if (adjacent) continue;
      if (segments_meet(ring[i], ring[(i + 1) % n], ring[j], ring[(j + 1) % n])) {
        if (first != nullptr) *first = i;
        if (second != nullptr) *second = j;
        return true;
      }
    }
  }
  return false;
}

SoilGeometry::SoilGeometry(std::vector<Body> bodies, std::vector<RigidRegion> rigid)
    : bodies_(std::move(bodies)), rigid_(std::move(rigid)) {
  const double inf = std::numeric_limits<double>::infinity();
  lo_ = {inf, inf};
  hi_ = {-inf, -inf};
  for (const Body& b : bodies_) {
    for (const Point& p : b.outer) {
      lo_ = {std::min(lo_.x, p.x), std::min(lo_.y, p.y)};
      hi_ = {std::max(hi_.x, p.x), std::max(hi_.y, p.y)};
    }
  }
  size_ = std::max({hi_.x - lo_.x, hi_.y - lo_.y, 1e-300});
  tol_ = 1e-9 * size_;
}

bool SoilGeometry::contains(Point p) const {
  return std::any_of(bodies_.begin(), bodies_.end(), [&](const Body& b) { return body_contains(b, p); });
}

bool SoilGeometry::on_rigid(Point p) const {
  return std::any_of(rigid_.begin(), rigid_.end(), [&](const RigidRegion& r) {
    return p.x >= r.lo[0] - tol_ && p.x <= r.hi[0] + tol_ && p.y >= r.lo[1] - tol_ && p.y <= r.hi[1] + tol_;
  });
}

namespace {

// A body's sections on the vertical at x: the even-odd pairing of its edges' heights (half-open
// in x, so a vertex is counted once and a vertical edge not at all), as (lo, hi) from y up.
void body_sections(const Body& b, double x, double y, std::vector<double>& heights,
                   std::vector<std::pair<double, double>>& out) {
  heights.clear();
  for_each_ring(b, [&](const std::vector<Point>& r) {
    const std::size_t n = r.size();
    for (std::size_t i = 0; i < n; ++i) {
      const Point a = r[i], c = r[(i + 1) % n];
      if ((a.x <= x && x < c.x) || (c.x <= x && x < a.x)) heights.push_back(a.y + (x - a.x) * (c.y - a.y) / (c.x - a.x));
    }
  });
  std::sort(heights.begin(), heights.end());
  for (std::size_t k = 0; k + 1 < heights.size(); k += 2) {
    const double lo = std::max(heights[k], y), hi = heights[k + 1];
    if (hi > lo) out.emplace_back(lo, hi);
  }
}

}  // namespace

double SoilGeometry::soil_above(double x, double y) const {
  // The bodies' sections merged (overlapping or touching bodies count once).
  std::vector<std::pair<double, double>> intervals;
  std::vector<double> heights;
  for (const Body& b : bodies_) body_sections(b, x, y, heights, intervals);
  std::sort(intervals.begin(), intervals.end());
  double length = 0.0, top = -std::numeric_limits<double>::infinity();
  for (const auto& [lo, hi] : intervals) {
    const double from = std::max(lo, top);
    if (hi > from) length += hi - from;
    top = std::max(top, hi);
  }
  return length;
}

bool SoilGeometry::layered() const {
  for (const Body& b : bodies_) {
    const Body& first = bodies_.front();
    if (b.soil.has_value() != first.soil.has_value()) return true;
    if (b.soil && (b.soil->cohesion != first.soil->cohesion || b.soil->friction_angle != first.soil->friction_angle ||
                   b.soil->unit_weight != first.soil->unit_weight)) {
      return true;
    }
  }
  return false;
}

double SoilGeometry::weight_above(double x, double y, const Soil& fallback) const {
  if (!layered()) return (bodies_.empty() ? fallback : bodies_.front().soil.value_or(fallback)).unit_weight * soil_above(x, y);
  // Each piece between the sections' ends weighs with the last body covering it.
  std::vector<std::pair<double, double>> sections;
  std::vector<std::size_t> owner;
  std::vector<double> heights;
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    body_sections(bodies_[i], x, y, heights, sections);
    owner.resize(sections.size(), i);
  }
  std::vector<double> cuts;
  for (const auto& [lo, hi] : sections) {
    cuts.push_back(lo);
    cuts.push_back(hi);
  }
  std::sort(cuts.begin(), cuts.end());
  double weight = 0.0;
  for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
    const double mid = 0.5 * (cuts[k] + cuts[k + 1]);
    if (!(cuts[k + 1] > cuts[k])) continue;
    for (std::size_t j = sections.size(); j-- > 0;) {
      if (sections[j].first <= mid && mid <= sections[j].second) {
        weight += bodies_[owner[j]].soil.value_or(fallback).unit_weight * (cuts[k + 1] - cuts[k]);
        break;
      }
    }
  }
  return weight;
}

Soil SoilGeometry::soil_at(Point p, const Soil& fallback) const {
  if (!layered()) return bodies_.empty() ? fallback : bodies_.front().soil.value_or(fallback);
  const Point q{p.x, p.y + 1e-6 * size_};  // just above: a base on a seam takes the body above it
  for (std::size_t i = bodies_.size(); i-- > 0;) {
    if (body_contains(bodies_[i], q)) return bodies_[i].soil.value_or(fallback);
  }
  return fallback;
}

std::vector<Crossing> SoilGeometry::lower_crossings(Point centre, double radius) const {
  std::vector<Crossing> out;
  const double probe = 1e-6 * size_;
  for (const Body& b : bodies_) {
    for_each_ring(b, [&](const std::vector<Point>& r) {
      const std::size_t n = r.size();
      for (std::size_t i = 0; i < n; ++i) {
        const Point a = r[i], c = r[(i + 1) % n];
        const double dx = c.x - a.x, dy = c.y - a.y;
        const double fx = a.x - centre.x, fy = a.y - centre.y;
        const double qa = dx * dx + dy * dy, qb = 2.0 * (fx * dx + fy * dy), qc = fx * fx + fy * fy - radius * radius;
        const double disc = qb * qb - 4.0 * qa * qc;
        if (qa <= 0.0 || disc < 0.0) continue;
        const double sq = std::sqrt(disc);
        const double len = std::sqrt(qa);
        for (const double t : {(-qb - sq) / (2.0 * qa), (-qb + sq) / (2.0 * qa)}) {
          if (t < -tol_ / len || t > 1.0 + tol_ / len) continue;
          const Point p{a.x + t * dx, a.y + t * dy};
          if (p.y >= centre.y - tol_) continue;
          // A seam between touching bodies has soil on both sides; keep only the union's boundary.
          // The sides are probed from a point of this edge next to p but off its ends (at a vertex
          // the normal offset could land outside a sharp wedge on both sides).
          const double ts = std::clamp(t, std::min(0.5, 4.0 * probe / len), std::max(0.5, 1.0 - 4.0 * probe / len));
          const Point q{a.x + ts * dx, a.y + ts * dy};
          const Point nrm{dy / len * probe, -dx / len * probe};
          const bool in1 = contains({q.x + nrm.x, q.y + nrm.y}), in2 = contains({q.x - nrm.x, q.y - nrm.y});
          if (in1 == in2) continue;
          out.push_back({p, on_rigid(p)});
        }
      }
    });
  }
  std::sort(out.begin(), out.end(), [](const Crossing& u, const Crossing& v) { return u.p.x < v.p.x; });
  std::vector<Crossing> merged;
  for (const Crossing& c : out) {
    if (!merged.empty() && std::hypot(c.p.x - merged.back().p.x, c.p.y - merged.back().p.y) < 1e3 * tol_) {
      merged.back().rigid = merged.back().rigid || c.rigid;
      continue;
    }
    merged.push_back(c);
  }
  return merged;
}

}  // namespace rktsph::lem
