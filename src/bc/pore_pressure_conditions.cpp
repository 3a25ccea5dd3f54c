#include "bc/pore_pressure_conditions.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "core/error.hpp"
#include "neighbours/cell_list.hpp"

namespace rktsph {

template <int Dim>
PorePressureConditions resolve_pore_pressure_conditions(const std::vector<BoundarySpec<Dim>>& specs,
                                                        const ParticleSet<Dim>& nodes,
                                                        const BoundaryNodes<Dim>& boundary, double dx, double reach,
                                                        const std::string& file) {
  const auto nn = static_cast<std::size_t>(nodes.size());
  PorePressureConditions pc;
  pc.drained.assign(nn, false);
  pc.value.assign(nn, 0.0);
  pc.function.assign(nn, -1);
  const double tol = 1e-6 * dx + 1e-12;
  for (const auto& spec : specs) {
    if (!spec.pore_pressure && !spec.impermeable) continue;
    for (std::size_t i = 0; i < nn; ++i) {
      if (!spec.region.contains(nodes.position[i], tol)) continue;
      pc.drained[i] = spec.pore_pressure.has_value();
      pc.value[i] = spec.pore_pressure.value_or(0.0);
      pc.function[i] = spec.function;
    }
  }

  // The wall planes, in the order of the boundary nodes that first show them.
  const double eps = 1e-6 * dx;
  for (std::size_t b = 0; b < boundary.size(); ++b) {
    const auto i = static_cast<std::size_t>(boundary.node[b]);
    for (int bit = 0; bit < 2 * Dim; ++bit) {
      if (((boundary.faces[b] >> bit) & 1u) == 0 || pc.drained[i]) continue;
      const MirrorPlane m{bit / 2, nodes.position[i][bit / 2], bit % 2 == 0 ? -1 : 1};
      const bool known = std::any_of(pc.planes.begin(), pc.planes.end(), [&](const MirrorPlane& q) {
        return q.axis == m.axis && q.outward == m.outward && std::abs(q.coord - m.coord) < eps;
      });
      if (!known) pc.planes.push_back(m);
    }
  }
  if (pc.planes.size() > 8) {
    throw InputError(
        fmt::format("{}: the pore-pressure walls lie on {} planes; at most 8 are supported", file, pc.planes.size()));
  }

  // Which planes each node mirrors across: the face node nearest to the node's foot on the
  // plane (ties to the lowest index) must be impermeable and within half a spacing.
  pc.mirror_mask.assign(nn, 0);
  const double near = 0.5 * dx + eps;
  for (std::size_t k = 0; k < pc.planes.size(); ++k) {
    const MirrorPlane& m = pc.planes[k];
    const int bit = 2 * m.axis + (m.outward > 0 ? 1 : 0);
    std::vector<Index> face;  // the face nodes of this plane, ascending
    std::vector<Vec<Dim>> face_x;
    for (std::size_t b = 0; b < boundary.size(); ++b) {
      const Index j = boundary.node[b];
      if (((boundary.faces[b] >> bit) & 1u) == 0 ||
          std::abs(nodes.position[static_cast<std::size_t>(j)][m.axis] - m.coord) > eps) {
        continue;
      }
      face.push_back(j);
      face_x.push_back(nodes.position[static_cast<std::size_t>(j)]);
    }
    if (face.empty()) continue;
    // Slightly wider than `near`: the exact test below decides, on the distance itself.
    const CellList<Dim> cells(face_x, near * (1.0 + 1e-9));
    for (std::size_t i = 0; i < nn; ++i) {
      const Vec<Dim>& x = nodes.position[i];
      if (std::abs(x[m.axis] - m.coord) >= reach) continue;
      Vec<Dim> foot = x;
      foot[m.axis] = m.coord;
      Index best = -1;
      double best_d = std::numeric_limits<double>::infinity();
      cells.for_each_neighbour(foot, [&](Index q, const Vec<Dim>&, double) {
        const Index j = face[static_cast<std::size_t>(q)];
        const double d = (nodes.position[static_cast<std::size_t>(j)] - foot).norm();
        if (d < best_d || (d == best_d && j < best)) {
          best_d = d;
          best = j;
        }
      });
      if (best >= 0 && best_d < near && !pc.drained[static_cast<std::size_t>(best)]) {
        pc.mirror_mask[i] = static_cast<std::uint8_t>(pc.mirror_mask[i] | (1u << k));
      }
    }
  }
  return pc;
}

#define RKTSPH_INSTANTIATE(D)                                                                                         \
  template PorePressureConditions resolve_pore_pressure_conditions<D>(const std::vector<BoundarySpec<D>>&,            \
                                                                      const ParticleSet<D>&, const BoundaryNodes<D>&, \
                                                                      double, double, const std::string&);
RKTSPH_INSTANTIATE(1)
RKTSPH_INSTANTIATE(2)
RKTSPH_INSTANTIATE(3)
#undef RKTSPH_INSTANTIATE

}  // namespace rktsph
