// Linear-exact corrected operators between the staggered sets (method-notes §3.2, §0.3 item 2):
// interpolation and gradient reproduce constants and linear fields exactly at every target,
// including truncated supports at edges and corners and on jittered particle sets; a quadratic
// field is not reproduced, which shows the checks can fail.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>

#include <fmt/format.h>

#include "../support/test_util.hpp"
#include "core/kernel.hpp"
#include "neighbours/relation.hpp"
#include "operators/corrected_operator.hpp"
#include "particles/lattice.hpp"

namespace rktsph {
namespace {

template <int Dim>
using Field = std::function<double(const Vec<Dim>&)>;

template <int Dim>
struct Errors {
  double interp = 0.0;  // max |Pi f - f(x_a)| / scale
  double grad = 0.0;    // max |grad f - exact| / scale
};

// Apply the operator to f sampled at the sources; compare with f and its gradient at targets.
template <int Dim>
Errors<Dim> apply_errors(const CorrectedOperator<Dim>& op, const std::vector<Vec<Dim>>& targets,
                         const ParticleSet<Dim>& sources, const Field<Dim>& f,
                         const std::function<Vec<Dim>(const Vec<Dim>&)>& grad, double scale,
                         const std::function<bool(const Vec<Dim>&)>& select = nullptr) {
  Errors<Dim> e;
  EXPECT_EQ(op.rows(), static_cast<Index>(targets.size()));
  for (Index a = 0; a < op.rows(); ++a) {
    const Vec<Dim>& xa = targets[static_cast<std::size_t>(a)];
    if (select && !select(xa)) continue;
    double val = 0.0;
    Vec<Dim> g = Vec<Dim>::Zero();
    const auto row = op.row(a);
    for (Index k = row.begin; k < row.end; ++k) {
      const auto ku = static_cast<std::size_t>(k);
      const double fb = f(sources.position[static_cast<std::size_t>(op.source(row, k))]);
      val += op.interp[ku] * fb;
      for (int d = 0; d < Dim; ++d) g[d] += op.grad[ku][static_cast<std::size_t>(d)] * fb;
    }
    e.interp = std::max(e.interp, std::abs(val - f(xa)) / scale);
    e.grad = std::max(e.grad, (g - grad(xa)).norm() / scale);
  }
  return e;
}

template <int Dim>
void jitter(std::vector<Vec<Dim>>& x, double amplitude, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-amplitude, amplitude);
  for (auto& p : x) {
    for (int d = 0; d < Dim; ++d) p[d] += u(rng);
  }
}

LatticeParticles<1> bar(double length, double dx) {
  Block<1> b;
  b.min = Vec<1>(0.0);
  b.max = Vec<1>(length);
  b.label = "bar";
  return generate_lattice<1>({b}, dx, Vec<1>(0.0), {1000.0});
}

LatticeParticles<2> plate(double lx, double ly, double dx) {
  Block<2> b;
  b.min = Vec<2>(0.0, 0.0);
  b.max = Vec<2>(lx, ly);
  b.label = "plate";
  return generate_lattice<2>({b}, dx, Vec<2>(0.0, 0.0), {1000.0});
}

constexpr double kTol = 1e-12;

// ---- 1D ----

class Operator1D : public ::testing::TestWithParam<bool> {};  // parameter: jittered

TEST_P(Operator1D, ExactForConstantAndLinearBothDirections) {
  const double dx = 0.25, L = 5.0;
  LatticeParticles<1> disc = bar(L, dx);
  if (GetParam()) {
    std::mt19937 rng(12345);
    jitter(disc.nodes.position, 0.2 * dx, rng);
    jitter(disc.stress_points.position, 0.2 * dx, rng);
  }
  const CubicSplineKernel<1> kernel(1.2 * dx);
  const auto en = build_corrected_operator<1>(disc.stress_points.position, disc.nodes, kernel);
  const auto ne = build_corrected_operator<1>(disc.nodes.position, disc.stress_points, kernel);
  EXPECT_EQ(en.degenerate_rows, 0);
  EXPECT_EQ(ne.degenerate_rows, 0);
  const double scale = 10.0;  // |f| over the bar
  const Field<1> c = [](const Vec<1>&) { return 3.25; };
  const Field<1> lin = [](const Vec<1>& x) { return -1.5 + 1.7 * x[0]; };
  auto zero = [](const Vec<1>&) { return Vec<1>(0.0); };
  auto glin = [](const Vec<1>&) { return Vec<1>(1.7); };
  for (const auto* op : {&en, &ne}) {
    const bool to_stress_points = op == &en;
    const auto& targets = to_stress_points ? disc.stress_points.position : disc.nodes.position;
    const auto& sources = to_stress_points ? disc.nodes : disc.stress_points;
    const auto ec = apply_errors<1>(*op, targets, sources, c, zero, scale);
    const auto el = apply_errors<1>(*op, targets, sources, lin, glin, scale);
    EXPECT_LT(ec.interp, kTol);
    EXPECT_LT(ec.grad, kTol);
    EXPECT_LT(el.interp, kTol);
    EXPECT_LT(el.grad, kTol);
    RecordProperty(to_stress_points ? "linear_grad_err_en" : "linear_grad_err_ne", fmt::format("{:.3g}", el.grad));
  }
  // The end node x = 0 has only stress points on one side (truncated support): check it alone.
  const auto end = apply_errors<1>(ne, disc.nodes.position, disc.stress_points, lin, glin, scale,
                                   [&](const Vec<1>& x) { return x[0] < 0.5 * dx || x[0] > L - 0.5 * dx; });
  EXPECT_LT(end.interp, kTol);
  EXPECT_LT(end.grad, kTol);
}

INSTANTIATE_TEST_SUITE_P(RegularAndJittered, Operator1D, ::testing::Bool());

// ---- 2D ----

class Operator2D : public ::testing::TestWithParam<bool> {};  // parameter: jittered

TEST_P(Operator2D, ExactForConstantAndLinearBothDirections) {
  const double dx = 0.5, lx = 4.0, ly = 3.0;
  LatticeParticles<2> disc = plate(lx, ly, dx);
  if (GetParam()) {
    std::mt19937 rng(2024);
    jitter(disc.nodes.position, 0.2 * dx, rng);
    jitter(disc.stress_points.position, 0.2 * dx, rng);
  }
  const CubicSplineKernel<2> kernel(1.2 * dx);
  const auto en = build_corrected_operator<2>(disc.stress_points.position, disc.nodes, kernel);
  const auto ne = build_corrected_operator<2>(disc.nodes.position, disc.stress_points, kernel);
  EXPECT_EQ(en.degenerate_rows, 0);
  EXPECT_EQ(ne.degenerate_rows, 0);
  const double scale = 10.0;
  const Field<2> c = [](const Vec<2>&) { return -2.0; };
  const Field<2> lin = [](const Vec<2>& x) { return 1.25 - 0.8 * x[0] + 2.3 * x[1]; };
  auto zero = [](const Vec<2>&) { return Vec<2>(0.0, 0.0); };
  auto glin = [](const Vec<2>&) { return Vec<2>(-0.8, 2.3); };
  double worst = 0.0;
  for (const auto* op : {&en, &ne}) {
    const bool to_stress_points = op == &en;
    const auto& targets = to_stress_points ? disc.stress_points.position : disc.nodes.position;
    const auto& sources = to_stress_points ? disc.nodes : disc.stress_points;
    const auto ec = apply_errors<2>(*op, targets, sources, c, zero, scale);
    const auto el = apply_errors<2>(*op, targets, sources, lin, glin, scale);
    EXPECT_LT(ec.interp, kTol);
    EXPECT_LT(ec.grad, kTol);
    EXPECT_LT(el.interp, kTol);
    EXPECT_LT(el.grad, kTol);
    worst = std::max({worst, el.interp, el.grad});
  }
  RecordProperty("linear_worst_relative_error", fmt::format("{:.3g}", worst));
  // Truncated supports: corners and edge midpoints of the body, checked on their own.
  const double tol_corner = 0.3 * dx;
  auto on_corner = [&](const Vec<2>& x) {
    const bool ex = x[0] < tol_corner || x[0] > lx - tol_corner;
    const bool ey = x[1] < tol_corner || x[1] > ly - tol_corner;
    return ex && ey;
  };
  auto on_edge = [&](const Vec<2>& x) {
    return x[0] < tol_corner || x[0] > lx - tol_corner || x[1] < tol_corner || x[1] > ly - tol_corner;
  };
  const auto corner = apply_errors<2>(ne, disc.nodes.position, disc.stress_points, lin, glin, scale, on_corner);
  const auto edge = apply_errors<2>(ne, disc.nodes.position, disc.stress_points, lin, glin, scale, on_edge);
  EXPECT_LT(corner.interp, kTol);
  EXPECT_LT(corner.grad, kTol);
  EXPECT_LT(edge.interp, kTol);
  EXPECT_LT(edge.grad, kTol);
}

INSTANTIATE_TEST_SUITE_P(RegularAndJittered, Operator2D, ::testing::Bool());

TEST(CorrectedOperator, ExactAtArbitraryPointsNearCornersOfAnLShape) {
  // Evaluation points outside both lattices: at the corners (convex and re-entrant) and in
  // between, from the nodes of an L-shaped body.
  const double dx = 0.5;
  Block<2> a, b;
  a.min = Vec<2>(0, 0);
  a.max = Vec<2>(4, 2);
  b.min = Vec<2>(0, 2);
  b.max = Vec<2>(2, 4);
  const auto disc = generate_lattice<2>({a, b}, dx, Vec<2>(0, 0), {1800.0});
  const CubicSplineKernel<2> kernel(1.2 * dx);
  const std::vector<Vec<2>> pts = {Vec<2>(0, 0), Vec<2>(4, 0),     Vec<2>(4, 2),      Vec<2>(2, 4),     Vec<2>(0, 4),
                                   Vec<2>(2, 2), Vec<2>(2.1, 2.1), Vec<2>(0.13, 3.9), Vec<2>(3.3, 0.07)};
  const Field<2> lin = [](const Vec<2>& x) { return 4.0 + 0.5 * x[0] - 1.25 * x[1]; };
  auto glin = [](const Vec<2>&) { return Vec<2>(0.5, -1.25); };
  for (const auto* set : {&disc.nodes, &disc.stress_points}) {
    const auto op = build_corrected_operator<2>(pts, *set, kernel);
    EXPECT_EQ(op.degenerate_rows, 0);
    const auto e = apply_errors<2>(op, pts, *set, lin, glin, 10.0);
    EXPECT_LT(e.interp, kTol);
    EXPECT_LT(e.grad, kTol);
  }
}

TEST(CorrectedOperator, QuadraticIsNotReproducedButErrorIsSmall) {
  // Discrimination: a quadratic field (not harmonic: x^2 - y^2 would be reproduced by the
  // symmetric regular lattice) gives a nonzero, O(dx^2) interpolation error (regular
  // lattice) and a nonzero gradient error (jittered lattice) in the interior.
  const double dx = 0.25, lx = 4.0, ly = 4.0;
  LatticeParticles<2> disc = plate(lx, ly, dx);
  const CubicSplineKernel<2> kernel(1.2 * dx);
  const Field<2> quad = [](const Vec<2>& x) { return x[0] * x[0] + 0.5 * x[0] * x[1] + x[1] * x[1]; };
  auto gquad = [](const Vec<2>& x) { return Vec<2>(2 * x[0] + 0.5 * x[1], 0.5 * x[0] + 2 * x[1]); };
  auto interior = [&](const Vec<2>& x) {
    return x[0] > 3 * dx && x[0] < lx - 3 * dx && x[1] > 3 * dx && x[1] < ly - 3 * dx;
  };
  const double scale = 16.0;
  {
    const auto en = build_corrected_operator<2>(disc.stress_points.position, disc.nodes, kernel);
    const auto e = apply_errors<2>(en, disc.stress_points.position, disc.nodes, quad, gquad, scale, interior);
    EXPECT_GT(e.interp, 1e-4);  // ~ second moment of the kernel, (h^2) / |f|
    EXPECT_LT(e.interp, 1e-1);
    RecordProperty("quadratic_interp_err_regular", fmt::format("{:.3g}", e.interp));
  }
  std::mt19937 rng(7);
  jitter(disc.nodes.position, 0.2 * dx, rng);
  jitter(disc.stress_points.position, 0.2 * dx, rng);
  const auto ne = build_corrected_operator<2>(disc.nodes.position, disc.stress_points, kernel);
  const auto e = apply_errors<2>(ne, disc.nodes.position, disc.stress_points, quad, gquad, scale, interior);
  EXPECT_GT(e.grad, 1e-6);
  EXPECT_LT(e.grad, 0.1);
  EXPECT_GT(e.interp, 1e-5);
  RecordProperty("quadratic_grad_err_jittered", fmt::format("{:.3g}", e.grad));
}

// ---- difference-form gradient (fix (a) of method-notes §0.3) ----

TEST(DifferenceGradient, ExactForLinearFieldWithExactFhat) {
  const double dx = 0.5, lx = 3.0, ly = 2.0;
  for (bool jittered : {false, true}) {
    LatticeParticles<2> disc = plate(lx, ly, dx);
    if (jittered) {
      std::mt19937 rng(99);
      jitter(disc.stress_points.position, 0.2 * dx, rng);
    }
    const CubicSplineKernel<2> kernel(1.2 * dx);
    // Rows at every boundary node and a few interior ones.
    std::vector<Index> which;
    for (Index i = 0; i < disc.nodes.size(); ++i) {
      if (disc.boundary.faces[static_cast<std::size_t>(i)] != 0 || i % 5 == 0) which.push_back(i);
    }
    const auto g = build_difference_gradient<2>(disc.nodes.position, which, disc.stress_points, kernel);
    ASSERT_EQ(g.row_start.size(), which.size() + 1);
    ASSERT_EQ(g.weight_sum.size(), which.size());
    const Field<2> lin = [](const Vec<2>& x) { return 0.7 + 3.0 * x[0] - 1.1 * x[1]; };
    const Vec<2> exact(3.0, -1.1);
    double worst = 0.0, worst_wrong_fhat = 0.0;
    for (std::size_t r = 0; r < which.size(); ++r) {
      const Vec<2>& xa = disc.nodes.position[static_cast<std::size_t>(which[r])];
      Vec<2> sum = Vec<2>::Zero(), s = Vec<2>::Zero();
      for (Index k = g.row_start[r]; k < g.row_start[r + 1]; ++k) {
        const auto ku = static_cast<std::size_t>(k);
        sum += g.weight[ku] * lin(disc.stress_points.position[static_cast<std::size_t>(g.source[ku])]);
        s += g.weight[ku];
      }
      EXPECT_NEAR((s - g.weight_sum[r]).norm(), 0.0, 1e-12);
      const Vec<2> grad = sum - g.weight_sum[r] * lin(xa);
      worst = std::max(worst, (grad - exact).norm() / exact.norm());
      // A wrong fhat (off by 1) must show at boundary nodes, where sum_b c_ab != 0.
      const Vec<2> grad_wrong = sum - g.weight_sum[r] * (lin(xa) + 1.0);
      worst_wrong_fhat = std::max(worst_wrong_fhat, (grad_wrong - exact).norm() / exact.norm());
    }
    EXPECT_LT(worst, 1e-12) << (jittered ? "jittered" : "regular");
    EXPECT_GT(worst_wrong_fhat, 0.1);
    RecordProperty(jittered ? "diff_grad_err_jittered" : "diff_grad_err_regular", fmt::format("{:.3g}", worst));
  }
}

// The in-place rebuild (V2) counts degenerate rows from whichever thread builds them. A row with
// no source in its support is degenerate; here 4000 targets, every other one far from the
// sources, so that the worker threads' blocks hold degenerate rows too (a per-thread counter
// once crashed there).
TEST(CorrectedOperator, TheRebuildCountsDegenerateRowsOnEveryThread) {
  const test::ThreadCount threads(2);
  const double dx = 0.1;
  ParticleSet<2> sources("nodes");
  for (int j = 0; j < 10; ++j) {
    for (int i = 0; i < 400; ++i) sources.add(Vec<2>(i * dx, j * dx), dx * dx, 2000.0, 0);
  }
  std::vector<Vec<2>> targets;
  for (int k = 0; k < 4000; ++k) {
    const double x = (k % 400) * dx + 0.5 * dx;
    targets.push_back(k % 2 == 0 ? Vec<2>(x, 0.45) : Vec<2>(x, 100.0 + 0.01 * k));
  }
  const CubicSplineKernel<2> kernel(1.2 * dx);
  Relation<2> relation;
  relation.build(targets, sources.position, operator_relation_options(kernel));
  CorrectedOperator<2> op;
  rebuild_corrected_operator<2>(relation, targets, sources, kernel, op, exec::Threads{16});
  EXPECT_EQ(op.degenerate_rows, 2000);
}

}  // namespace
}  // namespace rktsph
