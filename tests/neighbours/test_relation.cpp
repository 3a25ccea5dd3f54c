// Relation (neighbours/relation.hpp): the pairs of a brute-force search, sorted or in the cell
// list's order; a rebuild after the particles move gives the new pairs and a new version; the
// operators computed from a relation are those of a fresh search.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "../support/test_util.hpp"
#include "operators/corrected_operator.hpp"
#include "particles/lattice.hpp"

namespace rktsph {
namespace {

std::vector<Vec<2>> random_points(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 3.0);
  std::vector<Vec<2>> x(n);
  for (auto& p : x) p = Vec<2>(u(rng), u(rng));
  return x;
}

std::vector<std::vector<Index>> brute_force(const std::vector<Vec<2>>& targets, const std::vector<Vec<2>>& sources,
                                            double radius) {
  std::vector<std::vector<Index>> out(targets.size());
  for (std::size_t a = 0; a < targets.size(); ++a) {
    for (std::size_t b = 0; b < sources.size(); ++b) {
      if ((targets[a] - sources[b]).squaredNorm() < radius * radius) out[a].push_back(static_cast<Index>(b));
    }
  }
  return out;
}

TEST(Relation, MatchesABruteForceSearchAndRebuildsAfterAMove) {
  const test::ThreadCount threads(2);
  auto sources = random_points(3000, 1);
  const auto targets = random_points(2500, 2);
  Relation<2> rel;
  EXPECT_EQ(rel.version(), 0u);
  for (bool sorted : {true, false}) {
    rel.build(targets, sources, {0.25, 2, sorted});
    const auto ref = brute_force(targets, sources, 0.25);
    ASSERT_EQ(rel.rows(), static_cast<Index>(targets.size()));
    for (std::size_t a = 0; a < targets.size(); ++a) {
      std::vector<Index> row(rel.row(static_cast<Index>(a)).begin(), rel.row(static_cast<Index>(a)).end());
      if (sorted) {
        EXPECT_TRUE(std::is_sorted(row.begin(), row.end()));
      }
      std::sort(row.begin(), row.end());
      ASSERT_EQ(row, ref[a]) << "target " << a;
    }
  }
  EXPECT_EQ(rel.version(), 2u);
  // The sources move: the rebuilt relation is that of the new positions.
  for (auto& p : sources) p += Vec<2>(0.1, -0.05);
  rel.build(targets, sources, {0.25, 2, true});
  EXPECT_EQ(rel.version(), 3u);
  const auto moved = brute_force(targets, sources, 0.25);
  for (std::size_t a = 0; a < targets.size(); ++a) {
    const auto row = rel.row(static_cast<Index>(a));
    EXPECT_EQ(std::vector<Index>(row.begin(), row.end()), moved[a]);
  }
  // One and two threads build the same relation.
  std::vector<Index> two = rel.indices();
  {
    const test::ThreadCount one(1);
    rel.build(targets, sources, {0.25, 2, true});
  }
  EXPECT_EQ(rel.indices(), two);
  rel.release();
  EXPECT_EQ(rel.pairs(), 0u);
  EXPECT_EQ(rel.version(), 4u);
}

// The transpose of a relation (targets T, sources S) is the relation a search from S to T
// finds, row by row and in the same sorted order.
TEST(Relation, TransposeEqualsTheReverseSearch) {
  const test::ThreadCount threads(2);
  const auto s = random_points(3000, 3);
  const auto t = random_points(2500, 4);
  Relation<2> forward, reverse, transposed;
  forward.build(t, s, {0.25, 2, true});
  reverse.build(s, t, {0.25, 2, true});
  transposed.build_transpose(forward, static_cast<Index>(s.size()));
  ASSERT_GT(reverse.pairs(), 10000u);
  EXPECT_EQ(transposed.offsets(), reverse.offsets());
  EXPECT_EQ(transposed.indices(), reverse.indices());
  EXPECT_TRUE(transposed.options().sorted);
  EXPECT_EQ(transposed.version(), 1u);
}

TEST(Relation, OperatorsFromARelationEqualThoseOfAFreshSearch) {
  Block<2> b;
  b.min = Vec<2>(0, 0);
  b.max = Vec<2>(2, 1.5);
  auto lat = generate_lattice<2>({b}, 0.25, Vec<2>(0, 0), {1000.0});
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  for (auto& x : lat.stress_points.position) x += Vec<2>(u(rng), u(rng));  // moved off the lattice
  const CubicSplineKernel<2> kernel(1.2 * 0.25);
  Relation<2> rel;
  rel.build(lat.stress_points.position, lat.nodes.position, operator_relation_options(kernel));
  const auto from_relation = build_corrected_operator<2>(rel, lat.stress_points.position, lat.nodes, kernel);
  const auto fresh = build_corrected_operator<2>(lat.stress_points.position, lat.nodes, kernel);
  EXPECT_EQ(from_relation.base, fresh.base);
  EXPECT_EQ(from_relation.offset, fresh.offset);
  EXPECT_EQ(from_relation.interp, fresh.interp);
  ASSERT_EQ(from_relation.grad.size(), fresh.grad.size());
  for (std::size_t k = 0; k < fresh.grad.size(); ++k) EXPECT_EQ(from_relation.grad[k], fresh.grad[k]);
  // A relation of the wrong kind is refused.
  Relation<2> unsorted;
  unsorted.build(lat.stress_points.position, lat.nodes.position, {kernel.support_radius(), 2, false});
  EXPECT_THROW(build_corrected_operator<2>(unsorted, lat.stress_points.position, lat.nodes, kernel), SolverError);
}

}  // namespace
}  // namespace rktsph
