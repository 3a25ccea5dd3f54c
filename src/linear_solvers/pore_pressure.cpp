// GCC reports a false -Wnull-dereference inside Eigen's sparse headers when the iterative
// solvers grab a matrix (the outer-index pointer of a possibly empty matrix, SparseRef.h); the
// suppression must cover the header locations, hence before every include.
#pragma GCC diagnostic ignored "-Wnull-dereference"
#include "linear_solvers/pore_pressure.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <fmt/format.h>
#include <Eigen/IterativeLinearSolvers>

#include "core/error.hpp"
#include "linear_solvers/pattern_matrix.hpp"

namespace rktsph {
class PatternOperator;
}  // namespace rktsph

// Eigen's matrix-free interface (the "matrix-free solvers" pattern of its documentation): the
// iterative solvers need only y = A x, which PatternOperator forwards to PatternMatrix.
namespace Eigen::internal {
template <>
struct traits<rktsph::PatternOperator> : public traits<SparseMatrix<double>> {};
}  // namespace Eigen::internal

namespace rktsph {

/// A square PatternMatrix seen by Eigen's conjugate gradient and BiCGSTAB.
class PatternOperator : public Eigen::EigenBase<PatternOperator> {
 public:
  using Scalar = double;
  using RealScalar = double;
  using StorageIndex = int;
  enum { ColsAtCompileTime = Eigen::Dynamic, MaxColsAtCompileTime = Eigen::Dynamic, IsRowMajor = false };

  Eigen::Index rows() const { return m_ != nullptr ? m_->rows() : 0; }
  Eigen::Index cols() const { return m_ != nullptr ? m_->cols() : 0; }
  template <typename Rhs>
  Eigen::Product<PatternOperator, Rhs, Eigen::AliasFreeProduct> operator*(const Eigen::MatrixBase<Rhs>& x) const {
    return Eigen::Product<PatternOperator, Rhs, Eigen::AliasFreeProduct>(*this, x.derived());
  }
  void attach(const PatternMatrix& m) { m_ = &m; }
  const PatternMatrix& matrix() const { return *m_; }

 private:
  const PatternMatrix* m_ = nullptr;
};

/// The Jacobi preconditioner of Eigen, its diagonal taken from a PatternOperator.
class PatternJacobi : public Eigen::DiagonalPreconditioner<double> {
 public:
  template <typename MatType>
  PatternJacobi& analyzePattern(const MatType&) {
    return *this;
  }
  PatternJacobi& factorize(const PatternOperator& op) {
    const Eigen::VectorXd d = op.matrix().diagonal();
    m_invdiag.resize(d.size());
    for (Eigen::Index j = 0; j < d.size(); ++j) m_invdiag[j] = d[j] != 0.0 ? 1.0 / d[j] : 1.0;
    m_isInitialized = true;
    return *this;
  }
  PatternJacobi& compute(const PatternOperator& op) { return factorize(op); }
};

}  // namespace rktsph

namespace Eigen::internal {
template <typename Rhs>
struct generic_product_impl<rktsph::PatternOperator, Rhs, SparseShape, DenseShape, GemvProduct>
    : generic_product_impl_base<rktsph::PatternOperator, Rhs,
                                generic_product_impl<rktsph::PatternOperator, Rhs>> {
  using Scalar = typename Product<rktsph::PatternOperator, Rhs>::Scalar;
  // dst = A x written directly (the base class would zero dst and then add to it).
  template <typename Dest>
  static void evalTo(Dest& dst, const rktsph::PatternOperator& lhs, const Rhs& rhs) {
    const Eigen::VectorXd& x = rhs;
    lhs.matrix().multiply(std::span<const double>(x.data(), static_cast<std::size_t>(x.size())),
                          std::span<double>(dst.data(), static_cast<std::size_t>(dst.size())));
  }
  template <typename Dest>
  static void scaleAndAddTo(Dest& dst, const rktsph::PatternOperator& lhs, const Rhs& rhs, const Scalar& alpha) {
    // Eigen's solvers pass contiguous vectors; the product reads and writes them in place.
    const Eigen::VectorXd& x = rhs;
    lhs.matrix().multiply_add(std::span<const double>(x.data(), static_cast<std::size_t>(x.size())),
                              std::span<double>(dst.data(), static_cast<std::size_t>(dst.size())), alpha);
  }
};
}  // namespace Eigen::internal

