#include <gtest/gtest.h>

#include "materials/material.hpp"

namespace rktsph {
namespace {

TEST(ElasticConstants, LameConstantsAndInverse) {
  const auto c = ElasticConstants::from_E_nu(1.0e7, 0.3, 2000.0);
  EXPECT_NEAR(c.G, 1.0e7 / 2.6, 1e-6);
  EXPECT_NEAR(c.lambda, 1.0e7 * 0.3 / (1.3 * 0.4), 1e-6);
  EXPECT_NEAR(c.M, c.lambda + 2.0 * c.G, 1e-6);
  const Sym6 eps{1e-3, -2e-4, 5e-5, 3e-4, -1e-4, 2e-4};
  const Sym6 back = c.apply_inverse(c.apply(eps));
  for (std::size_t i = 0; i < 6; ++i) EXPECT_NEAR(back[i], eps[i], 1e-15);
}

TEST(Invariants, PressureAndVonMises) {
  // Uniaxial compression of 3 Pa: p = 1, q = 3.
  const Invariants inv = invariants({-3.0, 0.0, 0.0, 0.0, 0.0, 0.0});
  EXPECT_DOUBLE_EQ(inv.p, 1.0);
  EXPECT_NEAR(inv.q, 3.0, 1e-14);
  // Pure shear tau: q = sqrt(3) tau.
  EXPECT_NEAR(invariants({0, 0, 0, 2.0, 0, 0}).q, 2.0 * std::sqrt(3.0), 1e-14);
}

}  // namespace
}  // namespace rktsph
