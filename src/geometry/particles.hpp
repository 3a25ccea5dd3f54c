#pragma once
// The two interleaved particle sets of the staggered scheme (METHOD.md §3.3):
//   nodes    - the vertices of a cell lattice; they carry the persistent state at t^n;
//   elements - one per lattice cell, at its centre; they carry the half-step state t^{n+1/2}.
// Bodies are unions of axis-aligned blocks on one lattice of spacing dx. A node's volume is its
// tributary volume (dx^d inside, half on an edge, a quarter at a corner), so that each set
// carries the whole mass on its own.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/types.hpp"

namespace rktsph {

template <int Dim>
struct ParticleSet {
  std::vector<Vec<Dim>> position;  // m
  std::vector<double> volume;      // m^Dim (per unit thickness in 2D, per unit area in 1D)
  std::vector<double> density;     // kg/m^3
  std::vector<int> material;       // index into the case's material list

  Index size() const { return static_cast<Index>(position.size()); }
  double mass(Index i) const { return volume[static_cast<std::size_t>(i)] * density[static_cast<std::size_t>(i)]; }
};

/// A block of cells of one material: [min, max] must lie on the lattice.
template <int Dim>
struct Block {
  Vec<Dim> min;
  Vec<Dim> max;
  int material = 0;
  std::string label;  // for error messages ("geometry.block[0]")
};

/// The lattice of cells that holds the body; cell c occupies [origin + c*dx, origin + (c+1)*dx].
template <int Dim>
struct Lattice {
  double dx = 0.0;
  Vec<Dim> origin;
  std::array<int, Dim> cells{};     // cells per axis of the bounding box
  std::vector<int> cell_material;   // -1 where there is no material

  std::size_t cell_index(const std::array<int, Dim>& c) const;
  /// Material of a cell, or -1 outside the lattice or for an empty cell.
  int material_at(const std::array<int, Dim>& c) const;
};

/// Lattice boundary information per node: which faces of the body the node lies on.
/// Bit 2d is the face with outward normal -e_d, bit 2d+1 the face with outward normal +e_d.
template <int Dim>
struct NodeBoundary {
  std::vector<std::uint8_t> faces;               // per node
  std::vector<std::array<double, 2 * Dim>> area;  // tributary area of each face, m^(Dim-1)
};

template <int Dim>
struct Discretisation {
  double dx = 0.0;
  Lattice<Dim> lattice;
  ParticleSet<Dim> nodes;
  ParticleSet<Dim> elements;
  NodeBoundary<Dim> boundary;
  std::vector<std::array<int, Dim>> node_lattice_index;  // integer lattice coordinates
};

/// Build nodes and elements from blocks (all on one lattice of spacing dx starting at
/// `origin`). Throws InputError naming the block if it is not aligned with the lattice.
template <int Dim>
Discretisation<Dim> discretise(const std::vector<Block<Dim>>& blocks, double dx,
                               const Vec<Dim>& origin, const std::vector<double>& densities);

}  // namespace rktsph
