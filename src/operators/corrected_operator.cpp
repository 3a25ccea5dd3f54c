#include "operators/corrected_operator.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <unordered_map>

#include <Eigen/Dense>

#include "core/error.hpp"
#include "core/execution.hpp"
#include "neighbours/cell_list.hpp"
#include "operators/corrected_row.hpp"
#include "operators/row_pairs.hpp"

namespace rktsph {

using detail::Pair;
using detail::row_pairs;

namespace {

// Rows are assembled in fixed blocks: each block finds its own patterns (in parallel), then the
// blocks are merged in order. The patterns, and so the weights every row ends up with, are
// therefore the same whatever the number of threads (tests/solvers/test_threads.cpp).
constexpr Index kBuildBlock = 1024;

// Sources within this fraction of 2h of the edge of the support are left out. Their weights are
// below 1e-19 of the row's (W ~ (2 - q)^3, grad W ~ (2 - q)^2), so the operator is unchanged to
// round-off; but when 2h is a multiple of a lattice distance (h/dx = 1 or 1.5 for node-node
// pairs) such sources lie exactly on the edge, and round-off in the positions would keep them in
// some rows of a class and not in others, splitting the class into many patterns.
constexpr double kSupportGap = 1e-10;

inline std::uint64_t hash_mix(std::uint64_t h, std::uint64_t v) {
  h ^= v + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
  return h * 0xbf58476d1ce4e5b9ULL;
}

// The geometry of one row, which alone fixes its weights: per source (sorted by index) the
// offset from the row's first source, (x_b - x_a)/h and V_b.
template <int Dim>
struct RowGeometry {
  static constexpr std::size_t G = Dim + 1;  // doubles of geometry per pair
  std::vector<Pair<Dim>> pairs;
  std::vector<Index> offset;
  std::vector<double> geometry;
  std::uint64_t key = 0;

  // Offsets and geometry, and a hash of the offsets, of the first source's position (rounded to
  // 2^-20 h) and of the sum of the volumes (20 bits of mantissa): coarse enough that round-off
  // almost never changes it (a row that does land in another bucket only gets a pattern of its
  // own, which is still correct), fine enough that different rows (jittered sets) rarely share a
  // bucket. The full geometry is compared on a hash hit (PatternTable::find).
  void finish(const ParticleSet<Dim>& sources, double h) {
    const std::size_t n = pairs.size();
    offset.resize(n);
    geometry.resize(n * G);
    std::uint64_t k = n;
    double volume = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const Pair<Dim>& p = pairs[i];
      offset[i] = p.b - pairs[0].b;
      k = k * 0x9e3779b97f4a7c15ULL + static_cast<std::uint64_t>(offset[i]);
      for (int d = 0; d < Dim; ++d) geometry[i * G + static_cast<std::size_t>(d)] = -p.x_ab[d] / h;
      const double V = sources.volume[static_cast<std::size_t>(p.b)];
      geometry[i * G + Dim] = V;
      volume += V;
    }
    for (std::size_t d = 0; d < (n > 0 ? static_cast<std::size_t>(Dim) : 0); ++d) {
      // Round to nearest by truncation of q +- 1/2 (inline, unlike llround).
      const double q = geometry[d] * 1048576.0;
      k = hash_mix(k, static_cast<std::uint64_t>(static_cast<std::int64_t>(q < 0.0 ? q - 0.5 : q + 0.5)));
    }
    key = hash_mix(k, std::bit_cast<std::uint64_t>(volume) >> 32);
  }
};

// Patterns under construction (one table per block, and the merged one), with their geometry
// and a hash index on it.
template <int Dim>
struct PatternTable {
  static constexpr std::size_t G = Dim + 1;
  std::vector<Index> start{0};
  std::vector<Index> offset;
  std::vector<double> geometry;
  std::vector<double> interp;
  std::vector<std::array<double, Dim>> grad;
  std::vector<char> flags;  // per pattern: 1 degenerate, 2 regularised by the gradient floor
  std::vector<std::uint64_t> key;
  std::vector<Index> next_same_key;  // chain of the patterns that share a hash
  std::unordered_map<std::uint64_t, Index> head;

