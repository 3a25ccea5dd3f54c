#pragma once
// Corrected SPH interpolation and gradient between particle sets (method-notes §3.2, with the
// linear-exact (n_d+1) system that §0.3 item 2 found necessary for convergence), computed from
// a neighbour relation (neighbours/relation.hpp).
//
// At a target point a, with sources b in the kernel support, the (n_d+1) unknowns
// (f_a, grad f_a) solve
//     M_a [f_a; grad f_a] = sum_b V_b [W_ab; grad_a W_ab] f_b,
//     M_a = sum_b V_b [W_ab; grad_a W_ab] (x) [1, x_b - x_a],
// which is exact for linear fields everywhere, including truncated supports at boundaries.
// Where particles do not move (V1, V3) the weights M_a^{-1} V_b [W_ab; grad_a W_ab] are
// computed once and a time step is a streaming sum over them; where they move, the operator is
// rebuilt from the rebuilt relation.
//
// Storage: shared row patterns, a cache for fixed particles. The weights of a row depend only on the relative positions
// x_b - x_a and the volumes V_b of its sources. On a lattice (in lattice order) almost every row
// is a shifted copy of a few others: the interior rows are one class, the boundary rows a few
// classes per face, edge and corner. So each row is stored as (base source index, pattern id),
// and a pattern holds the source offsets relative to the base and the weights. A row's sources
// are b = base + offset[k]. Irregular (jittered) sets get one pattern per row, which is the
// plain CSR layout plus 8 bytes per row: nothing is lost in generality. On lattices the weights
// of a 10^5-node block fit in the L1 cache and the operator costs 8 bytes per row.
#include <array>
#include <cstddef>
#include <vector>

#include "core/execution.hpp"
#include "core/kernel.hpp"
#include "core/types.hpp"
#include "neighbours/relation.hpp"
#include "particles/particle_set.hpp"

namespace rktsph {

template <int Dim>
struct CorrectedOperator {
  /// Per pair: the interpolation weight, and the gradient weights along x, y, z. Kept in
  /// separate arrays so that a loop needing only one of them streams only that one.
  using GradWeights = std::array<double, Dim>;

  // Per row (target) a: its pattern and the source index its pattern's offsets start from.
  std::vector<Index> base;
  std::vector<Index> pattern;
  // Per pattern p (CSR): pairs [pattern_start[p], pattern_start[p+1]), sorted by offset, the
  // first offset 0 (the base is the row's smallest source index).
  std::vector<Index> pattern_start;
  std::vector<Index> offset;
  // Per pattern: 0 a corrected row, 1 degenerate (Shepard, plain gradient), 2 regularised by
  // the gradient floor (method-notes eq. (3.2.6)).
  std::vector<char> row_kind;
  std::vector<double> interp;
  std::vector<GradWeights> grad;
  // Runs of at most kMaxRun consecutive rows with one pattern and consecutive bases: for each
  // pair k the sources of a run's m rows are m consecutive particles, so a loop over a run
  // sums contiguous blocks with vector instructions (the rows of one lattice line).
  static constexpr Index kMaxRun = 16;
  std::vector<Index> run_start;  // rows of run r: [run_start[r], run_start[r+1])
  Index degenerate_rows = 0;     // rows that fell back to Shepard / uncorrected (too few sources)
  Index regularised_rows = 0;    // rows shifted by the gradient floor (method-notes eq. (3.2.6))
  std::size_t pair_count = 0;    // pairs summed over all rows (the uncompressed CSR length)

  /// The pairs of one row: k in [begin, end) indexes offset/interp/grad, the source of pair k
  /// is base + offset[k].
  struct Row {
    Index base;
    Index begin;
    Index end;
  };

