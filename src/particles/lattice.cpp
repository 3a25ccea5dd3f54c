#include "particles/lattice.hpp"

#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "core/error.hpp"

namespace rktsph {

double lattice_vertex(double origin, int i, double dx) { return origin + i * dx; }
double lattice_cell_centre(double origin, int i, double dx) { return origin + (i + 0.5) * dx; }

template <int Dim>
std::size_t Lattice<Dim>::cell_index(const std::array<int, Dim>& c) const {
  std::size_t idx = 0;
  for (int d = Dim - 1; d >= 0; --d) {
    idx = idx * static_cast<std::size_t>(cells[static_cast<std::size_t>(d)]) +
          static_cast<std::size_t>(c[static_cast<std::size_t>(d)]);
  }
  return idx;
}

template <int Dim>
int Lattice<Dim>::material_at(const std::array<int, Dim>& c) const {
  for (std::size_t d = 0; d < Dim; ++d) {
    if (c[d] < 0 || c[d] >= cells[d]) return -1;
  }
  return cell_material[cell_index(c)];
}

namespace {

int lattice_coordinate(double x, double origin, double dx, const std::string& label) {
  const double t = (x - origin) / dx;
  const double r = std::round(t);
  if (std::abs(t - r) > 1e-6) {
    throw InputError(
        fmt::format("{}: the block corner {} is not on the particle lattice (origin {}, spacing {}); "
                    "block extents must be whole multiples of the spacing",
                    label, x, origin, dx));
  }
  return static_cast<int>(r);
}

// Iterate over all integer points of a box [lo, hi) in Dim dimensions (last axis slowest).
template <int Dim, class F>
void for_each_index(const std::array<int, Dim>& lo, const std::array<int, Dim>& hi, F&& f) {
  for (std::size_t d = 0; d < Dim; ++d) {
    if (hi[d] <= lo[d]) return;
  }
  std::array<int, Dim> c = lo;
  while (true) {
    f(c);
    std::size_t d = 0;
    while (d < Dim) {
      if (++c[d] < hi[d]) break;
      c[d] = lo[d];
      ++d;
    }
    if (d == Dim) return;
  }
}

// SplitMix64 (Steele, Lea and Flood 2014): a bijective mix of 64 bits, good enough to make
// independent uniform draws from a counter.
std::uint64_t split_mix(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

}  // namespace

double jitter_unit_offset(std::uint64_t seed, int set, Index index, int axis) {
  std::uint64_t h = split_mix(seed);
  h = split_mix(h ^ static_cast<std::uint64_t>(set));
  h = split_mix(h ^ static_cast<std::uint64_t>(index));
  h = split_mix(h ^ static_cast<std::uint64_t>(axis));
  return 2.0 * (static_cast<double>(h >> 11) * 0x1.0p-53) - 1.0;  // the top 53 bits, in [-1, 1)
}

template <int Dim>
LatticeParticles<Dim> generate_lattice(const std::vector<Block<Dim>>& blocks, double dx, const Vec<Dim>& origin,
                                       const std::vector<double>& densities, const LatticeJitter& jitter) {
  if (blocks.empty()) throw InputError("the geometry has no block");
  if (!(jitter.fraction >= 0.0 && jitter.fraction < kMaxJitterFraction)) {
    throw InputError(
        fmt::format("the jitter must lie in [0, {}) spacings, got {}", kMaxJitterFraction, jitter.fraction));
  }
  LatticeParticles<Dim> out;
  out.dx = dx;
  Lattice<Dim>& lat = out.lattice;
  lat.dx = dx;
  lat.origin = origin;

  std::array<int, Dim> lo, hi;
  lo.fill(std::numeric_limits<int>::max());
  hi.fill(std::numeric_limits<int>::min());
  std::vector<std::array<int, Dim>> blo(blocks.size()), bhi(blocks.size());
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    for (std::size_t d = 0; d < Dim; ++d) {
      const int i = static_cast<int>(d);
      blo[b][d] = lattice_coordinate(blocks[b].min[i], origin[i], dx, blocks[b].label);
      bhi[b][d] = lattice_coordinate(blocks[b].max[i], origin[i], dx, blocks[b].label);
      if (bhi[b][d] <= blo[b][d]) {
        throw InputError(
            fmt::format("{}: max must exceed min by at least one spacing ({} m) "
                        "along axis {}",
                        blocks[b].label, dx, kAxisNames[d]));
      }
      lo[d] = std::min(lo[d], blo[b][d]);
      hi[d] = std::max(hi[d], bhi[b][d]);
    }
  }
  // Shift so that the lattice starts at the lowest block corner.
  for (std::size_t d = 0; d < Dim; ++d) {
    lat.origin[static_cast<int>(d)] = lattice_vertex(origin[static_cast<int>(d)], lo[d], dx);
    lat.cells[d] = hi[d] - lo[d];
  }
  std::size_t ncells = 1;
  for (std::size_t d = 0; d < Dim; ++d) ncells *= static_cast<std::size_t>(lat.cells[d]);
  lat.cell_material.assign(ncells, -1);
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    std::array<int, Dim> a, z;
    for (std::size_t d = 0; d < Dim; ++d) {
      a[d] = blo[b][d] - lo[d];
      z[d] = bhi[b][d] - lo[d];
    }
    // Later blocks overwrite earlier ones where they overlap (e.g. a footing inside soil).
    for_each_index<Dim>(
        a, z, [&](const std::array<int, Dim>& c) { lat.cell_material[lat.cell_index(c)] = blocks[b].material; });
  }

