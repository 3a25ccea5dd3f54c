// Free-surface detection (operators/free_surface.hpp, method-notes §3.6) and the traction-free
// rotation (§3.7): the flags of a square and of a disc, outward normals, and sigma.n = 0.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "operators/free_surface.hpp"
#include "particles/lattice.hpp"

namespace rktsph {
namespace {

struct Cloud {
  ParticleSet<2> set{"nodes"};
  std::set<std::pair<long, long>> cells;  // lattice coordinates of the particles
};

// Lattice points (i dx, j dx) where keep(x, y), with tributary-free unit volumes dx^2.
template <class Keep>
Cloud lattice_cloud(double dx, int n, Keep&& keep) {
  Cloud c;
  for (int j = -n; j <= n; ++j) {
    for (int i = -n; i <= n; ++i) {
      const Vec<2> x(i * dx, j * dx);
      if (!keep(x)) continue;
      c.set.add(x, dx * dx, 2000.0, 0);
      c.cells.insert({i, j});
    }
  }
  return c;
}

std::vector<std::uint8_t> flags_of(const Cloud& c, std::vector<Vec<2>>& normals, double dx,
                                   std::vector<std::uint8_t>* corners = nullptr) {
  const CubicSplineKernel<2> kernel(1.2 * dx);
  Relation<2> rel;
  rel.build(c.set.position, c.set.position, {kernel.support_radius(), 1, true});
  std::vector<std::uint8_t> flags;
  detect_free_surface<2>(c.set, rel, kernel, {}, {}, {}, flags, normals, exec::Threads{}, corners);
  return flags;
}

long count(const std::vector<std::uint8_t>& f) { return std::count(f.begin(), f.end(), std::uint8_t{1}); }

TEST(FreeSurface, TheFlagsOfASquareAreItsFaceNodesExactly) {
  const double dx = 0.1;
  const Cloud c = lattice_cloud(dx, 10, [](const Vec<2>&) { return true; });
  std::vector<Vec<2>> normals;
  std::vector<std::uint8_t> corners;
  const auto flags = flags_of(c, normals, dx, &corners);
  for (Index i = 0; i < c.set.size(); ++i) {
    const auto iu = static_cast<std::size_t>(i);
    const auto& x = c.set.position[iu];
    const bool side = std::abs(std::abs(x[0]) - 1.0) < 1e-9, top = std::abs(std::abs(x[1]) - 1.0) < 1e-9;
    EXPECT_EQ(flags[iu] != 0, side || top) << "node at " << x.transpose();
    // Only the four lattice corners are corners; every other face node, the corners'
    // neighbours included, gets its face's outward normal exactly (its two chords lie on the face).
    EXPECT_EQ(corners[iu] != 0, side && top) << "node at " << x.transpose();
    if (side != top) {
      const Vec<2> n = side ? Vec<2>(x[0] > 0 ? 1.0 : -1.0, 0.0) : Vec<2>(0.0, x[1] > 0 ? 1.0 : -1.0);
      EXPECT_NEAR((normals[iu] - n).norm(), 0.0, 1e-12) << x.transpose();
    }
    if (side && top) {
      // The corner's normal bisects it.
      EXPECT_NEAR(normals[iu].dot(x.normalized()), 1.0, 1e-12) << x.transpose();
    }
  }
  EXPECT_EQ(count(flags), 80);
  EXPECT_EQ(count(corners), 4);
}

TEST(FreeSurface, TheFlagsOfADiscAreItsOuterRingWithOutwardNormals) {
  const double dx = 0.1, R = 1.0;
  const Cloud c = lattice_cloud(dx, 12, [&](const Vec<2>& x) { return x.norm() <= R + 1e-9; });
  std::vector<Vec<2>> normals;
  std::vector<std::uint8_t> corners;
  const auto flags = flags_of(c, normals, dx, &corners);
  long missing = 0, wrong = 0;
  for (Index i = 0; i < c.set.size(); ++i) {
    const auto& x = c.set.position[static_cast<std::size_t>(i)];
    const long ix = std::lround(x[0] / dx), iy = std::lround(x[1] / dx);
    auto has = [&](long a, long b) { return c.cells.count({ix + a, iy + b}) != 0; };
    const bool edge = !has(1, 0) || !has(-1, 0) || !has(0, 1) || !has(0, -1);
    const bool deep = x.norm() < R - 2.0 * dx;  // a full support of material around it
    if (edge && flags[static_cast<std::size_t>(i)] == 0) ++missing;
    // The staircase of a lattice disc turns by 45 degrees at each step: not a corner. Only the
    // four one-node bumps on the axes (no lattice neighbour outward or along the face) are.
    const bool bump = !has(1, 0) + !has(-1, 0) + !has(0, 1) + !has(0, -1) == 3;
    EXPECT_EQ(corners[static_cast<std::size_t>(i)] != 0, bump) << "node at " << x.transpose();
    if (deep && flags[static_cast<std::size_t>(i)] != 0) ++wrong;
    if (flags[static_cast<std::size_t>(i)] != 0) {
      EXPECT_GT(normals[static_cast<std::size_t>(i)].dot(x.normalized()), 0.9) << "normal at " << x.transpose();
    }
  }
  EXPECT_EQ(missing, 0) << "edge nodes not flagged";
  EXPECT_EQ(wrong, 0) << "interior nodes flagged";
}

TEST(FreeSurface, ExcludedNodesAreNeverFlagged) {
  const double dx = 0.1;
  const Cloud c = lattice_cloud(dx, 5, [](const Vec<2>&) { return true; });
  const CubicSplineKernel<2> kernel(1.2 * dx);
  Relation<2> rel;
  rel.build(c.set.position, c.set.position, {kernel.support_radius() + 0.05, 2, true});  // a Verlet skin
  std::vector<std::uint8_t> excluded(static_cast<std::size_t>(c.set.size()), 1), flags;
  std::vector<Vec<2>> normals;
  detect_free_surface<2>(c.set, rel, kernel, {}, {}, excluded, flags, normals);
  EXPECT_EQ(count(flags), 0);
}

// The settled interior (method-notes §3.6): with a kept work space and a refresh distance, the
// second call on an unchanged disc evaluates only the nodes that were not settled and returns
// the same flags and normals; a node moved by more than the distance, a volume changed by more
// than 2 %, or a node frozen (volume 0) makes the next call a full pass again.
TEST(FreeSurface, TheSettledInteriorIsSkippedUntilANodeMovesOrSwells) {
  const double dx = 0.1;
  Cloud c = lattice_cloud(dx, 10, [](const Vec<2>& x) { return x.norm() < 0.95; });
  const CubicSplineKernel<2> kernel(1.2 * dx);
  Relation<2> rel;
  rel.build(c.set.position, c.set.position, {kernel.support_radius() + 0.05, 1, true});
  FreeSurfaceOptions options;
  options.refresh_displacement = 0.1 * dx;
  FreeSurfaceScratch<2> work;
  std::vector<std::uint8_t> flags, corners;
  std::vector<Vec<2>> normals;
  auto detect = [&] {
    detect_free_surface<2>(c.set, rel, kernel, options, {}, {}, flags, normals, exec::Threads{}, &corners, &work);
    return work.last_full;
  };
  EXPECT_TRUE(detect()) << "the first pass is full";
  const auto full_flags = flags;
  const auto full_normals = normals;
  const long settled = std::count(work.settled.begin(), work.settled.end(), std::uint8_t{1});
  EXPECT_GT(settled, c.set.size() / 2) << "most of the disc is settled";
  EXPECT_EQ(static_cast<long>(work.active.size()), c.set.size() - settled);
  EXPECT_FALSE(detect()) << "nothing moved: a partial pass";
  EXPECT_EQ(flags, full_flags);
  EXPECT_EQ(normals, full_normals);
  EXPECT_GT(count(flags), 0);
  // Every node moved by 0.09 dx: still partial. The centre node by 0.11 dx more: full.
  for (auto& x : c.set.position) x[0] += 0.09 * dx;
  EXPECT_FALSE(detect());
  const std::size_t centre =
      static_cast<std::size_t>(std::min_element(c.set.position.begin(), c.set.position.end(),
                                                [](const Vec<2>& a, const Vec<2>& b) { return a.norm() < b.norm(); }) -
                               c.set.position.begin());
  c.set.position[centre][1] += 0.11 * dx;
  EXPECT_TRUE(detect());
  EXPECT_FALSE(detect());
  c.set.volume[centre] *= 1.019;
  EXPECT_FALSE(detect()) << "1.9 % of volume";
  c.set.volume[centre] *= 1.002;
  EXPECT_TRUE(detect()) << "2.1 % of volume";
  c.set.volume[centre] = 0.0;
  EXPECT_TRUE(detect()) << "a node frozen";
  EXPECT_EQ(work.full_passes, 4);
  EXPECT_EQ(work.partial_passes, 4);
  // Without the refresh distance every pass is full.
  options.refresh_displacement = 0.0;
  EXPECT_TRUE(detect());
}

// Mirror images at rigid planes (step 7, method-notes §3.6): the block x in [-1, 1], y in [0, 1]
// resting on planes just beyond its faces, its nodes there not excluded (none in contact), so
// that only the images keep the plane from reading as a free surface.
DetectionMirrors<2> mirrors_within(const Cloud& c, double range, const std::vector<MirrorPlaneAt<2>>& planes) {
  DetectionMirrors<2> m;
  m.planes = planes;
  m.of_node.assign(static_cast<std::size_t>(c.set.size()), {-1, -1});
  for (std::size_t i = 0; i < m.of_node.size(); ++i) {
    int k = 0;
    for (std::size_t p = 0; p < planes.size(); ++p) {
      const double g = (c.set.position[i] - planes[p].point).dot(planes[p].normal);
      if (g >= 0.0 && g <= range) m.of_node[i][static_cast<std::size_t>(k++)] = static_cast<std::int32_t>(p);
    }
  }
  return m;
}

struct Detection {
  std::vector<std::uint8_t> flags, corners;
  std::vector<Vec<2>> normals;
};

Detection detect_block(const Cloud& c, double dx, const DetectionMirrors<2>* mirrors) {
  const CubicSplineKernel<2> kernel(1.2 * dx);
  Relation<2> rel;
  rel.build(c.set.position, c.set.position, {kernel.support_radius(), 1, true});
  Detection d;
  detect_free_surface<2>(c.set, rel, kernel, {}, {}, {}, d.flags, d.normals, exec::Threads{}, &d.corners, nullptr,
                         mirrors);
  return d;
}

TEST(FreeSurface, MirrorImagesAcrossARigidPlaneLeaveItsNeighboursUnflagged) {
  const double dx = 0.1, h = 1.2 * dx;
  const Cloud c = lattice_cloud(dx, 10, [](const Vec<2>& x) { return x[1] >= -1e-9; });
  // The base 0.3 dx below the bottom row (a row hovering within the contact's keep distance).
  const std::vector<MirrorPlaneAt<2>> base{{Vec<2>(0.0, -0.3 * dx), Vec<2>(0.0, 1.0)}};
  const Detection plain = detect_block(c, dx, nullptr);
  const DetectionMirrors<2> m = mirrors_within(c, 2.0 * h, base);
  const Detection mirrored = detect_block(c, dx, &m);
  long bottom_plain = 0;
  for (Index i = 0; i < c.set.size(); ++i) {
    const auto iu = static_cast<std::size_t>(i);
    const Vec<2>& x = c.set.position[iu];
    const bool side = std::abs(std::abs(x[0]) - 1.0) < 1e-9, top = std::abs(x[1] - 1.0) < 1e-9;
    if (x[1] < 1e-9 && !side) bottom_plain += plain.flags[iu];
    EXPECT_EQ(mirrored.flags[iu] != 0, side || top) << "node at " << x.transpose();
    // The sides run on into their images: every side node below the top is a face node with the
    // side's normal, the bottom one included; the top corners are the only corners.
    EXPECT_EQ(mirrored.corners[iu] != 0, side && top) << "node at " << x.transpose();
    if (side && !top) {
      EXPECT_NEAR((mirrored.normals[iu] - Vec<2>(x[0] > 0 ? 1.0 : -1.0, 0.0)).norm(), 0.0, 1e-12) << x.transpose();
    }
  }
  EXPECT_EQ(bottom_plain, 19) << "without the images the plane reads as a free surface";
  EXPECT_EQ(count(mirrored.flags), 21 + 2 * 10);
}

TEST(FreeSurface, MirrorImagesInAConcaveCornerLeaveBothWallsUnflagged) {
  // The block in the corner of a base and a wall on its left, each 0.3 dx beyond it: flagged are
  // the right side and the top only, the node nearest the corner (two planes and the image
  // across both) included among the unflagged.
  const double dx = 0.1, h = 1.2 * dx;
  const Cloud c = lattice_cloud(dx, 10, [](const Vec<2>& x) { return x[1] >= -1e-9; });
  const std::vector<MirrorPlaneAt<2>> walls{{Vec<2>(0.0, -0.3 * dx), Vec<2>(0.0, 1.0)},
                                            {Vec<2>(-1.0 - 0.3 * dx, 0.0), Vec<2>(1.0, 0.0)}};
  const DetectionMirrors<2> m = mirrors_within(c, 2.0 * h, walls);
  const Detection d = detect_block(c, dx, &m);
  for (Index i = 0; i < c.set.size(); ++i) {
    const auto iu = static_cast<std::size_t>(i);
    const Vec<2>& x = c.set.position[iu];
    const bool right = std::abs(x[0] - 1.0) < 1e-9, top = std::abs(x[1] - 1.0) < 1e-9;
    EXPECT_EQ(d.flags[iu] != 0, right || top) << "node at " << x.transpose();
    EXPECT_EQ(d.corners[iu] != 0, right && top) << "node at " << x.transpose();
  }
  EXPECT_EQ(count(d.flags), 21 + 10);
}

TEST(FreeSurface, TheTractionFreeRotationZeroesSigmaNAndKeepsTheTangentialStress) {
  const double a = 0.6;
  const Vec<2> n(std::cos(a), std::sin(a)), t(-std::sin(a), std::cos(a));
  double s[4] = {-3.0e4, -1.0e4, -2.0e4, 5.0e3};  // xx, yy, zz, xy
  auto tensor = [&] {
    Mat<2> S;
    S << s[0], s[3], s[3], s[1];
    return S;
  };
  const double tt0 = t.dot(tensor() * t);
  make_traction_free<2>(n, s);
  EXPECT_LT((tensor() * n).norm(), 1e-10);
  EXPECT_NEAR(t.dot(tensor() * t), tt0, 1e-9);
  EXPECT_EQ(s[2], -2.0e4);  // sigma_zz kept
}

TEST(FreeSurface, ACornerIsFreeOfInPlaneStressAndAFaceOfItsNormalTraction) {
  // Two free faces through a point (normals n1, n2 independent) leave no in-plane stress.
  double corner[4] = {-3.0e4, -1.0e4, -2.0e4, 5.0e3};
  make_surface_traction_free<2>(Vec<2>(1.0, 0.0), true, corner);
  EXPECT_EQ(corner[0], 0.0);
  EXPECT_EQ(corner[1], 0.0);
  EXPECT_EQ(corner[3], 0.0);
  EXPECT_EQ(corner[2], -2.0e4);  // sigma_zz kept
  double face[4] = {-3.0e4, -1.0e4, -2.0e4, 5.0e3};
  make_surface_traction_free<2>(Vec<2>(1.0, 0.0), false, face);
  EXPECT_EQ(face[0], 0.0);
  EXPECT_EQ(face[3], 0.0);
  EXPECT_NEAR(face[1], -1.0e4, 1e-9);  // the tangential stress kept
}

}  // namespace
}  // namespace rktsph
