// Re-seeding the stress points from the node cloud (particles/reseed.hpp, method-notes §5.2
// eqs. (5.2.1)-(5.2.3)): on the undeformed lattice it gives the generator's stress points
// exactly (an L-shape with a re-entrant corner, a 1D bar); on a stretched cloud it keeps the
// mass and gives the stretched density; its result does not depend on the nodes' order; cells
// that the caller excludes get no stress point; fields are sized to the new count.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include <Eigen/Dense>

#include "core/error.hpp"
#include "particles/lattice.hpp"
#include "particles/reseed.hpp"

namespace rktsph {
namespace {

LatticeParticles<2> l_shape(double dx) {
  Block<2> a, b;
  a.min = Vec<2>(0, 0);
  a.max = Vec<2>(4, 2);
  a.label = "a";
  b.min = Vec<2>(0, 2);
  b.max = Vec<2>(2, 4);
  b.label = "b";
  b.material = 1;
  return generate_lattice<2>({a, b}, dx, Vec<2>(0, 0), {2000.0, 1800.0});
}

ReseedOptions spacing(double dx) {
  ReseedOptions o;
  o.dx = dx;
  return o;
}

double total_mass(const ParticleSet<2>& s) {
  double m = 0.0;
  for (Index i = 0; i < s.size(); ++i) m += s.mass(i);
  return m;
}

TEST(Reseed, GivesTheGeneratorsStressPointsOnTheUndeformedLattice) {
  const double dx = 0.25;
  const LatticeParticles<2> lat = l_shape(dx);
  ParticleSet<2> sp = lat.stress_points;  // their materials carry over (nodes hold one at an interface)
  auto velocity = sp.add_field<double, 2>("velocity", {"vx", "vy"}, kFieldEvolving);
  std::int64_t next = 1000;
  const ReseedResult r = reseed_stress_points<2>(lat.nodes, lat.lattice.origin, spacing(dx), sp, next);
  ASSERT_EQ(sp.size(), lat.stress_points.size());  // 12 m^2 / dx^2 = 192 cells, none at the re-entrant corner
  EXPECT_EQ(r.before, 192);
  EXPECT_EQ(r.after, 192);
  // The cells on the interface between the two materials take the nodes' mass-weighted density
  // (the generator gives each its material's), which the mass factor offsets: 1.7e-5 here.
  EXPECT_NEAR(r.volume_factor, 1.0, 3e-5);
  EXPECT_EQ(next, 1192);
  // The generator orders its cells x fastest as the re-seeding does.
  for (Index e = 0; e < sp.size(); ++e) {
    const auto eu = static_cast<std::size_t>(e);
    EXPECT_NEAR((sp.position[eu] - lat.stress_points.position[eu]).norm(), 0.0, 1e-12) << e;
    EXPECT_NEAR(sp.volume[eu], r.volume_factor * dx * dx, 1e-15);
    EXPECT_EQ(sp.material[eu], lat.stress_points.material[eu]) << e;
    EXPECT_EQ(sp.global_id[eu], 1000 + e);
  }
  // Densities: the nodes' (mass-weighted at the interface between the two materials): within
  // the two blocks away from the interface, exactly the material's.
  for (Index e = 0; e < sp.size(); ++e) {
    const auto& x = sp.position[static_cast<std::size_t>(e)];
    if (std::abs(x[1] - 2.0) > dx) {
      EXPECT_NEAR(sp.density[static_cast<std::size_t>(e)], x[1] < 2.0 ? 2000.0 : 1800.0, 1e-9);
    }
  }
  EXPECT_EQ(sp.view(velocity).size(), sp.size());
  EXPECT_EQ(sp.replacements(), 1);
}

TEST(Reseed, GivesTheGeneratorsStressPointsOfABar) {
  Block<1> b;
  b.min = Vec<1>(0.0);
  b.max = Vec<1>(2.0);
  b.label = "bar";
  const LatticeParticles<1> lat = generate_lattice<1>({b}, 0.1, Vec<1>(0.0), {1500.0});
  ParticleSet<1> sp = lat.stress_points;
  std::int64_t next = 0;
  const ReseedResult r = reseed_stress_points<1>(lat.nodes, lat.lattice.origin, spacing(0.1), sp, next);
  EXPECT_EQ(r.before, 20);
  ASSERT_EQ(r.after, 20);
  EXPECT_NEAR(r.volume_factor, 1.0, 1e-14);
  for (std::size_t e = 0; e < 20; ++e) EXPECT_NEAR(sp.position[e][0], lat.stress_points.position[e][0], 1e-14);
}

// A uniform stretch x -> F x of the nodes with the continuity equation's volumes and densities:
// the new set keeps the old set's mass; every new stress point is inside the stretched body;
// the interior cells' density is rho0 / det F.
TEST(Reseed, KeepsTheMassAndGivesTheStretchedDensity) {
  const double dx = 0.25;
  LatticeParticles<2> lat = l_shape(dx);
  Eigen::Matrix2d F;
  F << 1.6, 0.3, 0.0, 1.1;
  const double J = F.determinant();
  for (Index i = 0; i < lat.nodes.size(); ++i) {
    const auto iu = static_cast<std::size_t>(i);
    lat.nodes.position[iu] = F * lat.nodes.position[iu];
    lat.nodes.volume[iu] *= J;
    lat.nodes.density[iu] /= J;
  }
  ParticleSet<2> sp = lat.stress_points;
  const double m0 = total_mass(sp);
  std::int64_t next = 0;
  const ReseedResult r = reseed_stress_points<2>(lat.nodes, lat.lattice.origin, spacing(dx), sp, next);
  EXPECT_NEAR(total_mass(sp) / m0, 1.0, 1e-13);
  EXPECT_GT(r.after, 192);  // the stretched body covers J = 1.76 times the cells
  EXPECT_LT(r.after, 192 * 2);
  const Eigen::Matrix2d Finv = F.inverse();
  Index interior = 0;
  for (Index e = 0; e < sp.size(); ++e) {
    const auto eu = static_cast<std::size_t>(e);
    const Vec<2> X = Finv * sp.position[eu];  // where the cell centre came from
    const bool in_l = X[0] > -0.5 * dx && X[1] > -0.5 * dx && X[1] < 4.0 + 0.5 * dx && X[0] < 4.0 + 0.5 * dx &&
                      !(X[0] > 2.0 + 0.5 * dx && X[1] > 2.0 + 0.5 * dx);
    EXPECT_TRUE(in_l) << "stress point " << e << " at " << sp.position[eu].transpose() << " outside the body";
    // Cells whose deposits all come from one block, away from its faces: the stretched density.
    if (X[0] > 2.0 * dx && X[0] < 4.0 - 2.0 * dx && X[1] > 2.0 * dx && X[1] < 2.0 - 2.0 * dx) {
      EXPECT_NEAR(sp.density[eu] * J / 2000.0, 1.0, 1e-12);
      ++interior;
    }
  }
  EXPECT_GT(interior, 20);
}

TEST(Reseed, DoesNotDependOnTheNodesOrderAndLeavesExcludedCellsEmpty) {
  const double dx = 0.25;
  LatticeParticles<2> lat = l_shape(dx);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jiggle(-0.3 * dx, 0.3 * dx);
  for (auto& x : lat.nodes.position) x += Vec<2>(jiggle(rng), jiggle(rng));
  ParticleSet<2> a = lat.stress_points, b = lat.stress_points;
  std::int64_t na = 0, nb = 0;
  reseed_stress_points<2>(lat.nodes, lat.lattice.origin, spacing(dx), a, na);
  std::vector<Index> order(static_cast<std::size_t>(lat.nodes.size()));
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), rng);
  lat.nodes.permute(order);
  reseed_stress_points<2>(lat.nodes, lat.lattice.origin, spacing(dx), b, nb);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t e = 0; e < a.position.size(); ++e) {
    EXPECT_EQ(a.position[e], b.position[e]);
    EXPECT_EQ(a.density[e], b.density[e]);  // bit for bit
    EXPECT_EQ(a.volume[e], b.volume[e]);
  }
  // A rigid body over x > 3 m: its cells get none, and the others carry the mass.
  ReseedOptions with_body = spacing(dx);
  with_body.excluded = [](const double* x) { return x[0] > 3.0; };
  ParticleSet<2> c = lat.stress_points;
  std::int64_t nc = 0;
  const ReseedResult r = reseed_stress_points<2>(lat.nodes, lat.lattice.origin, with_body, c, nc);
  EXPECT_GE(r.excluded_cells, 28);  // up to 4 columns x 8 rows; the jiggle can empty a corner cell
  EXPECT_EQ(c.size() + r.excluded_cells, a.size());
  for (const auto& x : c.position) EXPECT_LE(x[0], 3.0);
  EXPECT_NEAR(total_mass(c) / total_mass(lat.stress_points), 1.0, 1e-13);
}