  Index size() const { return static_cast<Index>(start.size()) - 1; }

  // Pattern whose offsets equal `off` and whose geometry matches `geo` within the tolerances,
  // or -1.
  Index find(std::uint64_t k, const Index* off, const double* geo, std::size_t n, double tol_x, double tol_v) const {
    const auto it = head.find(k);
    if (it == head.end()) return -1;
    for (Index p = it->second; p >= 0; p = next_same_key[static_cast<std::size_t>(p)]) {
      const auto b = static_cast<std::size_t>(start[static_cast<std::size_t>(p)]);
      const auto e = static_cast<std::size_t>(start[static_cast<std::size_t>(p) + 1]);
      if (e - b != n || !std::equal(off, off + n, offset.begin() + static_cast<std::ptrdiff_t>(b))) continue;
      bool same = true;
      for (std::size_t i = 0; i < n && same; ++i) {
        const double* g = &geometry[(b + i) * G];
        for (int d = 0; d < Dim; ++d) same = same && std::abs(g[d] - geo[i * G + static_cast<std::size_t>(d)]) <= tol_x;
        same = same &&
               std::abs(g[Dim] - geo[i * G + Dim]) <= tol_v * std::max(std::abs(g[Dim]), std::abs(geo[i * G + Dim]));
      }
      if (same) return p;
    }
    return -1;
  }

  // Append a pattern (its weights in interp/grad[first, first + n) of `w`); returns its id.
  Index add(std::uint64_t k, const Index* off, const double* geo, std::size_t n, const double* wi,
            const std::array<double, Dim>* wg, char pattern_flags, bool index) {
    const Index id = size();
    offset.insert(offset.end(), off, off + n);
    geometry.insert(geometry.end(), geo, geo + n * G);
    interp.insert(interp.end(), wi, wi + n);
    grad.insert(grad.end(), wg, wg + n);
    start.push_back(static_cast<Index>(offset.size()));
    flags.push_back(pattern_flags);
    key.push_back(k);
    next_same_key.push_back(-1);
    if (index) {
      // New patterns go to the end of their chain, so that find() returns the earliest match.
      const auto [it, inserted] = head.try_emplace(k, id);
      if (!inserted) {
        Index p = it->second;
        while (next_same_key[static_cast<std::size_t>(p)] >= 0) p = next_same_key[static_cast<std::size_t>(p)];
        next_same_key[static_cast<std::size_t>(p)] = id;
      }
    }
    return id;
  }
};

// The weights M_a^{-1} V_b [W_ab; h grad_a W_ab] of one row (method-notes §3.2), in units of h so
// that the (n_d+1) system is well scaled, with the gradient floor of eq. (3.2.6). Returns 1 if
// the row is degenerate, 2 if the floor regularised it, 0 otherwise.
template <int Dim>
char row_weights(const std::vector<Pair<Dim>>& pairs, const ParticleSet<Dim>& sources,
                 const CubicSplineKernel<Dim>& kernel, double gradient_floor,
                 std::vector<Eigen::Matrix<double, Dim + 1, 1>>& basis, std::vector<double>& wi,
                 std::vector<std::array<double, Dim>>& wg) {
  constexpr int N = Dim + 1;
  using MatN = Eigen::Matrix<double, N, N>;
  using VecN = Eigen::Matrix<double, N, 1>;
  const double h = kernel.h();
  const std::size_t n = pairs.size();
  MatN M = MatN::Zero();
  basis.resize(n);
  wi.resize(n);
  wg.resize(n);
  double shepard = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const auto& p = pairs[k];
    const double V = sources.volume[static_cast<std::size_t>(p.b)];
    VecN w;
    w[0] = V * kernel.value(p.r);
    w.template tail<Dim>() = V * h * kernel.gradient(p.x_ab);
    VecN dx;
    dx[0] = 1.0;
    dx.template tail<Dim>() = -p.x_ab / h;  // (x_b - x_a)/h
    M += w * dx.transpose();
    basis[k] = w;
    shepard += w[0];
  }
  const bool regularised = apply_gradient_floor<Dim>(M, gradient_floor);
  // M is O(1) in these units; a tiny determinant means too few or collinear sources.
  const bool ok = n > 0 && std::abs(M.determinant()) > 1e-8;
  const MatN Minv = ok ? MatN(M.inverse()) : MatN::Identity();
  for (std::size_t k = 0; k < n; ++k) {
    VecN c;
    if (ok) {
      c = Minv * basis[k];
    } else {
      // Too few sources for the corrected system: Shepard interpolation and the plain
      // kernel gradient (method-notes §3.2 guard).
      c = basis[k];
      c[0] = shepard > 0.0 ? basis[k][0] / shepard : 0.0;
    }
    wi[k] = c[0];
    for (int d = 0; d < Dim; ++d) wg[k][static_cast<std::size_t>(d)] = c[d + 1] / h;
  }
  return !ok ? 1 : regularised ? 2 : 0;
}

}  // namespace

