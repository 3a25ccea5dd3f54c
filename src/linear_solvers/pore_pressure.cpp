// GCC reports a false -Wnull-dereference inside Eigen's sparse headers when the iterative
// solvers grab a matrix (the outer-index pointer of a possibly empty matrix, SparseRef.h); the
// suppression must cover the header locations, hence before every include.
#pragma GCC diagnostic ignored "-Wnull-dereference"
#include "linear_solvers/pore_pressure.hpp"

#include <chrono>
#include <cmath>

#include <fmt/format.h>
#include <Eigen/IterativeLinearSolvers>

#include "core/error.hpp"

namespace rktsph {

namespace {
// From this many unknowns on, the Jacobi-PCG multiplies with the full matrix, which Eigen runs on
// its OpenMP threads; below, the fork/join of each product costs more than it saves (see Impl).
// The choice depends on the size only, so that the result does not depend on the thread count
// (each row's product is the same arithmetic on any number of threads).
constexpr Eigen::Index kParallelUnknowns = 20000;
}  // namespace

// Eigen::Lower: CG multiplies with the self-adjoint view of the lower triangle, serially. (With
// Lower | Upper on a row-major matrix Eigen runs the product on its OpenMP threads, which for
// a few thousand unknowns costs more in fork/join than it saves: 56 ms instead of ~1 ms per
// solve was measured on 2 busy cores.)
struct PorePressureSolver::Impl {
  Sparse K;     // free-free block of I/(Q dt) - k_eff S
  Sparse S_fd;  // free rows, drained columns of k_eff S (+ tau S_f) (Dirichlet values to the right-hand side)
  Sparse D;     // free rows of L - S, all columns (deferred correction)
  Sparse S_f;   // free rows of L (S without the deferred correction), all columns (incremental projection)
  Sparse F;     // free rows of tau (T G)_f, all columns (explicit half of the pressure filter)
  Eigen::ConjugateGradient<Sparse, Eigen::Lower, Eigen::DiagonalPreconditioner<double>> cg_diag;
  Eigen::ConjugateGradient<Sparse, Eigen::Lower, Eigen::IncompleteCholesky<double>> cg_ic;
  // Large systems: the full (both triangles) product, which Eigen runs on its OpenMP threads for a
  // row-major matrix (kParallelUnknowns).
  Eigen::ConjugateGradient<Sparse, Eigen::Lower | Eigen::Upper, Eigen::DiagonalPreconditioner<double>> cg_diag_parallel;
  bool parallel = false;
  // The implicit face condition (face_coupling): K + A, not symmetric.
  Sparse K_coupled;
  Sparse A;  // free rows of A, all columns (A p^n on the right-hand side)
  Eigen::BiCGSTAB<Sparse, Eigen::DiagonalPreconditioner<double>> bicgstab;
  bool coupled = false;
  Eigen::VectorXd rhs, x, p_all, p_d;
  Eigen::VectorXd previous;  // p^n on the free unknowns at the last solve (for the starting guess)
  bool has_previous = false;
};

PorePressureSolver::~PorePressureSolver() = default;

const PorePressureSolver::Sparse& PorePressureSolver::matrix() const { return impl_->K; }

bool PorePressureSolver::coupled() const { return impl_->coupled; }

PorePressureSolver::PorePressureSolver(const Sparse& full, const Sparse& symmetric, const std::vector<bool>& dirichlet,
                                       const Settings& settings, const Sparse* filter_symmetric,
                                       const Sparse* filter_explicit, const Sparse* face_coupling)
    : impl_(std::make_unique<Impl>()), settings_(settings) {
  const bool filtered = settings.filter > 0.0;
  if (filtered && (filter_symmetric == nullptr || filter_explicit == nullptr)) {
    throw SolverError("pore pressure: a filter coefficient was given without the filter operators");
  }
  const auto n = static_cast<std::size_t>(full.rows());
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
  const auto nf = static_cast<Eigen::Index>(free_.size());
  using Triplet = Eigen::Triplet<double>;
  std::vector<Triplet> k, sfd, d, sf, f;
  for (Eigen::Index r = 0; r < nf; ++r) {
    const auto i = static_cast<Eigen::Index>(free_[static_cast<std::size_t>(r)]);
    k.emplace_back(r, r, settings.inv_q_dt);
    if (filtered) {
      // tau S_f in K (its drained columns to the right-hand side), tau (T G)_f p^n on the
      // right-hand side.
      for (Sparse::InnerIterator it(*filter_symmetric, i); it; ++it) {
        const auto j = static_cast<std::size_t>(it.col());
        if (dirichlet[j]) {
          sfd.emplace_back(r, drained_index[j], settings.filter * it.value());
        } else {
          k.emplace_back(r, index_[j], -settings.filter * it.value());
        }
      }
      for (Sparse::InnerIterator it(*filter_explicit, i); it; ++it)
        f.emplace_back(r, it.col(), settings.filter * it.value());
    }
    for (Sparse::InnerIterator it(symmetric, i); it; ++it) {
      const auto j = static_cast<std::size_t>(it.col());
      if (dirichlet[j]) {
        sfd.emplace_back(r, drained_index[j], settings.k_eff * it.value());
      } else {
        k.emplace_back(r, index_[j], -settings.k_eff * it.value());
      }
      d.emplace_back(r, it.col(), -it.value());
      if (settings.incremental > 0.0 && !settings.deferred_correction) sf.emplace_back(r, it.col(), it.value());
    }
    for (Sparse::InnerIterator it(full, i); it; ++it) {
      d.emplace_back(r, it.col(), it.value());
      if (settings.incremental > 0.0 && settings.deferred_correction) sf.emplace_back(r, it.col(), it.value());
    }
  }
  impl_->K.resize(nf, nf);
  impl_->K.setFromTriplets(k.begin(), k.end());
  impl_->S_fd.resize(nf, nd);
  impl_->S_fd.setFromTriplets(sfd.begin(), sfd.end());
  impl_->D.resize(nf, static_cast<Eigen::Index>(n));
  impl_->D.setFromTriplets(d.begin(), d.end());
  impl_->D.prune(0.0, 1e-14);
  impl_->S_f.resize(nf, static_cast<Eigen::Index>(n));
  impl_->S_f.setFromTriplets(sf.begin(), sf.end());
  impl_->F.resize(nf, static_cast<Eigen::Index>(n));
  impl_->F.setFromTriplets(f.begin(), f.end());
  impl_->rhs.resize(nf);
  impl_->x.resize(nf);
  impl_->p_all.resize(static_cast<Eigen::Index>(n));
  impl_->p_d.resize(nd);
  if (face_coupling != nullptr && face_coupling->nonZeros() > 0) {
    std::vector<Triplet> kc, a;
    for (Eigen::Index r = 0; r < nf; ++r) {
      const auto i = static_cast<Eigen::Index>(free_[static_cast<std::size_t>(r)]);
      for (Sparse::InnerIterator it(*face_coupling, i); it; ++it) {
        const auto j = static_cast<std::size_t>(it.col());
        if (dirichlet[j]) throw SolverError("pore pressure: a face coupling at a drained node");
        kc.emplace_back(r, index_[j], it.value());
        a.emplace_back(r, it.col(), it.value());
      }
    }
    Sparse coupling(nf, nf);
    coupling.setFromTriplets(kc.begin(), kc.end());
    impl_->K_coupled = impl_->K + coupling;
    impl_->A.resize(nf, static_cast<Eigen::Index>(n));
    impl_->A.setFromTriplets(a.begin(), a.end());
    impl_->coupled = true;
  }
  if (nf == 0) return;
  if (impl_->coupled) {
    impl_->bicgstab.setTolerance(settings.tolerance);
    impl_->bicgstab.setMaxIterations(settings.max_iterations);
    impl_->bicgstab.compute(impl_->K_coupled);
    if (impl_->bicgstab.info() != Eigen::Success) throw SolverError("pore pressure: the Jacobi preconditioner failed");
    return;
  }
  // K and its preconditioner are factorised once (method-notes §2.4 "Solver").
  auto prepare = [&](auto& cg, const char* what) {
    cg.setTolerance(settings.tolerance);
    cg.setMaxIterations(settings.max_iterations);
    cg.compute(impl_->K);
    if (cg.info() != Eigen::Success) throw SolverError(fmt::format("pore pressure: {} failed", what));
  };
  impl_->parallel = settings.preconditioner == PressurePreconditioner::diagonal && nf >= kParallelUnknowns;
  if (settings.preconditioner == PressurePreconditioner::incomplete_cholesky) {
    prepare(impl_->cg_ic, "the incomplete-Cholesky factorisation of K");
  } else if (impl_->parallel) {
    prepare(impl_->cg_diag_parallel, "the Jacobi preconditioner");
  } else {
    prepare(impl_->cg_diag, "the Jacobi preconditioner");
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
  // Drained values at t^{n+1}: -K_fd p_d = S_fd p_d.
  if (nd > 0) m.rhs.noalias() += m.S_fd * m.p_d;
  if (settings_.deferred_correction) m.rhs.noalias() += settings_.k_eff * (m.D * m.p_all);
  if (settings_.incremental > 0.0) m.rhs.noalias() -= settings_.incremental * (m.S_f * m.p_all);
  if (settings_.filter > 0.0) m.rhs.noalias() -= m.F * m.p_all;
  if (m.coupled) m.rhs.noalias() += m.A * m.p_all;
  int iterations = 0;
  double error = 0.0;
  bool ok = false;
  auto run = [&](auto& cg) {
    m.x = cg.solveWithGuess(m.rhs, m.x);
    iterations = static_cast<int>(cg.iterations());
    error = cg.error();
    ok = cg.info() == Eigen::Success;
  };
  if (m.coupled) {
    run(m.bicgstab);
  } else if (settings_.preconditioner == PressurePreconditioner::incomplete_cholesky) {
    run(m.cg_ic);
  } else if (m.parallel) {
    run(m.cg_diag_parallel);
  } else {
    run(m.cg_diag);
  }
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

}  // namespace rktsph
