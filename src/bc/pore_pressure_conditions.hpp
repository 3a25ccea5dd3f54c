#pragma once
// Pore-pressure conditions of the saturated schemes (method-notes §4.1): drained faces (p_w
// prescribed, Dirichlet rows of the pressure equation) and impermeable walls (dp_w/dn = 0, by
// mirror images across the wall planes, operators/laplacian.hpp). Resolved from the case's
// boundary entries on the nodes, again whenever the nodes are reordered.
#include <cstdint>
#include <vector>

#include "case/case_setup.hpp"
#include "operators/laplacian.hpp"
#include "particles/lattice.hpp"
#include "particles/particle_set.hpp"

namespace rktsph {

struct PorePressureConditions {
  std::vector<bool> drained;              // per node: p_w prescribed
  std::vector<double> value;              // prescribed p_w at drained nodes, Pa
  std::vector<int> function;              // its time function (-1: constant)
  std::vector<MirrorPlane> planes;        // impermeable wall planes (at most 8)
  std::vector<std::uint8_t> mirror_mask;  // per node, bit k: planes[k] mirrors for this node
};

/// Drained and impermeable entries (a later entry wins), and the wall planes: every face plane
/// of the body that holds a non-drained boundary node. A node mirrors across a plane when the
/// boundary node nearest to its projection on the plane is an impermeable node of that face (a
/// footing on a drained surface mirrors only under the footing). `reach` is the kernel support.
template <int Dim>
PorePressureConditions resolve_pore_pressure_conditions(const std::vector<BoundarySpec<Dim>>& specs,
                                                        const ParticleSet<Dim>& nodes,
                                                        const BoundaryNodes<Dim>& boundary, double dx, double reach,
                                                        const std::string& file);

}  // namespace rktsph