template <int Dim>
CorrectedOperator<Dim> build_corrected_operator(const Relation<Dim>& relation, const std::vector<Vec<Dim>>& targets,
                                                const ParticleSet<Dim>& sources, const CubicSplineKernel<Dim>& kernel,
                                                const OperatorOptions& options) {
  constexpr std::size_t G = Dim + 1;
  const double h = kernel.h();
  const auto nt = static_cast<Index>(targets.size());
  if (relation.rows() != nt || !relation.options().sorted) {
    throw SolverError("corrected operator: the relation must have one sorted row per target");
  }
  const bool share = options.share_patterns;

  // Geometry tolerances for sharing a pattern. Lattice positions origin + i dx carry round-off
  // of an ulp of the largest coordinate, so relative positions of two rows of one class differ
  // by that much: accept a few ulps of it (in units of h), and 1e-12 h in any case. Volumes are
  // products of dx and exact fractions: relative 1e-12. The weights of rows that share a
  // pattern then differ from their own by round-off of the positions (the tests check 1e-12).
  double xmax = 0.0;
  for (const auto& x : targets) xmax = std::max(xmax, x.cwiseAbs().maxCoeff());
  for (const auto& x : sources.position) xmax = std::max(xmax, x.cwiseAbs().maxCoeff());
  const double tol_x = 1e-12 + 4.0 * std::numeric_limits<double>::epsilon() * xmax / h;
  const double tol_v = 1e-12;

  const Index nblocks = (nt + kBuildBlock - 1) / kBuildBlock;
  std::vector<PatternTable<Dim>> local(static_cast<std::size_t>(nblocks));
  std::vector<Index> base(static_cast<std::size_t>(nt)), pattern(static_cast<std::size_t>(nt));

  exec::particle_for(
      exec::Threads{}, nblocks,
      [&](Index blk) {
        RowGeometry<Dim> row;
        std::vector<Eigen::Matrix<double, Dim + 1, 1>> basis;
        std::vector<double> wi;
        std::vector<std::array<double, Dim>> wg;
        PatternTable<Dim>& table = local[static_cast<std::size_t>(blk)];
        const Index end = std::min(nt, (blk + 1) * kBuildBlock);
        for (Index a = blk * kBuildBlock; a < end; ++a) {
          const auto au = static_cast<std::size_t>(a);
          row_pairs(relation, a, targets[au], sources, row.pairs);
          row.finish(sources, h);
          const std::size_t n = row.pairs.size();
          base[au] = n > 0 ? row.pairs[0].b : 0;
          Index p = share ? table.find(row.key, row.offset.data(), row.geometry.data(), n, tol_x, tol_v) : -1;
          if (p < 0) {
            // A new geometry: its weights are computed once, here.
            const char flags = row_weights<Dim>(row.pairs, sources, kernel, options.gradient_floor, basis, wi, wg);
            p = table.add(row.key, row.offset.data(), row.geometry.data(), n, wi.data(), wg.data(), flags, share);
          }
          pattern[au] = p;
        }
      },
      exec::Schedule::dynamic, nt);

  // Merge the blocks in order: a block's pattern joins the first matching pattern of the
  // blocks before it.
  PatternTable<Dim> all;
  std::vector<Index> map;
  for (Index blk = 0; blk < nblocks; ++blk) {
    PatternTable<Dim>& table = local[static_cast<std::size_t>(blk)];
    map.assign(static_cast<std::size_t>(table.size()), -1);
    for (Index q = 0; q < table.size(); ++q) {
      const auto qu = static_cast<std::size_t>(q);
      const auto b = static_cast<std::size_t>(table.start[qu]);
      const auto n = static_cast<std::size_t>(table.start[qu + 1]) - b;
      Index g = share ? all.find(table.key[qu], &table.offset[b], &table.geometry[b * G], n, tol_x, tol_v) : -1;
      if (g < 0) {
        g = all.add(table.key[qu], &table.offset[b], &table.geometry[b * G], n, &table.interp[b], &table.grad[b],
                    table.flags[qu], share);
      }
      map[qu] = g;
    }
    const Index end = std::min(nt, (blk + 1) * kBuildBlock);
    for (Index a = blk * kBuildBlock; a < end; ++a)
      pattern[static_cast<std::size_t>(a)] = map[static_cast<std::size_t>(pattern[static_cast<std::size_t>(a)])];
    table = PatternTable<Dim>();  // release the block's storage as we go
  }

  CorrectedOperator<Dim> op;
  op.base = std::move(base);
  op.pattern = std::move(pattern);
  op.pattern_start = std::move(all.start);
  op.offset = std::move(all.offset);
  op.interp = std::move(all.interp);
  op.grad = std::move(all.grad);
  op.run_start.push_back(0);
  for (Index a = 1; a < nt; ++a) {
    const auto au = static_cast<std::size_t>(a);
    if (a - op.run_start.back() >= CorrectedOperator<Dim>::kMaxRun || op.pattern[au] != op.pattern[au - 1] ||
        op.base[au] != op.base[au - 1] + 1) {
      op.run_start.push_back(a);
    }
  }
  if (nt > 0) op.run_start.push_back(nt);
  for (Index a = 0; a < nt; ++a) {
    const auto p = static_cast<std::size_t>(op.pattern[static_cast<std::size_t>(a)]);
    op.pair_count += static_cast<std::size_t>(op.pattern_start[p + 1] - op.pattern_start[p]);
    if (all.flags[p] == 1) ++op.degenerate_rows;
    if (all.flags[p] == 2) ++op.regularised_rows;
  }
  op.row_kind = std::move(all.flags);
  return op;
}

