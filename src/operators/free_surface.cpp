#include "operators/free_surface.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <span>
#include <vector>

#include <Eigen/Dense>

namespace rktsph {

namespace {

// Smallest eigenvalue of the symmetric part of B.
template <int Dim>
double smallest_eigenvalue(const Mat<Dim>& B) {
  const Mat<Dim> S = 0.5 * (B + B.transpose());
  if constexpr (Dim == 1) {
    return S(0, 0);
  } else if constexpr (Dim == 2) {
    const double m = 0.5 * (S(0, 0) + S(1, 1)), d = 0.5 * (S(0, 0) - S(1, 1));
    return m - std::sqrt(d * d + S(0, 1) * S(0, 1));
  } else {
    Eigen::SelfAdjointEigenSolver<Mat<Dim>> eig;
    eig.computeDirect(S, Eigen::EigenvaluesOnly);
    return eig.eigenvalues()[0];
  }
}

// The candidates of node I inside the support, as x_I - x_J, |x_I - x_J|^2 and V_J in arrays of
// Real (structure of arrays), by a branch-free compaction; the arrays have room for row.size() +
// pad entries. Returns how many are inside.
template <int Dim, class Real>
std::size_t gather_support(std::span<const Index> row, const Vec<Dim>& xi, const ParticleSet<Dim>& set, double r2,
                           std::size_t pad, std::vector<Real> (&x)[Dim], std::vector<Real>& d2,
                           std::vector<Real>& volume) {
  const std::size_t m = row.size() + pad;
  if (d2.size() < m) {
    for (auto& v : x) v.resize(m);
    d2.resize(m);
    volume.resize(m);
  }
  std::size_t count = 0;
  for (const Index j : row) {
    const auto ju = static_cast<std::size_t>(j);
    const Vec<Dim> x_ij = xi - set.position[ju];
    const double s = x_ij.squaredNorm();
    for (int d = 0; d < Dim; ++d) x[d][count] = static_cast<Real>(x_ij[d]);
    d2[count] = static_cast<Real>(s);
    volume[count] = static_cast<Real>(set.volume[ju]);
    count += s < r2 ? 1 : 0;
  }
  return count;
}

// Whether x lies in front of every plane (a point behind one stands for the material there itself
// and is not reflected).
template <int Dim>
bool in_front_of(std::span<const MirrorPlaneAt<Dim>* const> planes, const Vec<Dim>& x) {
  for (const auto* p : planes) {
    if ((x - p->point).dot(p->normal) < 0.0) return false;
  }
  return true;
}

// The images of x across one plane, or across each of two and across both (the corner's).
template <int Dim, class F>
void for_each_image(std::span<const MirrorPlaneAt<Dim>* const> planes, const Vec<Dim>& x, F&& f) {
  for (const auto* p : planes) f(reflect(*p, x));
  if (planes.size() == 2) f(reflect(*planes[1], reflect(*planes[0], x)));
}

// The pairs of one node in arrays (structure of arrays), kept per thread between calls.
template <int Dim>
struct PairArrays {
  std::vector<double> x[Dim];  // x_I - x_J
  std::vector<double> d2;
  std::vector<double> volume;
  std::vector<double> factor;  // V_J W'(r)/r
  std::size_t n = 0;

  void gather(std::span<const Index> row, const Vec<Dim>& xi, const ParticleSet<Dim>& set, double r2) {
    n = gather_support<Dim, double>(row, xi, set, r2, 0, x, d2, volume);
    if (factor.size() < d2.size()) factor.resize(d2.size());
  }

  // Step 7: the images, across `planes` (one, or two and the image across both), of the
  // neighbours in front of every plane (a neighbour already behind one stands for the material
  // there itself), those inside the support appended.
  void append_images(std::span<const Index> row, const Vec<Dim>& xi, const ParticleSet<Dim>& set, double r2,
                     std::span<const MirrorPlaneAt<Dim>* const> planes) {
    const std::size_t images = planes.size() == 2 ? 3 : planes.size();
    const std::size_t m = n + images * row.size();
    if (d2.size() < m) {
      for (auto& v : x) v.resize(m);
      d2.resize(m);
      volume.resize(m);
      factor.resize(m);
    }
    for (const Index j : row) {
      const auto ju = static_cast<std::size_t>(j);
      const Vec<Dim>& xj = set.position[ju];
      if (!in_front_of(planes, xj)) continue;
      for_each_image(planes, xj, [&](const Vec<Dim>& image) {
        const Vec<Dim> x_ij = xi - image;
        const double s = x_ij.squaredNorm();
        if (s >= r2) return;
        for (int d = 0; d < Dim; ++d) x[d][n] = x_ij[d];
        d2[n] = s;
        volume[n] = set.volume[ju];
        ++n;
      });
    }
  }

