#pragma once
// Measures of a 2D particle cloud that a collapse or a run-out needs (issue 13 item 3, issue 12
// item 5; docs/output.md "Run-out measures"): the deposit's surface profile h(x) over columns,
// the run-out front, an independent "visual" boundary (an alpha shape: the boundary of the union
// of disks), and a particle-disorder measure from the nearest-neighbour distances. All work on
// positions only and allocate what they return.
#include <functional>
#include <vector>

#include "core/types.hpp"

namespace rktsph::io {

/// The surface profile of a deposit resting on a base at y = base_y, over columns of width
/// `column` starting at x0: h[k] = the highest particle of column k above the base (0 for an
/// empty column). The front is the right end of the body connected to the first column: the
/// largest x of a particle in the last occupied column before `gap_columns` empty columns in a
/// row; particles beyond are `detached`.
struct DepositProfile {
  double x0 = 0.0, column = 0.0;
  std::vector<double> h;        // m, per column
  std::vector<int> count;       // particles per column
  double front = 0.0;           // m, the largest x of the connected body
  int front_column = -1;        // its column
  long detached = 0;            // particles beyond the connected body
  double area = 0.0;            // m^2, sum h[k] * column over the connected columns
  /// Column centre x.
  double centre(std::size_t k) const { return x0 + (static_cast<double>(k) + 0.5) * column; }
};
DepositProfile deposit_profile(const std::vector<Vec<2>>& x, double x0, double x1, double column, double base_y = 0.0,
                               int gap_columns = 2);

/// The slope dh/dx of a profile at column k by a least-squares line over the columns whose
/// centres lie within half_width of column k's (at least three columns, else NaN); an empty
/// column counts at h = 0, the base (a front inside the window is a drop to the base).
double profile_slope(const DepositProfile& p, std::size_t k, double half_width);

/// The alpha-shape boundary of a cloud: particle i is on it when some point of the circle of
/// radius r about it is covered neither by another particle's disk of radius r nor by
/// `solid(point)` (a rigid body the cloud rests on; may be empty). The circle is sampled at
/// `samples` points. A lattice of spacing d with r = 1.5 d flags exactly its outer rows.
std::vector<char> alpha_boundary(const std::vector<Vec<2>>& x, double r,
                                 const std::function<bool(const Vec<2>&)>& solid = {}, int samples = 64);

/// Particle disorder from the nearest-neighbour distance d_i of each particle, in units of a
/// reference spacing dx: on a regular lattice d_i = dx for all, cv = 0.
struct Disorder {
  double min = 0.0, mean = 0.0, max = 0.0;  // of d_i / dx
  double cv = 0.0;                          // standard deviation / mean of d_i
  long clustered = 0;                       // d_i < 0.5 dx
  long isolated = 0;                        // d_i > 2 dx (no neighbour within the kernel's reach)
};
Disorder particle_disorder(const std::vector<Vec<2>>& x, double dx);

}  // namespace rktsph::io
