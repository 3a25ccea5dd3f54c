// V2's domain box (schemes/deactivate_stage.hpp, method-notes §5.2 "Domain box"): a block
// translating without stress through the face of the box loses its particles one column at a
// time; each is frozen where it crossed, at rest and without volume, the rest of the block goes
// on at its velocity (the frozen ones take no part in their sums), the mass balance closes, and
// a resumed run continues bit for bit.
#include <gtest/gtest.h>

#include <cmath>

#include "../support/test_util.hpp"
#include "case/case_builder.hpp"
#include "io/state_archive.hpp"
#include "schemes/deactivate_stage.hpp"
#include "schemes/simulation.hpp"

namespace rktsph {
namespace {

constexpr double kSpeed = 20.0;  // m/s, along +x

CaseBuilder<2> moving_block() {
  CaseBuilder<2> b("v2 block leaving the domain box");
  b.spacing(0.1)
      .block(Vec<2>(0.0, 0.0), Vec<2>(1.0, 0.5))
      .elastic(1.0e7, 0.3, 2000.0)
      .initial_velocity(Vec<2>(kSpeed, 0.0))
      .scheme("v2")
      .domain_box(Vec<2>(-0.5, -0.5), Vec<2>(1.25, 1.0))
      .time(1.0, 0.5);
  return b;
}

TEST(V2DomainBox, ParticlesLeavingTheBoxAreFrozenAndTheRestGoesOn) {
  const test::ThreadCount threads(2);
  Simulation<2> sim(moving_block().build());
  const auto* stage = sim.scheme().find<DeactivateOutside<2>>();
  ASSERT_NE(stage, nullptr);
  const double mass0 = sim.total_mass();
  // 0.5 m of travel: the node columns at x = 0.8, 0.9, 1 m (and their stress points) cross x = 1.25.
  const long steps = static_cast<long>(std::ceil(0.5 / (kSpeed * sim.dt())));
  for (long k = 0; k < steps; ++k) sim.step();
  EXPECT_GT(stage->deactivated(), 0);
  const auto active = sim.nodes().find<double, 1>("active");
  ASSERT_TRUE(active.valid());
  const auto a = sim.nodes().view(active);
  const auto flags = sim.nodes().view(sim.nodes().find<double, 1>("free_surface"));
  const auto v = sim.node_velocity();
  long frozen = 0;
  double worst = 0.0;
  for (Index i = 0; i < sim.nodes().size(); ++i) {
    const Vec<2>& x = sim.nodes().position[static_cast<std::size_t>(i)];
    if (a(i, 0) == 0.0) {
      ++frozen;
      EXPECT_EQ(sim.nodes().volume[static_cast<std::size_t>(i)], 0.0);
      EXPECT_EQ(v(i, 0), 0.0);
      EXPECT_EQ(v(i, 1), 0.0);
      EXPECT_EQ(flags(i, 0), 0.0);  // not part of the body's surface
      // Frozen where it crossed: within one step's travel of the face.
      EXPECT_GT(x[0], 1.25);
      EXPECT_LT(x[0], 1.25 + 1.01 * kSpeed * sim.dt());
    } else {
      EXPECT_LE(x[0], 1.25);
      worst = std::max(worst, std::abs(v(i, 0) - kSpeed) + std::abs(v(i, 1)));
    }
  }
  EXPECT_GE(frozen, 3 * 6);  // three columns of six nodes at least
  // The active block keeps its uniform motion: the frozen particles add nothing to its sums.
  EXPECT_LT(worst, 1e-9 * kSpeed);
  EXPECT_NEAR(sim.total_mass() + stage->deactivated_mass(), mass0, 1e-12 * mass0);
  // Frozen particles stay put over later steps.
  // By global id: V2 sorts its nodes as they move.
  std::vector<Vec<2>> before(sim.nodes().position.size());
  for (const Index i : sim.nodes_by_id()) {
    before[static_cast<std::size_t>(sim.nodes().global_id[static_cast<std::size_t>(i)])] =
        sim.nodes().position[static_cast<std::size_t>(i)];
  }
  for (int k = 0; k < 3; ++k) sim.step();
  for (Index i = 0; i < sim.nodes().size(); ++i) {
    const auto iu = static_cast<std::size_t>(i);
    const Vec<2>& was = before[static_cast<std::size_t>(sim.nodes().global_id[iu])];
    if (sim.nodes().view(active)(i, 0) == 0.0 && was[0] > 1.25) {
      EXPECT_EQ(sim.nodes().position[iu], was);
    }
  }
}

TEST(V2DomainBox, AResumedRunContinuesBitForBit) {
  const test::ThreadCount threads(1);
  const CaseSetup<2> setup = moving_block().build();
  Simulation<2> straight(setup);
  for (int k = 0; k < 40; ++k) straight.step();
  Simulation<2> first(setup);
  for (int k = 0; k < 25; ++k) first.step();
  io::StateArchive archive;
  first.save_state(archive);
  Simulation<2> resumed(setup);
  resumed.load_state(archive);
  for (int k = 25; k < 40; ++k) resumed.step();
  ASSERT_GT(straight.scheme().find<DeactivateOutside<2>>()->deactivated(), 0);
  EXPECT_EQ(resumed.scheme().find<DeactivateOutside<2>>()->deactivated(),
            straight.scheme().find<DeactivateOutside<2>>()->deactivated());
  EXPECT_EQ(resumed.nodes().position, straight.nodes().position);
  EXPECT_EQ(resumed.nodes().volume, straight.nodes().volume);
  const auto& vr = resumed.model().fields.velocity;
  EXPECT_EQ(values_of(resumed.model().nodes.view(vr)), values_of(straight.model().nodes.view(vr)));
}

}  // namespace
}  // namespace rktsph