template <int Dim>
RelationOptions operator_relation_options(const CubicSplineKernel<Dim>& kernel) {
  // Half-radius cells: 30 % fewer candidates to test than radius-sized ones (2D).
  return {kernel.support_radius() * (1.0 - kSupportGap), 2, true};
}

template <int Dim>
CorrectedOperator<Dim> build_corrected_operator(const std::vector<Vec<Dim>>& targets, const ParticleSet<Dim>& sources,
                                                const CubicSplineKernel<Dim>& kernel, const OperatorOptions& options) {
  Relation<Dim> relation;
  relation.build(targets, sources.position, operator_relation_options(kernel));
  return build_corrected_operator(relation, targets, sources, kernel, options);
}

template <int Dim>
void rebuild_corrected_operator(const Relation<Dim>& candidates, const std::vector<Vec<Dim>>& targets,
                                const ParticleSet<Dim>& sources, const CubicSplineKernel<Dim>& kernel,
                                CorrectedOperator<Dim>& op, const exec::Threads& policy, double gradient_floor) {
  const auto nt = static_cast<Index>(targets.size());
  if (candidates.rows() != nt || !candidates.options().sorted) {
    throw SolverError("corrected operator: the candidate relation must have one sorted row per target");
  }
  const double r_max = kernel.support_radius() * (1.0 - kSupportGap);
  const double r2 = r_max * r_max;
  // Pass 1: the pairs of every row, and the CSR starts.
  op.base.resize(static_cast<std::size_t>(nt));
  op.pattern.resize(static_cast<std::size_t>(nt));
  op.pattern_start.resize(static_cast<std::size_t>(nt) + 1);
  op.pattern_start[0] = 0;
  exec::particle_for(policy, nt, [&](Index a) {
    Index n = 0;
    const Vec<Dim>& xa = targets[static_cast<std::size_t>(a)];
    for (const Index b : candidates.row(a))
      n += (xa - sources.position[static_cast<std::size_t>(b)]).squaredNorm() < r2 ? 1 : 0;
    op.pattern_start[static_cast<std::size_t>(a) + 1] = n;
  });
  for (Index a = 0; a < nt; ++a) {
    op.pattern_start[static_cast<std::size_t>(a) + 1] += op.pattern_start[static_cast<std::size_t>(a)];
    op.pattern[static_cast<std::size_t>(a)] = a;
  }
  const auto pairs = static_cast<std::size_t>(op.pattern_start.back());
  op.offset.resize(pairs);
  op.row_kind.assign(static_cast<std::size_t>(nt), 0);
  op.interp.resize(pairs);
  op.grad.resize(pairs);
  // Pass 2: the weights, row by row (method-notes §3.2), in fixed blocks of rows.
  const Index nblocks = (nt + kBuildBlock - 1) / kBuildBlock;
  std::atomic<bool> mismatch{false};
  exec::particle_for(
      policy, nblocks,
      [&](Index blk) {
        // Work space of this thread, kept from call to call (no allocation once grown).
        static thread_local CorrectedRow<Dim> row;
        const Index end = std::min(nt, (blk + 1) * kBuildBlock);
        for (Index a = blk * kBuildBlock; a < end; ++a) {
          const auto au = static_cast<std::size_t>(a);
          // The row's kind as row_weights gives it for a stored build: degenerate before regularised.
          const bool ok = row.evaluate(candidates.row(a), targets[au], sources.position.data(), sources.volume.data(),
                                       kernel, r2, gradient_floor);
          op.row_kind[au] = !ok ? 1 : row.regularised() ? 2 : 0;
          const auto k0 = static_cast<std::size_t>(op.pattern_start[au]);
          if (row.size() != static_cast<std::size_t>(op.pattern_start[au + 1]) - k0) {
            mismatch.store(true, std::memory_order_relaxed);
            continue;
          }
          row.weights(&op.interp[k0], &op.grad[k0]);
          const Index* src = row.sources();
          const Index b0 = row.size() > 0 ? src[0] : 0;
          op.base[au] = b0;
          for (std::size_t j = 0; j < row.size(); ++j) op.offset[k0 + j] = src[j] - b0;
        }
      },
      exec::Schedule::dynamic, nt);
  if (mismatch.load()) {
    throw SolverError("corrected operator: the two passes of the rebuild counted different pairs (a bug)");
  }
  // One row per run: the rows share no pattern.
  op.run_start.resize(static_cast<std::size_t>(nt) + 1);
  for (Index a = 0; a <= nt; ++a) op.run_start[static_cast<std::size_t>(a)] = a;
  op.pair_count = pairs;
  op.degenerate_rows = static_cast<Index>(std::count(op.row_kind.begin(), op.row_kind.end(), 1));
  op.regularised_rows = static_cast<Index>(std::count(op.row_kind.begin(), op.row_kind.end(), 2));
}

