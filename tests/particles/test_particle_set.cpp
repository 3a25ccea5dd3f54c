// ParticleSet (particles/particle_set.hpp): fields by name through typed views, and a
// reordering that carries every property and field with its particle.
#include <gtest/gtest.h>

#include "core/error.hpp"
#include "particles/lattice.hpp"
#include "particles/particle_set.hpp"

namespace rktsph {
namespace {

ParticleSet<2> three_particles() {
  ParticleSet<2> s("test");
  s.add(Vec<2>(0.0, 0.0), 1.0, 1000.0, 0);
  s.add(Vec<2>(1.0, 0.0), 2.0, 2000.0, 1);
  s.add(Vec<2>(2.0, 0.0), 3.0, 3000.0, 0);
  return s;
}

TEST(ParticleSet, FieldsAreRegisteredOnceAndReadThroughViews) {
  ParticleSet<2> s = three_particles();
  const auto v = s.add_field<double, 2>("velocity", {"vx", "vy"}, kFieldOutput | kFieldEvolving);
  const auto flags = s.add_field<std::uint8_t, 1>("flags", {}, kFieldEvolving);
  const auto history = s.add_field<double, 0>("history", {"a", "b", "c"}, kFieldEvolving, 3);
  EXPECT_THROW((s.add_field<double, 2>("velocity", {}, 0)), SolverError);
  EXPECT_EQ((s.find<double, 2>("velocity").id), v.id);
  EXPECT_FALSE((s.find<double, 2>("nothing").valid()));
  EXPECT_THROW((s.find<double, 3>("velocity")), SolverError) << "wrong component count";
  EXPECT_THROW((s.find<std::uint8_t, 2>("velocity")), SolverError) << "wrong type";
  auto vv = s.view(v);
  vv(1, 0) = 4.0;
  vv(2, 1) = 5.0;
  EXPECT_EQ(vv[1][0], 4.0);
  EXPECT_EQ(s.view(history).components(), 3);
  s.view(history)(2, 2) = 7.0;
  s.view(flags)(0, 0) = 9;
  EXPECT_EQ(s.fields().size(), 3u);
  EXPECT_EQ(s.info(v.id).component_names[1], "vy");
  // A particle added later gets zeros in every field.
  s.add(Vec<2>(3.0, 0.0), 1.0, 1000.0, 0);
  EXPECT_EQ(s.view(v)(3, 0), 0.0);
  EXPECT_EQ(s.view(history)(3, 2), 0.0);
  EXPECT_EQ(s.view(v)(1, 0), 4.0);
  EXPECT_EQ(s.owned(), 4);
  EXPECT_EQ(s.ghosts(), 0);
  // Bytes: properties (16 + 8 + 8 + 4 + 8 per particle) and fields (16 + 1 + 24).
  EXPECT_EQ(s.bytes(), 4u * (16 + 8 + 8 + 4 + 8) + 4u * (16 + 1 + 24));
}

TEST(ParticleSet, PermuteCarriesEveryPropertyAndField) {
  ParticleSet<2> s = three_particles();
  const auto v = s.add_field<double, 2>("velocity", {"vx", "vy"}, kFieldEvolving);
  const auto flags = s.add_field<std::uint8_t, 1>("flags", {}, kFieldEvolving);
  for (Index i = 0; i < 3; ++i) {
    s.view(v)(i, 0) = 10.0 * i;
    s.view(v)(i, 1) = 10.0 * i + 1.0;
    s.view(flags)(i, 0) = static_cast<std::uint8_t>(i + 1);
  }
  s.permute({2, 0, 1});
  EXPECT_EQ(s.position[0][0], 2.0);
  EXPECT_EQ(s.volume[0], 3.0);
  EXPECT_EQ(s.density[1], 1000.0);
  EXPECT_EQ(s.material[2], 1);
  EXPECT_EQ(s.global_id[0], 2);
  EXPECT_EQ(s.global_id[1], 0);
  EXPECT_EQ(s.view(v)(0, 0), 20.0);
  EXPECT_EQ(s.view(v)(0, 1), 21.0);
  EXPECT_EQ(s.view(v)(2, 1), 11.0);
  EXPECT_EQ(s.view(flags)(0, 0), 3);
  EXPECT_THROW(s.permute({0, 1}), SolverError);
  // In place: a view taken before reads the reordered values (V2 sorts sets that stages and
  // output catalogues hold views of).
  const double* before = s.view(v).data();
  s.permute({1, 2, 0});
  EXPECT_EQ(s.view(v).data(), before);
  EXPECT_EQ(s.global_id, (std::vector<std::int64_t>{0, 1, 2}));
  EXPECT_EQ(before[2], 10.0);
}

TEST(BoundaryNodes, RemapFollowsAPermutationOfTheNodes) {
  Block<2> b;
  b.min = Vec<2>(0, 0);
  b.max = Vec<2>(2, 1);
  auto lat = generate_lattice<2>({b}, 0.5, Vec<2>(0, 0), {1000.0});
  const Index n = lat.nodes.size();
  const auto before = lat.boundary.dense_faces(n);
  std::vector<Index> order(static_cast<std::size_t>(n));
  for (Index k = 0; k < n; ++k) order[static_cast<std::size_t>(k)] = n - 1 - k;  // reverse
  lat.nodes.permute(order);
  lat.boundary.remap(order);
  const auto after = lat.boundary.dense_faces(n);
  for (Index k = 0; k < n; ++k)
    EXPECT_EQ(after[static_cast<std::size_t>(k)], before[static_cast<std::size_t>(n - 1 - k)]);
  EXPECT_TRUE(std::is_sorted(lat.boundary.node.begin(), lat.boundary.node.end()));
}

}  // namespace
}  // namespace rktsph
