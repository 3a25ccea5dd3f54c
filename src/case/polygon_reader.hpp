#pragma once
// [[geometry.polygon]] (docs/case-format.md "Polygon bodies"): polygon bodies read, validated
// and discretised (particles/polygon.hpp); and the edge of a polygon that a [[boundary]] entry
// selects. Internal to src/case; every error names the file, the line and the key.
#include <vector>

#include "case/case_setup.hpp"
#include "io/section.hpp"

namespace rktsph::case_reading {

/// Read the entries into c.polygons and their particles into c.imported (faces given). Needs
/// c.dx, c.origin and the materials; `geometry` is the [geometry] table, for the size guard
/// (case/size_limits.hpp) at its spacing before any particle is made.
template <int Dim>
void read_polygons(const io::Section& geometry, const std::vector<io::Section>& entries, CaseSetup<Dim>& c);

/// A [[boundary]] entry's keys polygon, edge and hole (optional): the edge it selects (checked
/// against c.polygons) and, in `region`, the edge's bounding box. False when the entry has none
/// of these keys (it selects a region).
template <int Dim>
bool read_boundary_edge(const io::Section& b, const CaseSetup<Dim>& c, BoundarySpec<Dim>& spec);

}  // namespace rktsph::case_reading