  // B = sum_J V_J (x_J - x_I) (x) grad_I W_IJ (symmetric: grad_I W_IJ = W'/r x_IJ) and
  // g = sum_J V_J grad_I W_IJ.
  void moments(double inv_h, double alpha, Mat<Dim>& B, Vec<Dim>& g) {
    const double* s2 = d2.data();
    const double* V = volume.data();
    double* f = factor.data();
#pragma omp simd
    for (std::size_t k = 0; k < n; ++k) {
      double W, h_dw_over_r;
      CubicSplineKernel<Dim>::value_and_scaled_derivative(std::sqrt(s2[k]), inv_h, alpha, W, h_dw_over_r);
      f[k] = V[k] * h_dw_over_r * inv_h;
    }
    for (int d = 0; d < Dim; ++d) {
      const double* xd = x[d].data();
      double sg = 0.0;
#pragma omp simd reduction(+ : sg)
      for (std::size_t k = 0; k < n; ++k) sg += f[k] * xd[k];
      g[d] = sg;
      for (int e = d; e < Dim; ++e) {
        const double* xe = x[e].data();
        double sb = 0.0;
#pragma omp simd reduction(+ : sb)
        for (std::size_t k = 0; k < n; ++k) sb += f[k] * xd[k] * xe[k];
        B(d, e) = -sb;
        B(e, d) = -sb;
      }
    }
  }
};

// The pre-screen of step 1 in single precision: lambda_min of B from the same pairs, 16 pairs a
// vector operation (twice double's lanes, and float's square root and division are cheaper).
// Only a node whose float eigenvalue lies clearly above interior_above is settled by it; every
// other node is evaluated again in double, so that flags and normals are those of the double
// evaluation. The float sums err by ~1e-5 at most (some 20 terms of O(1), each within a few ulp
// of 6e-8), far inside kScreenMargin.
inline constexpr double kScreenMargin = 1e-3;

template <int Dim>
struct ScreenArrays {
  static constexpr std::size_t kLanes = 16;
  std::vector<float> x[Dim];  // x_I - x_J
  std::vector<float> d2;
  std::vector<float> volume;