namespace {

// The least-squares basis of eq. (2.4.18) in units of h, xi = (x_b - x_a)/h: [1, xi_d,
// xi_d xi_e (d <= e)] (Q terms) and, on a lattice, the odd-even mode (-1)^(sum_d i_d), i_d the
// lattice offset of b from a.
template <int Dim>
struct QuadraticBasis {
  static constexpr int Q = 1 + Dim + Dim * (Dim + 1) / 2;
  static constexpr int Modes = (1 << Dim) - 1;  // (-1)^(sum over a non-empty subset of axes)
  static constexpr int QMax = Q + Modes;
  using Mat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, QMax, QMax>;
  using Vec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, QMax, 1>;
  double h;
  double spacing;          // 0: no odd-even column
  bool all_modes = false;  // false: the diagonal mode (every axis) only
  int modes() const { return spacing > 0.0 ? (all_modes ? Modes : 1) : 0; }
  int size() const { return Q + modes(); }
  Vec operator()(const rktsph::Vec<Dim>& x_ba) const {
    Vec p(size());
    const rktsph::Vec<Dim> xi = x_ba / h;
    p[0] = 1.0;
    int m = 1;
    for (int d = 0; d < Dim; ++d) p[m++] = xi[d];
    for (int d = 0; d < Dim; ++d) {
      for (int e = d; e < Dim; ++e) p[m++] = xi[d] * xi[e];
    }
    if (spacing > 0.0) {
      long offset[Dim];
      for (int d = 0; d < Dim; ++d) offset[d] = std::lround(x_ba[d] / spacing);
      // The diagonal mode first (subset = every axis), then the others.
      for (int subset = (1 << Dim) - 1; subset >= 1 && m < size(); --subset) {
        long parity = 0;
        for (int d = 0; d < Dim; ++d) parity += (subset >> d & 1) != 0 ? offset[d] : 0;
        p[m++] = parity % 2 == 0 ? 1.0 : -1.0;
      }
    }
    return p;
  }
  // (sum_b w_b P_b P_b^T)^{-1} over row r of op, w_b = V_b W_ab; false if the sources do not
  // determine the fit (smallest eigenvalue below 1e-10 of the largest: too few, or on a line).
  bool inverse_moments(const CorrectedOperator<Dim>& op, const typename CorrectedOperator<Dim>::Row& r,
                       const rktsph::Vec<Dim>& xa, const ParticleSet<Dim>& sources,
                       const CubicSplineKernel<Dim>& kernel, Mat& inverse) const {
    Mat M = Mat::Zero(size(), size());
    for (Index k = r.begin; k < r.end; ++k) {
      const auto b = static_cast<std::size_t>(op.source(r, k));
      const Vec pb = (*this)(sources.position[b] - xa);
      M += sources.volume[b] * kernel.value((sources.position[b] - xa).norm()) * pb * pb.transpose();
    }
    const Eigen::SelfAdjointEigenSolver<Mat> eig(M);
    const double lmax = eig.eigenvalues().maxCoeff(), lmin = eig.eigenvalues().minCoeff();
    if (!(lmax > 0.0) || lmin < 1e-10 * lmax) return false;
    inverse = eig.eigenvectors() * eig.eigenvalues().cwiseInverse().asDiagonal() * eig.eigenvectors().transpose();
    return true;
  }
};

}  // namespace

