// The execution seam (core/execution.hpp): the same loop on the sequential and the threaded
// policy, deterministic reductions, and exceptions from a parallel loop reaching the caller.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "../support/test_util.hpp"
#include "core/execution.hpp"

namespace rktsph {
namespace {

TEST(Execution, SequentialAndThreadsVisitEveryIndexOnce) {
  const test::ThreadCount threads(2);
  const Index n = 10000;
  std::vector<int> seq(static_cast<std::size_t>(n), 0), par(static_cast<std::size_t>(n), 0);
  exec::particle_for(exec::Sequential{}, n, [&](Index i) { seq[static_cast<std::size_t>(i)] += 1; });
  exec::particle_for(exec::Threads{}, n, [&](Index i) { par[static_cast<std::size_t>(i)] += 1; });
  exec::particle_for(
      exec::Threads{}, n, [&](Index i) { par[static_cast<std::size_t>(i)] += 1; }, exec::Schedule::dynamic);
  for (Index i = 0; i < n; ++i) {
    EXPECT_EQ(seq[static_cast<std::size_t>(i)], 1);
    EXPECT_EQ(par[static_cast<std::size_t>(i)], 2);
  }
}

// Sums of values whose floating-point sum depends on the order: the fixed blocks give the same
// bits on one and two threads and with the sequential policy.
TEST(Execution, ReductionIsBitIdenticalOnAnyThreadCount) {
  const Index n = 100003;
  std::vector<double> x(static_cast<std::size_t>(n));
  for (Index i = 0; i < n; ++i) x[static_cast<std::size_t>(i)] = std::sin(0.37 * i) * std::pow(10.0, (i % 17) - 8);
  auto sum = [&](const auto& policy) {
    exec::ReductionScratch scratch;
    return exec::particle_reduce<2>(policy, n, scratch, [&](Index i, double* acc) {
      acc[0] += x[static_cast<std::size_t>(i)];
      acc[1] += x[static_cast<std::size_t>(i)] * x[static_cast<std::size_t>(i)];
    });
  };
  const auto seq = sum(exec::Sequential{});
  std::array<double, 2> one{}, two{};
  {
    const test::ThreadCount threads(1);
    one = sum(exec::Threads{});
  }
  {
    const test::ThreadCount threads(2);
    two = sum(exec::Threads{});
  }
  EXPECT_EQ(std::memcmp(seq.data(), one.data(), sizeof(seq)), 0);
  EXPECT_EQ(std::memcmp(one.data(), two.data(), sizeof(one)), 0);
  double plain = 0.0;
  for (double v : x) plain += v;
  EXPECT_NEAR(seq[0], plain, 1e-12 * std::abs(plain) + 1e-20);
}

// A body that throws on some thread: the loop finishes, and the exception of the lowest index
// reaches the caller (a sequential loop would have thrown that one first).
TEST(Execution, AnExceptionInAParallelLoopReachesTheCaller) {
  const test::ThreadCount threads(2);
  const Index n = 50000;
  try {
    exec::particle_for(exec::Threads{}, n, [&](Index i) {
      if (i == 40000 || i == 123) throw std::runtime_error("index " + std::to_string(i));
    });
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "index 123");
  }
}

// The adaptive team size (exec::TeamChoice): loop calls fed with the wall time a way would take
// at a given throughput (particles per second), 1e4 particles and about 1 ms per call.
struct Machine {
  double team_rate;    // particles / s on the whole team
  double single_rate;  // on one thread
};

struct Outcome {
  long team_calls = 0, single_calls = 0;
};

Outcome feed(exec::TeamChoice& choice, const Machine& m, long calls) {
  Outcome o;
  for (long c = 0; c < calls; ++c) {
    const bool team = choice.team();
    (team ? o.team_calls : o.single_calls) += 1;
    const double particles = 1e4;
    choice.record(particles, particles / (team ? m.team_rate : m.single_rate));
  }
  return o;
}

TEST(TeamChoice, QuietMachineKeepsTheTeamAndTriesOneThreadRarely) {
  exec::TeamChoice choice;
  const Outcome o = feed(choice, {2e7, 1e7}, 20000);  // the team twice as fast
  EXPECT_TRUE(choice.chosen());
  EXPECT_EQ(choice.probe_interval(), exec::TeamChoice::kMaxProbe);
  // The warm-up epoch and the trials: 1 + about 20000 / 32 / 65 epochs of 32 calls.
  EXPECT_LT(static_cast<double>(o.single_calls) / 20000.0, 0.025) << o.single_calls;
}

TEST(TeamChoice, BusyMachineRunsOnOneThread) {
  exec::TeamChoice choice;
  const Outcome o = feed(choice, {1e6, 1e7}, 20000);  // a team waiting for preempted threads
  EXPECT_FALSE(choice.chosen());
  EXPECT_LT(static_cast<double>(o.team_calls) / 20000.0, 0.025) << o.team_calls;
}

TEST(TeamChoice, FollowsTheLoadBothWays) {
  exec::TeamChoice choice;
  feed(choice, {2e7, 1e7}, 5000);
  ASSERT_TRUE(choice.chosen());
  // Other processes take the cores: the team, measured at every call, is left within three
  // epochs (two slow epochs move the median).
  feed(choice, {5e5, 8e6}, 3 * exec::TeamChoice::kEpochCalls);
  EXPECT_FALSE(choice.chosen());
  // They stop: a trial finds the team faster again within the longest trial interval.
  feed(choice, {2e7, 1e7}, (exec::TeamChoice::kMaxProbe + 4) * exec::TeamChoice::kEpochCalls);
  EXPECT_TRUE(choice.chosen());
}

TEST(TeamChoice, TheFirstEpochIsNotKept) {
  // A run's first loops: the team's start and the set-up's heavier loops, 10x slower per
  // particle than the steps' on the team; then the steps, where the team is twice as fast.
  exec::TeamChoice choice;
  feed(choice, {2e6, 1e7}, exec::TeamChoice::kEpochCalls);
  const Outcome o = feed(choice, {2e7, 1e7}, 5000);
  EXPECT_TRUE(choice.chosen());
  // Never switched: the one-thread epoch of the start and trials after 16, 64 and 128 epochs.
  EXPECT_EQ(choice.probe_interval(), exec::TeamChoice::kMaxProbe);
  EXPECT_LE(o.single_calls, 4 * exec::TeamChoice::kEpochCalls);
}

TEST(TeamChoice, OneSlowEpochDoesNotDecide) {
  exec::TeamChoice choice;
  feed(choice, {2e7, 1e7}, 5000);
  ASSERT_TRUE(choice.chosen());
  feed(choice, {1e6, 1e7}, exec::TeamChoice::kEpochCalls);  // one epoch hit by a burst of load
  feed(choice, {2e7, 1e7}, 1);
  EXPECT_TRUE(choice.chosen());
}

// With the adaptive team size on, loops visit every index once and reductions keep their bits,
// whichever way each epoch runs.
TEST(Execution, AdaptiveTeamsGiveTheSameResults) {
  const test::ThreadCount threads(2);
  const Index n = 100003;
  std::vector<double> x(static_cast<std::size_t>(n));
  for (Index i = 0; i < n; ++i) x[static_cast<std::size_t>(i)] = std::sin(0.37 * i) * std::pow(10.0, (i % 17) - 8);
  auto sum = [&] {
    exec::ReductionScratch scratch;
    return exec::particle_reduce<1>(exec::Threads{}, n, scratch,
                                    [&](Index i, double* acc) { acc[0] += x[static_cast<std::size_t>(i)]; });
  };
  const auto reference = sum();
  exec::adaptive_teams() = true;
  const exec::TeamStats before = exec::team_stats();
  std::vector<int> visits(static_cast<std::size_t>(n), 0);
  for (int k = 0; k < 300; ++k) {
    const auto s = sum();
    EXPECT_EQ(std::memcmp(s.data(), reference.data(), sizeof(s)), 0) << "call " << k;
    exec::particle_for(exec::Threads{}, n, [&](Index i) { visits[static_cast<std::size_t>(i)] += 1; });
  }
  exec::adaptive_teams() = false;
  for (Index i = 0; i < n; ++i) ASSERT_EQ(visits[static_cast<std::size_t>(i)], 300);
  // Both ways ran: the first epoch on the team, the second on one thread.
  EXPECT_GT(exec::team_stats().team_calls - before.team_calls, 0);
  EXPECT_GT(exec::team_stats().single_calls - before.single_calls, 0);
  EXPECT_EQ(exec::team_stats().team_calls + exec::team_stats().single_calls - (before.team_calls + before.single_calls),
            600);
}

}  // namespace
}  // namespace rktsph
