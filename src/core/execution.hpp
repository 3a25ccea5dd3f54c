#pragma once
// The one seam for particle loops (docs/architecture.md, "Execution"). A loop body is written
// once, as a callable of the index, and a policy runs it: Sequential on the calling thread (for
// debugging and as the reference), Threads on OpenMP. A device policy would be a third overload
// with the same signatures; no physics code names OpenMP.
//
// Reductions are deterministic: particle_reduce sums fixed blocks of kReductionBlock indices,
// each in index order, then the block sums in block order, so the result is the same bit for
// bit on any number of threads (tests/core/test_execution.cpp).
#include <omp.h>

#include <algorithm>
#include <array>
#include <exception>
#include <initializer_list>
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

/// Adaptive team size (docs/architecture.md, "Execution"), off unless the program turns it on:
/// `rktsph` does when the user has not fixed the thread count. The parallel loops then run in
/// epochs, all on the whole team or all on the calling thread alone, and keep to whichever
/// gets through more particles per second of loop time (TeamChoice). On a machine whose cores
/// other processes keep busy a team waits at every barrier for its preempted members, and one
/// thread can be many times faster; results are bit for bit the same either way.
inline bool& adaptive_teams() {
  static bool on = false;
  return on;
}

/// The choice between the whole team and one thread for every adaptive loop. An epoch is at
/// least kEpochCalls loop calls and kEpochSeconds of their wall time, all run one way; its
/// throughput (particles / loop seconds) is kept, the last kSamples per way, and each way is
/// judged by their median, so that one epoch hit by a burst of load does not decide. The very
/// first epoch is not kept (it holds the team's start, the first touches of the arrays and, in
/// a run, the set-up's loops, a mix unlike the steps'); then one epoch runs each way. The loops
/// run on the better way; the other is tried for one epoch every `probe_interval()` epochs, an
/// interval that grows fourfold (up to kMaxProbe) each time the trial confirms the choice and
/// restarts at kMinProbe when the choice changes.
///
/// Epochs of many calls compare the ways in the conditions they run in (a team woken at every
/// loop, a step's mix of loops); single calls tried alone were measured to favour one thread
/// unfairly. The way in use is measured all the time, so a way that turns slow is left after
/// two slow epochs; the trials cost about 1/kMaxProbe of the loop time once the choice is
/// settled (1/(kMaxProbe + 1) of the epochs run the other way). Not thread-safe: the loops are
/// called from one thread.
class TeamChoice {
 public:
  static constexpr long kEpochCalls = 32;
  static constexpr double kEpochSeconds = 0.005;
  static constexpr int kSamples = 3;
  static constexpr int kMinProbe = 4;
  static constexpr int kMaxProbe = 64;
  static constexpr double kMargin = 0.95;  // the other way must be 5 % faster to take over

  /// Whether the loops of the current epoch run on the team.
  bool team() const { return epoch_team_; }
  /// The way chosen (the one run outside trials).
  bool chosen() const { return chosen_team_; }
  int probe_interval() const { return probe_; }
  long epochs() const { return epochs_; }
  /// Median throughput of the last epochs of one way, particles per second (0 before any).
  double throughput(bool team) const {
    const int k = team ? 1 : 0;
    const long n = std::min<long>(count_[k], kSamples);
    const double* v = rate_[k];
    if (n == 0) return 0.0;
    if (n == 1) return v[0];
    if (n == 2) return 0.5 * (v[0] + v[1]);
    return std::max(std::min(v[0], v[1]), std::min(std::max(v[0], v[1]), v[2]));
  }

  /// One loop call of the current epoch: its particles and wall time.
  void record(double particles, double seconds) {
    work_ += particles;
    time_ += seconds;
    if (++calls_ < kEpochCalls || time_ < kEpochSeconds) return;
    const int k = epoch_team_ ? 1 : 0;
    const double rate = work_ / time_;
    work_ = time_ = 0.0;
    calls_ = 0;
    if (epochs_++ == 0) return;  // the first: the team's start, first touches, a set-up's loops
    rate_[k][count_[k] % kSamples] = rate;
    ++count_[k];
    if (count_[0] == 0 || count_[1] == 0) {  // then one epoch of each way: team, one thread
      epoch_team_ = count_[1] == 0;
      return;
    }
    const bool trial = epoch_team_ != chosen_team_;
    if (throughput(!chosen_team_) * kMargin > throughput(chosen_team_)) {
      chosen_team_ = !chosen_team_;
      probe_ = kMinProbe;
      since_probe_ = 0;
    } else if (trial) {
      probe_ = std::min(4 * probe_, kMaxProbe);
    }
    epoch_team_ = chosen_team_;
    if (!trial && ++since_probe_ >= probe_) {
      since_probe_ = 0;
      epoch_team_ = !chosen_team_;
    }
  }

 private:
  double rate_[2][kSamples] = {};  // [0] one thread, [1] the team
  long count_[2] = {0, 0};
  bool epoch_team_ = true;
  bool chosen_team_ = true;
  int probe_ = kMinProbe;
  int since_probe_ = 0;
  long epochs_ = 0;
  long calls_ = 0;
  double work_ = 0.0, time_ = 0.0;
};

/// The process's TeamChoice (used from the thread that calls the loops, never inside one).
inline TeamChoice& team_choice() {
  static TeamChoice choice;
  return choice;
}

/// Calls of the adaptive loops on the whole team and on one thread (for the run's summary).
struct TeamStats {
  long team_calls = 0;
  long single_calls = 0;
};
inline TeamStats& team_stats() {
  static TeamStats stats;
  return stats;
}

/// An exception thrown by the body on a thread cannot leave the parallel region (it would
/// terminate the program): the one of the lowest index is kept and rethrown after the loop, on
/// the calling thread, as the sequential loop would have thrown it.
template <class F>
void particle_for(const Threads& policy, Index n, F&& f, Schedule schedule = Schedule::even, Index work = -1) {
  const Index particles = work < 0 ? n : work;
  // One index (a reduction of a single block) gains nothing from a team.
  bool parallel = particles > policy.min_parallel && n > 1;
  const int team = omp_get_max_threads();
  // Adaptive team size, chosen and measured on the calling thread, not inside another region.
  const bool adapt = parallel && team > 1 && adaptive_teams() && omp_in_parallel() == 0;
  double t0 = 0.0;
  if (adapt) {
    parallel = team_choice().team();
    (parallel ? team_stats().team_calls : team_stats().single_calls) += 1;
    t0 = omp_get_wtime();
  }
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
#pragma omp parallel for schedule(dynamic) if (parallel) num_threads(team)
    for (Index i = 0; i < n; ++i) guarded(i);
  } else {
#pragma omp parallel for schedule(static) if (parallel) num_threads(team)
    for (Index i = 0; i < n; ++i) guarded(i);
  }
  if (adapt) team_choice().record(static_cast<double>(particles), omp_get_wtime() - t0);
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
