// The search of `rktsph fos` (app/fos_search.hpp) on a fake classifier whose outcome flips at a
// known factor F*: the bracket holds F*, closes to the tolerance, takes the trial count the
// expansion-then-bisection predicts, does not depend on how many trials run at once, and ends
// with the right state on every error path.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <vector>

#include "app/fos_search.hpp"

namespace rktsph::fos {
namespace {

struct SearchRun {
  SearchStatus status;
  std::vector<Step> path;
  std::map<double, bool> known;
  int evaluations = 0;  // trials run, speculative ones included
  int batches = 0;
};

// The classifier: stable iff F <= F* (a material whose strength suffices up to F*).
SearchRun search(double f_star, const SearchSettings& settings, int width) {
  SearchRun r;
  r.status = run_search(
      settings, width,
      [&](const std::vector<double>& batch) {
        ++r.batches;
        EXPECT_LE(static_cast<int>(batch.size()), width);
        std::vector<bool> out;
        for (double f : batch) {
          EXPECT_EQ(r.known.count(f), 0u) << "F = " << f << " run twice";
          out.push_back(f <= f_star);
          ++r.evaluations;
        }
        return out;
      },
      r.path, r.known);
  return r;
}

TEST(FosSearch, BracketHoldsTheFlipAndClosesToTheTolerance) {
  for (double f_star : {1.0, 1.0004, 1.11, 1.2856, 1.37, 2.5, 7.0}) {
    for (double tol : {0.05, 0.01, 0.001}) {
      SearchSettings s;
      s.tolerance = tol;
      s.max_trials = 40;
      const SearchRun r = search(f_star, s, 1);
      ASSERT_EQ(r.status.state, SearchState::converged) << f_star << " " << tol;
      EXPECT_LE(r.status.lo, f_star);
      EXPECT_GT(r.status.hi, f_star);
      EXPECT_LE(r.status.hi - r.status.lo, tol * r.status.lo);
      EXPECT_LE(std::abs(r.status.factor() - f_star), 0.5 * tol * r.status.lo);
      EXPECT_EQ(r.path.front().factor, 1.0);
      EXPECT_TRUE(r.path.front().stable);
    }
  }
}

TEST(FosSearch, TrialCountOfExpansionThenBisection) {
  // F* = 1.37, growth 1.25: 1 and 1.25 stand, 1.5625 fails (3 trials); the bracket, 0.3125 wide,
  // halves until its width <= 0.01 lo (lo >= 1.25): 5 halvings to 0.0098. 8 trials in all.
  SearchSettings s;
  const SearchRun r = search(1.37, s, 1);
  ASSERT_EQ(r.status.state, SearchState::converged);
  EXPECT_EQ(r.path.size(), 8u);
  EXPECT_EQ(r.evaluations, 8);
  EXPECT_DOUBLE_EQ(r.path[1].factor, 1.25);
  EXPECT_DOUBLE_EQ(r.path[2].factor, 1.5625);
  EXPECT_DOUBLE_EQ(r.path[3].factor, 0.5 * (1.25 + 1.5625));
  EXPECT_NEAR(r.status.hi - r.status.lo, 0.3125 / 32.0, 1e-15);
}

TEST(FosSearch, ParallelTrialsTakeTheSamePathAndGiveTheSameFactor) {
  SearchSettings s;
  s.tolerance = 0.005;
  s.max_trials = 30;
  for (double f_star : {1.11, 1.37, 3.3}) {
    const SearchRun one = search(f_star, s, 1);
    for (int width : {2, 3, 4, 7, 16}) {
      const SearchRun many = search(f_star, s, width);
      ASSERT_EQ(many.status.state, SearchState::converged);
      EXPECT_EQ(many.status.factor(), one.status.factor()) << width;  // bit for bit
      ASSERT_EQ(many.path.size(), one.path.size());
      for (std::size_t k = 0; k < one.path.size(); ++k) EXPECT_EQ(many.path[k].factor, one.path[k].factor);
      EXPECT_GE(many.evaluations, one.evaluations);
      EXPECT_LT(many.batches, one.batches) << "width " << width << " saved no round";
    }
  }
}

TEST(FosSearch, BatchOfThreeIsTwoLevelsOfTheDecisionTree) {
  // From [1, 1.5625] (1 and 1.25 stand, 1.5625 fails): the midpoint 1.40625 and both of its
  // children, the lower one first.
  SearchSettings s;
  const std::vector<Step> path = {{1.0, true}, {1.25, true}, {1.5625, false}};
  const std::map<double, bool> known = {{1.0, true}, {1.25, true}, {1.5625, false}};
  const std::vector<double> b = speculative_batch(s, path, known, 3);
  ASSERT_EQ(b.size(), 3u);
  EXPECT_DOUBLE_EQ(b[0], 1.40625);
  EXPECT_DOUBLE_EQ(b[1], 0.5 * (1.25 + 1.40625));
  EXPECT_DOUBLE_EQ(b[2], 0.5 * (1.40625 + 1.5625));
}

TEST(FosSearch, UnreducedRunThatFailsEndsTheSearchAtOnce) {
  SearchSettings s;
  const SearchRun r = search(0.9, s, 1);
  EXPECT_EQ(r.status.state, SearchState::unreduced_fails);
  EXPECT_EQ(r.path.size(), 1u);
  EXPECT_TRUE(std::isnan(r.status.factor()));
  // In parallel the speculative trials run, but the verdict is the same and they stay known.
  const SearchRun p = search(0.9, s, 2);
  EXPECT_EQ(p.status.state, SearchState::unreduced_fails);
  EXPECT_EQ(p.path.size(), 1u);
  EXPECT_EQ(p.known.size(), 2u);
}

TEST(FosSearch, BracketThatDoesNotCloseWithinTheTrials) {
  SearchSettings s;
  s.max_trials = 5;  // 3 to bracket 1.37, then 2 halvings: 0.078 wide, tolerance 0.0125
  const SearchRun r = search(1.37, s, 1);
  EXPECT_EQ(r.status.state, SearchState::bracket_open);
  EXPECT_EQ(r.path.size(), 5u);
  EXPECT_LE(r.status.lo, 1.37);
  EXPECT_GT(r.status.hi, 1.37);
  EXPECT_TRUE(std::isnan(r.status.factor()));
  // Every trial stands: the expansion never finds a collapse.
  const SearchRun all = search(1e9, s, 3);
  EXPECT_EQ(all.status.state, SearchState::bracket_open);
  EXPECT_TRUE(std::isinf(all.status.hi));
  EXPECT_DOUBLE_EQ(all.status.lo, std::pow(1.25, 4));
  EXPECT_EQ(all.path.size(), 5u);
}

TEST(FosSearch, StableTrialAboveAFailureDoesNotMoveTheBracket) {
  // A non-monotone classifier: 1.25 fails but 1.5 stands; lo stays below hi.
  SearchSettings s;
  const std::vector<Step> path = {{1.0, true}, {1.25, false}, {1.5, true}};
  const SearchStatus st = status_after(s, path);
  EXPECT_EQ(st.state, SearchState::running);
  EXPECT_DOUBLE_EQ(st.lo, 1.0);
  EXPECT_DOUBLE_EQ(st.hi, 1.25);
  EXPECT_DOUBLE_EQ(st.next, 1.125);
}

TEST(FosSearch, GrowthSetsTheExpansion) {
  SearchSettings s;
  s.growth = 2.0;
  s.tolerance = 0.02;
  const SearchRun r = search(5.0, s, 1);
  ASSERT_EQ(r.status.state, SearchState::converged);
  EXPECT_DOUBLE_EQ(r.path[1].factor, 2.0);
  EXPECT_DOUBLE_EQ(r.path[2].factor, 4.0);
  EXPECT_DOUBLE_EQ(r.path[3].factor, 8.0);
  EXPECT_FALSE(r.path[3].stable);
}

}  // namespace
}  // namespace rktsph::fos
