// Shared row patterns of the corrected operator (operators/corrected_operator.hpp): the
// compressed operator gives every row the same sources and, to round-off, the same weights as
// the operator built row by row (OperatorOptions::share_patterns = false), on regular and
// jittered lattices and on a body with re-entrant corners; a regular lattice needs a handful of
// patterns whatever its size (the test fails if sharing stops working); jittered rows are never
// merged; and the result does not depend on the number of threads.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include <fmt/format.h>

#include "../support/test_util.hpp"
#include "core/kernel.hpp"
#include "operators/corrected_operator.hpp"
#include "particles/lattice.hpp"

namespace rktsph {
namespace {

template <int Dim>
LatticeParticles<Dim> box(const Vec<Dim>& hi, double dx) {
  Block<Dim> b;
  b.min = Vec<Dim>::Zero();
  b.max = hi;
  b.label = "box";
  return generate_lattice<Dim>({b}, dx, Vec<Dim>::Zero(), {1000.0});
}

// L-shape: a convex corner at every end and a re-entrant corner at (2, 2).
LatticeParticles<2> l_shape(double dx) {
  Block<2> a, b;
  a.min = Vec<2>(0, 0);
  a.max = Vec<2>(4, 2);
  b.min = Vec<2>(0, 2);
  b.max = Vec<2>(2, 4);
  return generate_lattice<2>({a, b}, dx, Vec<2>(0, 0), {1800.0});
}

template <int Dim>
void jitter(std::vector<Vec<Dim>>& x, double amplitude, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-amplitude, amplitude);
  for (auto& p : x) {
    for (int d = 0; d < Dim; ++d) p[d] += u(rng);
  }
}

struct Agreement {
  double weight = 0.0;  // max |w - w_ref| / max |w_ref| over the row, over rows
  double field = 0.0;   // max |(P f) - (P_ref f)| / sum |w_ref| |f|, interpolation and gradient
};

// Compare the compressed operator with the row-by-row one: same sources per row (exactly),
// weights and the interpolation/gradient of a random field to round-off.
template <int Dim>
Agreement compare(const CorrectedOperator<Dim>& op, const CorrectedOperator<Dim>& ref, std::mt19937& rng) {
  Agreement out;
  EXPECT_EQ(op.rows(), ref.rows());
  EXPECT_EQ(op.pairs(), ref.pairs());
  EXPECT_EQ(op.degenerate_rows, ref.degenerate_rows);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Index max_source = 0;
  for (Index a = 0; a < ref.rows(); ++a) {
    const auto r = ref.row(a);
    for (Index k = r.begin; k < r.end; ++k) max_source = std::max(max_source, ref.source(r, k));
  }
  std::vector<double> f(static_cast<std::size_t>(max_source) + 1);
  for (double& v : f) v = u(rng);
  for (Index a = 0; a < ref.rows(); ++a) {
    const auto r = op.row(a);
    const auto q = ref.row(a);
    EXPECT_EQ(r.end - r.begin, q.end - q.begin) << "row " << a;
    if (r.end - r.begin != q.end - q.begin) continue;
    double wmax = 0.0, gmax = 0.0;
    for (Index k = q.begin; k < q.end; ++k) {
      wmax = std::max(wmax, std::abs(ref.interp[static_cast<std::size_t>(k)]));
      for (int d = 0; d < Dim; ++d)
        gmax = std::max(gmax, std::abs(ref.grad[static_cast<std::size_t>(k)][static_cast<std::size_t>(d)]));
    }
    double val = 0.0, val_ref = 0.0, val_scale = 0.0;
    double g[Dim] = {}, g_ref[Dim] = {}, g_scale[Dim] = {};
    for (Index j = 0; j < q.end - q.begin; ++j) {
      const auto k = static_cast<std::size_t>(r.begin + j), kr = static_cast<std::size_t>(q.begin + j);
      const Index b = op.source(r, r.begin + j);
      EXPECT_EQ(b, ref.source(q, q.begin + j)) << "row " << a;
      const double fb = f[static_cast<std::size_t>(b)];
      out.weight = std::max(out.weight, std::abs(op.interp[k] - ref.interp[kr]) / wmax);
      val += op.interp[k] * fb;
      val_ref += ref.interp[kr] * fb;
      val_scale += std::abs(ref.interp[kr] * fb);
      for (std::size_t d = 0; d < Dim; ++d) {
        out.weight = std::max(out.weight, std::abs(op.grad[k][d] - ref.grad[kr][d]) / gmax);
        g[d] += op.grad[k][d] * fb;
        g_ref[d] += ref.grad[kr][d] * fb;
        g_scale[d] += std::abs(ref.grad[kr][d] * fb);
      }
    }
    out.field = std::max(out.field, std::abs(val - val_ref) / val_scale);
    for (int d = 0; d < Dim; ++d) {
      if (g_scale[d] > 0.0) out.field = std::max(out.field, std::abs(g[d] - g_ref[d]) / g_scale[d]);
    }
  }
  return out;
}

// Both directions of the staggered scheme and the same-set (V3) operator of one discretisation.
template <int Dim>
struct Operators {
  std::vector<CorrectedOperator<Dim>> shared, plain;
};

template <int Dim>
Operators<Dim> build_all(const LatticeParticles<Dim>& disc, const CubicSplineKernel<Dim>& kernel) {
  Operators<Dim> ops;
  const OperatorOptions plain{.share_patterns = false};
  ops.shared.push_back(build_corrected_operator<Dim>(disc.stress_points.position, disc.nodes, kernel));
  ops.shared.push_back(build_corrected_operator<Dim>(disc.nodes.position, disc.stress_points, kernel));
  ops.shared.push_back(build_corrected_operator<Dim>(disc.nodes.position, disc.nodes, kernel));
  ops.plain.push_back(build_corrected_operator<Dim>(disc.stress_points.position, disc.nodes, kernel, plain));
  ops.plain.push_back(build_corrected_operator<Dim>(disc.nodes.position, disc.stress_points, kernel, plain));
  ops.plain.push_back(build_corrected_operator<Dim>(disc.nodes.position, disc.nodes, kernel, plain));
  return ops;
}

constexpr double kRoundOff = 1e-12;

TEST(OperatorPatterns, RegularLatticeAgreesWithRowByRowWeightsAndNeedsFewPatterns) {
  std::mt19937 rng(2024);
  const double dx = 0.25;
  // h/dx = 1.2 (the default) and 1.0, where node-node pairs lie exactly on the support edge.
  for (const double h_over_dx : {1.2, 1.0}) {
    std::vector<Index> counts[2];
    double worst = 0.0;
    for (int size = 0; size < 2; ++size) {
      const double L = size == 0 ? 5.0 : 10.0;  // 20 x 20 and 40 x 40 cells
      const auto disc = box<2>(Vec<2>(L, 0.5 * L), dx);
      const CubicSplineKernel<2> kernel(h_over_dx * dx);
      const auto ops = build_all<2>(disc, kernel);
      for (std::size_t i = 0; i < ops.shared.size(); ++i) {
        const Agreement e = compare<2>(ops.shared[i], ops.plain[i], rng);
        EXPECT_LT(e.weight, kRoundOff) << "operator " << i << ", h/dx " << h_over_dx;
        EXPECT_LT(e.field, kRoundOff) << "operator " << i << ", h/dx " << h_over_dx;
        EXPECT_EQ(ops.plain[i].patterns(), ops.plain[i].rows());
        worst = std::max({worst, e.weight, e.field});
        counts[size].push_back(ops.shared[i].patterns());
      }
    }
    for (std::size_t i = 0; i < counts[0].size(); ++i) {
      // Interior, faces, edges and corners: a few dozen classes, the same on a lattice four
      // times as large. Row-by-row would be 231 to 3321 patterns here.
      EXPECT_LE(counts[0][i], 64) << "operator " << i << ", h/dx " << h_over_dx;
      EXPECT_EQ(counts[0][i], counts[1][i]) << "operator " << i << ", h/dx " << h_over_dx;
    }
    RecordProperty(fmt::format("patterns_h{}", h_over_dx), fmt::format("{}", fmt::join(counts[1], " ")));
    RecordProperty(fmt::format("max_rel_difference_h{}", h_over_dx), fmt::format("{:.3g}", worst));
  }
}

TEST(OperatorPatterns, InteriorRowsShareOnePattern) {
  const double dx = 0.5;
  const auto disc = box<2>(Vec<2>(10.0, 10.0), dx);
  const CubicSplineKernel<2> kernel(1.2 * dx);
  const auto en = build_corrected_operator<2>(disc.stress_points.position, disc.nodes, kernel);
  Index interior = -1;
  for (Index e = 0; e < en.rows(); ++e) {
    const Vec<2>& x = disc.stress_points.position[static_cast<std::size_t>(e)];
    if (x.minCoeff() < 3 * dx || x.maxCoeff() > 10.0 - 3 * dx) continue;
    if (interior < 0) interior = en.pattern[static_cast<std::size_t>(e)];
    EXPECT_EQ(en.pattern[static_cast<std::size_t>(e)], interior);
  }
  EXPECT_GE(interior, 0);
  // Operator storage: 8 bytes per row plus the patterns, against 36 bytes per pair row by row.
  EXPECT_LT(en.bytes(), static_cast<std::size_t>(en.rows()) * 8 + 20000);
}

TEST(OperatorPatterns, JitteredLatticeAgreesAndKeepsOnePatternPerRow) {
  std::mt19937 rng(77);
  const double dx = 0.25;
  LatticeParticles<2> disc = box<2>(Vec<2>(4.0, 3.0), dx);
  jitter(disc.nodes.position, 0.2 * dx, rng);
  jitter(disc.stress_points.position, 0.2 * dx, rng);
  const CubicSplineKernel<2> kernel(1.2 * dx);
  const auto ops = build_all<2>(disc, kernel);
  for (std::size_t i = 0; i < ops.shared.size(); ++i) {
    const Agreement e = compare<2>(ops.shared[i], ops.plain[i], rng);
    // Nothing is shared, so the weights are the row-by-row ones bit for bit (the sums may
    // still differ in the last bit where the compiler contracts one of them into an FMA).
    EXPECT_EQ(e.weight, 0.0) << "operator " << i;
    EXPECT_LT(e.field, kRoundOff) << "operator " << i;
    EXPECT_EQ(ops.shared[i].patterns(), ops.shared[i].rows()) << "operator " << i;
  }
}

TEST(OperatorPatterns, BodyWithCornersAgreesWithRowByRowWeights) {
  std::mt19937 rng(5);
  const auto disc = l_shape(0.125);
  const CubicSplineKernel<2> kernel(1.2 * 0.125);
  const auto ops = build_all<2>(disc, kernel);
  for (std::size_t i = 0; i < ops.shared.size(); ++i) {
    const Agreement e = compare<2>(ops.shared[i], ops.plain[i], rng);
    EXPECT_LT(e.weight, kRoundOff) << "operator " << i;
    EXPECT_LT(e.field, kRoundOff) << "operator " << i;
    EXPECT_LT(ops.shared[i].patterns(), ops.shared[i].rows() / 4) << "operator " << i;
  }
}

TEST(OperatorPatterns, OneAndThreeDimensions) {
  std::mt19937 rng(11);
  {
    const auto disc = box<1>(Vec<1>(10.0), 0.1);
    const CubicSplineKernel<1> kernel(0.8 * 0.1);
    const auto ops = build_all<1>(disc, kernel);
    for (std::size_t i = 0; i < ops.shared.size(); ++i) {
      const Agreement e = compare<1>(ops.shared[i], ops.plain[i], rng);
      EXPECT_LT(e.weight, kRoundOff);
      EXPECT_LT(e.field, kRoundOff);
      EXPECT_LE(ops.shared[i].patterns(), 8);
    }
  }
  {
    // 14^3 cells: boundary classes reach three layers in from each face, so a smaller cube is
    // nearly all boundary.
    const auto disc = box<3>(Vec<3>(3.5, 3.5, 3.5), 0.25);
    const CubicSplineKernel<3> kernel(1.2 * 0.25);
    const auto ops = build_all<3>(disc, kernel);
    for (std::size_t i = 0; i < ops.shared.size(); ++i) {
      const Agreement e = compare<3>(ops.shared[i], ops.plain[i], rng);
      EXPECT_LT(e.weight, kRoundOff);
      EXPECT_LT(e.field, kRoundOff);
      EXPECT_LT(ops.shared[i].patterns(), ops.shared[i].rows() / 2);
    }
  }
}

TEST(OperatorPatterns, IndependentOfTheThreadCount) {
  // Large enough (> 2048 rows) for the assembly to run in parallel, with a coordinate offset so
  // that positions carry round-off.
  const double dx = 0.1;
  Block<2> b;
  b.min = Vec<2>(1000.0, 0.0);
  b.max = Vec<2>(1008.0, 4.0);
  b.label = "strip";
  const auto disc = generate_lattice<2>({b}, dx, Vec<2>(1000.0, 0.0), {1000.0});
  const CubicSplineKernel<2> kernel(1.2 * dx);
  auto build = [&](int threads) {
    const test::ThreadCount guard(threads);
    return build_corrected_operator<2>(disc.nodes.position, disc.stress_points, kernel);
  };
  const auto one = build(1);
  const auto two = build(2);
  EXPECT_EQ(one.base, two.base);
  EXPECT_EQ(one.pattern, two.pattern);
  EXPECT_EQ(one.pattern_start, two.pattern_start);
  EXPECT_EQ(one.offset, two.offset);
  ASSERT_EQ(one.interp.size(), two.interp.size());
  EXPECT_EQ(std::memcmp(one.interp.data(), two.interp.data(), one.interp.size() * sizeof(double)), 0);
  EXPECT_EQ(std::memcmp(one.grad.data(), two.grad.data(), one.grad.size() * sizeof(one.grad[0])), 0);
  EXPECT_LT(one.patterns(), 100);
}

}  // namespace
}  // namespace rktsph
