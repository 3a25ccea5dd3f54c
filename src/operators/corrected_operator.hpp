#pragma once
// Corrected SPH interpolation and gradient between particle sets (METHOD.md §3.2, with the
// linear-exact (n_d+1) system that §0.3 item 2 found necessary for convergence).
//
// At a target point a, with sources b in the kernel support, the (n_d+1) unknowns
// (f_a, grad f_a) solve
//     M_a [f_a; grad f_a] = sum_b V_b [W_ab; grad_a W_ab] f_b,
//     M_a = sum_b V_b [W_ab; grad_a W_ab] (x) [1, x_b - x_a],
// which is exact for linear fields everywhere, including truncated supports at boundaries.
// Particles never move in V1/V3, so the weights M_a^{-1} V_b [W_ab; grad_a W_ab] are computed
// once and a time step is a streaming sum over them.
#include <array>
#include <vector>

#include "core/kernel.hpp"
#include "core/types.hpp"
#include "geometry/particles.hpp"

namespace rktsph {

template <int Dim>
struct CorrectedOperator {
  /// Per pair: the interpolation weight, and the gradient weights along x, y, z. Kept in
  /// separate arrays so that a loop needing only one of them streams only that one.
  using GradWeights = std::array<double, Dim>;

  std::vector<Index> row_start;  // CSR: pairs of target a are [row_start[a], row_start[a+1])
  std::vector<Index> source;     // source particle of each pair
  std::vector<double> interp;
  std::vector<GradWeights> grad;
  Index degenerate_rows = 0;     // rows that fell back to Shepard / uncorrected (too few sources)

  Index rows() const { return static_cast<Index>(row_start.size()) - 1; }
  std::size_t pairs() const { return source.size(); }
  std::size_t bytes() const {
    return row_start.size() * sizeof(Index) + source.size() * sizeof(Index) +
           interp.size() * sizeof(double) + grad.size() * sizeof(GradWeights);
  }
};

/// CSPM difference-form gradient with a given value at the target (METHOD.md §3.2):
///   grad f_a = A_a^{-1} sum_b V_b (f_b - fhat_a) grad_a W_ab  =  sum_b c_ab f_b - (sum_b c_ab) fhat_a
/// Used at boundary nodes where a component is prescribed, so that the prescribed value
/// reaches the dynamics (METHOD.md §0.3 item 1, fix (a)).
template <int Dim>
struct DifferenceGradient {
  std::vector<Index> row_start;
  std::vector<Index> source;
  std::vector<Vec<Dim>> weight;   // c_ab
  std::vector<Vec<Dim>> weight_sum;  // sum_b c_ab, per row
};

/// Build the corrected operator from `sources` to the points `targets`, for every source
/// within the kernel support. Each row's pairs are sorted by source index.
template <int Dim>
CorrectedOperator<Dim> build_corrected_operator(const std::vector<Vec<Dim>>& targets,
                                                const ParticleSet<Dim>& sources,
                                                const CubicSplineKernel<Dim>& kernel);

/// Build difference-form gradients at the selected targets (one row per entry of `which`).
template <int Dim>
DifferenceGradient<Dim> build_difference_gradient(const std::vector<Vec<Dim>>& targets,
                                                  const std::vector<Index>& which,
                                                  const ParticleSet<Dim>& sources,
                                                  const CubicSplineKernel<Dim>& kernel);

}  // namespace rktsph