template <int Dim>
CorrectedOperator<Dim> quadratic_exact_gradient(const CorrectedOperator<Dim>& op, const std::vector<Vec<Dim>>& targets,
                                                const ParticleSet<Dim>& sources, const CubicSplineKernel<Dim>& kernel,
                                                double lattice_spacing, const std::vector<char>* fit_rows,
                                                Index* replaced) {
  // The fit of eq. (2.4.18); the odd-even column keeps the fitted gradient blind to that mode,
  // as a full support's symmetric one is.
  using Basis = QuadraticBasis<Dim>;
  const Basis basis{kernel.h(), lattice_spacing};
  const int nb = basis.size();
  const double h = kernel.h();
  CorrectedOperator<Dim> out = op;
  const Index np = op.patterns();
  auto selected = [&](Index a) { return fit_rows == nullptr || (*fit_rows)[static_cast<std::size_t>(a)] != 0; };
  // Per pattern, a representative among the selected rows, and whether unselected rows share it.
  std::vector<Index> representative(static_cast<std::size_t>(np), -1);
  std::vector<char> mixed(static_cast<std::size_t>(np), 0);
  for (Index a = 0; a < op.rows(); ++a) {
    const auto p = static_cast<std::size_t>(op.pattern[static_cast<std::size_t>(a)]);
    if (selected(a)) {
      if (representative[p] < 0) representative[p] = a;
    } else {
      mixed[p] = 1;
    }
  }
  // A pattern shared by selected and unselected rows is split: the selected rows move to a copy
  // of it, fitted below (rows then run one by one: the runs of op assume one pattern per run).
  std::vector<Index> moved_to(static_cast<std::size_t>(np), -1);
  for (Index p = 0; p < np; ++p) {
    if (representative[static_cast<std::size_t>(p)] < 0 || mixed[static_cast<std::size_t>(p)] == 0) continue;
    const Index begin = op.pattern_start[static_cast<std::size_t>(p)],
                end = op.pattern_start[static_cast<std::size_t>(p) + 1];
    moved_to[static_cast<std::size_t>(p)] = out.patterns();
    // The copy keeps its pattern's kind (row_kind has one entry per pattern).
    if (!op.row_kind.empty()) out.row_kind.push_back(op.row_kind[static_cast<std::size_t>(p)]);
    for (Index k = begin; k < end; ++k) {
      out.offset.push_back(op.offset[static_cast<std::size_t>(k)]);
      out.interp.push_back(op.interp[static_cast<std::size_t>(k)]);
      out.grad.push_back(op.grad[static_cast<std::size_t>(k)]);
    }
    out.pattern_start.push_back(static_cast<Index>(out.offset.size()));
  }
  if (fit_rows != nullptr) {
    for (Index a = 0; a < op.rows(); ++a) {
      const auto p = static_cast<std::size_t>(op.pattern[static_cast<std::size_t>(a)]);
      if (moved_to[p] >= 0 && selected(a)) out.pattern[static_cast<std::size_t>(a)] = moved_to[p];
    }
    out.run_start.resize(static_cast<std::size_t>(op.rows()) + 1);
    for (Index a = 0; a <= op.rows(); ++a) out.run_start[static_cast<std::size_t>(a)] = a;
  }
  std::vector<char> fitted(static_cast<std::size_t>(np), 0);
  for (Index p = 0; p < np; ++p) {
    const Index a = representative[static_cast<std::size_t>(p)];
    if (a < 0) continue;
    const auto r = op.row(a);
    const Vec<Dim>& xa = targets[static_cast<std::size_t>(a)];
    // op's own weights are kept where they are exact for the quadratics and blind to the odd-even
    // mode (sum_b h g_ab,d m(xi_b) = 0 for those basis terms m, to round-off): a full support.
    double defect = 0.0;
    for (int d = 0; d < Dim; ++d) {
      typename Basis::Vec moment = Basis::Vec::Zero(nb);
      for (Index k = r.begin; k < r.end; ++k) {
        moment += h * op.grad[static_cast<std::size_t>(k)][static_cast<std::size_t>(d)] *
                  basis(sources.position[static_cast<std::size_t>(op.source(r, k))] - xa);
      }
      defect = std::max(defect, moment.tail(nb - 1 - Dim).cwiseAbs().maxCoeff());
    }
    if (defect < 1e-9) continue;
    typename Basis::Mat Minv;
    if (!basis.inverse_moments(op, r, xa, sources, kernel, Minv)) continue;
    const Index shift =
        moved_to[static_cast<std::size_t>(p)] >= 0
            ? out.pattern_start[static_cast<std::size_t>(moved_to[static_cast<std::size_t>(p)])] - r.begin
            : 0;
    for (Index k = r.begin; k < r.end; ++k) {
      const auto b = static_cast<std::size_t>(op.source(r, k));
      const double w = sources.volume[b] * kernel.value((sources.position[b] - xa).norm());
      const typename Basis::Vec c = Minv * basis(sources.position[b] - xa) * w;
      for (int d = 0; d < Dim; ++d) {
        out.grad[static_cast<std::size_t>(k + shift)][static_cast<std::size_t>(d)] = c[1 + d] / h;
      }
    }
    fitted[static_cast<std::size_t>(p)] = 1;
  }
  if (replaced != nullptr) {
    *replaced = 0;
    for (Index a = 0; a < op.rows(); ++a) {
      if (selected(a)) *replaced += fitted[static_cast<std::size_t>(op.pattern[static_cast<std::size_t>(a)])];
    }
  }
  return out;
}

