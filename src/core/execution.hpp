#pragma once
// The one seam for particle loops (docs/architecture.md, "Execution"). A loop body is written
// once, as a callable of the index, and a policy runs it: Sequential on the calling thread (for
// debugging and as the reference), Threads on OpenMP. A device policy would be a third overload
// with the same signatures; no physics code names OpenMP.
//
// Reductions are deterministic: particle_reduce sums fixed blocks of kReductionBlock indices,
// each in index order, then the block sums in block order, so the result is the same bit for
// bit on any number of threads (tests/core/test_execution.cpp).
#include <algorithm>
#include <array>
#include <exception>
#include <vector>

#include "core/types.hpp"

namespace rktsph::exec {

/// Every index on the calling thread, in order.
struct Sequential {};

/// OpenMP threads. A loop whose work is at most `min_parallel` particles runs on the calling
/// thread: for small sets the fork/join costs more than the loop.
struct Threads {
  Index min_parallel = 2048;
};

enum class Schedule {
  even,     // equal contiguous chunks (uniform cost per index)
  dynamic,  // chunks handed out as threads free up (uneven cost, e.g. sub-stepped sources)
};

/// Indices summed together before their sum joins the total (fixed: the sum does not depend on
/// the thread count).
inline constexpr Index kReductionBlock = 4096;

/// f(i) for i in [0, n). `work` is the particle count that decides whether threads pay off
/// (a loop over runs of particles passes the particle count).
template <class F>
void particle_for(const Sequential&, Index n, F&& f, Schedule = Schedule::even, Index = 0) {
  for (Index i = 0; i < n; ++i) f(i);
}

/// An exception thrown by the body on a thread cannot leave the parallel region (it would
/// terminate the program): the one of the lowest index is kept and rethrown after the loop, on
/// the calling thread, as the sequential loop would have thrown it.
template <class F>
void particle_for(const Threads& policy, Index n, F&& f, Schedule schedule = Schedule::even, Index work = -1) {
  const bool parallel = (work < 0 ? n : work) > policy.min_parallel;
  std::exception_ptr error;
  Index error_index = n;
  auto guarded = [&](Index i) {
    try {
      f(i);
    } catch (...) {
#pragma omp critical(rktsph_particle_for_error)
      if (i < error_index) {
        error_index = i;
        error = std::current_exception();
      }
    }
  };
  if (schedule == Schedule::dynamic) {
#pragma omp parallel for schedule(dynamic) if (parallel)
    for (Index i = 0; i < n; ++i) guarded(i);
  } else {
#pragma omp parallel for schedule(static) if (parallel)
    for (Index i = 0; i < n; ++i) guarded(i);
  }
  if (error) std::rethrow_exception(error);
}

/// Storage for the block sums of particle_reduce, grown once and reused (no allocation in the
/// time loop once it has the size of the largest reduction).
struct ReductionScratch {
  std::vector<double> block_sums;
};

/// The sums over i in [0, n) of N quantities: f(i, acc) adds particle i's contributions to
/// acc[0..N). Sums are formed per fixed block, then over the blocks in order (deterministic).
template <int N, class Policy, class F>
std::array<double, N> particle_reduce(const Policy& policy, Index n, ReductionScratch& scratch, F&& f) {
  const Index blocks = (n + kReductionBlock - 1) / kReductionBlock;
  const auto need = static_cast<std::size_t>(blocks) * N;
  if (scratch.block_sums.size() < need) scratch.block_sums.resize(need);
  double* block_sums = scratch.block_sums.data();
  particle_for(
      policy, blocks,
      [&](Index blk) {
        double acc[N] = {};
        const Index end = std::min(n, (blk + 1) * kReductionBlock);
        for (Index i = blk * kReductionBlock; i < end; ++i) f(i, acc);
        for (int s = 0; s < N; ++s)
          block_sums[static_cast<std::size_t>(blk) * N + static_cast<std::size_t>(s)] = acc[s];
      },
      Schedule::even, n);
  std::array<double, N> total{};
  for (Index blk = 0; blk < blocks; ++blk) {
    for (int s = 0; s < N; ++s)
      total[static_cast<std::size_t>(s)] += block_sums[static_cast<std::size_t>(blk) * N + static_cast<std::size_t>(s)];
  }
  return total;
}

}  // namespace rktsph::exec
