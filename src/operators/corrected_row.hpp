#pragma once
// One row of the corrected operator (method-notes §3.2, eq. (3.2.3)) evaluated from the current
// positions: the target's candidates inside the support are gathered by a branch-free
// compaction, then the kernel basis w_b = V_b [W_ab; h grad_a W_ab] and the moment matrix M_a
// in loops over the pairs that the compiler vectorises (`omp simd`: the square root, the
// division and the kernel's piece 8 pairs at a time, no mispredicted branch).
//
// A row is used in two ways (method-notes §5.2, "Operators on the fly"):
//   weights()   the pair weights c_ab = M_a^{-1} w_b, written into a stored operator (the
//               rebuild of operators/corrected_operator.cpp);
//   apply()     the value and gradient of a field directly, M_a^{-1} sum_b w_b f_b: the same
//               sums in another order (equal to round-off), with nothing stored per pair. The
//               V2 step applies its operators this way, so that a step neither writes nor
//               reads back the weights (28 bytes a pair).
// A degenerate row (too few sources: |det M_a| <= 1e-8) falls back to Shepard interpolation
// and the plain kernel gradient, in both uses. With a gradient floor (solver.gradient_floor,
// method-notes eq. (3.2.6)) a row whose gradient renormalisation matrix is nearly singular (a
// thin sheet or a lone particle: the weights there grow without bound) is regularised instead,
// keeping constant fields exact.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <span>
#include <vector>

#include <Eigen/Dense>

#include "core/kernel.hpp"
#include "core/types.hpp"

namespace rktsph {

/// The gradient floor of method-notes eq. (3.2.6) applied to a row's moment matrix M (in the
/// units of h, where an interior row of a lattice has M = I): the Schur complement of the value
/// block, S = M_gg - M_g0 M_0g / M_00, is the renormalisation matrix of the Shepard-difference
/// gradient; each eigenvalue lambda_k of its symmetric part that lies below `floor` is raised to
/// it by M_gg += (floor - lambda_k) e_k e_k^T. The first column of M is untouched, so that
/// M^{-1} still maps a constant field to itself, and the directions the sources do span keep
/// their linear exactness (along a sheet one particle thick, say); rows the floor does not reach
/// are unchanged. Returns true if M was changed.
template <int Dim>
inline bool apply_gradient_floor(Eigen::Matrix<double, Dim + 1, Dim + 1>& M, double floor) {
  if (!(floor > 0.0) || !(M(0, 0) > 0.0)) return false;
  using MatD = Eigen::Matrix<double, Dim, Dim>;
  // Gershgorin's discs first, on M_00 S (no division): every eigenvalue of sym(S) lies above
  // min_i (S_ii - sum_j!=i |S_ij|), which settles the rows of a regular cloud (S near I).
  if constexpr (Dim > 1) {
    const double m00 = M(0, 0);
    double lower = std::numeric_limits<double>::infinity();
    for (int i = 0; i < Dim; ++i) {
      double radius = 0.0;
      for (int j = 0; j < Dim; ++j) {
        if (j == i) continue;
        radius += std::abs(
            0.5 * (m00 * (M(1 + i, 1 + j) + M(1 + j, 1 + i)) - M(1 + i, 0) * M(0, 1 + j) - M(1 + j, 0) * M(0, 1 + i)));
      }
      lower = std::min(lower, m00 * M(1 + i, 1 + i) - M(1 + i, 0) * M(0, 1 + i) - radius);
    }
    if (lower >= floor * m00) return false;
  }
  MatD S;
  for (int i = 0; i < Dim; ++i)
    for (int j = 0; j < Dim; ++j) S(i, j) = M(1 + i, 1 + j) - M(1 + i, 0) * M(0, 1 + j) / M(0, 0);
  const MatD sym = 0.5 * (S + S.transpose());
  if constexpr (Dim == 1) {
    if (!(sym(0, 0) < floor)) return false;
    M(1, 1) += floor - sym(0, 0);
    return true;
  } else {
    if constexpr (Dim == 2) {
      // The smaller eigenvalue in closed form next.
      const double mean = 0.5 * (sym(0, 0) + sym(1, 1)), half = 0.5 * (sym(0, 0) - sym(1, 1));
      if (!(mean - std::sqrt(half * half + sym(0, 1) * sym(0, 1)) < floor)) return false;
    }
    Eigen::SelfAdjointEigenSolver<MatD> eigen;
    eigen.computeDirect(sym);
    bool changed = false;
    for (int k = 0; k < Dim; ++k) {
      const double lambda = eigen.eigenvalues()(k);
      if (!(lambda < floor)) continue;
      const auto e = eigen.eigenvectors().col(k);
      M.template bottomRightCorner<Dim, Dim>() += (floor - lambda) * (e * e.transpose());
      changed = true;
    }
    return changed;
  }
}

template <int Dim>
class CorrectedRow {
 public:
  static constexpr int N = Dim + 1;