namespace rktsph {

// The system matrix (K, or K + A with the implicit faces) and the right-hand-side operator are
// PatternMatrix objects (8 bytes per row on a lattice instead of 12 per nonzero, method-notes
// §5.3 "Storage"); each row's product is one serial sum, so the iterates are the same on any
// number of threads.
struct PorePressureSolver::Impl {
  PatternMatrix K;    // free-free block of I/(Q dt) - k_eff S (- tau S_f) (+ A with implicit faces)
  PatternMatrix S_fd; // free rows, drained columns of k_eff S (+ tau S_f) (Dirichlet values to the right-hand side)
  // Free rows, all columns: k_eff (L - S) (deferred correction) - c L (incremental projection;
  // c S without the deferred correction) - tau (T G)_f (explicit half of the pressure filter)
  // + A (implicit faces): everything p^n contributes to the right-hand side, in one product.
  PatternMatrix R;
  PatternOperator op;
  Eigen::ConjugateGradient<PatternOperator, Eigen::Lower | Eigen::Upper, PatternJacobi> cg_diag;
  Sparse K_sparse;  // K's entries, for the incomplete-Cholesky option only
  Eigen::ConjugateGradient<Sparse, Eigen::Lower, Eigen::IncompleteCholesky<double>> cg_ic;
  Eigen::BiCGSTAB<PatternOperator, PatternJacobi> bicgstab;
  bool coupled = false;
  Eigen::VectorXd rhs, x, p_all, p_d;
  Eigen::VectorXd previous;  // p^n on the free unknowns at the last solve (for the starting guess)
  bool has_previous = false;
};

PorePressureSolver::~PorePressureSolver() = default;

PorePressureSolver::Sparse PorePressureSolver::matrix() const { return impl_->K.to_sparse(); }

bool PorePressureSolver::coupled() const { return impl_->coupled; }

Index PorePressureSolver::matrix_patterns() const { return impl_->K.patterns(); }

Index PorePressureSolver::rhs_patterns() const { return impl_->R.patterns(); }

std::size_t PorePressureSolver::bytes() const {
  const Impl& m = *impl_;
  return m.K.bytes() + m.S_fd.bytes() + m.R.bytes() +
         static_cast<std::size_t>(m.K_sparse.nonZeros()) * (sizeof(double) + sizeof(int)) +
         (free_.size() + index_.size()) * sizeof(Index) +
         static_cast<std::size_t>(m.rhs.size() + m.x.size() + m.p_all.size() + m.p_d.size() + m.previous.size()) *
             sizeof(double);
}

namespace {
// A row being assembled from several sparse rows: (column, value) pairs, merged by column.
struct RowBuffer {
  std::vector<std::pair<Index, double>> entries;
  std::vector<Index> columns;
  std::vector<double> values;
  void clear() { entries.clear(); }
  void add(Index col, double v) { entries.emplace_back(col, v); }
  // Sorted by column, duplicates summed in the order they were added, exact zeros dropped
  // (a cancelled entry of L - S) unless it is the diagonal `keep`.
  void merge(Index keep = -1) {
    std::stable_sort(entries.begin(), entries.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    columns.clear();
    values.clear();
    for (std::size_t k = 0; k < entries.size();) {
      const Index c = entries[k].first;
      double sum = 0.0;
      for (; k < entries.size() && entries[k].first == c; ++k) sum += entries[k].second;
      if (sum == 0.0 && c != keep) continue;
      columns.push_back(c);
      values.push_back(sum);
    }
  }
};
}  // namespace

namespace {
// The symmetric matrix whose lower triangle is that of `a`: a's upper triangle is replaced by the
// transpose of its lower one, as the conjugate gradient's self-adjoint view of the lower triangle
// did before the pattern storage. The mirror-image rows of S (the impermeable walls, §3.5) make
// the assembled K slightly unsymmetric (relative |K - K^T| = 1.5e-2 in Case 16, 1e-3 in Case 15,
// round-off elsewhere), and the conjugate gradient needs a symmetric operator. The transpose is
// formed from a count and one list of the strictly lower entries (12 bytes each), not a CSR copy.
PatternMatrix symmetric_from_lower(const PatternMatrix& a) {
  const Index n = a.rows();
  std::vector<Index> start(static_cast<std::size_t>(n) + 1, 0);
  for (Index j = 0; j < n; ++j) {
    const auto row = a.row(j);
    for (const Index off : row.offset) {
      const Index c = row.base + off;
      if (c < j) ++start[static_cast<std::size_t>(c) + 1];
    }
  }
  for (Index r = 0; r < n; ++r) start[static_cast<std::size_t>(r) + 1] += start[static_cast<std::size_t>(r)];
  std::vector<Index> upper_col(static_cast<std::size_t>(start.back()));
  std::vector<double> upper_val(upper_col.size());
  std::vector<Index> fill(start.begin(), start.end() - 1);
  for (Index j = 0; j < n; ++j) {  // rows in increasing order: each row's upper columns come sorted
    const auto row = a.row(j);
    for (std::size_t k = 0; k < row.offset.size(); ++k) {
      const Index c = row.base + row.offset[k];
      if (c >= j) break;
      const auto at = static_cast<std::size_t>(fill[static_cast<std::size_t>(c)]++);
      upper_col[at] = j;
      upper_val[at] = row.value[k];
    }
  }
  PatternMatrix::Builder out(n, n);
  std::vector<Index> cols;
  std::vector<double> vals;
  for (Index r = 0; r < n; ++r) {
    cols.clear();
    vals.clear();
    const auto row = a.row(r);
    for (std::size_t k = 0; k < row.offset.size(); ++k) {
      const Index c = row.base + row.offset[k];
      if (c > r) break;
      cols.push_back(c);
      vals.push_back(row.value[k]);
    }
    for (auto k = static_cast<std::size_t>(start[static_cast<std::size_t>(r)]);
         k < static_cast<std::size_t>(start[static_cast<std::size_t>(r) + 1]); ++k) {
      cols.push_back(upper_col[k]);
      vals.push_back(upper_val[k]);
    }
    out.add_row(cols, vals);
  }
  return out.finish();
}
}  // namespace

PorePressureSolver::PorePressureSolver(const Sparse& full, const Sparse& symmetric, const std::vector<bool>& dirichlet,
                                       const Settings& settings, const Sparse* filter_symmetric,
                                       const Sparse* filter_explicit, const Sparse* face_coupling)
    : impl_(std::make_unique<Impl>()), settings_(settings) {
  const PatternMatrix fs = filter_symmetric != nullptr ? PatternMatrix(*filter_symmetric) : PatternMatrix();
  const PatternMatrix fe = filter_explicit != nullptr ? PatternMatrix(*filter_explicit) : PatternMatrix();
  build(PatternMatrix(full), PatternMatrix(symmetric), dirichlet, filter_symmetric != nullptr ? &fs : nullptr,
        filter_explicit != nullptr ? &fe : nullptr, face_coupling);
}

PorePressureSolver::PorePressureSolver(const PatternMatrix& full, const PatternMatrix& symmetric,
                                       const std::vector<bool>& dirichlet, const Settings& settings,
                                       const PatternMatrix* filter_symmetric, const PatternMatrix* filter_explicit,
                                       const Sparse* face_coupling)
    : impl_(std::make_unique<Impl>()), settings_(settings) {
  build(full, symmetric, dirichlet, filter_symmetric, filter_explicit, face_coupling);
}

void PorePressureSolver::build(const PatternMatrix& full, const PatternMatrix& symmetric,
                               const std::vector<bool>& dirichlet, const PatternMatrix* filter_symmetric,
                               const PatternMatrix* filter_explicit, const Sparse* face_coupling) {
  const Settings& settings = settings_;
  const bool filtered = settings.filter > 0.0;
  if (filtered && (filter_symmetric == nullptr || filter_explicit == nullptr)) {
    throw SolverError("pore pressure: a filter coefficient was given without the filter operators");
  }
  const auto n = static_cast<std::size_t>(symmetric.rows());
  index_.assign(n, -1);
  std::vector<Index> drained_index(n, -1);
  Index nd = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (dirichlet[i]) {
      drained_index[i] = nd++;
    } else {
      index_[i] = static_cast<Index>(free_.size());
      free_.push_back(static_cast<Index>(i));
    }
  }
  const auto nf = static_cast<Index>(free_.size());
  Impl& m = *impl_;
  m.coupled = face_coupling != nullptr && face_coupling->nonZeros() > 0;
  // Rows are assembled one at a time straight into the pattern storage: no triplet list and no
  // intermediate CSR copy of the whole system (the set-up's peak memory).
  PatternMatrix::Builder kb(nf, nf), fdb(nf, nd), rb(nf, static_cast<Index>(n));
  RowBuffer kr, fdr, rr;
  const bool incremental = settings.incremental > 0.0;
  // Row i of a pattern matrix as (column, value) pairs.
  auto for_row = [](const PatternMatrix& a, Index i, auto&& f) {
    const auto row = a.row(i);
    for (std::size_t k = 0; k < row.offset.size(); ++k) f(row.base + row.offset[k], row.value[k]);
  };
  for (Index r = 0; r < nf; ++r) {
    const Index i = free_[static_cast<std::size_t>(r)];
    kr.clear();
    fdr.clear();
    rr.clear();
    kr.add(r, settings.inv_q_dt);
    if (filtered) {
      // tau S_f in K (its drained columns to the right-hand side), tau (T G)_f p^n on the
      // right-hand side.
      for_row(*filter_symmetric, i, [&](Index j, double v) {
        if (dirichlet[static_cast<std::size_t>(j)]) {
          fdr.add(drained_index[static_cast<std::size_t>(j)], settings.filter * v);
        } else {
          kr.add(index_[static_cast<std::size_t>(j)], -settings.filter * v);
        }
      });
      for_row(*filter_explicit, i, [&](Index j, double v) { rr.add(j, -settings.filter * v); });
    }
    for_row(symmetric, i, [&](Index j, double v) {
      if (dirichlet[static_cast<std::size_t>(j)]) {
        fdr.add(drained_index[static_cast<std::size_t>(j)], settings.k_eff * v);
      } else {
        kr.add(index_[static_cast<std::size_t>(j)], -settings.k_eff * v);
      }
      if (settings.deferred_correction) rr.add(j, -settings.k_eff * v);
      if (incremental && !settings.deferred_correction) rr.add(j, -settings.incremental * v);
    });
    for_row(full, i, [&](Index j, double v) {
      if (settings.deferred_correction) rr.add(j, settings.k_eff * v);
      if (incremental && settings.deferred_correction) rr.add(j, -settings.incremental * v);
    });
    if (m.coupled) {
      for (Sparse::InnerIterator it(*face_coupling, static_cast<Eigen::Index>(i)); it; ++it) {
        const auto j = static_cast<std::size_t>(it.col());
        if (dirichlet[j]) throw SolverError("pore pressure: a face coupling at a drained node");
        kr.add(index_[j], it.value());
        rr.add(static_cast<Index>(it.col()), it.value());
      }
    }
    kr.merge(r);
    fdr.merge();
    rr.merge();
    kb.add_row(kr.columns, kr.values);
    fdb.add_row(fdr.columns, fdr.values);
    rb.add_row(rr.columns, rr.values);
  }
  m.K = m.coupled ? kb.finish() : symmetric_from_lower(kb.finish());
  m.S_fd = fdb.finish();
  m.R = rb.finish();
  m.op.attach(m.K);
  m.rhs.resize(nf);
  m.x.resize(nf);
  m.p_all.resize(static_cast<Eigen::Index>(n));
  m.p_d.resize(nd);
  if (nf == 0) return;
  if (m.coupled) {
    m.bicgstab.setTolerance(settings.tolerance);
    m.bicgstab.setMaxIterations(settings.max_iterations);
    m.bicgstab.compute(m.op);
    if (m.bicgstab.info() != Eigen::Success) throw SolverError("pore pressure: the Jacobi preconditioner failed");
    return;
  }
  // K and its preconditioner are set up once (method-notes §2.4 "Solver").
  auto prepare = [&](auto& cg, const auto& matrix, const char* what) {
    cg.setTolerance(settings.tolerance);
    cg.setMaxIterations(settings.max_iterations);
    cg.compute(matrix);
    if (cg.info() != Eigen::Success) throw SolverError(fmt::format("pore pressure: {} failed", what));
  };
  if (settings.preconditioner == PressurePreconditioner::incomplete_cholesky) {
    m.K_sparse = m.K.to_sparse();
    prepare(m.cg_ic, m.K_sparse, "the incomplete-Cholesky factorisation of K");
  } else {
    prepare(m.cg_diag, m.op, "the Jacobi preconditioner");
  }
}

PorePressureSolver::WarmStart PorePressureSolver::warm_start() const {
  WarmStart w;
  w.previous.assign(impl_->previous.data(), impl_->previous.data() + impl_->previous.size());
  w.valid = impl_->has_previous;
  return w;
}

void PorePressureSolver::set_warm_start(const WarmStart& w) {
  if (w.valid && w.previous.size() != free_.size()) {
    throw InputError("the checkpoint's pressure warm start does not match this case's unknowns");
  }
  impl_->previous = Eigen::Map<const Eigen::VectorXd>(w.previous.data(), static_cast<Eigen::Index>(w.previous.size()));
  impl_->has_previous = w.valid;
}

void PorePressureSolver::solve(std::span<const double> source, std::span<const double> p_old, std::span<double> p) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto nf = static_cast<Eigen::Index>(free_.size());
  if (nf == 0) return;
  Impl& m = *impl_;
  Eigen::Index nd = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    m.p_all[static_cast<Eigen::Index>(i)] = p_old[i];
    if (index_[i] < 0) m.p_d[nd++] = p[i];
  }
  // Starting guess: p^n extrapolated linearly in time, 2 p^n - p^{n-1} (p^n on the first solve).
  // Only the iteration count depends on it, not the converged p^{n+1}.
  if (m.previous.size() != nf) {
    m.previous.resize(nf);
    m.has_previous = false;
  }
  for (Eigen::Index r = 0; r < nf; ++r) {
    const auto i = static_cast<std::size_t>(free_[static_cast<std::size_t>(r)]);
    m.rhs[r] = source[i];
    m.x[r] = m.has_previous ? 2.0 * p_old[i] - m.previous[r] : p_old[i];
    m.previous[r] = p_old[i];
  }
  m.has_previous = true;
  const std::span<double> rhs(m.rhs.data(), static_cast<std::size_t>(nf));
  // Drained values at t^{n+1}: -K_fd p_d = S_fd p_d.
  if (nd > 0) m.S_fd.multiply_add(std::span<const double>(m.p_d.data(), static_cast<std::size_t>(nd)), rhs, 1.0);
  m.R.multiply_add(std::span<const double>(m.p_all.data(), static_cast<std::size_t>(m.p_all.size())), rhs, 1.0);
  int iterations = 0;
  double error = 0.0;
  const bool ok = iterate(m.rhs, m.x, iterations, error);
  if (!ok || !std::isfinite(error)) {
    throw SolverError(
        fmt::format("pore pressure: the {} did not converge ({} iterations, "
                    "relative residual {:.3g}, tolerance {:.3g})",
                    m.coupled ? "BiCGSTAB" : "conjugate gradient", iterations, error, settings_.tolerance));
  }
  for (Eigen::Index r = 0; r < nf; ++r) p[static_cast<std::size_t>(free_[static_cast<std::size_t>(r)])] = m.x[r];
  ++stats_.solves;
  stats_.total_iterations += iterations;
  stats_.max_iterations = std::max<long>(stats_.max_iterations, iterations);
  stats_.last_iterations = iterations;
  stats_.last_error = error;
  stats_.max_error = std::max(stats_.max_error, error);
  stats_.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

