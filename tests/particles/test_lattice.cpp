// generate_lattice(): nodes at lattice vertices with tributary volumes, stress points at cell centres,
// boundary face flags and face areas (method-notes §3.3).
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

#include "core/error.hpp"
#include "particles/lattice.hpp"

namespace rktsph {
namespace {

constexpr std::uint8_t kMinusX = 1u << 0, kPlusX = 1u << 1, kMinusY = 1u << 2, kPlusY = 1u << 3;

// L-shape: [0,4]x[0,2] plus [0,2]x[2,4] (area 12 m^2), dx = 0.5.
LatticeParticles<2> l_shape(double dx = 0.5) {
  Block<2> a, b;
  a.min = Vec<2>(0, 0);
  a.max = Vec<2>(4, 2);
  a.label = "geometry.block[0]";
  b.min = Vec<2>(0, 2);
  b.max = Vec<2>(2, 4);
  b.label = "geometry.block[1]";
  return generate_lattice<2>({a, b}, dx, Vec<2>(0, 0), {2000.0});
}

Index find_node(const LatticeParticles<2>& d, double x, double y) {
  for (Index i = 0; i < d.nodes.size(); ++i) {
    const auto& p = d.nodes.position[static_cast<std::size_t>(i)];
    if (std::abs(p[0] - x) < 1e-12 && std::abs(p[1] - y) < 1e-12) return i;
  }
  ADD_FAILURE() << "no node at (" << x << ", " << y << ")";
  return 0;
}

TEST(Discretise, CountsAndTotalVolumesOfAnLShape) {
  const double dx = 0.5;
  const auto d = l_shape(dx);
  // cells: 8x4 + 4x4 = 48; nodes: 9x5 + 5x4 (rows y = 2.5..4) = 65.
  EXPECT_EQ(d.stress_points.size(), 48);
  EXPECT_EQ(d.nodes.size(), 65);
  const double vn = std::accumulate(d.nodes.volume.begin(), d.nodes.volume.end(), 0.0);
  const double ve = std::accumulate(d.stress_points.volume.begin(), d.stress_points.volume.end(), 0.0);
  EXPECT_NEAR(vn, 12.0, 1e-12);
  EXPECT_NEAR(ve, 12.0, 1e-12);
  for (double v : d.stress_points.volume) EXPECT_DOUBLE_EQ(v, dx * dx);
  // Stress points sit at cell centres, strictly inside the body.
  for (const auto& x : d.stress_points.position) {
    const double fx = x[0] / dx - std::floor(x[0] / dx), fy = x[1] / dx - std::floor(x[1] / dx);
    EXPECT_NEAR(fx, 0.5, 1e-12);
    EXPECT_NEAR(fy, 0.5, 1e-12);
    EXPECT_FALSE(x[0] > 2.0 && x[1] > 2.0) << "stress point in the missing quadrant";
  }
  // Mass: each set carries the whole mass.
  double mn = 0.0, me = 0.0;
  for (Index i = 0; i < d.nodes.size(); ++i) mn += d.nodes.mass(i);
  for (Index i = 0; i < d.stress_points.size(); ++i) me += d.stress_points.mass(i);
  EXPECT_NEAR(mn, 12.0 * 2000.0, 1e-8);
  EXPECT_NEAR(me, 12.0 * 2000.0, 1e-8);
}

TEST(Discretise, TributaryVolumes) {
  const double dx = 0.5, c = dx * dx;
  const auto d = l_shape(dx);
  auto vol = [&](double x, double y) { return d.nodes.volume[static_cast<std::size_t>(find_node(d, x, y))]; };
  EXPECT_DOUBLE_EQ(vol(1.0, 1.0), c);      // interior
  EXPECT_DOUBLE_EQ(vol(2.0, 1.5), c);      // interior (below the re-entrant corner)
  EXPECT_DOUBLE_EQ(vol(1.5, 0.0), c / 2);  // bottom edge
  EXPECT_DOUBLE_EQ(vol(0.0, 3.0), c / 2);  // left edge
  EXPECT_DOUBLE_EQ(vol(3.0, 2.0), c / 2);  // top edge of the lower block
  EXPECT_DOUBLE_EQ(vol(2.0, 3.0), c / 2);  // right edge of the upper block
  EXPECT_DOUBLE_EQ(vol(0.0, 0.0), c / 4);  // convex corners
  EXPECT_DOUBLE_EQ(vol(4.0, 0.0), c / 4);
  EXPECT_DOUBLE_EQ(vol(4.0, 2.0), c / 4);
  EXPECT_DOUBLE_EQ(vol(2.0, 4.0), c / 4);
  EXPECT_DOUBLE_EQ(vol(0.0, 4.0), c / 4);
  EXPECT_DOUBLE_EQ(vol(2.0, 2.0), 3 * c / 4);  // re-entrant corner
}

TEST(Discretise, FaceFlagsAndAreas) {
  const double dx = 0.5;
  const auto d = l_shape(dx);
  const auto dense = d.boundary.dense_faces(d.nodes.size());
  auto faces = [&](double x, double y) { return dense[static_cast<std::size_t>(find_node(d, x, y))]; };
  auto area = [&](double x, double y) { return d.boundary.area_of(find_node(d, x, y)); };
  EXPECT_EQ(faces(1.0, 1.0), 0);
  EXPECT_EQ(faces(2.0, 1.5), 0);
  EXPECT_EQ(faces(2.0, 2.0), 0) << "a re-entrant corner lies on no face";
  EXPECT_EQ(faces(1.5, 0.0), kMinusY);
  EXPECT_EQ(faces(0.0, 3.0), kMinusX);
  EXPECT_EQ(faces(3.0, 2.0), kPlusY);
  EXPECT_EQ(faces(2.0, 3.0), kPlusX);
  EXPECT_EQ(faces(4.0, 1.0), kPlusX);
  EXPECT_EQ(faces(1.0, 4.0), kPlusY);
  EXPECT_EQ(faces(0.0, 0.0), kMinusX | kMinusY);
  EXPECT_EQ(faces(4.0, 0.0), kPlusX | kMinusY);
  EXPECT_EQ(faces(4.0, 2.0), kPlusX | kPlusY);
  EXPECT_EQ(faces(2.0, 4.0), kPlusX | kPlusY);
  EXPECT_EQ(faces(0.0, 4.0), kMinusX | kPlusY);

  // Face areas (per unit thickness): dx on an edge, dx/2 at a corner, on the flagged face only.
  const auto edge = area(1.5, 0.0);
  EXPECT_DOUBLE_EQ(edge[2], dx);
  EXPECT_EQ(edge[0] + edge[1] + edge[3], 0.0);
  const auto corner = area(4.0, 2.0);
  EXPECT_DOUBLE_EQ(corner[1], dx / 2);
  EXPECT_DOUBLE_EQ(corner[3], dx / 2);
  EXPECT_EQ(corner[0] + corner[2], 0.0);
  const auto reentrant = area(2.0, 2.0);
  for (double a : reentrant) EXPECT_EQ(a, 0.0);

  // Total face area per orientation = the length of the body's faces with that normal.
  double total[4] = {0, 0, 0, 0};
  for (const auto& a : d.boundary.area) {
    for (std::size_t s = 0; s < 4; ++s) total[s] += a[s];
  }
  // The re-entrant corner node carries no face, so the half spacing of each face that ends
  // there (x = 2 for y in [2, 2.25], y = 2 for x in [2, 2.25]) belongs to no node: the faces
  // that meet at the re-entrant corner are short by dx/2 (this only affects the traction-power
  // bookkeeping of the energy balance when a loaded face ends at a re-entrant corner).
  EXPECT_NEAR(total[0], 4.0, 1e-12);           // -x: x = 0, y in [0, 4]
  EXPECT_NEAR(total[1], 4.0 - dx / 2, 1e-12);  // +x: x = 4 (y in [0,2]) and x = 2 (y in [2,4])
  EXPECT_NEAR(total[2], 4.0, 1e-12);           // -y: y = 0
  EXPECT_NEAR(total[3], 4.0 - dx / 2, 1e-12);  // +y: y = 2 (x in [2,4]) and y = 4 (x in [0,2])
}

TEST(Discretise, OneDimensionalBar) {
  Block<1> b;
  b.min = Vec<1>(-1.0);
  b.max = Vec<1>(2.0);
  b.label = "bar";
  const auto d = generate_lattice<1>({b}, 0.25, Vec<1>(0.0), {1500.0});
  ASSERT_EQ(d.nodes.size(), 13);
  ASSERT_EQ(d.stress_points.size(), 12);
  EXPECT_DOUBLE_EQ(d.nodes.position.front()[0], -1.0);
  EXPECT_DOUBLE_EQ(d.nodes.position.back()[0], 2.0);
  EXPECT_DOUBLE_EQ(d.nodes.volume.front(), 0.125);
  EXPECT_DOUBLE_EQ(d.nodes.volume[5], 0.25);
  EXPECT_EQ(d.boundary.faces.front(), kMinusX);
  EXPECT_EQ(d.boundary.faces.back(), kPlusX);
  EXPECT_DOUBLE_EQ(d.boundary.area.front()[0], 1.0);  // unit cross-section
  EXPECT_DOUBLE_EQ(d.stress_points.position.front()[0], -0.875);
}

TEST(Discretise, MaterialsAndInterfaceDensity) {
  // Two materials side by side: interface nodes get the mass-weighted density.
  Block<2> a, b;
  a.min = Vec<2>(0, 0);
  a.max = Vec<2>(1, 1);
  a.material = 0;
  b.min = Vec<2>(1, 0);
  b.max = Vec<2>(2, 1);
  b.material = 1;
  const auto d = generate_lattice<2>({a, b}, 0.5, Vec<2>(0, 0), {1000.0, 3000.0});
  const auto i = static_cast<std::size_t>(find_node(d, 1.0, 0.5));
  EXPECT_DOUBLE_EQ(d.nodes.density[i], 2000.0);
  const auto j = static_cast<std::size_t>(find_node(d, 1.5, 0.5));
  EXPECT_EQ(d.nodes.material[j], 1);
  EXPECT_DOUBLE_EQ(d.nodes.density[j], 3000.0);
}

TEST(Discretise, MisalignedBlockIsAnInputErrorNamingTheBlock) {
  Block<2> a, b;
  a.min = Vec<2>(0, 0);
  a.max = Vec<2>(4, 2);
  a.label = "case.toml, line 7, key 'geometry.block[0]'";
  b.min = Vec<2>(0, 2);
  b.max = Vec<2>(2.3, 4);
  b.label = "case.toml, line 11, key 'geometry.block[1]'";
  try {
    generate_lattice<2>({a, b}, 0.5, Vec<2>(0, 0), {2000.0});
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("geometry.block[1]"), std::string::npos) << msg;
    EXPECT_NE(msg.find("2.3"), std::string::npos) << msg;
    EXPECT_EQ(msg.find("geometry.block[0]"), std::string::npos) << msg;
  }
  // A block thinner than one spacing is also refused.
  Block<2> thin;
  thin.min = Vec<2>(0, 0);
  thin.max = Vec<2>(0, 1);
  thin.label = "thin";
  EXPECT_THROW(generate_lattice<2>({thin}, 0.5, Vec<2>(0, 0), {2000.0}), InputError);
}

}  // namespace
}  // namespace rktsph
