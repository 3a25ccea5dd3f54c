// The toe-row scaling check of Case 4(a) (docs/cases.md, restated criterion;
// validation/cut_common.hpp toe_scaling): a corner field r^(lambda - 1) sampled at the toe rows of
// dx = 0.5 / 0.25 / 0.125 m passes, a residual that does not grow (a non-singular defect) or grows
// at another rate does not.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "validation/cut_common.hpp"

namespace rktsph::validation {
namespace {

const std::vector<double> kSpacings = {0.5, 0.25, 0.125};

std::vector<double> toe_rows(double exponent) {
  std::vector<double> r;
  for (double dx : kSpacings) r.push_back(0.09 * std::pow(dx / 0.5, exponent));
  return r;
}

TEST(ToeScaling, TheCornerFieldIsConstantOnceScaled) {
  const ToeScaling t = toe_scaling(kSpacings, toe_rows(kToeWilliamsLambda - 1.0));
  ASSERT_EQ(t.scaled.size(), 3u);
  EXPECT_NEAR(t.max_deviation, 0.0, 1e-12);
  EXPECT_NEAR(t.mean, 0.09 * std::pow(0.5, 1.0 - kToeWilliamsLambda), 1e-12);
}

TEST(ToeScaling, AResidualThatDoesNotGrowFailsTheFifteenPercentBand) {
  // Constant 9 %: scaled by dx^0.289 it falls by 18 % per halving.
  const ToeScaling t = toe_scaling(kSpacings, toe_rows(0.0));
  EXPECT_GT(t.max_deviation, 0.15);
}

TEST(ToeScaling, TheFiguresOfTheLastFullRunPass) {
  // docs/VALIDATION.md, Case 4: toe row 9.02 / 10.66 / 13.08 % of rho g H.
  const ToeScaling t = toe_scaling(kSpacings, {0.0902, 0.1066, 0.1308});
  EXPECT_LT(t.max_deviation, 0.15);
  EXPECT_NEAR(t.scaled[0], 0.0739, 5e-4);
}

TEST(ToeScaling, TooFewOrNonFiniteFiguresGiveNaN) {
  EXPECT_TRUE(std::isnan(toe_scaling({0.5}, {0.09}).max_deviation));
  EXPECT_TRUE(std::isnan(toe_scaling(kSpacings, {0.09, NAN, 0.1}).max_deviation));
}

}  // namespace
}  // namespace rktsph::validation