bool PorePressureSolver::iterate(const Eigen::VectorXd& b, Eigen::VectorXd& x, int& iterations, double& error) {
  Impl& m = *impl_;
  bool ok = false;
  auto run = [&](auto& cg) {
    x = cg.solveWithGuess(b, x);
    iterations = static_cast<int>(cg.iterations());
    error = cg.error();
    ok = cg.info() == Eigen::Success;
  };
  if (m.coupled) {
    run(m.bicgstab);
  } else if (settings_.preconditioner == PressurePreconditioner::incomplete_cholesky) {
    run(m.cg_ic);
  } else {
    run(m.cg_diag);
  }
  return ok;
}

void PorePressureSolver::solve_matrix(std::span<const double> b, std::span<double> x) {
  const auto nf = static_cast<Eigen::Index>(free_.size());
  std::fill(x.begin(), x.end(), 0.0);
  if (nf == 0) return;
  Eigen::VectorXd rhs(nf), out = Eigen::VectorXd::Zero(nf);
  for (Eigen::Index r = 0; r < nf; ++r) rhs[r] = b[static_cast<std::size_t>(free_[static_cast<std::size_t>(r)])];
  int iterations = 0;
  double error = 0.0;
  const bool ok = iterate(rhs, out, iterations, error);
  if (!ok || !std::isfinite(error)) {
    throw SolverError(fmt::format("pore pressure: the rigid-body coupling solve did not converge ({} iterations, "
                                  "relative residual {:.3g})",
                                  iterations, error));
  }
  for (Eigen::Index r = 0; r < nf; ++r) x[static_cast<std::size_t>(free_[static_cast<std::size_t>(r)])] = out[r];
}

}  // namespace rktsph