template <int Dim>
std::vector<double> odd_even_amplitude(const CorrectedOperator<Dim>& op, const std::vector<Vec<Dim>>& targets,
                                       const ParticleSet<Dim>& sources, const CubicSplineKernel<Dim>& kernel,
                                       double lattice_spacing, Index* undetermined) {
  if (!(lattice_spacing > 0.0)) throw SolverError("odd-even amplitude: needs the lattice spacing");
  using Basis = QuadraticBasis<Dim>;
  const Basis basis{kernel.h(), lattice_spacing, true};
  // One weight per pair slot of op: rows that share a pattern share their geometry, hence their
  // weights, so op's patterns index these as they index op's own.
  std::vector<double> weight(op.interp.size(), 0.0);
  const Index np = op.patterns();
  std::vector<Index> representative(static_cast<std::size_t>(np), -1);
  for (Index a = 0; a < op.rows(); ++a) {
    Index& r = representative[static_cast<std::size_t>(op.pattern[static_cast<std::size_t>(a)])];
    if (r < 0) r = a;
  }
  std::vector<char> determined(static_cast<std::size_t>(np), 0);
  for (Index p = 0; p < np; ++p) {
    const Index a = representative[static_cast<std::size_t>(p)];
    if (a < 0) continue;
    const auto r = op.row(a);
    const Vec<Dim>& xa = targets[static_cast<std::size_t>(a)];
    // The amplitude weights: the sum of the odd-even coefficients of the fit (each mode is 1 at
    // the target), so that a_a = p_a on a pure mode. Where the sources span fewer than three
    // lattice levels beyond the target along an axis (rows next to a face), the mode along that
    // axis is a parabola there (1, -1, 1 = 1 - 4i + 2i^2) and the full fit is singular: such a
    // row takes the diagonal mode alone (it is no null mode of the one-sided operators anyway).
    // A guard against rows where a mode is barely separable from the quadratics: sum |w| > 4,
    // a would amplify the other content.
    auto try_fit = [&](const Basis& fit) {
      typename Basis::Mat Minv;
      if (!fit.inverse_moments(op, r, xa, sources, kernel, Minv)) return false;
      double total = 0.0;
      for (Index k = r.begin; k < r.end; ++k) {
        const auto b = static_cast<std::size_t>(op.source(r, k));
        const double w = sources.volume[b] * kernel.value((sources.position[b] - xa).norm());
        const double c = (Minv * fit(sources.position[b] - xa)).tail(fit.modes()).sum() * w;
        weight[static_cast<std::size_t>(k)] = c;
        total += std::abs(c);
      }
      if (total <= 4.0) return true;
      for (Index k = r.begin; k < r.end; ++k) weight[static_cast<std::size_t>(k)] = 0.0;
      return false;
    };
    if (!try_fit(basis) && !try_fit(Basis{kernel.h(), lattice_spacing, false})) continue;
    determined[static_cast<std::size_t>(p)] = 1;
  }
  if (undetermined != nullptr) {
    *undetermined = 0;
    for (Index a = 0; a < op.rows(); ++a) {
      *undetermined += determined[static_cast<std::size_t>(op.pattern[static_cast<std::size_t>(a)])] == 0 ? 1 : 0;
    }
  }
  return weight;
}

