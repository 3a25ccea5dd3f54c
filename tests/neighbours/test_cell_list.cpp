// Cell list (neighbours/cell_list.hpp): for_each_neighbour and collect find exactly the points
// a brute-force search finds, for cells of the search radius and of fractions of it, at query
// points inside and outside the box of the points.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "neighbours/cell_list.hpp"

namespace rktsph {
namespace {

template <int Dim>
void check(int subdivisions, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 3.0);
  std::vector<Vec<Dim>> points(400);
  for (auto& p : points) {
    for (int d = 0; d < Dim; ++d) p[d] = u(rng);
  }
  const double radius = 0.45;
  const CellList<Dim> cells(points, radius, subdivisions);
  std::uniform_real_distribution<double> q(-0.5, 3.5);  // some queries outside the box
  std::vector<typename CellList<Dim>::Hit> buf;
  for (int t = 0; t < 200; ++t) {
    Vec<Dim> x;
    for (int d = 0; d < Dim; ++d) x[d] = q(rng);
    std::vector<Index> brute, found, collected;
    for (std::size_t j = 0; j < points.size(); ++j) {
      if ((x - points[j]).squaredNorm() < radius * radius) brute.push_back(static_cast<Index>(j));
    }
    cells.for_each_neighbour(x, [&](Index j, const Vec<Dim>& x_ij, double r) {
      EXPECT_NEAR((x_ij - (x - points[static_cast<std::size_t>(j)])).norm(), 0.0, 1e-15);
      EXPECT_NEAR(r, x_ij.norm(), 1e-15);
      found.push_back(j);
    });
    const std::size_t n = cells.collect(x, radius * radius, buf);
    for (std::size_t i = 0; i < n; ++i) collected.push_back(buf[i].j);
    // collect reports in the order of for_each_neighbour
    EXPECT_EQ(collected, found);
    std::sort(found.begin(), found.end());
    EXPECT_EQ(found, brute) << "subdivisions " << subdivisions;
  }
}

TEST(CellList, MatchesBruteForce) {
  std::mt19937 rng(3);
  for (int s : {1, 2, 3}) {
    check<1>(s, rng);
    check<2>(s, rng);
    check<3>(s, rng);
  }
}

}  // namespace
}  // namespace rktsph

namespace rktsph {
namespace {

// A particle flung far away (a run gone unstable) or a non-finite position stops the search
// with a diagnosis instead of allocating a grid of astronomical size.
TEST(CellList, FarFlungOrNonFinitePointsAreASolverError) {
  std::vector<Vec<2>> points;
  for (int i = 0; i < 100; ++i) points.emplace_back(0.1 * (i % 10), 0.1 * (i / 10));
  EXPECT_NO_THROW(CellList<2>(points, 0.24));
  points.emplace_back(0.0, 1e100);
  try {
    CellList<2> cells(points, 0.24);
    FAIL() << "no error for a point 1e100 m away";
  } catch (const SolverError& e) {
    EXPECT_NE(std::string(e.what()).find("flung far apart"), std::string::npos) << e.what();
  }
  points.back() = Vec<2>(std::numeric_limits<double>::quiet_NaN(), 0.0);
  EXPECT_THROW(CellList<2>(points, 0.24), SolverError);
  // A sparse but sound set: two clusters 1 km apart are within the floor of 2^24 cells.
  points.back() = Vec<2>(1000.0, 0.0);
  EXPECT_NO_THROW(CellList<2>(points, 0.24));
}

}  // namespace
}  // namespace rktsph
