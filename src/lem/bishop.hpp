#pragma once
// Bishop's simplified method of slices on circular slip surfaces, and the search for the
// critical circle (method-notes §9). Dry soil (no pore pressure), no external loads, no
// tension crack.
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "lem/slope_geometry.hpp"

namespace rktsph::lem {

struct Circle {
  Point centre;
  double radius = 0.0;
};

struct Slice {
  double x = 0.0;           // m, centre of the slice
  double width = 0.0;       // m
  double base_y = 0.0;      // m, height of the base at x
  double height = 0.0;      // m, soil above the base at x
  double alpha = 0.0;       // rad, base inclination: > 0 where the base descends in the direction of sliding
  double weight = 0.0;      // N/m
  double cohesion = 0.0;    // Pa, of the soil at the base
  double tan_phi = 0.0;     // of the soil at the base
  double base_length = 0.0; // m, width / cos(alpha)
  double m_alpha = 0.0;     // cos(alpha) + sin(alpha) tan(phi) / F, after the safeguard
  bool m_alpha_limited = false;
};

/// Why a circle gives no factor of safety (the search skips it).
enum class Rejection {
  none,
  no_soil,            // the circle misses the soil or only grazes it
  extends_above,      // its horizontal extremes are in the soil (the slip surface would be its upper half)
  not_two_crossings,  // its lower half leaves and re-enters the soil (the slip mass is not one piece)
  rigid,              // it enters or leaves through a rigid region (fixed base, rollers)
  no_driving,         // the weight has no moment about the centre
  not_converged,      // the fixed-point iteration did not converge
};
const char* rejection_name(Rejection r);

struct CircleResult {
  Rejection rejection = Rejection::none;
  double factor = 0.0;      // Bishop's simplified F
  double fellenius = 0.0;   // the ordinary method's F on the same slices
  Point entry, exit;        // the crossings: entry upslope (the crest side), exit downslope (the toe side)
  int direction = 0;        // +1: the mass slides towards +x, -1: towards -x
  int iterations = 0;
  std::size_t limited_slices = 0;  // slices whose m_alpha was raised to the floor
  std::vector<Slice> slices;
  bool valid() const { return rejection == Rejection::none; }
};

struct BishopOptions {
  int slices = 50;
  double m_alpha_floor = 0.2;  // method-notes eq. (9.6)
  double tolerance = 1e-7;     // relative change of F that ends the iteration
  int max_iterations = 200;
};

/// Slices (equal widths between the entry and the exit) and F of one circle (eqs. (9.1)-(9.6)).
/// `soil` is that of the bodies without their own; a slice weighs each body above its base with
/// that body's unit weight and takes c and phi of the body its base lies in.
CircleResult evaluate_circle(const SoilGeometry& soil_geometry, const Soil& soil, const Circle& circle,
                             const BishopOptions& options, bool keep_slices = false);

/// The F of given slices by Bishop's simplified method, eq. (9.2), by fixed-point iteration from
/// the ordinary method's value, with each slice's own cohesion and tan_phi; fills each slice's
/// m_alpha. `iterations` receives the count.
std::optional<double> bishop_factor(std::vector<Slice>& slices, const BishopOptions& options, int* iterations,
                                    std::size_t* limited);
/// The same with one soil for every slice (its c and phi written into them).
std::optional<double> bishop_factor(std::vector<Slice>& slices, const Soil& soil, const BishopOptions& options,
                                    int* iterations, std::size_t* limited);
/// The ordinary method of slices (Fellenius), eq. (9.3), with each slice's cohesion and tan_phi.
double fellenius_factor(const std::vector<Slice>& slices);
/// The same with one soil for every slice.
double fellenius_factor(const std::vector<Slice>& slices, const Soil& soil);

struct SearchOptions {
  BishopOptions bishop;
  int grid = 21;         // centres per axis of each level
  int radii = 30;        // radii scanned per centre before the golden-section refinement
  int levels = 5;        // the first grid and four refinements around the best centre
  // The first level's box of centres; absent: x from three soil heights H before the soil to 3H
  // past it, y from the soil's mid-height to 3H above its top (a vertical cut's critical
  // centre lies 1.4H beyond the face and 1.2H above the crest).
  std::optional<double> x_lo, x_hi, y_lo, y_hi;
};

struct GridPoint {
  Point centre;
  double factor = 0.0;  // the least F over the radii at this centre; infinity if none valid
  double radius = 0.0;
};

struct SearchResult {
  CircleResult critical;
  Circle circle;
  std::vector<GridPoint> first_grid;  // the first level, for the contour plot
  double x_lo = 0, x_hi = 0, y_lo = 0, y_hi = 0;  // the first level's box
  double final_spacing_x = 0, final_spacing_y = 0;  // the last level's centre spacing
  std::size_t circles_evaluated = 0;
  std::size_t circles_valid = 0;
  bool found() const { return critical.valid(); }
};

SearchResult search_critical_circle(const SoilGeometry& soil_geometry, const Soil& soil, const SearchOptions& options);

}  // namespace rktsph::lem
