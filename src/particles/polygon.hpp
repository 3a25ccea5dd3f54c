#pragma once
// Polygon bodies (2D; docs/case-format.md "[[geometry.polygon]]", method-notes §3.9): a closed
// outer boundary, counter-clockwise, with optional holes, clockwise, discretised into the two
// particle sets of the staggered scheme:
//   stress points - one per lattice cell the body covers, at the centroid of the covered part,
//                   with its area as volume; a cell covering less than kMergeFraction of a cell
//                   gives its part to the neighbouring cell that covers most;
//   nodes         - boundary nodes on the edges (every vertex, and the edge cut into pieces of
//                   at most dx), with outward normals from the geometry and tributary lengths
//                   as face areas; and the lattice vertices inside the body at least
//                   kInteriorClearance dx from its boundary. A node's volume is the part of the
//                   body nearer to it than to any other node (within each cell, on sub-squares
//                   of dx / kVolumeSubdivision), so that the volumes sum to the area.
// Where the body covers whole cells with nodes at their four corners it is today's lattice: a
// rectangle on the lattice gives the block's particles, volumes and faces.
#include <optional>
#include <string>
#include <vector>

#include "core/types.hpp"
#include "particles/lattice.hpp"

namespace rktsph {

using Ring = std::vector<Vec<2>>;

/// One [[geometry.polygon]]: rings without a repeated closing vertex.
struct PolygonBody {
  Ring outer;               // counter-clockwise
  std::vector<Ring> holes;  // each clockwise, inside `outer`
  int material = 0;
  std::string label;  // "case.toml, line 12, key 'geometry.polygon[0]'", for error messages
  const Ring& ring(int r) const { return r == 0 ? outer : holes[static_cast<std::size_t>(r - 1)]; }
  int rings() const { return 1 + static_cast<int>(holes.size()); }
};

/// A stress point holding less than this fraction of a cell's area is merged into a neighbour.
inline constexpr double kMergeFraction = 0.5;
/// Interior lattice vertices closer than this many spacings to the boundary are left out: the
/// boundary nodes stand there.
inline constexpr double kInteriorClearance = 0.5;
/// No two nodes, and no two stress points, may be closer than this many spacings (a sharper
/// vertex or two edges closer than the spacing can resolve are refused).
inline constexpr double kMinParticleDistance = 0.25;
/// Sub-squares per cell side on which the volumes of the nodes of a cut cell are found.
inline constexpr int kVolumeSubdivision = 4;

/// Twice the signed area of a ring (positive counter-clockwise), m^2.
double ring_double_area(const Ring& ring);
/// Area of the body (outer less holes), m^2.
double polygon_area(const PolygonBody& body);

/// What is wrong with a polygon: the ring (0 outer, 1 + j hole j) and a message; empty when it
/// is valid (at least 3 distinct vertices per ring, no repeated consecutive vertex, non-zero
/// area, outer counter-clockwise, holes clockwise, no ring crossing itself or another, holes
/// inside the outer boundary and outside each other).
struct PolygonProblem {
  int ring = 0;
  std::string message;
};
std::optional<PolygonProblem> polygon_problem(const PolygonBody& body);

/// Whether x is inside the body (even-odd over its rings; a point on an edge counts either way).
bool point_in_polygon(const PolygonBody& body, const Vec<2>& x);

/// Drop a repeated closing vertex (the first given again at the end) of a ring as read.
Ring open_ring(Ring ring);

/// Nodes, stress points and boundary nodes (with their edges, geometric normals and face areas,
/// BoundaryNodes) of polygon bodies on the lattice of spacing dx through `origin`. The bodies
/// must be valid (polygon_problem) and disjoint. Throws InputError naming the body where two
/// particles would be closer than kMinParticleDistance dx, or bodies overlap.
LatticeParticles<2> generate_polygon_particles(const std::vector<PolygonBody>& bodies, double dx,
                                               const Vec<2>& origin, const std::vector<double>& densities);

}  // namespace rktsph