  Index rows() const { return static_cast<Index>(base.size()); }
  // An empty operator (V2 applies its operators on the fly and stores none) has no patterns.
  Index patterns() const { return pattern_start.empty() ? 0 : static_cast<Index>(pattern_start.size()) - 1; }
  Index runs() const { return run_start.empty() ? 0 : static_cast<Index>(run_start.size()) - 1; }
  std::size_t pairs() const { return pair_count; }
  Row row(Index a) const {
    const auto p = static_cast<std::size_t>(pattern[static_cast<std::size_t>(a)]);
    return {base[static_cast<std::size_t>(a)], pattern_start[p], pattern_start[p + 1]};
  }
  Index source(const Row& r, Index k) const { return r.base + offset[static_cast<std::size_t>(k)]; }
  /// Whether row a is degenerate or regularised (not a plain corrected row).
  bool irregular(Index a) const {
    return !row_kind.empty() && row_kind[static_cast<std::size_t>(pattern[static_cast<std::size_t>(a)])] != 0;
  }
  std::size_t bytes() const {
    return (base.size() + pattern.size() + pattern_start.size() + offset.size() + run_start.size()) * sizeof(Index) +
           row_kind.size() + interp.size() * sizeof(double) + grad.size() * sizeof(GradWeights);
  }
};

/// CSPM difference-form gradient with a given value at the target (method-notes §3.2):
///   grad f_a = A_a^{-1} sum_b V_b (f_b - fhat_a) grad_a W_ab  =  sum_b c_ab f_b - (sum_b c_ab) fhat_a
/// Used at boundary nodes where a component is prescribed, so that the prescribed value
/// reaches the dynamics (method-notes §0.3 item 1, fix (a)).
template <int Dim>
struct DifferenceGradient {
  std::vector<Index> row_start;
  std::vector<Index> source;
  std::vector<Vec<Dim>> weight;      // c_ab
  std::vector<Vec<Dim>> weight_sum;  // sum_b c_ab, per row
};

struct OperatorOptions {
  /// Rows whose geometry (source offsets, relative positions, volumes) matches an earlier row
  /// to round-off share its pattern and weights. false: one pattern per row, every row's
  /// weights computed from its own geometry (the reference the tests compare against).
  bool share_patterns = true;
  /// The gradient floor of method-notes eq. (3.2.6) (solver.gradient_floor; 0: none).
  double gradient_floor = 0.0;
};

/// The relation the corrected operator is built from: sources within the support (less a
/// relative 1e-10, see corrected_operator.cpp), rows sorted by source index.
template <int Dim>
RelationOptions operator_relation_options(const CubicSplineKernel<Dim>& kernel);
/// The relation of the difference gradient: sources within the support, sorted.
template <int Dim>
RelationOptions difference_gradient_relation_options(const CubicSplineKernel<Dim>& kernel);

/// Build the corrected operator from `sources` to the points `targets` over `relation` (built
/// with operator_relation_options, one row per target). The result does not depend on the
/// number of threads.
template <int Dim>
CorrectedOperator<Dim> build_corrected_operator(const Relation<Dim>& relation, const std::vector<Vec<Dim>>& targets,
                                                const ParticleSet<Dim>& sources, const CubicSplineKernel<Dim>& kernel,
                                                const OperatorOptions& options = {});
/// The same, with the relation built here and dropped.
template <int Dim>
CorrectedOperator<Dim> build_corrected_operator(const std::vector<Vec<Dim>>& targets, const ParticleSet<Dim>& sources,
                                                const CubicSplineKernel<Dim>& kernel,
                                                const OperatorOptions& options = {});

/// Rebuild `op` in place for particles that have moved: one pattern per row (plain CSR), the
/// sources of row a those of `candidates` row a (sorted, e.g. a Verlet list with a skin) that lie
/// within the support (less the relative 1e-10 of operator_relation_options). The weights are
/// those of build_corrected_operator without pattern sharing; op's storage is reused, so once it
/// has grown nothing is allocated. `gradient_floor` as OperatorOptions's.
template <int Dim>
void rebuild_corrected_operator(const Relation<Dim>& candidates, const std::vector<Vec<Dim>>& targets,
                                const ParticleSet<Dim>& sources, const CubicSplineKernel<Dim>& kernel,
                                CorrectedOperator<Dim>& op, const exec::Threads& policy = {},
                                double gradient_floor = 0.0);

/// The gradient of `op` made exact for quadratic fields on every row (the pressure filter's
/// gradient, method-notes eq. (2.4.11)): a pattern whose weights already are (a full support on a
/// lattice, by symmetry) is kept as it is; on the others (truncated supports: faces, corners,
/// jittered sets) the gradient weights are those of a least-squares fit of the quadratic
/// polynomials weighted by V_b W_ab over the same sources (eq. (2.4.18)), with the lattice's
/// odd-even mode as one more basis function when `lattice_spacing` > 0 (so that the gradient does
/// not mistake that mode for a curved field on a one-sided support). A pattern whose fit
/// is ill-conditioned (too few sources) keeps op's linear-exact weights. Rows that share a
/// pattern share their geometry, so each pattern is fitted once. `fit_rows`, if given, selects
/// the rows that may be fitted (non-zero entries; a pattern shared with unselected rows is split,
/// and the result then runs row by row). `replaced`, if given, receives the number of rows whose
/// weights were replaced.
template <int Dim>
CorrectedOperator<Dim> quadratic_exact_gradient(const CorrectedOperator<Dim>& op, const std::vector<Vec<Dim>>& targets,
                                                const ParticleSet<Dim>& sources, const CubicSplineKernel<Dim>& kernel,
                                                double lattice_spacing, const std::vector<char>* fit_rows = nullptr,
                                                Index* replaced = nullptr);

/// The local amplitude of the lattice's odd-even modes (method-notes eq. (2.4.19)): the weights
/// of a_a = sum_b w_ab p_b, one per pair slot of `op` (row a's pairs are op.row(a), sources
/// op.source(r, k)), the sum of the odd-even
/// coefficients of a least-squares fit of the quadratics and the 2^Dim - 1 modes
/// (-1)^(sum of i_d over a non-empty subset of the axes) over op's sources, so that a = p on each
/// pure mode and a = 0 on every quadratic field, on every row (faces included). Rows where the fit is
/// undetermined or the mode barely separable (sum_b |w_ab| > 4) get zero weights; their number
/// goes to `undetermined`.
template <int Dim>
std::vector<double> odd_even_amplitude(const CorrectedOperator<Dim>& op, const std::vector<Vec<Dim>>& targets,
                                       const ParticleSet<Dim>& sources, const CubicSplineKernel<Dim>& kernel,
                                       double lattice_spacing, Index* undetermined = nullptr);

/// Difference-form gradients at `targets` over `relation` (built with
/// difference_gradient_relation_options, one row per target).
template <int Dim>
DifferenceGradient<Dim> build_difference_gradient(const Relation<Dim>& relation, const std::vector<Vec<Dim>>& targets,
                                                  const ParticleSet<Dim>& sources,
                                                  const CubicSplineKernel<Dim>& kernel);
/// The same into `out`, reusing its storage (the V2 step rebuilds it every step without
/// allocating once its capacity suffices).
template <int Dim>
void build_difference_gradient_into(const Relation<Dim>& relation, const std::vector<Vec<Dim>>& targets,
                                    const ParticleSet<Dim>& sources, const CubicSplineKernel<Dim>& kernel,
                                    DifferenceGradient<Dim>& out);
/// The same at the selected targets (one row per entry of `which`), with the relation built here.
/// The difference gradient at the targets of the rows `which` of `relation` (one sorted row per
/// target, a wider Verlet list cut back to the support), in the order of `which`.
template <int Dim>
void build_difference_gradient_rows(const Relation<Dim>& relation, const std::vector<Vec<Dim>>& targets,
                                    const std::vector<Index>& which, const ParticleSet<Dim>& sources,
                                    const CubicSplineKernel<Dim>& kernel, DifferenceGradient<Dim>& out);
template <int Dim>
DifferenceGradient<Dim> build_difference_gradient(const std::vector<Vec<Dim>>& targets, const std::vector<Index>& which,
                                                  const ParticleSet<Dim>& sources,
                                                  const CubicSplineKernel<Dim>& kernel);

}  // namespace rktsph