// A film thinner than half a cell (a run-out front): its cells are filled 0.3 and get no stress
// point by the fill alone; with the cover window they do, where a node lies near the centre.
// On the undeformed lattice the window changes nothing (no node lies within 1/2 dx of a centre).
TEST(Reseed, TheCoverWindowSeedsAThinFilmAndLeavesTheLatticeAlone) {
  const double dx = 0.25;
  ParticleSet<2> film("nodes");
  for (int k = 0; k < 12; ++k) film.add(Vec<2>((k + 0.5) * dx, 0.5 * dx), 0.3 * dx * dx, 2000.0, 0);
  ParticleSet<2> sp("stress_points");
  sp.add(Vec<2>(0.5 * dx, 0.5 * dx), dx * dx, 2000.0, 0);
  std::int64_t next = 0;
  EXPECT_THROW(reseed_stress_points<2>(film, Vec<2>(0.0, 0.0), spacing(dx), sp, next), SolverError);  // none filled
  ReseedOptions covered = spacing(dx);
  covered.cover = 0.25;
  const ReseedResult r = reseed_stress_points<2>(film, Vec<2>(0.0, 0.0), covered, sp, next);
  EXPECT_EQ(r.after, 12);
  for (Index e = 0; e < sp.size(); ++e) {
    const auto eu = static_cast<std::size_t>(e);
    EXPECT_NEAR((sp.position[eu] - film.position[eu]).norm(), 0.0, 1e-15);
    EXPECT_NEAR(sp.density[eu], 2000.0, 1e-9);
  }
  const LatticeParticles<2> lat = l_shape(dx);
  ParticleSet<2> a = lat.stress_points, b = lat.stress_points;
  std::int64_t na = 0, nb = 0;
  reseed_stress_points<2>(lat.nodes, lat.lattice.origin, spacing(dx), a, na);
  ReseedOptions wide = spacing(dx);
  wide.cover = 0.49;
  reseed_stress_points<2>(lat.nodes, lat.lattice.origin, wide, b, nb);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t e = 0; e < a.position.size(); ++e) EXPECT_EQ(a.position[e], b.position[e]);
}

