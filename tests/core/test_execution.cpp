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

}  // namespace
}  // namespace rktsph
