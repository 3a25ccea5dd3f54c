// Bishop's simplified method of slices and the critical-circle search (method-notes §9).
#include "lem/bishop.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rktsph::lem {

const char* rejection_name(Rejection r) {
  switch (r) {
    case Rejection::none: return "none";
    case Rejection::no_soil: return "no_soil";
    case Rejection::extends_above: return "extends_above";
    case Rejection::not_two_crossings: return "not_two_crossings";
    case Rejection::rigid: return "rigid";
    case Rejection::no_driving: return "no_driving";
    case Rejection::not_converged: return "not_converged";
  }
  return "unknown";
}

double fellenius_factor(const std::vector<Slice>& slices) {
  // Eq. (9.3): F = sum(c l + W cos(alpha) tan(phi)) / sum(W sin(alpha)).
  double resisting = 0.0, driving = 0.0;
  for (const Slice& s : slices) {
    resisting += s.cohesion * s.base_length + s.weight * std::cos(s.alpha) * s.tan_phi;
    driving += s.weight * std::sin(s.alpha);
  }
  return resisting / driving;
}

double fellenius_factor(const std::vector<Slice>& slices, const Soil& soil) {
  std::vector<Slice> with = slices;
  for (Slice& s : with) {
    s.cohesion = soil.cohesion;
    s.tan_phi = std::tan(soil.friction_angle);
  }
  return fellenius_factor(with);
}

std::optional<double> bishop_factor(std::vector<Slice>& slices, const BishopOptions& options, int* iterations,
                                    std::size_t* limited) {
  double driving = 0.0;
  for (const Slice& s : slices) driving += s.weight * std::sin(s.alpha);
  if (!(driving > 0.0)) return std::nullopt;
  double F = fellenius_factor(slices);
  if (!(F > 0.0) || !std::isfinite(F)) F = 1.0;
  for (int it = 1; it <= options.max_iterations; ++it) {
    // Eq. (9.2) with m_alpha of eq. (9.5) at the previous F; the floor of eq. (9.6) only on the
    // toe side (alpha < 0), where friction lowers m_alpha.
    double resisting = 0.0;
    std::size_t n_limited = 0;
    for (Slice& s : slices) {
      double m = std::cos(s.alpha) + std::sin(s.alpha) * s.tan_phi / F;
      s.m_alpha_limited = s.alpha < 0.0 && m < options.m_alpha_floor;
      if (s.m_alpha_limited) {
        m = options.m_alpha_floor;
        ++n_limited;
      }
      s.m_alpha = m;
      resisting += (s.cohesion * s.width + s.weight * s.tan_phi) / m;
    }
    const double next = resisting / driving;
    const bool done = std::abs(next - F) <= options.tolerance * next;
    F = next;
    if (done) {
      if (iterations != nullptr) *iterations = it;
      if (limited != nullptr) *limited = n_limited;
      return F;
    }
  }
  return std::nullopt;
}

std::optional<double> bishop_factor(std::vector<Slice>& slices, const Soil& soil, const BishopOptions& options,
                                    int* iterations, std::size_t* limited) {
  for (Slice& s : slices) {
    s.cohesion = soil.cohesion;
    s.tan_phi = std::tan(soil.friction_angle);
  }
  return bishop_factor(slices, options, iterations, limited);
}

CircleResult evaluate_circle(const SoilGeometry& g, const Soil& soil, const Circle& circle,
                             const BishopOptions& options, bool keep_slices) {
  CircleResult out;
  const Point c = circle.centre;
  const double R = circle.radius;
  if (!(R > 0.0)) {
    out.rejection = Rejection::no_soil;
    return out;
  }
  // The slip surface is the lower half of the circle: its ends at the centre's height must be
  // out of the soil, else the crossings would lie on the upper half.
  if (g.contains({c.x - R, c.y}) || g.contains({c.x + R, c.y})) {
    out.rejection = Rejection::extends_above;
    return out;
  }
  const auto crossings = g.lower_crossings(c, R);
  if (crossings.size() < 2) {
    out.rejection = Rejection::no_soil;
    return out;
  }
  if (crossings.size() != 2) {
    out.rejection = Rejection::not_two_crossings;
    return out;
  }
  if (crossings[0].rigid || crossings[1].rigid) {
    out.rejection = Rejection::rigid;
    return out;
  }
  const double xa = crossings[0].p.x, xb = crossings[1].p.x;
  const double x_mid = 0.5 * (xa + xb);
  const double y_mid = c.y - std::sqrt(std::max(0.0, R * R - (x_mid - c.x) * (x_mid - c.x)));
  if (xb - xa < 1e-6 * g.size() || !g.contains({x_mid, y_mid})) {
    out.rejection = Rejection::no_soil;
    return out;
  }
  const int n = options.slices;
  const double b = (xb - xa) / n;
  std::vector<Slice> slices(static_cast<std::size_t>(n));
  double moment = 0.0;  // sum of W (x - x_c): > 0 turns the mass clockwise (it slides towards -x)
  for (int i = 0; i < n; ++i) {
    Slice& s = slices[static_cast<std::size_t>(i)];
    s.x = xa + (i + 0.5) * b;
    s.width = b;
    const double dx = s.x - c.x;
    s.base_y = c.y - std::sqrt(std::max(0.0, R * R - dx * dx));
    s.height = g.soil_above(s.x, s.base_y);  // eq. (9.4)
    s.weight = b * g.weight_above(s.x, s.base_y, soil);
    const Soil base = g.soil_at({s.x, s.base_y}, soil);
    s.cohesion = base.cohesion;
    s.tan_phi = std::tan(base.friction_angle);
    s.alpha = std::asin(std::clamp(dx / R, -1.0, 1.0));
    moment += s.weight * dx;
  }
  if (!(std::abs(moment) > 1e-12 * soil.unit_weight * g.size() * g.size() * g.size())) {
    out.rejection = Rejection::no_driving;
    return out;
  }
  // Eq. (9.1): alpha measured so that the weight drives, sum(W sin(alpha)) > 0.
  const double sense = moment > 0.0 ? 1.0 : -1.0;
  out.direction = moment > 0.0 ? -1 : 1;
  for (Slice& s : slices) {
    s.alpha *= sense;
    s.base_length = s.width / std::cos(s.alpha);
  }
  const auto F = bishop_factor(slices, options, &out.iterations, &out.limited_slices);
  if (!F) {
    out.rejection = Rejection::not_converged;
    return out;
  }
  out.factor = *F;
  out.fellenius = fellenius_factor(slices);
  const Point left = crossings[0].p, right = crossings[1].p;
  out.entry = out.direction < 0 ? right : left;
  out.exit = out.direction < 0 ? left : right;
  if (keep_slices) out.slices = std::move(slices);
  return out;
}

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct Best {
  double factor = kInf;
  double radius = 0.0;
};

