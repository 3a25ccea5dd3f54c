#pragma once
// Free-surface detection and normals on a particle set (method-notes §3.6), for the
// large-deformation scheme V2:
//   1. B_I = sum_J V_J (x_J - x_I) (x) grad_I W_IJ and its smallest eigenvalue lambda_I: a
//      surface node if lambda_I <= surface_below, interior if > interior_above, else a candidate;
//   2. the normal n_I = nu / |nu|, nu = -B_I^{-1} sum_J V_J grad_I W_IJ (outward);
//   3. candidates: the umbrella scan of Marrone et al. about T = x_I + h n_I (2D: the square
//      test within sqrt(2) h, 3D: a cone of half-angle pi/4), any neighbour inside it making the
//      node interior;
//   4. 2D: the improved normal, from the perpendiculars to the chords to the two adjacent surface
//      nodes (one on either side); a corner where those two differ by more than kCornerTurn;
//      3D: from the triangles that the chords to the nearest partner in each quarter of the
//      tangent plane span (method-notes eq. (3.6.6)); an edge where two of their normals differ by
//      more than kCornerTurn, a vertex (corner) where a third differs from both;
//   5. temporal coherence: a node that was not on the surface may become one only next to a
//      node that was, or with lambda_I <= surface_below (a genuinely new surface);
//   6. nodes excluded by the caller (explicit boundary conditions) are never flagged;
//   7. mirror images (optional): a node beside a rigid plane that the material reaches sums, in
//      steps 1-3 only, the reflections of its neighbours across that plane as well, so that the
//      plane does not cut its support (method-notes §3.6, "Mirror images at rigid bodies").
#include <array>
#include <cstdint>
#include <vector>

#include "core/execution.hpp"
#include "core/kernel.hpp"
#include "neighbours/relation.hpp"
#include "particles/particle_set.hpp"