#define RKTSPH_INSTANTIATE(D)                                                                                        \
  template RelationOptions operator_relation_options<D>(const CubicSplineKernel<D>&);                                \
  template CorrectedOperator<D> build_corrected_operator<D>(const Relation<D>&, const std::vector<Vec<D>>&,          \
                                                            const ParticleSet<D>&, const CubicSplineKernel<D>&,      \
                                                            const OperatorOptions&);                                 \
  template CorrectedOperator<D> build_corrected_operator<D>(const std::vector<Vec<D>>&, const ParticleSet<D>&,       \
                                                            const CubicSplineKernel<D>&, const OperatorOptions&);    \
  template void rebuild_corrected_operator<D>(const Relation<D>&, const std::vector<Vec<D>>&, const ParticleSet<D>&, \
                                              const CubicSplineKernel<D>&, CorrectedOperator<D>&,                    \
                                              const exec::Threads&, double);                                         \
  template CorrectedOperator<D> quadratic_exact_gradient<D>(const CorrectedOperator<D>&, const std::vector<Vec<D>>&, \
                                                            const ParticleSet<D>&, const CubicSplineKernel<D>&,      \
                                                            double, const std::vector<char>*, Index*);               \
  template std::vector<double> odd_even_amplitude<D>(const CorrectedOperator<D>&, const std::vector<Vec<D>>&,        \
                                                     const ParticleSet<D>&, const CubicSplineKernel<D>&, double,     \
                                                     Index*);
RKTSPH_INSTANTIATE(1)
RKTSPH_INSTANTIATE(2)
RKTSPH_INSTANTIATE(3)
#undef RKTSPH_INSTANTIATE

}  // namespace rktsph
