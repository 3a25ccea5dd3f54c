#pragma once
// The lattice generator of the two interleaved particle sets of the staggered scheme
// (method-notes §3.3):
//   nodes         - the vertices of a cell lattice; they carry the persistent state at t^n;
//   stress points - one per lattice cell, at its centre; they carry the half-step state at
//                   t^{n+1/2}.
// Bodies are unions of axis-aligned blocks on one lattice of spacing dx. A node's volume is its
// tributary volume (dx^d inside, half on an edge, a quarter at a corner), so that each set
// carries the whole mass on its own.
#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/types.hpp"
#include "particles/particle_set.hpp"

namespace rktsph {

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
  std::array<int, Dim> cells{};    // cells per axis of the bounding box
  std::vector<int> cell_material;  // -1 where there is no material

  std::size_t cell_index(const std::array<int, Dim>& c) const;
  /// Material of a cell, or -1 outside the lattice or for an empty cell.
  int material_at(const std::array<int, Dim>& c) const;
};

/// An edge of a polygon body (particles/polygon.hpp) that a boundary node lies on: the body,
/// the ring (0 the outer boundary, 1 + j hole j) and the edge (k from vertex k to vertex k + 1).
struct EdgeRef {
  int body = -1;
  int ring = -1;
  int edge = -1;
  bool operator==(const EdgeRef&) const = default;
};

/// The traction-free condition at a boundary node of a polygon (method-notes §3.9):
///   axes   - every face of the node is normal to an axis: the face bits hold, as on a lattice;
///   normal - sigma.n = 0 about the node's unit normal (one inclined face, or two faces meeting
///            at a vertex that turns by at most kCornerTurn: their bisector);
///   corner - two faces at a convex vertex turning by more: no in-plane stress;
///   none   - a re-entrant vertex turning by more (as a lattice's inner corner: no condition).
enum class FaceCondition : std::uint8_t { axes = 0, normal = 1, corner = 2, none = 3 };

/// The nodes on the faces of the body, with the faces each lies on (bit 2d of `faces`: the face
/// with outward normal -e_d; bit 2d+1: +e_d) and its tributary area of each face, m^(Dim-1).
/// Kept as a sorted list of node indices, not as node fields: the faces are a small part of a
/// large set. remap() follows a reordering of the nodes.
///
/// Polygon bodies add faces of any inclination: `inclined` is the sum of A n over the node's
/// faces that are normal to no axis (its length the area of a single one), `normal` and
/// `condition` the traction-free condition there, `edges` the polygon edges it lies on (two at
/// a vertex). These four are empty for lattices and particle files, else parallel to `node`.
template <int Dim>
struct BoundaryNodes {
  std::vector<Index> node;  // ascending
  std::vector<std::uint8_t> faces;
  std::vector<std::array<double, 2 * Dim>> area;
  std::vector<Vec<Dim>> inclined;
  std::vector<Vec<Dim>> normal;
  std::vector<FaceCondition> condition;
  std::vector<std::array<EdgeRef, 2>> edges;

  bool has_geometry() const { return !condition.empty(); }

  std::size_t size() const { return node.size(); }
  /// The face areas of node i (zeros for a node on no face).
  std::array<double, 2 * Dim> area_of(Index i) const {
    const auto it = std::lower_bound(node.begin(), node.end(), i);
    if (it == node.end() || *it != i) return {};
    return area[static_cast<std::size_t>(it - node.begin())];
  }
  /// The faces of every node of a set of `nodes` particles (0 inside).
  std::vector<std::uint8_t> dense_faces(Index nodes) const {
    std::vector<std::uint8_t> out(static_cast<std::size_t>(nodes), 0);
    for (std::size_t k = 0; k < node.size(); ++k) out[static_cast<std::size_t>(node[k])] = faces[k];
    return out;
  }
  /// After ParticleSet::permute(order): node order[k] is now node k.
  void remap(const std::vector<Index>& order) {
    std::vector<Index> new_index(order.size());
    for (std::size_t k = 0; k < order.size(); ++k)
      new_index[static_cast<std::size_t>(order[k])] = static_cast<Index>(k);
    std::vector<std::size_t> perm(node.size());
    for (std::size_t k = 0; k < perm.size(); ++k) perm[k] = k;
    for (auto& i : node) i = new_index[static_cast<std::size_t>(i)];
    std::sort(perm.begin(), perm.end(), [&](std::size_t a, std::size_t b) { return node[a] < node[b]; });
    BoundaryNodes out;
    for (std::size_t k : perm) {
      out.node.push_back(node[k]);
      out.faces.push_back(faces[k]);
      out.area.push_back(area[k]);
      if (has_geometry()) {
        out.inclined.push_back(inclined[k]);
        out.normal.push_back(normal[k]);
        out.condition.push_back(condition[k]);
        out.edges.push_back(edges[k]);
      }
    }
    *this = std::move(out);
  }
};

/// geometry.jitter: a random displacement of the generated particles, for tests of the operators
/// on disordered sets. Every stress point and every node on no face of the body moves by an
/// offset drawn uniformly from [-fraction dx, fraction dx]^Dim; face nodes (BoundaryNodes) stay
/// where they are, so boundary entries select them and their faces and areas still hold.
/// Volumes do not change. The offsets are a hash of (seed, set, particle index, axis): the
/// same seed gives the same particles on any thread count.
struct LatticeJitter {
  double fraction = 0.0;  // of the spacing; 0 = none
  std::uint64_t seed = 0;
};
/// The jitter must stay below half a spacing: then a stress point stays inside its cell and a
/// node inside the half-spacing box around its lattice site, so that no two particles of a set
/// can meet or swap and no interior node reaches a face.
inline constexpr double kMaxJitterFraction = 0.5;

/// The offset in [-1, 1) of particle `index` of set `set` (0 nodes, 1 stress points) along `axis`.
double jitter_unit_offset(std::uint64_t seed, int set, Index index, int axis);

template <int Dim>
struct LatticeParticles {
  double dx = 0.0;
  Lattice<Dim> lattice;
  ParticleSet<Dim> nodes{"nodes"};
  ParticleSet<Dim> stress_points{"stress_points"};
  BoundaryNodes<Dim> boundary;
};

/// The coordinates of lattice vertex `i` and of the centre of cell `i` along one axis. Out of
/// line, so that every generator (blocks, polygons) gets the same bits whatever the compiler
/// contracts in its own loops (with -march=native, origin + i dx may become a fused
/// multiply-add in one place and not in another).
double lattice_vertex(double origin, int i, double dx);
double lattice_cell_centre(double origin, int i, double dx);


/// Build nodes and stress points from blocks (all on one lattice of spacing dx starting at
/// `origin`), displaced by `jitter`. Throws InputError naming the block if it is not aligned
/// with the lattice, or if the jitter is not in [0, kMaxJitterFraction).
template <int Dim>
LatticeParticles<Dim> generate_lattice(const std::vector<Block<Dim>>& blocks, double dx, const Vec<Dim>& origin,
                                       const std::vector<double>& densities, const LatticeJitter& jitter = {});

}  // namespace rktsph