  /// The candidates of target xa (any order) with |x_a - x_b|^2 < r2, kept in candidate order,
  /// their basis and the moment matrix. `position` and `volume` are the sources' (indexed by
  /// the candidates); `gradient_floor` as in apply_gradient_floor (0: none). Returns false for a
  /// degenerate row. Allocates only while the work space grows.
  bool evaluate(std::span<const Index> candidates, const Vec<Dim>& xa, const Vec<Dim>* position, const double* volume,
                const CubicSplineKernel<Dim>& kernel, double r2, double gradient_floor = 0.0) {
    gather(candidates, xa, position, volume, r2);
    return moments(kernel, gradient_floor);
  }
  /// Whether the last row evaluated was regularised by the gradient floor.
  bool regularised() const { return regularised_; }
  /// Whether the last row evaluated was degenerate (Shepard and the plain gradient).
  bool degenerate() const { return !ok_; }

  std::size_t size() const { return n_; }
  /// The sources of the row, in candidate order.
  const Index* sources() const { return source_.data(); }

  /// The pair weights: interp[k] and grad[k] for the row's k = 0..size()-1.
  void weights(double* interp, std::array<double, Dim>* grad) const {
    const double* w[N];
    for (int i = 0; i < N; ++i) w[i] = basis_[i].data();
    if (ok_) {
#pragma omp simd
      for (std::size_t k = 0; k < n_; ++k) {
        double c[N];
        for (int i = 0; i < N; ++i) {
          c[i] = 0.0;
          for (int j = 0; j < N; ++j) c[i] += minv_[i][j] * w[j][k];
        }
        interp[k] = c[0];
        for (int d = 0; d < Dim; ++d) grad[k][static_cast<std::size_t>(d)] = c[d + 1] * inv_h_;
      }
    } else {
      for (std::size_t k = 0; k < n_; ++k) {
        interp[k] = shepard_ > 0.0 ? w[0][k] / shepard_ : 0.0;
        for (int d = 0; d < Dim; ++d) grad[k][static_cast<std::size_t>(d)] = w[1 + d][k] * inv_h_;
      }
    }
  }

  /// The value's pair weights alone, interp[k] as weights() writes it (Shepard's when
  /// degenerate): what a nodal filter needs to apply the row again after the step (method-notes
  /// eq. (2.3.4), with the operators on the fly).
  void value_weights(double* interp) const {
    const double* w[N];
    for (int i = 0; i < N; ++i) w[i] = basis_[i].data();
    if (ok_) {
#pragma omp simd
      for (std::size_t k = 0; k < n_; ++k) {
        double c = 0.0;
        for (int j = 0; j < N; ++j) c += minv_[0][j] * w[j][k];
        interp[k] = c;
      }
    } else {
      for (std::size_t k = 0; k < n_; ++k) interp[k] = shepard_ > 0.0 ? w[0][k] / shepard_ : 0.0;
    }
  }

  /// The corrected value (out[0]) and gradient (out[1 + d], d/dx_d) at the target of two fields
  /// of NA and NB values per source (`field_a` + NA b holds source b's), eq. (3.2.3) applied as
  /// M_a^{-1} sum_b w_b f_b, in one pass over the pairs (the state of V2's steps: velocity and
  /// stress), each pair's values summed as short vectors.
  template <int NA, int NB>
  void apply(const double* field_a, const double* field_b, double (&out_a)[N][NA], double (&out_b)[N][NB]) const {
    using VA = Eigen::Matrix<double, NA, 1>;
    using VB = Eigen::Matrix<double, NB, 1>;
    VA sa[N];
    VB sb[N];
    for (int i = 0; i < N; ++i) sa[i].setZero(), sb[i].setZero();
    for (std::size_t k = 0; k < n_; ++k) {
      const auto b = static_cast<std::size_t>(source_[k]);
      const Eigen::Map<const VA> fa(field_a + b * NA);
      const Eigen::Map<const VB> fb(field_b + b * NB);
      for (int i = 0; i < N; ++i) {
        const double wk = basis_[i][k];
        sa[i] += wk * fa;
        sb[i] += wk * fb;
      }
    }
    double s_a[N][NA], s_b[N][NB];
    for (int i = 0; i < N; ++i) {
      for (int j = 0; j < NA; ++j) s_a[i][j] = sa[i][j];
      for (int j = 0; j < NB; ++j) s_b[i][j] = sb[i][j];
    }
    finish<NA>(s_a, out_a);
    finish<NB>(s_b, out_b);
  }

