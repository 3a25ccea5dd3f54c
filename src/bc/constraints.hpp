#pragma once
// Prescribed nodal components (method-notes §4.1, §0.3 items 1 and 8): boundary entries of the
// case (regions with a velocity, a stress or both, scaled by a time function) and the
// traction-free default on every face of the body, resolved to per-node constraints.
//
// A constraint is stored by node index, valid for one ordering: remap() follows a reordering of
// the nodes (V2 sorts them by cell), and resolve() runs on the nodes as made.
#include <cstdint>
#include <vector>

#include "bc/time_function.hpp"
#include "case/case_setup.hpp"
#include "core/types.hpp"
#include "particles/lattice.hpp"
#include "particles/particle_set.hpp"

namespace rktsph {

/// One prescribed component at a node: the velocity along an axis (component < Dim) or a
/// stress slot (component = Dim + slot), scaled by a time function, or the velocity of a rigid
/// body (body >= 0, small deformation: bodies/plates.hpp).
struct NodalConstraint {
  int component = 0;
  double value = 0.0;
  int function = -1;
  int body = -1;
  /// The traction-free default of a lattice face (a stress slot held at zero), not an entry's
  /// own component: in V2 a rigid body pressing that face makes its normal stress a reaction
  /// (StaggeredModel::released_by_contact).
  bool face_default = false;
};

template <int Dim>
class NodalConstraints {
 public:
  /// Resolve the case's boundary entries on the nodes. Throws InputError naming an entry that
  /// selects no node. With `free_faces = false` the traction-free default is kept only at nodes
  /// an entry selects (they stay on their wall); the other face nodes are left to free-surface
  /// detection (V2).
  void resolve(const std::vector<BoundarySpec<Dim>>& specs, const ParticleSet<Dim>& nodes,
               const BoundaryNodes<Dim>& boundary, double dx, bool free_faces = true);

  /// Follow ParticleSet::permute(order) of the nodes (node order[k] is now node k): V2 sorts
  /// its moving nodes, whose constraints were resolved on the positions as made and cannot be
  /// resolved again on the moved ones. constrained() stays ascending.
  void remap(const std::vector<Index>& order);

  /// The face nodes of polygon bodies made traction-free by rotation to their local frame
  /// (method-notes §3.7, §3.9): sigma.n = 0 about rotated_normals()[k] at node rotated()[k], or
  /// no in-plane stress where rotated_corners()[k] is 1. A node a boundary entry selects keeps
  /// the entry's conditions (and those of its faces normal to an axis) instead. Empty unless
  /// `free_faces` and the boundary has faces normal to no axis.
  const std::vector<Index>& rotated() const { return rotated_; }
  const std::vector<Vec<Dim>>& rotated_normals() const { return rotated_normals_; }
  const std::vector<std::uint8_t>& rotated_corners() const { return rotated_corners_; }
  /// The traction (normal, tangential; Pa, tension positive) prescribed at rotated()[k] by an
  /// entry's `traction` on an inclined edge (zero: traction-free), scaled by the time function
  /// rotated_functions()[k] (-1 = 1). At such a node the face condition is used about its normal
  /// even at a corner.
  const std::vector<Vec<Dim>>& rotated_tractions() const { return rotated_tractions_; }
  const std::vector<int>& rotated_functions() const { return rotated_functions_; }

  /// Constraints of node i: list()[k] for k in [row(i), row(i + 1)), sorted by component.
  Index begin(Index i) const { return row_[static_cast<std::size_t>(i)]; }
  Index end(Index i) const { return row_[static_cast<std::size_t>(i) + 1]; }
  const NodalConstraint& operator[](Index k) const { return list_[static_cast<std::size_t>(k)]; }
  /// Nodes with at least one constraint, ascending.
  const std::vector<Index>& constrained() const { return constrained_; }
  /// Position of node i in constrained(), or -1.
  Index constrained_row(Index i) const { return constrained_row_[static_cast<std::size_t>(i)]; }
  std::size_t bytes() const {
    return row_.size() * sizeof(Index) + list_.size() * sizeof(NodalConstraint) +
           constrained_row_.size() * sizeof(Index);
  }

 private:
  std::vector<Index> row_;
  std::vector<NodalConstraint> list_;
  std::vector<Index> constrained_;
  std::vector<Index> constrained_row_;
  std::vector<Index> rotated_;
  std::vector<Vec<Dim>> rotated_normals_;
  std::vector<std::uint8_t> rotated_corners_;
  std::vector<Vec<Dim>> rotated_tractions_;
  std::vector<int> rotated_functions_;
};

}  // namespace rktsph
