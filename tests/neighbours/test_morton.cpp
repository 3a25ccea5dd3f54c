// Morton order (neighbours/morton.hpp): the keys interleave the cell coordinates' bits, the
// order sorts by key with ties by global id whatever order the particles come in, an ordered
// set is recognised as such, and the order puts neighbours in space near each other in memory.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <random>
#include <vector>

#include "neighbours/cell_list.hpp"
#include "neighbours/morton.hpp"

namespace rktsph {
namespace {

// Bit b of axis d goes to bit Dim b + d.
template <int Dim>
std::uint64_t interleave_by_bits(const std::array<std::int64_t, Dim>& c, int bits) {
  std::uint64_t key = 0;
  for (int b = 0; b < bits; ++b) {
    for (int d = 0; d < Dim; ++d) {
      const auto v = static_cast<std::uint64_t>(c[static_cast<std::size_t>(d)]);
      key |= ((v >> b) & 1u) << (Dim * b + d);
    }
  }
  return key;
}

TEST(Morton, KeysInterleaveTheCellCoordinates) {
  EXPECT_EQ(morton_key<2>({1, 0}), 1u);
  EXPECT_EQ(morton_key<2>({0, 1}), 2u);
  EXPECT_EQ(morton_key<2>({1, 1}), 3u);
  EXPECT_EQ(morton_key<2>({2, 0}), 4u);
  EXPECT_EQ(morton_key<3>({1, 0, 0}), 1u);
  EXPECT_EQ(morton_key<3>({0, 1, 0}), 2u);
  EXPECT_EQ(morton_key<3>({0, 0, 1}), 4u);
  EXPECT_EQ(morton_key<3>({2, 0, 0}), 8u);
  EXPECT_EQ(morton_key<1>({12345}), 12345u);
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<std::int64_t> two(0, (std::int64_t{1} << 32) - 1), three(0, (1 << 21) - 1);
  for (int k = 0; k < 1000; ++k) {
    const std::array<std::int64_t, 2> c2{two(rng), two(rng)};
    const std::array<std::int64_t, 3> c3{three(rng), three(rng), three(rng)};
    ASSERT_EQ(morton_key<2>(c2), interleave_by_bits<2>(c2, 32));
    ASSERT_EQ(morton_key<3>(c3), interleave_by_bits<3>(c3, 21));
  }
  // Beyond the range, clamped (still ordered along each axis).
  EXPECT_EQ(morton_key<3>({-5, 0, 0}), 0u);
  EXPECT_EQ(morton_key<3>({std::int64_t{1} << 40, 0, 0}), morton_key<3>({(1 << 21) - 1, 0, 0}));
}

// A 60 x 40 lattice, spacing 1, shuffled; ids are the lattice order.
struct Cloud {
  std::vector<Vec<2>> x;
  std::vector<std::int64_t> id;
};
Cloud shuffled_lattice(unsigned seed) {
  Cloud c;
  for (int j = 0; j < 40; ++j) {
    for (int i = 0; i < 60; ++i) {
      c.x.emplace_back(i, j);
      c.id.push_back(static_cast<std::int64_t>(c.id.size()));
    }
  }
  std::vector<std::size_t> p(c.x.size());
  std::iota(p.begin(), p.end(), 0);
  std::shuffle(p.begin(), p.end(), std::mt19937(seed));
  Cloud s;
  for (const std::size_t k : p) s.x.push_back(c.x[k]), s.id.push_back(c.id[k]);
  return s;
}

TEST(Morton, OrderSortsByKeyThenIdWhateverTheStartingOrder) {
  const Vec<2> lo(-0.5, -0.5);
  const double cell = 2.4;
  std::vector<Index> order;
  std::vector<std::uint64_t> keys;
  std::vector<std::int64_t> first;
  for (const unsigned seed : {1u, 2u, 3u}) {
    const Cloud c = shuffled_lattice(seed);
    ASSERT_TRUE(morton_order<2>(c.x, c.id, lo, cell, order, keys));
    std::vector<std::int64_t> ids;
    std::vector<std::uint64_t> sorted_keys;
    for (const Index i : order) {
      const auto iu = static_cast<std::size_t>(i);
      ids.push_back(c.id[iu]);
      sorted_keys.push_back(morton_key<2>({static_cast<std::int64_t>(std::floor((c.x[iu][0] - lo[0]) / cell)),
                                           static_cast<std::int64_t>(std::floor((c.x[iu][1] - lo[1]) / cell))}));
    }
    for (std::size_t k = 1; k < ids.size(); ++k) {
      ASSERT_LE(sorted_keys[k - 1], sorted_keys[k]);
      if (sorted_keys[k - 1] == sorted_keys[k]) {
        ASSERT_LT(ids[k - 1], ids[k]);
      }
    }
    if (first.empty()) first = ids;
    EXPECT_EQ(ids, first) << "the order depends on the positions and ids only";
    // Once sorted, the set is recognised as sorted: no reordering, the identity returned.
    Cloud sorted;
    for (const Index i : order)
      sorted.x.push_back(c.x[static_cast<std::size_t>(i)]), sorted.id.push_back(c.id[static_cast<std::size_t>(i)]);
    std::vector<Index> again;
    EXPECT_FALSE(morton_order<2>(sorted.x, sorted.id, lo, cell, again, keys));
    for (std::size_t k = 0; k < again.size(); ++k) ASSERT_EQ(again[k], static_cast<Index>(k));
  }
}

// Neighbours in space end up near each other in memory: over the pairs within 2.4 spacings,
// the mean distance of their indices is a small multiple of a cell's row of particles in Morton
// order, against a third of the set in a random order.
TEST(Morton, NeighboursInSpaceAreNearInMemory) {
  const Cloud c = shuffled_lattice(11);
  std::vector<Index> order;
  std::vector<std::uint64_t> keys;
  ASSERT_TRUE(morton_order<2>(c.x, c.id, Vec<2>(-0.5, -0.5), 2.4, order, keys));
  std::vector<Vec<2>> sorted;
  for (const Index i : order) sorted.push_back(c.x[static_cast<std::size_t>(i)]);
  auto mean_gap = [](const std::vector<Vec<2>>& x) {
    const CellList<2> cells(x, 2.4);
    double sum = 0.0;
    long pairs = 0;
    for (std::size_t i = 0; i < x.size(); ++i) {
      cells.for_each_neighbour(x[i], [&](Index j, const Vec<2>&, double) {
        sum += std::abs(static_cast<double>(j) - static_cast<double>(i));
        ++pairs;
      });
    }
    return sum / static_cast<double>(pairs);
  };
  const double random = mean_gap(c.x), morton = mean_gap(sorted);
  EXPECT_GT(random, 0.25 * static_cast<double>(c.x.size()));
  EXPECT_LT(morton, 0.05 * static_cast<double>(c.x.size()));
  std::printf("mean index gap of neighbour pairs, 2400 particles: random %.0f, Morton %.1f\n", random, morton);
}

}  // namespace
}  // namespace rktsph