// 3D: a box of 4 x 3 x 2 cells. Its 8 corner cells are filled 27/64 < 1/2 (no fill separates
// them from a cell at a re-entrant edge, 7/16): they are dropped, every other cell is kept,
// and the mass stays with the others.
TEST(Reseed, InThreeDimensionsDropsOnlyTheBoxCorners) {
  Block<3> b;
  b.min = Vec<3>(0.0, 0.0, 0.0);
  b.max = Vec<3>(1.0, 0.75, 0.5);
  b.label = "box";
  const double dx = 0.25;
  const LatticeParticles<3> lat = generate_lattice<3>({b}, dx, Vec<3>(0.0, 0.0, 0.0), {1800.0});
  ParticleSet<3> sp = lat.stress_points;
  double m0 = 0.0;
  for (Index e = 0; e < sp.size(); ++e) m0 += sp.mass(e);
  std::int64_t next = 0;
  ReseedOptions o;
  o.dx = dx;
  const ReseedResult r = reseed_stress_points<3>(lat.nodes, lat.lattice.origin, o, sp, next);
  EXPECT_EQ(r.before, 24);
  EXPECT_EQ(r.after, 16);
  double m = 0.0;
  for (Index e = 0; e < sp.size(); ++e) m += sp.mass(e);
  EXPECT_NEAR(m / m0, 1.0, 1e-14);
  for (const auto& x : sp.position) {
    const bool corner =
        (x[0] < dx || x[0] > 1.0 - dx) && (x[1] < dx || x[1] > 0.75 - dx) && (x[2] < dx || x[2] > 0.5 - dx);
    EXPECT_FALSE(corner) << x.transpose();
  }
}

TEST(Reseed, RefusesANonPositiveSpacing) {
  const LatticeParticles<2> lat = l_shape(0.5);
  ParticleSet<2> sp = lat.stress_points;
  std::int64_t next = 0;
  EXPECT_THROW(reseed_stress_points<2>(lat.nodes, lat.lattice.origin, spacing(0.0), sp, next), SolverError);
}

}  // namespace
}  // namespace rktsph
