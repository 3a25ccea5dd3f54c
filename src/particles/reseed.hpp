#pragma once
// Re-seeding the stress points from the node cloud (method-notes §5.2, "Regularisation",
// eqs. (5.2.1)-(5.2.4)): in large deformation the stress points drift out of the node cloud
// (a run-out front outruns them, a neck stretches between them) and the corrected operators
// lose their support. The nodes carry the persistent state (velocity, stress, history,
// displacement); the stress points only carry positions and densities from one step to the
// next (their half-step state is made again from the nodes by step 1). So the stress-point set
// can be rebuilt from the nodes at any step start without transferring any state but the
// density: one stress point at the centre of every cell of the case's lattice (its origin and
// spacing) that the nodes fill at least `fill` of, as the lattice generator placed them.
//
// The fill of a cell is the nodes' volume deposited on the cell centres with the bilinear
// (cloud-in-cell) weights, eq. (5.2.1); its density the deposited mass over the deposited
// volume, eq. (5.2.2); its material that of the nearest old stress point within the
// neighbouring cells (nodes at an interface hold one material each), else the nodes' majority. On the case's own
// undeformed lattice this gives the generator's stress points exactly in 1D and 2D: a cell of
// the body is filled 1 inside, 3/4 on a face, 9/16 at a corner; a cell beyond a face 1/4, at a
// re-entrant corner 7/16; so the default fill 1/2 separates them, and every density is the
// nodes'. In 3D a convex corner cell is filled 27/64 and one at a re-entrant edge 7/16: no
// fill separates them, and the default drops the former (its mass goes to the others).
// The new stress points' volumes are one cell each, scaled by one factor so that the set
// carries the mass it carried before, eq. (5.2.3): a uniform scale of the source volumes leaves
// the corrected operators (method-notes §3.2) unchanged, so the factor only keeps the mass.
#include <cstdint>
#include <functional>
#include <vector>

#include "core/types.hpp"
#include "particles/particle_set.hpp"

namespace rktsph {

struct ReseedOptions {
  double dx = 0.0;    // the lattice spacing, m
  double fill = 0.5;  // the least filled fraction of a cell that gets a stress point
  /// A cell less filled gets one too where a node lies within cover * dx of its centre along
  /// every axis (a thin front), at the centroid of its deposits; 0: none. Below 1/2 no node of
  /// the undeformed lattice does.
  double cover = 0.0;
  /// A cell centre where this is true gets no stress point (inside a rigid body); may be empty.
  std::function<bool(const double* x)> excluded;
};

/// What a re-seeding made.
struct ReseedResult {
  Index before = 0, after = 0;  // stress points
  double volume_factor = 1.0;   // eq. (5.2.3): the new volumes over a cell's volume
  Index excluded_cells = 0;     // filled cells left out by ReseedOptions::excluded
};

/// The stress points of the node cloud `nodes` on the lattice with origin `origin`: written
/// into `stress_points` (its particles replaced; every field zeroed; global ids continue from
/// `next_global_id`, which is advanced), with the stress points' total mass kept. Cells are
/// ordered by their lattice index (x fastest), so the result does not depend on the order of
/// the nodes' deposits or the thread count. Throws SolverError if no cell is filled.
template <int Dim>
ReseedResult reseed_stress_points(const ParticleSet<Dim>& nodes, const Vec<Dim>& origin, const ReseedOptions& options,
                                  ParticleSet<Dim>& stress_points, std::int64_t& next_global_id);

}  // namespace rktsph
