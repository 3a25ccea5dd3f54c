// The run-out measures of io/runout.hpp (docs/output.md "Run-out measures"): the deposit profile
// and front of a known heap, the least-squares slope, the alpha-shape boundary of a lattice, and
// the disorder measure of a regular and a perturbed lattice.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "io/runout.hpp"

namespace rktsph::io {
namespace {

// A lattice of spacing d over [0, nx d] x [0, ny d].
std::vector<Vec<2>> lattice(int nx, int ny, double d) {
  std::vector<Vec<2>> x;
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) x.emplace_back(i * d, j * d);
  }
  return x;
}

TEST(DepositProfile, AStaircaseHeapGivesItsHeightsFrontAndArea) {
  const double d = 0.5;
  std::vector<Vec<2>> x;
  // Column k (x in [k d, (k + 1) d)) holds particles up to height (4 - k) d, k = 0..3.
  for (int k = 0; k < 4; ++k) {
    for (int j = 0; j <= 4 - k; ++j) x.emplace_back((k + 0.25) * d, j * d);
  }
  x.emplace_back(3.4 * d, 0.0);  // the front particle of column 3
  x.emplace_back(9.2 * d, 0.0);  // detached: beyond two empty columns
  const DepositProfile p = deposit_profile(x, 0.0, 12 * d, d);
  ASSERT_EQ(p.h.size(), 12u);
  for (int k = 0; k < 4; ++k) EXPECT_DOUBLE_EQ(p.h[static_cast<std::size_t>(k)], (4 - k) * d);
  EXPECT_EQ(p.front_column, 3);
  EXPECT_DOUBLE_EQ(p.front, 3.4 * d);
  EXPECT_EQ(p.detached, 1);
  EXPECT_DOUBLE_EQ(p.area, (4 + 3 + 2 + 1) * d * d);
  // One empty column is not a gap: the particle joins the body.
  x.back() = Vec<2>(5.5 * d, 0.0);
  const DepositProfile q = deposit_profile(x, 0.0, 12 * d, d);
  EXPECT_EQ(q.front_column, 5);
  EXPECT_EQ(q.detached, 0);
}

TEST(DepositProfile, TheSlopeOfALinearProfileIsExact) {
  std::vector<Vec<2>> x;
  const double d = 0.25;
  for (int k = 0; k < 20; ++k) x.emplace_back((k + 0.5) * d, 3.0 - 0.1 * (k + 0.5) * d);
  const DepositProfile p = deposit_profile(x, 0.0, 20 * d, d);
  EXPECT_NEAR(profile_slope(p, 10, 2.0 * d), -0.1, 1e-12);
  EXPECT_NEAR(profile_slope(p, 0, 2.0 * d), -0.1, 1e-12);  // one-sided at the end: three columns
  EXPECT_TRUE(std::isnan(profile_slope(p, 10, 0.4 * d)));  // a single column: no slope
}

TEST(AlphaBoundary, ALatticeHasExactlyItsOuterRowsOnTheBoundary) {
  const double d = 0.1;
  const int nx = 12, ny = 8;
  const auto x = lattice(nx, ny, d);
  const auto b = alpha_boundary(x, 1.5 * d);
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) {
      const bool outer = i == 0 || j == 0 || i == nx || j == ny;
      EXPECT_EQ(b[static_cast<std::size_t>(j * (nx + 1) + i)] != 0, outer) << i << "," << j;
    }
  }
  // A base below y = 0 and a wall left of x = 0 cover those faces: only the top and the right.
  const auto c = alpha_boundary(x, 1.5 * d, [](const Vec<2>& p) { return p[1] < 0.0 || p[0] < 0.0; });
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) {
      EXPECT_EQ(c[static_cast<std::size_t>(j * (nx + 1) + i)] != 0, i == nx || j == ny) << i << "," << j;
    }
  }
}

TEST(AlphaBoundary, AHoleWiderThanTheDiskIsBoundedAndANarrowOneIsNot) {
  const double d = 0.1;
  const int n = 20;
  auto x = lattice(n, n, d);
  std::vector<Vec<2>> holed;
  for (const auto& p : x) {
    if ((p - Vec<2>(1.0, 1.0)).norm() > 0.25) holed.push_back(p);  // removes the particles within 2.5 d
  }
  const auto b = alpha_boundary(holed, 1.5 * d);
  int rim = 0, elsewhere = 0;
  for (std::size_t i = 0; i < holed.size(); ++i) {
    const double r = (holed[i] - Vec<2>(1.0, 1.0)).norm();
    const bool outer = holed[i].minCoeff() < 1e-9 || holed[i].maxCoeff() > n * d - 1e-9;
    if (b[i] != 0 && r < 0.35) ++rim;
    if (b[i] != 0 && r >= 0.35 && !outer) ++elsewhere;
  }
  EXPECT_GE(rim, 8);  // the hole's rim: at least the nearest ring, at 2.8 d and 3 d
  EXPECT_EQ(elsewhere, 0);
  std::vector<Vec<2>> one;
  for (const auto& p : x) {
    if ((p - Vec<2>(1.0, 1.0)).norm() > 1e-9) one.push_back(p);  // a single missing particle
  }
  const auto c = alpha_boundary(one, 1.5 * d);
  for (std::size_t i = 0; i < one.size(); ++i) {
    if ((one[i] - Vec<2>(1.0, 1.0)).norm() < 0.5) {
      EXPECT_EQ(c[i], 0) << one[i].transpose();
    }
  }
}

TEST(ParticleDisorder, ALatticeIsOrderedAndAPerturbedOneIsNot) {
  const double d = 0.2;
  auto x = lattice(10, 10, d);
  const Disorder a = particle_disorder(x, d);
  EXPECT_NEAR(a.min, 1.0, 1e-12);
  EXPECT_NEAR(a.max, 1.0, 1e-12);
  EXPECT_NEAR(a.cv, 0.0, 1e-9);
  EXPECT_EQ(a.clustered, 0);
  EXPECT_EQ(a.isolated, 0);
  x[5] += Vec<2>(0.6 * d, 0.0);         // 0.4 d from its right neighbour
  x.emplace_back(30.0 * d, 30.0 * d);  // far from everything
  const Disorder b = particle_disorder(x, d);
  EXPECT_NEAR(b.min, 0.4, 1e-12);
  EXPECT_EQ(b.clustered, 2);
  EXPECT_EQ(b.isolated, 1);
  EXPECT_GT(b.cv, 0.0);
}

}  // namespace
}  // namespace rktsph::io
