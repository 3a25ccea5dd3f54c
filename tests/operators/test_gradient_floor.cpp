// The gradient floor of the corrected operators (method-notes §3.2, eq. (3.2.6);
// operators/corrected_row.hpp apply_gradient_floor): it must leave every row of a lattice as it
// is, keep constant fields exact everywhere and linear fields exact along the directions the
// sources span, and bound the weights of a row whose sources nearly lie on a line (a thin sheet,
// the nose of a run-out), where the plain correction's weights grow without bound.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/kernel.hpp"
#include "neighbours/relation.hpp"
#include "operators/corrected_operator.hpp"
#include "operators/corrected_row.hpp"
#include "particles/lattice.hpp"

namespace rktsph {
namespace {

template <int Dim>
CorrectedOperator<Dim> build(const std::vector<Vec<Dim>>& targets, const ParticleSet<Dim>& sources,
                             const CubicSplineKernel<Dim>& kernel, double floor) {
  OperatorOptions options;
  options.gradient_floor = floor;
  options.share_patterns = false;
  return build_corrected_operator<Dim>(targets, sources, kernel, options);
}

template <int Dim>
void expect_same_weights(const CorrectedOperator<Dim>& a, const CorrectedOperator<Dim>& b) {
  ASSERT_EQ(a.interp.size(), b.interp.size());
  for (std::size_t k = 0; k < a.interp.size(); ++k) {
    EXPECT_EQ(a.interp[k], b.interp[k]);
    for (int d = 0; d < Dim; ++d)
      EXPECT_EQ(a.grad[k][static_cast<std::size_t>(d)], b.grad[k][static_cast<std::size_t>(d)]);
  }
}

// Both operators of the staggered scheme, on an L-shaped 2D lattice (convex and re-entrant
// corners) at h = 1.2 dx with V2's default floor 0.05, and on a 3D block with 0.025 (the
// defaults of the case reader): no row is touched, the weights are those without the floor.
TEST(GradientFloor, LeavesEveryLatticeRowUntouched) {
  const double dx = 0.25;
  {
    Block<2> a, b;
    a.min = Vec<2>(0.0, 0.0), a.max = Vec<2>(3.0, 1.0), a.label = "a";
    b.min = Vec<2>(0.0, 1.0), b.max = Vec<2>(1.0, 2.5), b.label = "b";
    const LatticeParticles<2> lp = generate_lattice<2>({a, b}, dx, Vec<2>(0.0, 0.0), {1000.0, 1000.0});
    const CubicSplineKernel<2> kernel(1.2 * dx);
    for (const bool to_nodes : {false, true}) {
      const auto& targets = to_nodes ? lp.nodes.position : lp.stress_points.position;
      const auto& sources = to_nodes ? lp.stress_points : lp.nodes;
      const CorrectedOperator<2> with = build<2>(targets, sources, kernel, 0.05);
      const CorrectedOperator<2> without = build<2>(targets, sources, kernel, 0.0);
      EXPECT_EQ(with.regularised_rows, 0);
      EXPECT_EQ(with.degenerate_rows, 0);
      expect_same_weights(with, without);
    }
  }
  {
    Block<3> a;
    a.min = Vec<3>(0.0, 0.0, 0.0), a.max = Vec<3>(1.5, 1.0, 1.0), a.label = "a";
    const LatticeParticles<3> lp = generate_lattice<3>({a}, dx, Vec<3>(0.0, 0.0, 0.0), {1000.0});
    const CubicSplineKernel<3> kernel(1.2 * dx);
    for (const bool to_nodes : {false, true}) {
      const auto& targets = to_nodes ? lp.nodes.position : lp.stress_points.position;
      const auto& sources = to_nodes ? lp.stress_points : lp.nodes;
      const CorrectedOperator<3> with = build<3>(targets, sources, kernel, 0.025);
      EXPECT_EQ(with.regularised_rows, 0);
      expect_same_weights(with, build<3>(targets, sources, kernel, 0.0));
    }
  }
}

// The smallest eigenvalue over a block lattice's rows, as method-notes §3.2 tabulates it at
// h = 1.2 dx and the defaults rely on: the corner node's row from the stress points, 0.126 /
// 0.058 / 0.028 in 1D / 2D / 3D. A floor just under it touches no row, one just over it the
// corner nodes' rows (2, 4, 8 of them) and nothing else.
template <int Dim>
void expect_lattice_threshold(double below, double above) {
  const double dx = 0.25;
  Block<Dim> block;
  block.min = Vec<Dim>::Zero();
  block.max = Vec<Dim>::Constant(1.5);
  block.label = "block";
  const LatticeParticles<Dim> lp = generate_lattice<Dim>({block}, dx, Vec<Dim>::Zero(), {1000.0});
  const CubicSplineKernel<Dim> kernel(1.2 * dx);
  EXPECT_EQ(build<Dim>(lp.nodes.position, lp.stress_points, kernel, below).regularised_rows, 0) << Dim << "D";
  EXPECT_EQ(build<Dim>(lp.nodes.position, lp.stress_points, kernel, above).regularised_rows, 1 << Dim) << Dim << "D";
  EXPECT_EQ(build<Dim>(lp.stress_points.position, lp.nodes, kernel, above).regularised_rows, 0) << Dim << "D";
}

TEST(GradientFloor, TheLatticesSmallestEigenvalueIsTheCornerNodesAsTabulated) {
  expect_lattice_threshold<1>(0.125, 0.127);
  expect_lattice_threshold<2>(0.058, 0.059);
  expect_lattice_threshold<3>(0.028, 0.029);
}

// A sheet one particle thick seen from points on and beside it: straight (a row of sources),
// or ragged (every fourth source doubled 0.2 dx below the row, the crowding at the nose of a
// run-out).
struct Sheet {
  ParticleSet<2> sources{"stress_points"};
  std::vector<Vec<2>> targets;
};
Sheet sheet_of_sources(double dx, bool ragged) {
  Sheet s;
  for (int i = 0; i < 24; ++i) {
    s.sources.add(Vec<2>((i + 0.5) * dx, 0.5 * dx), dx * dx, 2000.0, 0);
    if (ragged && i % 4 == 1) s.sources.add(Vec<2>((i + 0.5) * dx, 0.3 * dx), dx * dx, 2000.0, 0);
  }
  for (int i = 4; i <= 20; ++i) {
    for (const double y : {0.0, 0.5, 1.0}) s.targets.push_back(Vec<2>(i * dx, y * dx));
  }
  return s;
}

// The largest sum over a row of |interpolation weight| (gradient = false) or of h |gradient
// weight| (true): 1 and about 1.3 inside a lattice.
double largest_weight_sum(const CorrectedOperator<2>& op, double h, bool gradient = false) {
  double largest = 0.0;
  for (Index a = 0; a < op.rows(); ++a) {
    const auto row = op.row(a);
    double sum = 0.0;
    for (Index k = row.begin; k < row.end; ++k) {
      const auto ku = static_cast<std::size_t>(k);
      sum += gradient ? h * std::hypot(op.grad[ku][0], op.grad[ku][1]) : std::abs(op.interp[ku]);
    }
    largest = std::max(largest, sum);
  }
  return largest;
}

// f = 3 + 2x (along the sheet) through every row of op: constants exact to round-off, the
// value and d/dx of f within `tolerance`.
void expect_along_the_sheet(const CorrectedOperator<2>& op, const Sheet& sheet, double tolerance) {
  for (Index a = 0; a < op.rows(); ++a) {
    const auto row = op.row(a);
    double value = 0.0, ones = 0.0;
    Vec<2> grad = Vec<2>::Zero(), grad_ones = Vec<2>::Zero();
    for (Index k = row.begin; k < row.end; ++k) {
      const auto ku = static_cast<std::size_t>(k);
      const Vec<2>& x = sheet.sources.position[static_cast<std::size_t>(op.source(row, k))];
      const double f = 3.0 + 2.0 * x[0];
      value += op.interp[ku] * f;
      ones += op.interp[ku];
      for (int d = 0; d < 2; ++d) {
        grad[d] += op.grad[ku][static_cast<std::size_t>(d)] * f;
        grad_ones[d] += op.grad[ku][static_cast<std::size_t>(d)];
      }
    }
    const Vec<2>& xa = sheet.targets[static_cast<std::size_t>(a)];
    EXPECT_NEAR(ones, 1.0, 1e-12);
    EXPECT_NEAR(grad_ones.norm(), 0.0, 1e-9);
    EXPECT_NEAR(value, 3.0 + 2.0 * xa[0], tolerance * (3.0 + 2.0 * xa[0])) << "target " << xa.transpose();
    EXPECT_NEAR(grad[0], 2.0, tolerance * 2.0) << "target " << xa.transpose();
  }
}

// A sheet at dx = 0.25 m, h = 1.2 dx, and its operator without the floor and with 0.05.
struct SheetOperators {
  Sheet sheet;
  CubicSplineKernel<2> kernel;
  CorrectedOperator<2> plain, floored;
  explicit SheetOperators(bool ragged)
      : sheet(sheet_of_sources(0.25, ragged)),
        kernel(1.2 * 0.25),
        plain(build<2>(sheet.targets, sheet.sources, kernel, 0.0)),
        floored(build<2>(sheet.targets, sheet.sources, kernel, 0.05)) {}
};

// A straight sheet has no extent across itself: without the floor every row is degenerate
// (Shepard and the plain kernel gradient); with it every row is regularised across the sheet
// only, and stays exact for a linear field along it.
TEST(GradientFloor, MakesAStraightSheetExactAlongItInsteadOfDegenerate) {
  const SheetOperators ops(false);
  const auto& [sheet, kernel, plain, floored] = ops;
  EXPECT_EQ(plain.degenerate_rows, plain.rows());
  EXPECT_EQ(floored.degenerate_rows, 0);
  EXPECT_EQ(floored.regularised_rows, floored.rows());
  EXPECT_LT(largest_weight_sum(floored, kernel.h()), 2.0);
  expect_along_the_sheet(floored, sheet, 1e-12);
}

// A ragged sheet is not degenerate, and there the plain correction's weights blow up (sum of
// |w| 10.4, of h |grad w| 25; the nose of Case 9 reached 20-31); the floor bounds them (1.4,
// 3.4), keeps constants exact and a field along the sheet within 1 % (the deficient
// direction is not exactly across the sheet, so the shift touches the other a little).
TEST(GradientFloor, BoundsTheWeightsOfARaggedSheet) {
  const SheetOperators ops(true);
  const auto& [sheet, kernel, plain, floored] = ops;
  EXPECT_EQ(plain.degenerate_rows, 0);
  EXPECT_EQ(floored.degenerate_rows, 0);
  EXPECT_GT(floored.regularised_rows, 0);
  EXPECT_GT(largest_weight_sum(plain, kernel.h()), 10.0);
  EXPECT_GT(largest_weight_sum(plain, kernel.h(), true), 20.0);
  EXPECT_LT(largest_weight_sum(floored, kernel.h()), 2.0);
  EXPECT_LT(largest_weight_sum(floored, kernel.h(), true), 4.0);
  expect_along_the_sheet(floored, sheet, 1e-2);
}

// The row evaluated on the fly (V2's default, CorrectedRow) and the stored operator apply the
// same floor.
TEST(GradientFloor, OnTheFlyRowsMatchTheStoredOperator) {
  const double dx = 0.25;
  const Sheet sheet = sheet_of_sources(dx, true);
  const CubicSplineKernel<2> kernel(1.2 * dx);
  const CorrectedOperator<2> stored = build<2>(sheet.targets, sheet.sources, kernel, 0.05);
  std::vector<Index> all(sheet.sources.size());
  for (std::size_t b = 0; b < all.size(); ++b) all[b] = static_cast<Index>(b);
  const double r = kernel.support_radius();
  CorrectedRow<2> row;
  std::vector<double> interp;
  std::vector<std::array<double, 2>> grad;
  int regularised = 0;
  for (Index a = 0; a < stored.rows(); ++a) {
    row.evaluate(all, sheet.targets[static_cast<std::size_t>(a)], sheet.sources.position.data(),
                 sheet.sources.volume.data(), kernel, r * r * (1.0 - 1e-10), 0.05);
    regularised += row.regularised() ? 1 : 0;
    interp.resize(row.size());
    grad.resize(row.size());
    row.weights(interp.data(), grad.data());
    const auto srow = stored.row(a);
    ASSERT_EQ(static_cast<Index>(row.size()), srow.end - srow.begin);
    for (std::size_t k = 0; k < row.size(); ++k) {
      const auto sk = static_cast<std::size_t>(srow.begin) + k;
      ASSERT_EQ(row.sources()[k], stored.source(srow, srow.begin + static_cast<Index>(k)));
      EXPECT_NEAR(interp[k], stored.interp[sk], 1e-12);
      for (int d = 0; d < 2; ++d) EXPECT_NEAR(grad[k][d], stored.grad[sk][static_cast<std::size_t>(d)], 1e-10);
    }
  }
  EXPECT_EQ(regularised, stored.regularised_rows);
}

}  // namespace
}  // namespace rktsph