  /// The corrected value alone of a field of nf values per source (the history variables).
  void interpolate(const double* field, int nf, double* out) const {
    for (int j = 0; j < nf; ++j) out[j] = 0.0;
    if (!ok_) {
      if (shepard_ <= 0.0) return;
      for (std::size_t k = 0; k < n_; ++k) {
        const double c = basis_[0][k] / shepard_;
        const double* f = field + static_cast<std::size_t>(source_[k]) * static_cast<std::size_t>(nf);
        for (int j = 0; j < nf; ++j) out[j] += c * f[j];
      }
      return;
    }
    // The value's row of M^{-1} folded into one weight per pair: M^{-1}_0j w_j,b.
    for (std::size_t k = 0; k < n_; ++k) {
      double c = 0.0;
      for (int i = 0; i < N; ++i) c += minv_[0][i] * basis_[i][k];
      const double* f = field + static_cast<std::size_t>(source_[k]) * static_cast<std::size_t>(nf);
      for (int j = 0; j < nf; ++j) out[j] += c * f[j];
    }
  }

 private:
  // Pairs are processed kLanes at a time, the last block padded with pairs of no volume (zero
  // weights): the loops then have no remainder, and their sums stay in vector registers (with a
  // remainder GCC spilled the nine sums of M: BM_V2Step 45.5 -> 43.5 ms, docs/VALIDATION.md).
  static constexpr std::size_t kLanes = 8;
  std::size_t padded() const { return (n_ + kLanes - 1) / kLanes * kLanes; }

  void reserve(std::size_t m) {
    m += kLanes;
    if (source_.size() >= m) return;
    source_.resize(m);
    for (auto& v : x_ab_) v.resize(m);
    d2_.resize(m);
    volume_.resize(m);
    for (auto& v : basis_) v.resize(m);
  }

  void gather(std::span<const Index> candidates, const Vec<Dim>& xa, const Vec<Dim>* position, const double* volume,
              double r2) {
    reserve(candidates.size());
    std::size_t count = 0;
    for (const Index b : candidates) {
      const auto bu = static_cast<std::size_t>(b);
      const Vec<Dim> x = xa - position[bu];
      const double s = x.squaredNorm();
      source_[count] = b;
      for (int d = 0; d < Dim; ++d) x_ab_[d][count] = x[d];
      d2_[count] = s;
      volume_[count] = volume[bu];
      count += s < r2 ? 1 : 0;
    }
    n_ = count;
    for (std::size_t k = count; k < padded(); ++k) {
      for (int d = 0; d < Dim; ++d) x_ab_[d][k] = 0.0;
      d2_[k] = 0.0;
      volume_[k] = 0.0;
    }
  }

