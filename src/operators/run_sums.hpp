#pragma once
// Vectorised sums of a shared-pattern operator (operators/corrected_operator.hpp) over runs of
// its rows: the inner kernels of the staggered steps and the filter.
#include <cstddef>
#include <type_traits>

#include "core/types.hpp"
#include "operators/corrected_operator.hpp"

namespace rktsph {

// Sums over one run of an operator (CorrectedOperator::run_start): rows r0..r0+m-1 share a
// pattern and have consecutive bases, so pair k reads the same weights for every row, from the
// contiguous block src[(base + off[k]) * stride, ...) of len = m * stride doubles. Output q of
// slot i is
//   acc[q][i] = sum_k w_q[k] src[(base + off[k]) * stride + i],
// with weights(k, w) giving w_0..w_{NW-1} of pair k. The sum runs over k in pattern order for
// every slot, as a per-row loop would, but L slots at a time: the block loop is vector FMAs
// with NW * L / 8 independent accumulators in registers (enough to hide the FMA latency),
// where a per-row loop over a few state components does not vectorise.
template <int NW, std::size_t L, class Weights>
inline void run_sums(const double* src, std::size_t stride, std::size_t len, const Index* off, Index k0, Index k1,
                     Weights&& weights, double* const* acc) {
  std::size_t i0 = 0;
  auto block = [&](std::size_t width, auto fixed) {
    constexpr bool kFull = decltype(fixed)::value;
    double a[NW][L] = {};
    for (Index k = k0; k < k1; ++k) {
      const double* s = src + static_cast<std::size_t>(off[k]) * stride + i0;
      double w[NW];
      weights(k, w);
      if constexpr (kFull) {
        for (std::size_t l = 0; l < L; ++l) {
          for (int q = 0; q < NW; ++q) a[q][l] += w[q] * s[l];
        }
      } else {
        for (std::size_t l = 0; l < width; ++l) {
          for (int q = 0; q < NW; ++q) a[q][l] += w[q] * s[l];
        }
      }
    }
    for (int q = 0; q < NW; ++q) {
      for (std::size_t l = 0; l < width; ++l) acc[q][i0 + l] = a[q][l];
    }
  };
  for (; i0 + L <= len; i0 += L) block(L, std::true_type{});
  if (i0 < len) block(len - i0, std::false_type{});
}

// Interpolation (acc[0]) and gradient (acc[1..Dim]) at the rows of run r of `op` of the field
// `src` of N values per source particle.
template <int Dim, int N>
inline void interpolate_run(const CorrectedOperator<Dim>& op, const double* src, Index r,
                            double (&acc)[Dim + 1][CorrectedOperator<Dim>::kMaxRun * N]) {
  const Index a0 = op.run_start[static_cast<std::size_t>(r)], a1 = op.run_start[static_cast<std::size_t>(r) + 1];
  const auto p = static_cast<std::size_t>(op.pattern[static_cast<std::size_t>(a0)]);
  if (a1 - a0 == 1) {
    // A run of one row (every row of a rebuilt operator, V2): the N values of a source in
    // registers, the same sums in the same order as run_sums, without its variable-width loop.
    const double* base = src + static_cast<std::size_t>(op.base[static_cast<std::size_t>(a0)]) * N;
    double a[Dim + 1][N] = {};
    for (Index k = op.pattern_start[p]; k < op.pattern_start[p + 1]; ++k) {
      const auto ku = static_cast<std::size_t>(k);
      const double* s = base + static_cast<std::size_t>(op.offset[ku]) * N;
      const double w0 = op.interp[ku];
      for (int l = 0; l < N; ++l) a[0][l] += w0 * s[l];
      for (int d = 0; d < Dim; ++d) {
        const double g = op.grad[ku][static_cast<std::size_t>(d)];
        for (int l = 0; l < N; ++l) a[1 + d][l] += g * s[l];
      }
    }
    for (int q = 0; q <= Dim; ++q)
      for (int l = 0; l < N; ++l) acc[q][l] = a[q][l];
    return;
  }
  double* sums[Dim + 1];
  for (int q = 0; q <= Dim; ++q) sums[q] = acc[q];
  run_sums<Dim + 1, 16>(
      src + static_cast<std::size_t>(op.base[static_cast<std::size_t>(a0)]) * N, N,
      static_cast<std::size_t>(a1 - a0) * N, op.offset.data(), op.pattern_start[p], op.pattern_start[p + 1],
      [&](Index k, double* w) {
        w[0] = op.interp[static_cast<std::size_t>(k)];
        for (int d = 0; d < Dim; ++d) w[1 + d] = op.grad[static_cast<std::size_t>(k)][static_cast<std::size_t>(d)];
      },
      sums);
}

// The gradient alone (acc[d], d < Dim) at the rows of run r of `op` of the field `src` of N
// values per source, L lanes wide. For fields of one or two values a run of at most kMaxRun
// rows spans at most 32 doubles: with eight lanes most of it is in full blocks, with sixteen
// most falls in run_sums' variable-width tail (measured slower, docs/VALIDATION.md).
template <int Dim, int N, std::size_t L = 8>
inline void gradient_run(const CorrectedOperator<Dim>& op, const double* src, Index r,
                         double (&acc)[Dim][CorrectedOperator<Dim>::kMaxRun * N]) {
  const Index a0 = op.run_start[static_cast<std::size_t>(r)], a1 = op.run_start[static_cast<std::size_t>(r) + 1];
  const auto p = static_cast<std::size_t>(op.pattern[static_cast<std::size_t>(a0)]);
  double* sums[Dim];
  for (int d = 0; d < Dim; ++d) sums[d] = acc[d];
  run_sums<Dim, L>(
      src + static_cast<std::size_t>(op.base[static_cast<std::size_t>(a0)]) * N, N,
      static_cast<std::size_t>(a1 - a0) * N, op.offset.data(), op.pattern_start[p], op.pattern_start[p + 1],
      [&](Index k, double* w) {
        for (int d = 0; d < Dim; ++d) w[d] = op.grad[static_cast<std::size_t>(k)][static_cast<std::size_t>(d)];
      },
      sums);
}

}  // namespace rktsph
