#include "case/polygon_reader.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "case/case_reader_sections.hpp"
#include "case/size_limits.hpp"
#include "core/error.hpp"

namespace rktsph::case_reading {

namespace {

Ring ring_of(const std::vector<std::vector<double>>& rows) {
  Ring ring;
  for (const auto& r : rows) ring.emplace_back(r[0], r[1]);
  return open_ring(std::move(ring));
}

}  // namespace

template <int Dim>
void read_polygons(const io::Section& geometry, const std::vector<io::Section>& entries, CaseSetup<Dim>& c) {
  if constexpr (Dim != 2) {
    entries.front().fail("", "polygon bodies are two-dimensional: give geometry.dimension = 2");
  } else {
    for (const io::Section& p : entries) {
      PolygonBody body;
      body.outer = ring_of(p.number_rows("vertices", 2));
      if (p.has("holes")) {
        for (const auto& rows : p.number_row_lists("holes", 2)) body.holes.push_back(ring_of(rows));
      } else {
        p.number("holes", 0.0);  // mark as read
      }
      body.material = material_index(c.material_names, p, "material");
      body.label = p.where();
      if (auto problem = polygon_problem(body)) p.fail(problem->ring == 0 ? "vertices" : "holes", problem->message);
      p.finish();
      c.polygons.push_back(std::move(body));
    }
    // Size guard before the lattice over the polygons is allocated: its cells, and the particles
    // estimated from the area and the perimeter.
    double cells = 1.0, area = 0.0, perimeter = 0.0;
    for (int d = 0; d < 2; ++d) {
      double lo = 1e300, hi = -1e300;
      for (const PolygonBody& b : c.polygons) {
        for (const Vec<2>& x : b.outer) {
          lo = std::min(lo, x[d]);
          hi = std::max(hi, x[d]);
        }
      }
      const double span = (hi - lo) / c.dx + 2.0;
      const double reach = std::max(std::abs(lo - c.origin[d]), std::abs(hi - c.origin[d])) / c.dx;
      geometry.require(span <= kMaxLatticeCoordinate && reach <= kMaxLatticeCoordinate, "spacing",
                       fmt::format("with a spacing of {} m the polygons reach {:.3g} cells from geometry.origin "
                                   "along {}; the lattice holds at most {:.0e}",
                                   c.dx, std::max(span, reach), kAxisNames[static_cast<std::size_t>(d)],
                                   kMaxLatticeCoordinate));
      cells *= span;
    }
    for (const PolygonBody& b : c.polygons) {
      area += polygon_area(b);
      for (int r = 0; r < b.rings(); ++r) {
        const Ring& ring = b.ring(r);
        for (std::size_t k = 0; k < ring.size(); ++k) perimeter += (ring[(k + 1) % ring.size()] - ring[k]).norm();
      }
    }
    const double particles = area / (c.dx * c.dx) + perimeter / c.dx + 1.0;
    if (auto problem = memory_problem(c, false, particles, particles, 6.0 * cells)) geometry.fail(problem->key, problem->message);
    std::vector<double> densities;
    for (const auto& m : c.materials) densities.push_back(m->density());
    LatticeParticles<2> lat = generate_polygon_particles(c.polygons, c.dx, c.origin, densities);
    typename CaseSetup<Dim>::ImportedParticles imported;
    imported.nodes = std::move(lat.nodes);
    imported.stress_points = std::move(lat.stress_points);
    imported.boundary = std::move(lat.boundary);
    imported.faces_given = true;
    c.imported = std::move(imported);
  }
}

template <int Dim>
bool read_boundary_edge(const io::Section& b, const CaseSetup<Dim>& c, BoundarySpec<Dim>& spec) {
  if (!b.has("polygon") && !b.has("edge") && !b.has("hole")) {
    b.integer("polygon", 0);  // mark as read
    b.integer("edge", 0);
    b.integer("hole", 0);
    return false;
  }
  if (c.polygons.empty()) b.fail(b.has("edge") ? "edge" : "polygon", "selects a polygon edge, but the geometry has no [[geometry.polygon]]");
  for (int d = 0; d < Dim; ++d) {
    const std::string axis(kAxisNames[static_cast<std::size_t>(d)]);
    if (b.has(axis)) b.fail(axis, "give either a polygon edge (polygon, edge) or a region (x, y), not both");
  }
  const std::int64_t polygon = b.integer("polygon", 0);
  const auto polygons = static_cast<std::int64_t>(c.polygons.size());
  b.require(polygon >= 0 && polygon < polygons, "polygon",
            fmt::format("no polygon {}: the geometry has {} (numbered from 0 in the order of [[geometry.polygon]])",
                        polygon, polygons));
  const PolygonBody& body = c.polygons[static_cast<std::size_t>(polygon)];
  if (!b.has("edge")) b.fail("", "a polygon's boundary entry needs the edge it acts on (edge = k)");
  const std::int64_t hole = b.integer("hole", -1);
  const auto holes = static_cast<std::int64_t>(body.holes.size());
  if (b.has("hole")) {
    b.require(hole >= 0 && hole < holes, "hole",
              fmt::format("polygon {} has no hole {}: it has {} (numbered from 0)", polygon, hole, holes));
  }
  const int ring = static_cast<int>(hole + 1);
  const Ring& r = body.ring(ring);
  const std::int64_t edge = b.integer("edge");
  const auto edges = static_cast<std::int64_t>(r.size());
  b.require(edge >= 0 && edge < edges, "edge",
            fmt::format("{} of polygon {} has no edge {}: it has {} edges, 0 to {} (edge k runs from vertex k to "
                        "vertex k + 1)",
                        ring == 0 ? std::string("the outer boundary") : fmt::format("hole {}", hole), polygon, edge,
                        edges, edges - 1));
  spec.edge = EdgeRef{static_cast<int>(polygon), ring, static_cast<int>(edge)};
  const Vec<2>& a = r[static_cast<std::size_t>(edge)];
  const Vec<2>& e = r[static_cast<std::size_t>((edge + 1) % edges)];
  for (std::size_t d = 0; d < static_cast<std::size_t>(Dim) && d < 2; ++d) {
    spec.region.lo[d] = std::min(a[static_cast<int>(d)], e[static_cast<int>(d)]);
    spec.region.hi[d] = std::max(a[static_cast<int>(d)], e[static_cast<int>(d)]);
    spec.region.bounded[d] = true;
  }
  return true;
}

template void read_polygons<1>(const io::Section&, const std::vector<io::Section>&, CaseSetup<1>&);
template void read_polygons<2>(const io::Section&, const std::vector<io::Section>&, CaseSetup<2>&);
template void read_polygons<3>(const io::Section&, const std::vector<io::Section>&, CaseSetup<3>&);
template bool read_boundary_edge<1>(const io::Section&, const CaseSetup<1>&, BoundarySpec<1>&);
template bool read_boundary_edge<2>(const io::Section&, const CaseSetup<2>&, BoundarySpec<2>&);
template bool read_boundary_edge<3>(const io::Section&, const CaseSetup<3>&, BoundarySpec<3>&);

}  // namespace rktsph::case_reading
