#pragma once
// The pore-pressure step of the V3 fractional-step scheme (method-notes §2.4 step 2, §5.3):
//
//   p^{n+1}/(Q* dt) - k_eff L p^{n+1} = p^n/(Q* dt) - S_w div v*,   k_eff = k_w + S_w dt / rho,
//
// on the nodes, with L the corrected Laplacian of operators/laplacian.hpp. The matrix
// K = I/(Q* dt) - k_eff S uses the symmetric part S of L, so K is symmetric positive definite;
// the rest, k_eff (L - S) p^n, is deferred to the right-hand side (method-notes §3.5, §6 item 8).
// Drained nodes (p prescribed) are eliminated symmetrically: their rows and columns leave K and
// the known values move to the right-hand side. K and its preconditioner are built once (the
// particles do not move and dt is fixed), stored by shared row patterns (pattern_matrix.hpp);
// each step is one Eigen::ConjugateGradient solve, matrix-free over that storage, started from
// an extrapolation of p^n. Nothing here is a hand-written Krylov method.
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <Eigen/SparseCore>

#include "core/types.hpp"
#include "linear_solvers/pattern_matrix.hpp"

namespace rktsph {

enum class PressurePreconditioner { diagonal, incomplete_cholesky };

struct PressureSolveStats {
  long solves = 0;
  long total_iterations = 0;
  long max_iterations = 0;
  int last_iterations = 0;
  double last_error = 0.0;  // relative residual |K x - b| / |b| of the last solve
  double max_error = 0.0;
  double seconds = 0.0;  // wall time in solve()
  double mean_iterations() const {
    return solves > 0 ? static_cast<double>(total_iterations) / static_cast<double>(solves) : 0.0;
  }
};

class PorePressureSolver {
 public:
  using Sparse = Eigen::SparseMatrix<double, Eigen::RowMajor>;
  struct Settings {
    double inv_q_dt = 0.0;    // 1/(Q* dt), 1/(Pa s)
    double k_eff = 0.0;       // k_w + S_w dt/rho, m^3 s/kg
    double tolerance = 1e-8;  // relative residual
    int max_iterations = 2000;
    PressurePreconditioner preconditioner = PressurePreconditioner::diagonal;
    bool deferred_correction = true;  // add k_eff (L - S) p^n to the right-hand side
    /// Incremental projection: the coefficient c = S_w dt/rho of the stabilisation; solve() then
    /// adds -c L p^n (-c S p^n without the deferred correction, which then uses k_w alone) to
    /// the right-hand side, and the caller adds S_w dt div(grad p^n / rho) to `source`, so that
    /// the stabilisation acts on p^{n+1} - p^n only. 0 = non-incremental (method-notes §2.4).
    double incremental = 0.0;
    /// Coefficient tau (m^3 s/kg) of the linear-exact pressure filter tau (S_f p^{n+1} - (T G)_f
    /// p^n) (operators/laplacian.hpp, build_filter_gradient_part); 0 = none. Needs set_filter().
    double filter = 0.0;
  };

  /// `full` and `symmetric` are L and S (1/m^2); `dirichlet[I]` is true at drained nodes.
  /// With `settings.filter` > 0, `filter_symmetric` and `filter_explicit` are S_f and (T G)_f.
  /// With `face_coupling` (A of schemes/face_pressure_coupling.hpp, node x node, its columns at
  /// free nodes), the matrix is K + A and the right-hand side gains A p^n: K + A is not
  /// symmetric, so the solve is Eigen's BiCGSTAB with the Jacobi preconditioner.
  PorePressureSolver(const Sparse& full, const Sparse& symmetric, const std::vector<bool>& dirichlet,
                     const Settings& settings, const Sparse* filter_symmetric = nullptr,
                     const Sparse* filter_explicit = nullptr, const Sparse* face_coupling = nullptr);
  /// The same from pattern-stored operators (the V3 stage's set-up; no CSR copy of any of them).
  PorePressureSolver(const PatternMatrix& full, const PatternMatrix& symmetric, const std::vector<bool>& dirichlet,
                     const Settings& settings, const PatternMatrix* filter_symmetric = nullptr,
                     const PatternMatrix* filter_explicit = nullptr, const Sparse* face_coupling = nullptr);
  ~PorePressureSolver();
  PorePressureSolver(const PorePressureSolver&) = delete;
  PorePressureSolver& operator=(const PorePressureSolver&) = delete;

  /// One step: `p` holds p^n on entry (with the drained nodes already set to their values at
  /// t^{n+1}) and p^{n+1} on exit. `source[I]` = p^n_I/(Q* dt) - S_w (div v*)_I. Throws
  /// SolverError if the conjugate gradient does not converge.
  void solve(std::span<const double> source, std::span<const double> p_old, std::span<double> p);

  /// x = K^{-1} b on the free nodes, zero at the drained ones (b and x per node): the system
  /// matrix alone, no right-hand-side operator, from a zero guess; neither the warm start nor
  /// the statistics change. For the rigid bodies' coupling (method-notes eq. (4.6.3)), set up
  /// once. Throws SolverError if the iteration does not converge.
  void solve_matrix(std::span<const double> b, std::span<double> x);

  const PressureSolveStats& stats() const { return stats_; }
  void set_stats(const PressureSolveStats& s) { stats_ = s; }
  /// The previous solve's p^n on the free unknowns, from which the next starting guess is
  /// extrapolated (checkpoints save and restore it: the guess fixes the iterates).
  struct WarmStart {
    std::vector<double> previous;
    bool valid = false;
  };
  WarmStart warm_start() const;
  void set_warm_start(const WarmStart& w);
  Index unknowns() const { return static_cast<Index>(free_.size()); }
  /// The system matrix on the free (non-drained) nodes: K, or K + A with the implicit face
  /// coupling (tests: symmetry, definiteness).
  Sparse matrix() const;
  /// Memory held: the matrices and the solver's vectors, bytes.
  std::size_t bytes() const;
  /// Shared row patterns of the system matrix and of the right-hand-side operator.
  Index matrix_patterns() const;
  Index rhs_patterns() const;
  /// True when the implicit face coupling is in the matrix (BiCGSTAB instead of CG).
  bool coupled() const;

 private:
  void build(const PatternMatrix& full, const PatternMatrix& symmetric, const std::vector<bool>& dirichlet,
             const PatternMatrix* filter_symmetric, const PatternMatrix* filter_explicit, const Sparse* face_coupling);
  /// The configured Krylov solver on K x = b from the guess in x; false if it did not converge.
  bool iterate(const Eigen::VectorXd& b, Eigen::VectorXd& x, int& iterations, double& error);
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::vector<Index> free_;   // free node of each unknown
  std::vector<Index> index_;  // unknown of each node, -1 at drained nodes
  Settings settings_;
  PressureSolveStats stats_;
};

}  // namespace rktsph