  const double cell_volume = std::pow(dx, Dim);
  const double corner_share = cell_volume / static_cast<double>(1 << Dim);
  const double face_share = cell_volume / dx / static_cast<double>(1 << (Dim - 1));

  // Stress points: one per occupied cell, at its centre (method-notes §3.3).
  std::array<int, Dim> zero{};
  zero.fill(0);
  for_each_index<Dim>(zero, lat.cells, [&](const std::array<int, Dim>& c) {
    const int m = lat.cell_material[lat.cell_index(c)];
    if (m < 0) return;
    Vec<Dim> x;
    for (std::size_t d = 0; d < Dim; ++d) {
      x[static_cast<int>(d)] = lattice_cell_centre(lat.origin[static_cast<int>(d)], c[d], dx);
    }
    out.stress_points.add(x, cell_volume, densities[static_cast<std::size_t>(m)], m);
  });

  // Nodes: every lattice vertex touching an occupied cell, with its tributary volume.

  std::array<int, Dim> nodes_hi;
  for (std::size_t d = 0; d < Dim; ++d) nodes_hi[d] = lat.cells[d] + 1;
  for_each_index<Dim>(zero, nodes_hi, [&](const std::array<int, Dim>& v) {
    double volume = 0.0, mass = 0.0;
    int material = -1;
    // faces: a node lies on the face with outward normal -e_d if every cell on its -d side
    // is empty (and on +e_d likewise); the face area is the share of the cells that bound it.
    std::array<int, 2 * Dim> present_side{};
    std::array<int, 2 * Dim> cells_side{};
    present_side.fill(0);
    cells_side.fill(0);
    const std::array<int, Dim> off_lo = [] {
      std::array<int, Dim> a;
      a.fill(-1);
      return a;
    }();
    const std::array<int, Dim> off_hi = [] {
      std::array<int, Dim> a;
      a.fill(1);
      return a;
    }();
    for_each_index<Dim>(off_lo, off_hi, [&](const std::array<int, Dim>& o) {
      std::array<int, Dim> c;
      for (std::size_t d = 0; d < Dim; ++d) c[d] = v[d] + o[d];
      const int m = lat.material_at(c);
      for (std::size_t d = 0; d < Dim; ++d) {
        const std::size_t side = 2 * d + (o[d] < 0 ? 0 : 1);
        ++cells_side[side];
        if (m >= 0) ++present_side[side];
      }
      if (m < 0) return;
      if (material < 0) material = m;
      volume += corner_share;
      mass += corner_share * densities[static_cast<std::size_t>(m)];
    });
    if (material < 0) return;
    Vec<Dim> x;
    for (std::size_t d = 0; d < Dim; ++d) {
      x[static_cast<int>(d)] = lattice_vertex(lat.origin[static_cast<int>(d)], v[d], dx);
    }
    std::uint8_t faces = 0;
    std::array<double, 2 * Dim> area{};
    area.fill(0.0);
    for (std::size_t d = 0; d < Dim; ++d) {
      // Face with outward normal -e_d: nothing on the -d side; its area is set by the +d cells.
      if (present_side[2 * d] == 0) {
        faces = static_cast<std::uint8_t>(faces | (1u << (2 * d)));
        area[2 * d] = present_side[2 * d + 1] * face_share;
      }
      if (present_side[2 * d + 1] == 0) {
        faces = static_cast<std::uint8_t>(faces | (1u << (2 * d + 1)));
        area[2 * d + 1] = present_side[2 * d] * face_share;
      }
    }
    if (faces != 0) {
      out.boundary.node.push_back(out.nodes.size());
      out.boundary.faces.push_back(faces);
      out.boundary.area.push_back(area);
    }
    out.nodes.add(x, volume, mass / volume, material);  // density mass-weighted at material interfaces
  });

  if (jitter.fraction > 0.0) {
    const double amplitude = jitter.fraction * dx;
    for (Index e = 0; e < out.stress_points.size(); ++e) {
      for (int d = 0; d < Dim; ++d)
        out.stress_points.position[static_cast<std::size_t>(e)][d] +=
            amplitude * jitter_unit_offset(jitter.seed, 1, e, d);
    }
    std::size_t next_face = 0;  // boundary.node is ascending
    for (Index i = 0; i < out.nodes.size(); ++i) {
      if (next_face < out.boundary.node.size() && out.boundary.node[next_face] == i) {
        ++next_face;
        continue;
      }
      for (int d = 0; d < Dim; ++d)
        out.nodes.position[static_cast<std::size_t>(i)][d] += amplitude * jitter_unit_offset(jitter.seed, 0, i, d);
    }
  }
  return out;
}

template struct Lattice<1>;
template struct Lattice<2>;
template struct Lattice<3>;
template LatticeParticles<1> generate_lattice<1>(const std::vector<Block<1>>&, double, const Vec<1>&,
                                                 const std::vector<double>&, const LatticeJitter&);
template LatticeParticles<2> generate_lattice<2>(const std::vector<Block<2>>&, double, const Vec<2>&,
                                                 const std::vector<double>&, const LatticeJitter&);
template LatticeParticles<3> generate_lattice<3>(const std::vector<Block<3>>&, double, const Vec<3>&,
                                                 const std::vector<double>&, const LatticeJitter&);

}  // namespace rktsph