// The least F over the radii of circles centred at c: a scan, then a golden-section search in
// the bracket around the scan's best radius (an invalid circle counts as F = infinity, so the
// refinement stays in the valid range and closes on its edge where the least F lies there,
// e.g. a toe circle on a rigid base).
Best best_radius(const SoilGeometry& g, const Soil& soil, Point c, const SearchOptions& o, std::size_t& evaluated,
                 std::size_t& valid) {
  auto F = [&](double R) {
    ++evaluated;
    const CircleResult r = evaluate_circle(g, soil, {c, R}, o.bishop);
    if (!r.valid()) return kInf;
    ++valid;
    return r.factor;
  };
  double r_far = 0.0;
  for (const Body& b : g.bodies()) {
    for (const Point& p : b.outer) r_far = std::max(r_far, std::hypot(p.x - c.x, p.y - c.y));
  }
  const double r_near = std::max(0.0, c.y - g.y_max());
  if (!(r_far > r_near)) return {};
  const int n = o.radii;
  const double dr = (r_far - r_near) / (n + 1);
  Best best;
  int k_best = -1;
  for (int k = 1; k <= n; ++k) {
    const double R = r_near + k * dr;
    const double f = F(R);
    if (f < best.factor) {
      best = {f, R};
      k_best = k;
    }
  }
  if (k_best < 0) return best;
  double a = r_near + (k_best - 1) * dr, bb = r_near + (k_best + 1) * dr;
  const double phi = 0.5 * (std::sqrt(5.0) - 1.0);
  double x1 = bb - phi * (bb - a), x2 = a + phi * (bb - a);
  double f1 = F(x1), f2 = F(x2);
  for (int it = 0; it < 40 && bb - a > 1e-7 * g.size(); ++it) {
    const bool keep_left = f1 < f2 || (f1 == kInf && f2 == kInf && best.radius < 0.5 * (a + bb));
    if (keep_left) {
      bb = x2;
      x2 = x1;
      f2 = f1;
      x1 = bb - phi * (bb - a);
      f1 = F(x1);
    } else {
      a = x1;
      x1 = x2;
      f1 = f2;
      x2 = a + phi * (bb - a);
      f2 = F(x2);
    }
    if (f1 < best.factor) best = {f1, x1};
    if (f2 < best.factor) best = {f2, x2};
  }
  return best;
}

}  // namespace

SearchResult search_critical_circle(const SoilGeometry& g, const Soil& soil, const SearchOptions& o) {
  SearchResult out;
  const double H = g.y_max() - g.y_min();
  double x_lo = o.x_lo.value_or(g.x_min() - 3.0 * H), x_hi = o.x_hi.value_or(g.x_max() + 3.0 * H);
  double y_lo = o.y_lo.value_or(g.y_min() + 0.5 * H), y_hi = o.y_hi.value_or(g.y_max() + 3.0 * H);
  out.x_lo = x_lo;
  out.x_hi = x_hi;
  out.y_lo = y_lo;
  out.y_hi = y_hi;
  const int n = std::max(o.grid, 3);
  GridPoint best{{0, 0}, kInf, 0.0};
  for (int level = 0; level < o.levels; ++level) {
    const double hx = (x_hi - x_lo) / (n - 1), hy = (y_hi - y_lo) / (n - 1);
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const Point c{x_lo + i * hx, y_lo + j * hy};
        const Best b = best_radius(g, soil, c, o, out.circles_evaluated, out.circles_valid);
        if (level == 0) out.first_grid.push_back({c, b.factor, b.radius});
        if (b.factor < best.factor) best = {c, b.factor, b.radius};
      }
    }
    out.final_spacing_x = hx;
    out.final_spacing_y = hy;
    if (best.factor == kInf) break;
    // The next level: a box four spacings wide around the best centre so far.
    x_lo = best.centre.x - 2.0 * hx;
    x_hi = best.centre.x + 2.0 * hx;
    y_lo = best.centre.y - 2.0 * hy;
    y_hi = best.centre.y + 2.0 * hy;
  }
  if (best.factor < kInf) {
    out.circle = {best.centre, best.radius};
    out.critical = evaluate_circle(g, soil, out.circle, o.bishop, true);
  } else {
    out.critical.rejection = Rejection::no_soil;
  }
  return out;
}

}  // namespace rktsph::lem
