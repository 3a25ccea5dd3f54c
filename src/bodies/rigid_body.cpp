#include "bodies/rigid_body.hpp"

#include <cmath>

#include "core/error.hpp"

namespace rktsph {

RigidBody::RigidBody(const BodySpec& spec) : spec_(spec) {
  if (spec_.shape == BodyShape::plane) {
    if (spec_.points.size() != 1) throw InputError(spec_.where + ": a plane needs one point");
    const double len = spec_.normal.norm();
    if (!(len > 0.0)) throw InputError(spec_.where + ": a plane needs a non-zero normal");
    spec_.normal /= len;
    return;
  }
  if (spec_.points.size() < 2) throw InputError(spec_.where + ": a body needs at least one segment (two points)");
  double arc = 0.0;
  for (std::size_t k = 0; k + 1 < spec_.points.size(); ++k) {
    const Vec<2> d = spec_.points[k + 1] - spec_.points[k];
    const double len = d.norm();
    if (!(len > 0.0)) throw InputError(spec_.where + ": two consecutive points of the body coincide");
    vertex_.push_back(spec_.points[k]);
    tangent_.push_back(d / len);
    normal_.emplace_back(-d[1] / len, d[0] / len);  // the soil on the left of a -> b
    length_.push_back(len);
    arc_.push_back(arc);
    arc += len;
  }
  s_begin_ = 0.0;
  s_end_ = arc;
}

BodyGap RigidBody::gap(const Vec<2>& x, const Vec<2>& offset, double depth) const {
  BodyGap out;
  if (spec_.shape == BodyShape::plane) {
    const Vec<2> r = x - (spec_.points[0] + offset);
    out.normal = spec_.normal;
    out.g = r.dot(spec_.normal);
    out.s = r.dot(body_tangent(spec_.normal));
    out.within = true;
    return out;
  }
  // The segment whose extent holds the projection of x and that is nearest (a concave corner
  // has two; the one nearer decides). A point past a convex corner, in the wedge that no
  // segment's extent covers, is within no segment: it cannot be touching the body there.
  double best = std::numeric_limits<double>::infinity();
  segments_holding(x, offset, depth, [&](std::size_t k, double s, double g) {
    if (std::abs(g) >= best) return;
    best = std::abs(g);
    out.g = g;
    out.normal = normal_[k];
    out.s = arc_[k] + s;
    out.within = true;
  });
  return out;
}

}  // namespace rktsph
