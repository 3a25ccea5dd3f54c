#pragma once
// Rigid bodies for the large-deformation scheme V2 in 2D (method-notes §4.5): a plane (half
// space), a segment or an open polyline, each with the signed distance of a point to it, the
// unit normal pointing into the soil and the rigid velocity, moving by translation either with
// prescribed velocity components (time functions) or driven by a prescribed force (load
// control: M dV/dt = F_applied + F_reaction - c_d M V). The contact of the nodes with them is
// bodies/contact.hpp. Bodies do not rotate.
#include <array>
#include <limits>
#include <string>
#include <vector>

#include "core/types.hpp"

namespace rktsph {

enum class ContactLaw { rough, smooth, coulomb, bonded };
enum class BodyShape { plane, segment, polyline };

/// A rigid body as the case describes it ([[body]], docs/case-format.md "Rigid bodies").
struct BodySpec {
  std::string name;
  std::string where;  // "case.toml, line 12" for messages
  BodyShape shape = BodyShape::plane;
  /// plane: one point on it; segment: its ends a, b; polyline: its vertices. For a segment and
  /// a polyline the soil lies on the LEFT when walking from the first point to the last.
  std::vector<Vec<2>> points;
  Vec<2> normal = Vec<2>(0.0, 1.0);  // plane only: unit normal pointing into the soil
  ContactLaw law = ContactLaw::rough;
  double friction = 0.0;  // Coulomb mu >= 0
  double adhesion = 0.0;  // Pa: the shear strength at zero normal stress, and the tension a contact bears
  /// Release on the 1-2-1 patch mean of sigma_nn (`release = "patch"`) rather than the node's
  /// own (`"node"`, the default): method-notes §4.5, "Separation".
  bool release_on_patch_mean = false;
  /// Per axis: the velocity value * function(t) (prescribed), or, where force_driven is set,
  /// the applied force value * function(t) in N/m (2D: per unit thickness).
  std::array<double, 2> velocity{0.0, 0.0};
  std::array<int, 2> velocity_function{-1, -1};
  std::array<bool, 2> force_driven{false, false};
  std::array<double, 2> force{0.0, 0.0};
  std::array<int, 2> force_function{-1, -1};
  double mass = 0.0;  // kg/m, force-driven bodies only
  bool any_force() const { return force_driven[0] || force_driven[1]; }
};

/// The position of a point relative to a body: signed distance g (> 0 on the soil side), the
/// body's unit normal n there (into the soil), the coordinate s along the body (arc length
/// from the first point; plane: along t from its point) and whether the point lies within the
/// body's extent (its projection falls on the body, and it is at most `depth` behind it).
struct BodyGap {
  double g = std::numeric_limits<double>::infinity();
  Vec<2> normal = Vec<2>::Zero();
  double s = 0.0;
  bool within = false;
};

/// The tangent of a body's frame: t = (n_y, -n_x), so that n is t turned by +90 degrees
/// (a segment from a to b has t = (b - a)/|b - a| and the soil on its left).
inline Vec<2> body_tangent(const Vec<2>& n) { return Vec<2>(n[1], -n[0]); }

class RigidBody {
 public:
  explicit RigidBody(const BodySpec& spec);

  const BodySpec& spec() const { return spec_; }
  /// The gap of x with the body translated by `offset` from where the case puts it. Points more
  /// than `depth` behind a segment or polyline are not within it (a plane is a half space).
  BodyGap gap(const Vec<2>& x, const Vec<2>& offset, double depth) const;
  /// The planes of the body's faces in front of which x lies (the segments whose extent holds
  /// the projection of x, x at most `range` in front and `depth` behind; a plane body's own
  /// plane), with the body translated by `offset`: calls f(point on the plane, unit normal into
  /// the soil, signed distance of x) for each. What the free surface's mirror images reflect
  /// across (method-notes §3.6, "Mirror images at rigid bodies").
  template <class F>
  void planes_near(const Vec<2>& x, const Vec<2>& offset, double depth, double range, F&& f) const {
    if (spec_.shape == BodyShape::plane) {
      const Vec<2> p = spec_.points[0] + offset;
      const double g = (x - p).dot(spec_.normal);
      if (g >= -depth && g <= range) f(p, spec_.normal, g);
      return;
    }
    segments_holding(x, offset, depth, [&](std::size_t k, double, double g) {
      if (g <= range) f(Vec<2>(vertex_[k] + offset), normal_[k], g);
    });
  }
  /// The ends of the body along s (a plane has none: -inf, +inf).
  double s_begin() const { return s_begin_; }
  double s_end() const { return s_end_; }

 private:
  /// The segments whose extent holds the projection of x (to 1e-9 of the body's length) with x
  /// at most `depth` behind them: f(segment k, s along it, signed distance g). A point past a
  /// convex corner, in the wedge no segment's extent covers, is held by none.
  template <class F>
  void segments_holding(const Vec<2>& x, const Vec<2>& offset, double depth, F&& f) const {
    const double tol = 1e-9 * (s_end_ - s_begin_);
    for (std::size_t k = 0; k < vertex_.size(); ++k) {
      const Vec<2> r = x - (vertex_[k] + offset);
      const double s = r.dot(tangent_[k]);
      if (s < -tol || s > length_[k] + tol) continue;
      const double g = r.dot(normal_[k]);
      if (g >= -depth) f(k, s, g);
    }
  }

  BodySpec spec_;
  std::vector<Vec<2>> vertex_, tangent_, normal_;
  std::vector<double> length_, arc_;  // per segment: its length and the arc length at its start
  double s_begin_ = -std::numeric_limits<double>::infinity();
  double s_end_ = std::numeric_limits<double>::infinity();
};

}  // namespace rktsph