namespace rktsph {

/// The turn between the two chords at a surface node above which it is a corner (2D), rad. A
/// face cut from the lattice (a slope, a curve) is a staircase whose chords turn by 45 degrees
/// at each step; those are not corners, so the threshold lies between that and the 90 degrees
/// of a block's corner. A genuine obtuse crest (a 45 degree slope's, turning by 45 degrees) is
/// then treated as a face with the bisecting normal.
inline constexpr double kCornerTurn = 1.0471975511965976;  // 60 degrees

struct FreeSurfaceOptions {
  double surface_below = 0.2;    // lambda_min of B at or below which a node is on the surface
  double interior_above = 0.75;  // lambda_min above which it is interior without the scan
  // Settled interior (method-notes §3.6, "Settled interior"): with a work space kept between
  // calls and refresh_displacement > 0, a node whose lambda_min exceeded settled_above at the
  // last full pass is not evaluated again (it stays interior) until some node has moved more
  // than refresh_displacement (m) or changed its volume by more than the fraction refresh_volume
  // since that pass; then every node is evaluated again. 0 evaluates every node every call.
  double refresh_displacement = 0.0;
  double refresh_volume = 0.02;
  double settled_above = 0.85;
};

/// Work space of detect_free_surface, kept by its caller between steps (no allocation once grown),
/// and the state of the settled interior: each node's lambda_min, and the positions, volumes and
/// settled flags of the last full pass (saved with a checkpoint, permuted with the nodes).
template <int Dim>
struct FreeSurfaceScratch {
  std::vector<double> lambda;
  std::vector<std::uint8_t> keep;
  std::vector<Vec<Dim>> improved;
  std::vector<std::uint8_t> settled;
  std::vector<Index> active;  // the nodes not settled at the last full pass
  std::vector<Vec<Dim>> reference_position;
  std::vector<double> reference_volume;
  exec::ReductionScratch reduction;  // the refresh test's block sums
  std::int64_t full_passes = 0;      // calls that evaluated every node
  std::int64_t partial_passes = 0;   // calls that skipped the settled interior
  bool last_full = true;             // whether the last call was a full pass
  std::size_t bytes() const {
    return lambda.capacity() * sizeof(double) + keep.capacity() + improved.capacity() * sizeof(Vec<Dim>) +
           settled.capacity() + active.capacity() * sizeof(Index) + reference_position.capacity() * sizeof(Vec<Dim>) +
           reference_volume.capacity() * sizeof(double);
  }
};

/// A rigid plane across which neighbours are reflected for the detection only (no field value
/// is mirrored): a point on it and its unit normal, pointing into the material.
template <int Dim>
struct MirrorPlaneAt {
  Vec<Dim> point = Vec<Dim>::Zero();
  Vec<Dim> normal = Vec<Dim>::Zero();
};

/// The mirror planes of a detection: `planes`, and for each node the indices of at most two of
/// them (-1: none). Empty `of_node`: no node has any.
template <int Dim>
struct DetectionMirrors {
  static constexpr int kPerNode = 2;
  std::vector<MirrorPlaneAt<Dim>> planes;
  std::vector<std::array<std::int32_t, kPerNode>> of_node;
  bool has(std::size_t i) const { return !of_node.empty() && of_node[i][0] >= 0; }
  std::size_t bytes() const {
    return planes.capacity() * sizeof(MirrorPlaneAt<Dim>) + of_node.capacity() * sizeof(of_node[0]);
  }
};

/// The reflection of x across a plane.
template <int Dim>
Vec<Dim> reflect(const MirrorPlaneAt<Dim>& plane, const Vec<Dim>& x) {
  return x - 2.0 * (x - plane.point).dot(plane.normal) * plane.normal;
}

/// Flags (1 = free surface) and outward unit normals of every particle of `set`, from
/// `relation` (the set's own neighbours within the support; a wider Verlet list is cut back).
/// `previous` (may be empty) holds the flags of the last step for the temporal coherence;
/// `excluded` (may be empty) the particles never flagged. Normals are zero off the surface.
/// `corners`, if given, gets 1 at the surface nodes where faces meet with no single normal (2D:
/// two faces; 3D: three, a vertex; see step 4). `edges`, if given (3D), gets at a node where two
/// faces meet along a line the unit direction of that edge, zero elsewhere.
/// `mirrors`, if given, the planes whose images each node sums in steps 1-3 (step 7): a node
/// with images is never settled (its images move with the bodies, not with the nodes).
template <int Dim>
void detect_free_surface(const ParticleSet<Dim>& set, const Relation<Dim>& relation,
                         const CubicSplineKernel<Dim>& kernel, const FreeSurfaceOptions& options,
                         const std::vector<std::uint8_t>& previous, const std::vector<std::uint8_t>& excluded,
                         std::vector<std::uint8_t>& flags, std::vector<Vec<Dim>>& normals,
                         const exec::Threads& policy = {}, std::vector<std::uint8_t>* corners = nullptr,
                         FreeSurfaceScratch<Dim>* scratch = nullptr, const DetectionMirrors<Dim>* mirrors = nullptr,
                         std::vector<Vec<Dim>>* edges = nullptr);

/// Traction-free stress by rotation to the local frame (method-notes §3.7): sigma.n = 0 with the
/// tangential stress kept, sigma <- sigma - (sigma n) (x) n - n (x) (sigma n) + (n.sigma n) n (x) n;
/// the out-of-plane sigma_zz is kept in 2D.
template <int Dim>
void make_traction_free(const Vec<Dim>& n, double* stress);

/// Traction-free on the faces through a corner: 2D, two faces, no in-plane stress (sigma_zz
/// kept); 3D, three independent faces (a vertex), no stress at all.
template <int Dim>
void make_corner_traction_free(double* stress);

/// Traction-free on the two faces through an edge of direction e (3D, |e| = 1, method-notes
/// eq. (3.7.4)): sigma n1 = sigma n2 = 0 leaves only the stress along the edge,
/// sigma <- (e . sigma e) e (x) e.
template <int Dim>
void make_edge_traction_free(const Vec<Dim>& e, double* stress);

/// The surface condition of a node: the corner's, the edge's along `edge` (3D, nonzero there),
/// or the face's about n.
template <int Dim>
void make_surface_traction_free(const Vec<Dim>& n, bool corner, const Vec<Dim>& edge, double* stress) {
  if (corner)
    make_corner_traction_free<Dim>(stress);
  else if (edge.squaredNorm() > 0.0)
    make_edge_traction_free<Dim>(edge, stress);
  else
    make_traction_free<Dim>(n, stress);
}

/// The same where no node is on an edge (2D, V1's polygon faces).
template <int Dim>
void make_surface_traction_free(const Vec<Dim>& n, bool corner, double* stress) {
  make_surface_traction_free<Dim>(n, corner, Vec<Dim>::Zero(), stress);
}

}  // namespace rktsph
