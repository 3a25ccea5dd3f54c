#pragma once
// The soil of a limit-equilibrium analysis (method-notes §9): a union of bodies, each a closed
// polygon with optional holes, and the rigid regions (boxes) a slip surface may not cross.
// Everything the slices need is asked of the union by point membership and vertical
// sections, so overlapping or touching bodies (a union of blocks) need no outline merging.
#include <array>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace rktsph::lem {

struct Point {
  double x = 0.0;
  double y = 0.0;
};

/// The Mohr-Coulomb strength and weight of a soil: tau_f = c + sigma_n tan(phi).
struct Soil {
  double cohesion = 0.0;        // Pa
  double friction_angle = 0.0;  // rad
  double unit_weight = 0.0;     // N/m^3
};

/// One body: its outer ring (counter-clockwise, not repeated at the end) and its holes.
struct Body {
  std::vector<Point> outer;
  std::vector<std::vector<Point>> holes;
  std::string name;  // for messages and the plot
  /// Its own soil (a layered slope); absent: the soil the analysis is given.
  std::optional<Soil> soil;
  std::string material;  // the soil's [materials.NAME], for the output
};

/// A region a slip surface may not cross: a box, each axis bounded or not (a [[boundary]] entry
/// with a velocity condition, e.g. the fixed base y = [0, 0] or rollers x = [40, 40]).
struct RigidRegion {
  std::array<double, 2> lo{-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  std::array<double, 2> hi{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  std::string name;
};

/// A crossing of a circle with the boundary of the soil.
struct Crossing {
  Point p;
  bool rigid = false;  // on a rigid region
};

class SoilGeometry {
 public:
  SoilGeometry(std::vector<Body> bodies, std::vector<RigidRegion> rigid);

  const std::vector<Body>& bodies() const { return bodies_; }
  const std::vector<RigidRegion>& rigid_regions() const { return rigid_; }
  double x_min() const { return lo_.x; }
  double x_max() const { return hi_.x; }
  double y_min() const { return lo_.y; }
  double y_max() const { return hi_.y; }
  /// The length scale of the soil (the larger side of its bounding box).
  double size() const { return size_; }

  /// Inside the union of the bodies (even-odd rule per body, holes excluded).
  bool contains(Point p) const;
  /// Length of soil on the vertical line at x above the height y (eq. (9.4)).
  double soil_above(double x, double y) const;
  /// Weight per unit width of the soil on the vertical line at x above y: each body's length
  /// times its unit weight (`fallback` for a body without a soil). Where bodies overlap the
  /// later one counts, as the particle case's blocks give the later block's material.
  double weight_above(double x, double y, const Soil& fallback) const;
  /// The soil just above p (a slice's base): the last body containing it; `fallback` where that
  /// body has no soil or none contains it.
  Soil soil_at(Point p, const Soil& fallback) const;
  /// Whether the bodies carry more than one soil.
  bool layered() const;
  /// The crossings of the circle (centre, radius) with the boundary of the union whose height
  /// is below the centre (its lower half), seams between touching bodies left out, coincident
  /// crossings (a vertex) merged; sorted by x.
  std::vector<Crossing> lower_crossings(Point centre, double radius) const;
  bool on_rigid(Point p) const;

 private:
  std::vector<Body> bodies_;
  std::vector<RigidRegion> rigid_;
  Point lo_, hi_;
  double size_ = 1.0;
  double tol_ = 1e-9;
};

/// Signed area of a ring (> 0 counter-clockwise).
double signed_area(const std::vector<Point>& ring);
/// Whether two non-adjacent edges of the ring cross or touch (a self-intersecting polygon);
/// `first`/`second` receive the edges' indices (edge i runs from vertex i to i+1).
bool self_intersects(const std::vector<Point>& ring, std::size_t* first, std::size_t* second);

}  // namespace rktsph::lem
