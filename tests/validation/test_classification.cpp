// The stable / collapse classification of docs/cases.md §1.3 (validation/cut_common.hpp) is not
// trivially true: synthetic histories of each kind are told apart, and on a coarse case-5 cut
// the full strength at N = 3.4 stands while half the cohesion (N = 6.8) collapses.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "../support/test_util.hpp"
#include "validation/cut_common.hpp"

namespace rktsph::validation {
namespace {

constexpr double kH = 10.0;

struct History {
  std::vector<double> t, uc, ke;
};

template <class U, class K>
History make(U&& uc, K&& ke, double t_end = 8.0) {
  History h;
  for (double t = 0.0; t <= t_end + 1e-9; t += 0.01) {
    h.t.push_back(t);
    h.uc.push_back(uc(t));
    h.ke.push_back(ke(t));
  }
  return h;
}

TEST(CutClassification, SyntheticHistories) {
  // Settles after the ramp, kinetic energy decays by four orders: stable.
  auto settle = make([](double t) { return 2e-3 * std::min(t, 3.0) / 3.0; },
                     [](double t) { return t < 3.0 ? 100.0 : 100.0 * std::exp(-3.0 * (t - 3.0)); });
  auto c = classify_cut(settle.t, settle.uc, settle.ke, kH);
  EXPECT_EQ(c.outcome, CutOutcome::stable);
  EXPECT_LT(c.uc_change, 1e-3 * kH);
  EXPECT_LT(c.ke_ratio, 1e-2);

  // Displacement at rest but still ringing (kinetic energy only 10x below its peak): not stable.
  auto ringing =
      make([](double t) { return 2e-3 * std::min(t, 3.0) / 3.0; }, [](double t) { return t < 3.0 ? 100.0 : 10.0; });
  EXPECT_NE(classify_cut(ringing.t, ringing.uc, ringing.ke, kH).outcome, CutOutcome::stable);

  // Large crest displacement: collapse.
  auto large = make([](double t) { return t < 4.0 ? 0.0 : 0.4 * (t - 4.0); }, [](double) { return 50.0; });
  EXPECT_EQ(classify_cut(large.t, large.uc, large.ke, kH).outcome, CutOutcome::collapse);

  // Below 0.05 H but accelerating at the end: collapse.
  auto accel = make([](double t) { return t < 6.0 ? 0.0 : 0.1 * (t - 6.0) * (t - 6.0); }, [](double) { return 5.0; });
  const auto ca = classify_cut(accel.t, accel.uc, accel.ke, kH);
  EXPECT_LT(ca.uc_end, 0.05 * kH);
  EXPECT_TRUE(ca.accelerating);
  EXPECT_EQ(ca.outcome, CutOutcome::collapse);

  // Steady creep at constant speed, below 0.05 H: neither.
  auto creep = make([](double t) { return 0.02 * t; }, [](double) { return 1.0; });
  EXPECT_EQ(classify_cut(creep.t, creep.uc, creep.ke, kH).outcome, CutOutcome::undecided);
}

// Case 5 at dx = 1 m (20 x 10 cells): the full strength at N = 3.4 is classified stable and the
// same cut with half the cohesion (c = 28.855 kPa, N = 6.8) collapses.
TEST(CutClassification, WeakenedCutCollapsesAndFullStrengthStands) {
  const test::ThreadCount threads(2);
  const std::string file = std::string(RKTSPH_SOURCE_DIR) + "/cases/thesis/05_viscoplastic_cut_2d.toml";
  const CutRun full = run_cut(file, {"geometry.spacing=1.0", "output.interval=0"}, 0.02);
  const CutRun weak = run_cut(file, {"geometry.spacing=1.0", "output.interval=0", "material.cohesion=28855"}, 0.02);
  std::printf("N = 3.4: %s (u_c = %.4g m, change %.3g m, kinetic ratio %.3g); half cohesion: %s (u_c = %.4g m)\n",
              outcome_name(full.classification.outcome), full.classification.uc_end, full.classification.uc_change,
              full.classification.ke_ratio, outcome_name(weak.classification.outcome), weak.classification.uc_end);
  ASSERT_TRUE(full.error.empty()) << full.error;
  EXPECT_EQ(full.classification.outcome, CutOutcome::stable);
  EXPECT_EQ(weak.classification.outcome, CutOutcome::collapse);
  EXPECT_GT(weak.classification.uc_end, 0.05 * kH);
}

}  // namespace
}  // namespace rktsph::validation