  // The basis V_b [W_ab; h grad_a W_ab] (grad_a W_ab = W'/r x_ab) and
  // M = sum_b w_b (x) [1, (x_b - x_a)/h] (O(1) in these units); M^{-1} unless degenerate.
  bool moments(const CubicSplineKernel<Dim>& kernel, double gradient_floor) {
    using MatN = Eigen::Matrix<double, N, N>;
    inv_h_ = kernel.inv_h();
    const double inv_h = inv_h_, alpha = kernel.alpha();
    const std::size_t n = padded();
    const double* d2 = d2_.data();
    const double* V = volume_.data();
    const double* x[Dim];
    double* w[N];
    for (int d = 0; d < Dim; ++d) x[d] = x_ab_[d].data();
    for (int i = 0; i < N; ++i) w[i] = basis_[i].data();
    // Block by block of kLanes pairs, each a vector operation; the sums of M kept per lane
    // and added up at the end.
    double m[N][N][kLanes] = {};
    for (std::size_t k0 = 0; k0 < n; k0 += kLanes) {
#pragma omp simd
      for (std::size_t l = 0; l < kLanes; ++l) {
        const std::size_t k = k0 + l;
        double W, g;
        CubicSplineKernel<Dim>::value_and_scaled_derivative(std::sqrt(d2[k]), inv_h, alpha, W, g);
        double wk[N];
        wk[0] = V[k] * W;
        for (int d = 0; d < Dim; ++d) wk[1 + d] = V[k] * g * x[d][k];
        for (int i = 0; i < N; ++i) {
          w[i][k] = wk[i];
          m[i][0][l] += wk[i];
          for (int d = 0; d < Dim; ++d) m[i][1 + d][l] += wk[i] * x[d][k];
        }
      }
    }
    // M = sum_b w (x) [1, (x_b - x_a)/h], O(1) in these units.
    MatN M;
    for (int i = 0; i < N; ++i) {
      for (int j = 0; j < N; ++j) {
        double sum = 0.0;
        for (std::size_t l = 0; l < kLanes; ++l) sum += m[i][j][l];
        M(i, j) = j == 0 ? sum : -sum * inv_h;
      }
    }
    shepard_ = M(0, 0);
    regularised_ = apply_gradient_floor<Dim>(M, gradient_floor);
    if constexpr (N == 3) {
      // By cofactors, the determinant from the same ones: Eigen's determinant() and inverse()
      // computed it twice (about a sixth of the V2 step in a perf profile of BM_V2Step).
      const double c00 = M(1, 1) * M(2, 2) - M(1, 2) * M(2, 1);
      const double c01 = M(1, 2) * M(2, 0) - M(1, 0) * M(2, 2);
      const double c02 = M(1, 0) * M(2, 1) - M(1, 1) * M(2, 0);
      const double det = M(0, 0) * c00 + M(0, 1) * c01 + M(0, 2) * c02;
      ok_ = n > 0 && std::abs(det) > 1e-8;
      if (ok_) {
        const double r = 1.0 / det;
        minv_[0][0] = c00 * r;
        minv_[1][0] = c01 * r;
        minv_[2][0] = c02 * r;
        minv_[0][1] = (M(0, 2) * M(2, 1) - M(0, 1) * M(2, 2)) * r;
        minv_[1][1] = (M(0, 0) * M(2, 2) - M(0, 2) * M(2, 0)) * r;
        minv_[2][1] = (M(0, 1) * M(2, 0) - M(0, 0) * M(2, 1)) * r;
        minv_[0][2] = (M(0, 1) * M(1, 2) - M(0, 2) * M(1, 1)) * r;
        minv_[1][2] = (M(0, 2) * M(1, 0) - M(0, 0) * M(1, 2)) * r;
        minv_[2][2] = (M(0, 0) * M(1, 1) - M(0, 1) * M(1, 0)) * r;
      }
    } else {
      ok_ = n > 0 && std::abs(M.determinant()) > 1e-8;
      if (ok_) {
        const MatN Minv = M.inverse();
        for (int i = 0; i < N; ++i)
          for (int j = 0; j < N; ++j) minv_[i][j] = Minv(i, j);
      }
    }
    return ok_;
  }

  // out = M^{-1} s with the gradient rows back in 1/m; Shepard and the plain gradient when
  // degenerate.
  template <int NF>
  void finish(const double (&s)[N][NF], double (&out)[N][NF]) const {
    if (ok_) {
      for (int i = 0; i < N; ++i) {
        const double scale = i == 0 ? 1.0 : inv_h_;
        for (int j = 0; j < NF; ++j) {
          double v = 0.0;
          for (int q = 0; q < N; ++q) v += minv_[i][q] * s[q][j];
          out[i][j] = v * scale;
        }
      }
      return;
    }
    for (int j = 0; j < NF; ++j) out[0][j] = shepard_ > 0.0 ? s[0][j] / shepard_ : 0.0;
    for (int i = 1; i < N; ++i)
      for (int j = 0; j < NF; ++j) out[i][j] = s[i][j] * inv_h_;
  }

  std::vector<Index> source_;
  std::vector<double> x_ab_[Dim];  // x_a - x_b
  std::vector<double> d2_;         // |x_a - x_b|^2
  std::vector<double> volume_;
  std::vector<double> basis_[N];  // V_b [W_ab; h grad_a W_ab]
  std::size_t n_ = 0;
  double minv_[N][N] = {};
  double shepard_ = 0.0, inv_h_ = 0.0;
  bool ok_ = false;
  bool regularised_ = false;
};

}  // namespace rktsph
