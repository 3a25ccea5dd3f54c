// V2's node shifting (schemes/shift_stage.hpp, method-notes §5.2 eqs. (5.2.5)-(5.2.7)): on a
// disordered block the interior nodes move apart (the closest pair grows), never more than the
// cap; nodes whose support reaches the free surface or the held base stay; the masses are kept;
// linear velocity, stress and displacement fields are carried to the new positions exactly; on
// the undisturbed lattice nothing moves.
#include <gtest/gtest.h>

#include <cmath>

#include "../support/test_util.hpp"
#include "../support/v2_block.hpp"
#include "case/case_builder.hpp"
#include "schemes/shift_stage.hpp"
#include "schemes/simulation.hpp"
#include "schemes/v2_stages.hpp"

namespace rktsph {
namespace {

CaseBuilder<2> block(double jitter) {
  CaseBuilder<2> b = test::v2_block("v2 shift block");
  if (jitter > 0.0) b.jitter(jitter, 3);
  b.fix_velocity(Region<2>::plane(1, -1.0), {0, 1});
  return b;
}

struct Linear {
  Eigen::Matrix2d A;
  Vec<2> b;
  Vec<2> v(const Vec<2>& x) const { return A * x + b; }
  double s(const Vec<2>& x, int c) const { return 1.0e3 * (c + 1) * (x[0] - 2.0 * x[1]) + 5.0e2 * c; }
};

// Build the step's operators, detect the surface, seed linear fields and shift once.
void seed_and_shift(Simulation<2>& sim, const Linear& f) {
  const StepContext context{0.0, sim.dt(), 0.0};
  sim.scheme().find<RebuildOperators<2>>()->run(context);
  sim.scheme().find<DetectFreeSurface<2>>()->run(context);  // the shift waits for a first detection
  auto v = sim.mutable_node_velocity();
  auto s = sim.mutable_node_stress();
  auto u = sim.model().nodes.view(sim.model().fields.displacement);
  for (Index i = 0; i < sim.nodes().size(); ++i) {
    const Vec<2>& x = sim.nodes().position[static_cast<std::size_t>(i)];
    const Vec<2> vi = f.v(x);
    for (int d = 0; d < 2; ++d) v(i, d) = vi[d], u(i, d) = 0.5 * vi[d];
    for (int c = 0; c < 4; ++c) s(i, c) = f.s(x, c);
  }
  sim.scheme().find<ShiftNodes<2>>()->run(context);
}

TEST(V2Shift, CarriesLinearFieldsExactlyAndSpreadsADisorderedBlock) {
  const test::ThreadCount threads(2);
  CaseBuilder<2> b = block(0.3);
  b.shift(ShiftSetting::periodic, 1);
  Simulation<2> sim(b.build());
  const std::vector<Vec<2>> before = sim.nodes().position;
  std::vector<double> mass(before.size());
  for (std::size_t i = 0; i < mass.size(); ++i) mass[i] = sim.nodes().mass(static_cast<Index>(i));
  ShiftNodes<2>& shift = *sim.scheme().find<ShiftNodes<2>>();
  // The closest pair of nodes well inside the block (where nodes are shifted).
  auto closest_inside = [&sim] {
    const auto& x = sim.nodes().position;
    double best = 1e300;
    for (std::size_t i = 0; i < x.size(); ++i) {
      for (std::size_t j = i + 1; j < x.size(); ++j) {
        if (x[i].cwiseAbs().maxCoeff() < 0.6 && x[j].cwiseAbs().maxCoeff() < 0.6)
          best = std::min(best, (x[i] - x[j]).norm());
      }
    }
    return best;
  };
  const double closest_before = closest_inside();
  Linear f;
  f.A << 0.3, -1.2, 0.7, 0.1;
  f.b = Vec<2>(0.5, -0.25);
  seed_and_shift(sim, f);
  EXPECT_EQ(shift.shifts(), 1);
  EXPECT_GT(closest_inside(), 1.2 * closest_before);  // the closest pair moved apart
  const auto v = sim.node_velocity();
  const auto s = sim.model().nodes.view(sim.model().fields.stress);
  const auto u = sim.model().nodes.view(sim.model().fields.displacement);
  double moved = 0.0, error_v = 0.0, error_s = 0.0, error_u = 0.0;
  for (Index i = 0; i < sim.nodes().size(); ++i) {
    const auto iu = static_cast<std::size_t>(i);
    const auto k = static_cast<std::size_t>(sim.nodes().global_id[iu]);  // as made (V2 sorts its nodes)
    const Vec<2>& x = sim.nodes().position[iu];
    const double dr = (x - before[k]).norm();
    moved = std::max(moved, dr);
    EXPECT_LE(dr, 0.2 * 0.1 + 1e-15);  // the cap, 0.2 dx
    // Within a support (2.4 dx, plus the jitter) of the faces: the cut support would push them.
    const double margin = 1.0 - 0.24 - 0.03;
    if (std::abs(before[k][0]) > margin || std::abs(before[k][1]) > margin) {
      EXPECT_EQ(dr, 0.0) << i;
    }
    EXPECT_NEAR(sim.nodes().mass(i) / mass[k], 1.0, 1e-14);
    error_v = std::max(error_v, (v.vec(i) - f.v(x)).norm());
    error_u = std::max(error_u, (Vec<2>(u(i, 0), u(i, 1)) - 0.5 * f.v(x)).norm());
    for (int c = 0; c < 4; ++c) error_s = std::max(error_s, std::abs(s(i, c) - f.s(x, c)));
  }
  EXPECT_GT(moved, 0.01 * 0.1);
  EXPECT_LT(error_v, 1e-12);
  EXPECT_LT(error_u, 1e-12);
  EXPECT_LT(error_s, 1e-8);  // Pa, against fields of 1e3-1e4 Pa
}

TEST(V2Shift, LeavesTheInteriorOfTheLatticeInPlace) {
  const test::ThreadCount threads(1);
  CaseBuilder<2> b = block(0.0);
  b.shift(ShiftSetting::periodic, 1);
  Simulation<2> sim(b.build());
  const std::vector<Vec<2>> before = sim.nodes().position;
  Linear f;
  f.A.setZero();
  f.b = Vec<2>(0.0, 0.0);
  seed_and_shift(sim, f);
  // Inside, a symmetric neighbourhood; near the faces, a cut support: no node moves.
  for (std::size_t i = 0; i < before.size(); ++i) {
    const auto k = static_cast<std::size_t>(sim.nodes().global_id[i]);  // as made (V2 sorts its nodes)
    EXPECT_LT((sim.nodes().position[i] - before[k]).norm(), 1e-15) << i;
  }
}

}  // namespace
}  // namespace rktsph
