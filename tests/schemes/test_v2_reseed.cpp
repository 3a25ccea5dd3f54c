// V2 with the stress points re-seeded from the node cloud (schemes/reseed_stage.hpp,
// method-notes §5.2 "Regularisation"): a body in uniform translation re-seeded every other
// step keeps a zero stress, a uniform velocity and the stress points' mass; the automatic
// trigger fires on stress points drifted from the nodes and puts them back on cell centres; a
// re-seeding run is bit for bit the same on one and two threads.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "../support/test_util.hpp"
#include "case/case_builder.hpp"
#include "schemes/reseed_stage.hpp"
#include "schemes/simulation.hpp"

namespace rktsph {
namespace {

CaseBuilder<2> block(double dx = 0.1) {
  CaseBuilder<2> b("v2 reseed block");
  b.spacing(dx)
      .origin(Vec<2>(-1.0, -1.0))
      .block(Vec<2>(-1.0, -1.0), Vec<2>(1.0, 1.0))
      .elastic(1.0e7, 0.3, 2000.0)
      .scheme("v2");
  return b;
}

const ReseedStressPoints<2>& reseed_stage(const Simulation<2>& sim) {
  for (const auto& s : sim.scheme().stages()) {
    if (const auto* r = dynamic_cast<const ReseedStressPoints<2>*>(s.get())) return *r;
  }
  throw std::runtime_error("no re-seeding stage");
}

double stress_point_mass(const Simulation<2>& sim) {
  double m = 0.0;
  for (Index e = 0; e < sim.stress_points().size(); ++e) m += sim.stress_points().mass(e);
  return m;
}

// Off the lattice by a cell centre's offset: the distance of x's coordinates from the nearest
// cell centre of the lattice with origin (-1, -1) and spacing dx.
double off_centre(const Vec<2>& x, double dx) {
  double worst = 0.0;
  for (int d = 0; d < 2; ++d) {
    const double s = (x[d] + 1.0) / dx - 0.5;
    worst = std::max(worst, std::abs(s - std::round(s)) * dx);
  }
  return worst;
}

TEST(V2Reseed, ATranslatingBodyKeepsZeroStressUniformVelocityAndMass) {
  const test::ThreadCount threads(1);
  // 1.6 spacings of travel in 120 steps: the body crosses cells, so the set changes.
  Simulation<2> sim(
      block().initial_velocity(Vec<2>(2.0, 1.0)).reseed(ReseedSetting::periodic, 2).time(1.0, 0.5).build());
  const double m0 = stress_point_mass(sim);
  Index smallest = sim.stress_points().size(), largest = smallest;
  for (int n = 0; n < 120; ++n) {
    sim.step();
    smallest = std::min(smallest, sim.stress_points().size());
    largest = std::max(largest, sim.stress_points().size());
  }
  EXPECT_EQ(reseed_stage(sim).reseeds(), 60);
  EXPECT_NEAR(stress_point_mass(sim) / m0, 1.0, 1e-12);
  EXPECT_GT(largest, smallest);  // cells entered and left as the body moved off the lattice
  double stress = 0.0, dv = 0.0;
  const auto s = sim.model().nodes.view(sim.model().fields.stress);
  const auto v = sim.node_velocity();
  for (Index i = 0; i < sim.nodes().size(); ++i) {
    for (int c = 0; c < 4; ++c) stress = std::max(stress, std::abs(s(i, c)));
    dv = std::max(dv, (v.vec(i) - Vec<2>(2.0, 1.0)).norm());
  }
  EXPECT_LT(stress, 1e-6);  // Pa, against rho c v ~ 3e5 Pa for a real velocity jump
  EXPECT_LT(dv, 1e-12);
  // The last re-seeding was at the start of this step: the stress points moved one step since.
  // Inside, they are on cell centres; within a spacing of the faces the cover window's points
  // sit at the centroids of their cells' deposits.
  const double travel = sim.dt() * Vec<2>(2.0, 1.0).norm();
  const Vec<2> shift = sim.time() * Vec<2>(2.0, 1.0);
  for (const auto& x : sim.stress_points().position) {
    const Vec<2> from_centre = (x - shift).cwiseAbs();
    if (from_centre.maxCoeff() < 1.0 - 0.1) {
      EXPECT_LT(off_centre(x, 0.1), travel + 1e-12) << x.transpose();
    }
  }
}

TEST(V2Reseed, TheAutomaticTriggerPutsDriftedStressPointsBackOnCellCentres) {
  const test::ThreadCount threads(1);
  Simulation<2> sim(block().reseed(ReseedSetting::automatic, 1).time(1.0, 0.5).build());
  sim.step();  // the case's own arrangement: the baseline (none uncovered)
  // Drift every stress point by 0.8 dx along x: the left column of nodes is then 1.4 dx from
  // its nearest stress point.
  for (auto& x : sim.model().stress_points.position) x[0] += 0.08;
  sim.step();  // checked at the end of the step: the next one re-seeds
  EXPECT_EQ(reseed_stage(sim).reseeds(), 0);
  sim.step();
  EXPECT_EQ(reseed_stage(sim).reseeds(), 1);
  EXPECT_EQ(sim.stress_points().size(), 400);
  // At rest without loads the stress points stay where they were put (a step's motion since).
  for (const auto& x : sim.stress_points().position) EXPECT_LT(off_centre(x, 0.1), 1e-9);
  for (int n = 0; n < 5; ++n) sim.step();
  EXPECT_EQ(reseed_stage(sim).reseeds(), 1);  // nothing uncovered any more
  EXPECT_EQ(reseed_stage(sim).uncovered(), 0);
}

TEST(V2Reseed, OneAndTwoThreadsGiveBitIdenticalResults) {
  auto run = [](int threads) {
    const test::ThreadCount guard(threads);
    CaseBuilder<2> b = block(2.0 / 60.0);
    b.gravity(Vec<2>(0.0, -9.81)).fix_velocity(Region<2>::plane(1, -1.0), {0, 1}).time(0.02, 0.5);
    b.initial_velocity(Vec<2>(0.0, 0.0), 0.5).reseed(ReseedSetting::periodic, 5);
    Simulation<2> sim(b.build());
    for (int n = 0; n < 30; ++n) sim.step();
    std::vector<double> out = values_of(sim.model().nodes.view(sim.model().fields.stress));
    for (const auto& x : sim.stress_points().position) out.insert(out.end(), {x[0], x[1]});
    for (double rho : sim.stress_points().density) out.push_back(rho);
    return out;
  };
  const auto one = run(1), two = run(2);
  ASSERT_EQ(one.size(), two.size());
  EXPECT_EQ(std::memcmp(one.data(), two.data(), one.size() * sizeof(double)), 0);
}

}  // namespace
}  // namespace rktsph