  // Returns the smallest eigenvalue of B (the symmetric B of PairArrays::moments).
  double lambda(std::span<const Index> row, const Vec<Dim>& xi, const ParticleSet<Dim>& set, double r2, double inv_h,
                double alpha) {
    const std::size_t count = gather_support<Dim, float>(row, xi, set, r2, kLanes, x, d2, volume);
    const std::size_t padded = (count + kLanes - 1) / kLanes * kLanes;
    for (std::size_t k = count; k < padded; ++k) {
      for (int d = 0; d < Dim; ++d) x[d][k] = 0.0f;
      d2[k] = 0.0f;
      volume[k] = 0.0f;  // no volume: no contribution
    }
    const float ih = static_cast<float>(inv_h), al = static_cast<float>(alpha);
    // The Dim (Dim + 1) / 2 entries of the symmetric B, row by row.
    constexpr int kEntries = Dim * (Dim + 1) / 2;
    constexpr std::array<int, 6> kRow =
        Dim == 3 ? std::array<int, 6>{0, 0, 0, 1, 1, 2} : std::array<int, 6>{0, 0, 1, 0, 0, 0};
    constexpr std::array<int, 6> kCol =
        Dim == 3 ? std::array<int, 6>{0, 1, 2, 1, 2, 2} : std::array<int, 6>{0, 1, 1, 0, 0, 0};
    float sb[kEntries][kLanes] = {};
    const float* s2 = d2.data();
    const float* V = volume.data();
    const float* xs[Dim];
    for (int d = 0; d < Dim; ++d) xs[d] = x[d].data();
    for (std::size_t k0 = 0; k0 < padded; k0 += kLanes) {
#pragma omp simd
      for (std::size_t l = 0; l < kLanes; ++l) {
        const std::size_t k = k0 + l;
        // V_J W'(r)/r = V_J (h W'/r) / h.
        const float f = V[k] * CubicSplineKernel<Dim>::template scaled_derivative<float>(std::sqrt(s2[k]), ih, al) * ih;
        for (int c = 0; c < kEntries; ++c) sb[c][l] += f * xs[kRow[c]][k] * xs[kCol[c]][k];
      }
    }
    Mat<Dim> B;
    for (int c = 0; c < kEntries; ++c) {
      double sum = 0.0;
      for (std::size_t l = 0; l < kLanes; ++l) sum += static_cast<double>(sb[c][l]);
      B(kRow[c], kCol[c]) = -sum;
      B(kCol[c], kRow[c]) = -sum;
    }
    return smallest_eigenvalue<Dim>(B);
  }
};

}  // namespace

template <int Dim>
void detect_free_surface(const ParticleSet<Dim>& set, const Relation<Dim>& relation,
                         const CubicSplineKernel<Dim>& kernel, const FreeSurfaceOptions& options,
                         const std::vector<std::uint8_t>& previous, const std::vector<std::uint8_t>& excluded,
                         std::vector<std::uint8_t>& flags, std::vector<Vec<Dim>>& normals, const exec::Threads& policy,
                         std::vector<std::uint8_t>* corners, FreeSurfaceScratch<Dim>* scratch,
                         const DetectionMirrors<Dim>* mirrors, std::vector<Vec<Dim>>* edges) {
  FreeSurfaceScratch<Dim> local;
  FreeSurfaceScratch<Dim>& work = scratch != nullptr ? *scratch : local;
  const Index n = set.size();
  const auto nu = static_cast<std::size_t>(n);
  const double h = kernel.h();
  const double inv_h = kernel.inv_h(), alpha = kernel.alpha();
  const double r2 = kernel.support_radius() * kernel.support_radius();
  const double near2 = 2.0 * h * h;  // (sqrt(2) h)^2
  std::vector<double>& lambda = work.lambda;
  // The settled interior (method-notes §3.6) is skipped unless some node has moved or changed
  // its volume enough since the last full pass. A partial pass needs that pass's state and the
  // caller's flags and normals as this function left them (zero at every settled node).
  bool full = true;
  if (options.refresh_displacement > 0.0 && work.settled.size() == nu && work.reference_position.size() == nu &&
      work.reference_volume.size() == nu && lambda.size() == nu && flags.size() == nu && normals.size() == nu) {
    // One sweep on the threads: any node moved more than refresh_displacement, or whose volume
    // changed by more than refresh_volume of its reference (a frozen node, volume 0, counts).
    const double d2 = options.refresh_displacement * options.refresh_displacement, dv = options.refresh_volume;
    const Vec<Dim>* x = set.position.data();
    const Vec<Dim>* x0 = work.reference_position.data();
    const double* v = set.volume.data();
    const double* v0 = work.reference_volume.data();
    const auto over = exec::particle_reduce<1>(policy, n, work.reduction, [&](Index i, double* acc) {
      const auto iu = static_cast<std::size_t>(i);
      const bool moved = (x[iu] - x0[iu]).squaredNorm() > d2;
      const bool swelled = std::abs(v[iu] - v0[iu]) > dv * v0[iu];
      acc[0] += moved || swelled ? 1.0 : 0.0;
    });
    full = over[0] > 0.0;
  }
  work.last_full = full;
  std::vector<Index>& active = work.active;
  if (full) {
    ++work.full_passes;
    flags.assign(nu, 0);
    normals.assign(nu, Vec<Dim>::Zero());
    lambda.assign(nu, 0.0);
    work.settled.assign(nu, 0);
  } else {
    ++work.partial_passes;
    for (const Index i : active) {
      flags[static_cast<std::size_t>(i)] = 0;
      normals[static_cast<std::size_t>(i)].setZero();
    }
  }
  // The nodes this pass evaluates: every node, or the active ones (those not settled).
  const Index count = full ? n : static_cast<Index>(active.size());
  const Index* which = full ? nullptr : active.data();
  std::uint8_t* settled = work.settled.data();
  // Steps 1-3: B, the first normal, the pre-screen and the umbrella scan of the candidates.
  exec::particle_for(policy, count, [&](Index k) {
    const Index i = which != nullptr ? which[k] : k;
    const auto iu = static_cast<std::size_t>(i);
    const Vec<Dim>& xi = set.position[iu];
    // Most nodes are settled by the single-precision screen; the rest are evaluated in double:
    // the neighbours in the support gathered branch-free into arrays (a coincident particle,
    // d2 = 0, contributes nothing: its x_IJ is zero), then B and g summed in loops the compiler
    // vectorises (the square root and the kernel's piece 8 pairs at a time).
    // A node with mirror images skips the screen (which sums the real neighbours only), so it
    // is never settled either.
    const MirrorPlaneAt<Dim>* plane_of[DetectionMirrors<Dim>::kPerNode] = {};
    std::size_t planes = 0;
    if (mirrors != nullptr && mirrors->has(iu)) {
      for (const std::int32_t p : mirrors->of_node[iu]) {
        if (p >= 0) plane_of[planes++] = &mirrors->planes[static_cast<std::size_t>(p)];
      }
    }
    const std::span<const MirrorPlaneAt<Dim>* const> own_planes(plane_of, planes);
    if (planes == 0) {
      static thread_local ScreenArrays<Dim> screen;
      const double screened = screen.lambda(relation.row(i), xi, set, r2, inv_h, alpha);
      if (screened > options.interior_above + kScreenMargin) {
        lambda[iu] = screened;  // only ever compared with the thresholds, which it clears
        if (full) settled[iu] = screened > options.settled_above && (excluded.empty() || excluded[iu] == 0) ? 1 : 0;
        return;
      }
    }
    static thread_local PairArrays<Dim> pairs;
    pairs.gather(relation.row(i), xi, set, r2);
    if (planes > 0) pairs.append_images(relation.row(i), xi, set, r2, own_planes);
    Mat<Dim> B;
    Vec<Dim> g;
    pairs.moments(inv_h, alpha, B, g);
    lambda[iu] = smallest_eigenvalue<Dim>(B);
    // The rest concerns candidates only: an interior node (most of a body) stops here.
    if (lambda[iu] > options.interior_above) return;
    if (!excluded.empty() && excluded[iu] != 0) return;
    Vec<Dim> nu_i = std::abs(B.determinant()) > 1e-12 ? Vec<Dim>(-(B.inverse() * g)) : Vec<Dim>(-g);
    const double len = nu_i.norm();
    const Vec<Dim> normal = len > 0.0 ? Vec<Dim>(nu_i / len) : Vec<Dim>::Zero();
    bool surface = false;
    if (lambda[iu] <= options.surface_below) {
      surface = true;
    } else if (lambda[iu] <= options.interior_above && len > 0.0) {
      // The umbrella scan: any neighbour in the region just outside I along n makes I interior.
      const Vec<Dim> T = xi + h * normal;
      auto in_umbrella = [&](const Vec<Dim>& xj) {
        const Vec<Dim> rel = xj - xi;
        const double d2 = rel.squaredNorm();
        if (d2 >= r2 || d2 == 0.0) return false;
        const Vec<Dim> y = xj - T;
        if (d2 >= near2) return y.squaredNorm() < h * h;
        if constexpr (Dim == 2) {
          const Vec<Dim> tangent(-normal[1], normal[0]);
          return std::abs(normal.dot(y)) + std::abs(tangent.dot(y)) < h;
        } else {
          return rel.dot(normal) > std::cos(0.25 * std::numbers::pi) * std::sqrt(d2);  // the cone
        }
      };
      surface = true;
      for (const Index j : relation.row(i)) {
        // A particle without volume (deactivated outside a domain box) is no material.
        if (j == i || set.volume[static_cast<std::size_t>(j)] == 0.0) continue;
        if (in_umbrella(set.position[static_cast<std::size_t>(j)])) {
          surface = false;
          break;
        }
      }
      // The images (step 7), of the node itself too: a plane just beyond the node fills the
      // umbrella as the material behind it would.
      for (std::size_t c = 0; surface && planes > 0 && c < relation.row(i).size(); ++c) {
        const auto ju = static_cast<std::size_t>(relation.row(i)[c]);
        if (set.volume[ju] == 0.0) continue;
        const Vec<Dim>& xj = set.position[ju];
        if (!in_front_of(own_planes, xj)) continue;
        for_each_image(own_planes, xj, [&](const Vec<Dim>& image) { surface = surface && !in_umbrella(image); });
      }
    }
    if (surface) {
      flags[iu] = 1;
      normals[iu] = normal;
    }
  });
  if (full && options.refresh_displacement > 0.0) {
    work.reference_position.assign(set.position.begin(), set.position.end());
    work.reference_volume.assign(set.volume.begin(), set.volume.end());
    active.clear();
    for (Index i = 0; i < n; ++i) {
      if (settled[static_cast<std::size_t>(i)] == 0) active.push_back(i);
    }
  }
  // Every later step reads and writes only the flagged nodes' own entries (and their neighbours'
  // flags, previous flags and positions, which no step writes), so they run in place over the
  // nodes just evaluated: the flagged ones are among them.
  //
  // Step 5: temporal coherence. A node not on the surface at the last step joins it only next to
  // one that was, or when its support is plainly one-sided (lambda <= surface_below).
  if (!previous.empty()) {
    std::vector<std::uint8_t>& drop = work.keep;
    drop.assign(static_cast<std::size_t>(count), 0);
    exec::particle_for(policy, count, [&](Index k) {
      const Index i = which != nullptr ? which[k] : k;
      const auto iu = static_cast<std::size_t>(i);
      if (flags[iu] == 0 || previous[iu] != 0 || lambda[iu] <= options.surface_below) return;
      bool near_surface = false;
      for (const Index j : relation.row(i)) near_surface = near_surface || previous[static_cast<std::size_t>(j)] != 0;
      if (!near_surface) drop[static_cast<std::size_t>(k)] = 1;
    });
    for (Index k = 0; k < count; ++k) {
      if (drop[static_cast<std::size_t>(k)] == 0) continue;
      const auto iu = static_cast<std::size_t>(which != nullptr ? which[k] : k);
      flags[iu] = 0;
      normals[iu].setZero();
    }
  }
  // Step 4 (2D): the improved normal, from the chords to the two adjacent surface nodes: the
  // nearest partner on either side along the tangent of the first normal, a partner being a
  // flagged neighbour or an excluded one that is not plainly interior (a wall's surface node,
  // where the free surface meets a wall). Each chord's perpendicular is turned to the first
  // normal's side; their mean is the normal. Where the two perpendiculars differ by more than
  // kCornerTurn the node is a corner: two faces meet there and no single normal holds. The
  // first normals are kept until every node has its improved one (a node reads only its own).
  if (corners != nullptr) {
    if (full || corners->size() != nu) {
      corners->assign(nu, 0);
    } else {
      for (Index k = 0; k < count; ++k) (*corners)[static_cast<std::size_t>(which[k])] = 0;
    }
  }
  if (edges != nullptr) {
    if (full || edges->size() != nu) {
      edges->assign(nu, Vec<Dim>::Zero());
    } else {
      for (Index k = 0; k < count; ++k) (*edges)[static_cast<std::size_t>(which[k])].setZero();
    }
  }
  // Step 4 in 3D (method-notes eq. (3.6.6)): the same from the chords to the nearest partner in
  // each quarter of the tangent plane of the first normal (about +t1, +t2, -t1, -t2): the normal
  // is the mean of the normals of the four triangles that consecutive chords span, each turned to
  // the first normal's side (a vertex normal). Beside an edge the nearest partner across it is the
  // edge node, which lies in the face's plane, so the row next to an edge gets its face's normal,
  // where the first normal leans towards the other face. At an edge or a vertex the triangles'
  // normals are those of the faces that meet there and their mean bisects them: where two of them
  // differ by more than kCornerTurn the node is on an edge, of direction n1 x n2 for the two most
  // different, and where a third differs by as much from both, on a vertex (a corner: three
  // faces, method-notes eq. (3.7.4)).
  if constexpr (Dim >= 2) {
    const double corner_cos = std::cos(kCornerTurn);
    std::vector<Vec<Dim>>& improved = work.improved;
    improved.resize(static_cast<std::size_t>(count));
    // Node j as a partner of surface node i: a flagged neighbour, or an excluded one that is not
    // plainly interior (a wall's surface node).
    auto partner = [&](Index i, Index j) {
      const auto ju = static_cast<std::size_t>(j);
      if (j == i || set.volume[ju] == 0.0) return false;
      return flags[ju] != 0 || (!excluded.empty() && excluded[ju] != 0 && lambda[ju] <= options.interior_above);
    };
    exec::particle_for(policy, count, [&](Index k) {
      const Index i = which != nullptr ? which[k] : k;
      const auto iu = static_cast<std::size_t>(i);
      improved[static_cast<std::size_t>(k)] = normals[iu];
      if (flags[iu] == 0) return;
      const Vec<Dim> n0 = normals[iu];
      if constexpr (Dim == 2) {
        const Vec<Dim> tangent(-n0[1], n0[0]);
        double best[2] = {r2, r2};
        Vec<Dim> chord[2] = {Vec<Dim>::Zero(), Vec<Dim>::Zero()};
        for (const Index j : relation.row(i)) {
          if (!partner(i, j)) continue;
          const Vec<Dim> c = set.position[static_cast<std::size_t>(j)] - set.position[iu];
          const double d2 = c.squaredNorm();
          const double along = tangent.dot(c);
          if (along == 0.0) continue;
          const int side = along > 0.0 ? 0 : 1;
          if (d2 < best[side]) {
            best[side] = d2;
            chord[side] = c;
          }
        }
        Vec<Dim> p[2];
        int found = 0;
        for (int side = 0; side < 2; ++side) {
          if (chord[side].squaredNorm() == 0.0) continue;
          Vec<Dim> q(-chord[side][1], chord[side][0]);
          if (q.dot(n0) < 0.0) q = -q;
          p[found++] = q.normalized();
        }
        if (found == 0) return;
        const Vec<Dim> sum = found == 2 ? Vec<Dim>(p[0] + p[1]) : p[0];
        if (sum.norm() > 0.0) improved[static_cast<std::size_t>(k)] = sum / sum.norm();
        if (found == 2 && corners != nullptr && p[0].dot(p[1]) < corner_cos) (*corners)[iu] = 1;
      } else {
        if (n0.squaredNorm() == 0.0) return;
        // A tangent frame: t1 normal to n0 and to the axis least aligned with it.
        int axis = 0;
        for (int d = 1; d < 3; ++d) axis = std::abs(n0[d]) < std::abs(n0[axis]) ? d : axis;
        const Vec<Dim> t1 = n0.cross(Vec<Dim>::Unit(axis)).normalized();
        const Vec<Dim> t2 = n0.cross(t1);
        double best[4] = {r2, r2, r2, r2};
        Vec<Dim> chord[4] = {Vec<Dim>::Zero(), Vec<Dim>::Zero(), Vec<Dim>::Zero(), Vec<Dim>::Zero()};
        for (const Index j : relation.row(i)) {
          if (!partner(i, j)) continue;
          const Vec<Dim> c = set.position[static_cast<std::size_t>(j)] - set.position[iu];
          const double a = t1.dot(c), b = t2.dot(c);
          if (a == 0.0 && b == 0.0) continue;
          const int quarter = std::abs(a) >= std::abs(b) ? (a > 0.0 ? 0 : 2) : (b > 0.0 ? 1 : 3);
          const double d2 = c.squaredNorm();
          if (d2 < best[quarter]) {
            best[quarter] = d2;
            chord[quarter] = c;
          }
        }
        Vec<Dim> sum = Vec<Dim>::Zero();
        Vec<Dim> m[4];
        int found = 0;
        for (int q = 0; q < 4; ++q) {
          const Vec<Dim>& a = chord[q];
          const Vec<Dim>& b = chord[(q + 1) % 4];
          if (a.squaredNorm() == 0.0 || b.squaredNorm() == 0.0) continue;
          Vec<Dim> mq = a.cross(b);
          if (mq.squaredNorm() == 0.0) continue;
          if (mq.dot(n0) < 0.0) mq = -mq;
          m[found] = mq.normalized();
          sum += m[found++];
        }
        if (sum.norm() > 0.0) improved[static_cast<std::size_t>(k)] = sum / sum.norm();
        // The two most different triangle normals: an edge if they turn by more than kCornerTurn.
        int p = 0, q = 0;
        double lowest = 1.0;
        for (int a = 0; a < found; ++a) {
          for (int b = a + 1; b < found; ++b) {
            if (m[a].dot(m[b]) < lowest) lowest = m[a].dot(m[b]), p = a, q = b;
          }
        }
        if (lowest >= corner_cos) return;
        bool vertex = false;
        for (int c = 0; c < found; ++c) vertex = vertex || (m[c].dot(m[p]) < corner_cos && m[c].dot(m[q]) < corner_cos);
        if (vertex) {
          if (corners != nullptr) (*corners)[iu] = 1;
        } else if (edges != nullptr) {
          (*edges)[iu] = m[p].cross(m[q]).normalized();
        }
      }
    });
    for (Index k = 0; k < count; ++k) {
      const auto iu = static_cast<std::size_t>(which != nullptr ? which[k] : k);
      if (flags[iu] != 0) normals[iu] = improved[static_cast<std::size_t>(k)];
    }
  }
}

template <int Dim>
void make_corner_traction_free(double* s) {
  // 2D: two traction-free faces through the point, sigma n1 = sigma n2 = 0 with n1, n2
  // independent, leave no in-plane stress (the out-of-plane sigma_zz is kept, as for a face).
  // 3D: three independent faces (a vertex) leave no stress at all.
  if constexpr (Dim == 2) {
    s[stress_slot<Dim>(0, 0)] = 0.0;
    s[stress_slot<Dim>(1, 1)] = 0.0;
    s[stress_slot<Dim>(0, 1)] = 0.0;
  } else if constexpr (Dim == 3) {
    for (int c = 0; c < kStressComponents<Dim>; ++c) s[c] = 0.0;
  } else {
    static_cast<void>(s);
  }
}

template <int Dim>
void make_edge_traction_free(const Vec<Dim>& e, double* s) {
  // sigma n1 = sigma n2 = 0 for the two faces through the edge leaves sigma = (e.sigma e) e (x) e.
  if constexpr (Dim == 3) {
    Mat<Dim> S;
    for (int k = 0; k < Dim; ++k) {
      for (int d = 0; d < Dim; ++d) S(k, d) = s[stress_slot<Dim>(k, d)];
    }
    const double see = e.dot(S * e);
    for (int k = 0; k < Dim; ++k) {
      for (int d = k; d < Dim; ++d) s[stress_slot<Dim>(k, d)] = see * e[k] * e[d];
    }
  } else {
    static_cast<void>(e);
    static_cast<void>(s);
  }
}

template <int Dim>
void make_traction_free(const Vec<Dim>& n, double* s) {
  if constexpr (Dim == 1) {
    s[0] = 0.0;  // the normal stress of an end (the lateral ones are kept)
  } else {
    // sigma <- sigma - (sigma n) (x) n - n (x) (sigma n) + (n . sigma n) n (x) n
    Mat<Dim> S;
    for (int k = 0; k < Dim; ++k) {
      for (int d = 0; d < Dim; ++d) S(k, d) = s[stress_slot<Dim>(k, d)];
    }
    const Vec<Dim> sn = S * n;
    const double nsn = n.dot(sn);
    const Mat<Dim> R = S - sn * n.transpose() - n * sn.transpose() + nsn * n * n.transpose();
    for (int k = 0; k < Dim; ++k) {
      for (int d = k; d < Dim; ++d) s[stress_slot<Dim>(k, d)] = R(k, d);
    }
  }
}

#define RKTSPH_INSTANTIATE(D)                                                                                     \
  template void detect_free_surface<D>(const ParticleSet<D>&, const Relation<D>&, const CubicSplineKernel<D>&,    \
                                       const FreeSurfaceOptions&, const std::vector<std::uint8_t>&,               \
                                       const std::vector<std::uint8_t>&, std::vector<std::uint8_t>&,              \
                                       std::vector<Vec<D>>&, const exec::Threads&, std::vector<std::uint8_t>*,    \
                                       FreeSurfaceScratch<D>*, const DetectionMirrors<D>*, std::vector<Vec<D>>*); \
  template void make_traction_free<D>(const Vec<D>&, double*);                                                    \
  template void make_corner_traction_free<D>(double*);                                                            \
  template void make_edge_traction_free<D>(const Vec<D>&, double*);
RKTSPH_INSTANTIATE(1)
RKTSPH_INSTANTIATE(2)
RKTSPH_INSTANTIATE(3)
#undef RKTSPH_INSTANTIATE

}  // namespace rktsph
