// geometry.jitter (particles/lattice.hpp, LatticeJitter): interior nodes and stress points
// displaced by up to j dx, face nodes left in place, volumes unchanged; the corrected operators
// stay exact for linear fields on the disordered sets; the same seed gives the same particles
// on any thread count; a short V1 elastic run on a jittered set stays stable and close to the
// regular one.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>

#include "../support/test_util.hpp"
#include "case/case_builder.hpp"
#include "schemes/simulation.hpp"
#include "schemes/staggered_model.hpp"

namespace rktsph {
namespace {

constexpr double kE = 1.0e7, kNu = 0.3, kRho = 2000.0;

// A plate [0, 2] x [0, 1] m on a fixed base, loaded on its top by a smoothly applied pressure.
CaseSetup<2> plate(double jitter, std::uint64_t seed, double dx = 0.1, double end = 0.01) {
  return CaseBuilder<2>("jittered plate")
      .spacing(dx)
      .block(Vec<2>(0.0, 0.0), Vec<2>(2.0, 1.0))
      .elastic(kE, kNu, kRho)
      .jitter(jitter, seed)
      .fix_velocity(Region<2>::plane(1, 0.0), {0, 1})
      .prescribe_stress(Region<2>::plane(1, 1.0), StressComponent::yy, -1.0e4, "load")
      .function("load", TimeFunction::smoothstep(0.05))
      .time(end, 0.5)
      .build();
}

// max over the targets of |Pi f - f| and |grad f - grad f exact| for f linear, relative to |f|max.
template <int Dim>
std::pair<double, double> linear_errors(const CorrectedOperator<Dim>& op, const std::vector<Vec<Dim>>& targets,
                                        const ParticleSet<Dim>& sources) {
  Vec<Dim> slope;
  for (int d = 0; d < Dim; ++d) slope[d] = 0.7 - 1.3 * d;
  auto f = [&](const Vec<Dim>& x) { return 1.25 + slope.dot(x); };
  const double scale = 10.0;
  double interp = 0.0, grad = 0.0;
  for (Index a = 0; a < op.rows(); ++a) {
    const auto row = op.row(a);
    double value = 0.0;
    Vec<Dim> g = Vec<Dim>::Zero();
    for (Index k = row.begin; k < row.end; ++k) {
      const auto ku = static_cast<std::size_t>(k);
      const double fb = f(sources.position[static_cast<std::size_t>(op.source(row, k))]);
      value += op.interp[ku] * fb;
      for (int d = 0; d < Dim; ++d) g[d] += op.grad[ku][static_cast<std::size_t>(d)] * fb;
    }
    interp = std::max(interp, std::abs(value - f(targets[static_cast<std::size_t>(a)])) / scale);
    grad = std::max(grad, (g - slope).norm() / scale);
  }
  return {interp, grad};
}

TEST(Jitter, MovesInteriorParticlesWithinTheBoundAndKeepsFaceNodes) {
  const double dx = 0.1, j = 0.3;
  const StaggeredModel<2> regular(plate(0.0, 7));
  const StaggeredModel<2> jittered(plate(j, 7));
  ASSERT_EQ(regular.nodes.size(), jittered.nodes.size());
  ASSERT_EQ(regular.stress_points.size(), jittered.stress_points.size());
  EXPECT_EQ(regular.boundary.node, jittered.boundary.node);
  std::vector<std::uint8_t> on_face(static_cast<std::size_t>(regular.nodes.size()), 0);
  for (const Index i : regular.boundary.node) on_face[static_cast<std::size_t>(i)] = 1;
  double largest = 0.0;
  int moved = 0;
  for (std::size_t i = 0; i < on_face.size(); ++i) {
    const Vec<2> offset = jittered.nodes.position[i] - regular.nodes.position[i];
    EXPECT_EQ(jittered.nodes.volume[i], regular.nodes.volume[i]);
    if (on_face[i] != 0) {
      EXPECT_EQ(offset.norm(), 0.0) << "face node " << i << " moved";
      continue;
    }
    moved += offset.norm() > 0.0 ? 1 : 0;
    largest = std::max(largest, offset.cwiseAbs().maxCoeff());
  }
  for (std::size_t e = 0; e < static_cast<std::size_t>(regular.stress_points.size()); ++e) {
    const Vec<2> offset = jittered.stress_points.position[e] - regular.stress_points.position[e];
    EXPECT_EQ(jittered.stress_points.volume[e], regular.stress_points.volume[e]);
    EXPECT_GT(offset.norm(), 0.0);
    largest = std::max(largest, offset.cwiseAbs().maxCoeff());
  }
  const auto interior = static_cast<int>(regular.nodes.size() - static_cast<Index>(regular.boundary.size()));
  EXPECT_EQ(moved, interior);
  EXPECT_LE(largest, j * dx);
  EXPECT_GT(largest, 0.9 * j * dx);  // the draws fill the range
  RecordProperty("largest_offset_over_dx", fmt::format("{:.4f}", largest / dx));
}

TEST(Jitter, CorrectedOperatorsStayExactForLinearFields) {
  const test::ThreadCount threads(1);
  for (const double j : {0.1, 0.3, 0.45}) {
    const StaggeredModel<2> model(plate(j, 11));
    EXPECT_EQ(model.degenerate_operator_rows(), 0) << "jitter " << j;
    const auto [ei, eg] = linear_errors<2>(model.to_stress_points, model.stress_points.position, model.nodes);
    const auto [ni, ng] = linear_errors<2>(model.to_nodes, model.nodes.position, model.stress_points);
    EXPECT_LT(ei, 1e-12) << "nodes -> stress points, jitter " << j;
    EXPECT_LT(eg, 1e-12) << "nodes -> stress points, jitter " << j;
    EXPECT_LT(ni, 1e-12) << "stress points -> nodes, jitter " << j;
    EXPECT_LT(ng, 1e-12) << "stress points -> nodes, jitter " << j;
    std::printf("jitter %.2f: linear interpolation error %.2e / %.2e, gradient %.2e / %.2e\n", j, ei, ni, eg, ng);
  }
  // 1D: a bar, both ends on faces.
  const CaseSetup<1> bar = CaseBuilder<1>("jittered bar")
                               .spacing(0.05)
                               .block(Vec<1>(0.0), Vec<1>(3.0))
                               .elastic(kE, kNu, kRho)
                               .jitter(0.4, 3)
                               .time(0.01)
                               .build();
  const StaggeredModel<1> model(bar);
  EXPECT_EQ(model.degenerate_operator_rows(), 0);
  const auto [ei, eg] = linear_errors<1>(model.to_stress_points, model.stress_points.position, model.nodes);
  const auto [ni, ng] = linear_errors<1>(model.to_nodes, model.nodes.position, model.stress_points);
  EXPECT_LT(std::max({ei, eg, ni, ng}), 1e-12);
}

TEST(Jitter, TheSeedFixesThePositionsOnAnyThreadCount) {
  auto positions = [](std::uint64_t seed, int threads) {
    const test::ThreadCount guard(threads);
    const StaggeredModel<2> model(plate(0.2, seed));
    std::vector<Vec<2>> all = model.nodes.position;
    all.insert(all.end(), model.stress_points.position.begin(), model.stress_points.position.end());
    return all;
  };
  const auto a = positions(42, 1);
  EXPECT_EQ(a, positions(42, 1));
  EXPECT_EQ(a, positions(42, 2));
  const auto b = positions(43, 1);
  ASSERT_EQ(a.size(), b.size());
  std::size_t differ = 0;
  for (std::size_t k = 0; k < a.size(); ++k) differ += a[k] != b[k] ? 1 : 0;
  // Every stress point and every interior node (the face nodes stay).
  const StaggeredModel<2> model(plate(0.2, 42));
  EXPECT_EQ(differ, a.size() - model.boundary.size());
  // The offsets are uniform: their mean and variance over all draws.
  double sum = 0.0, squares = 0.0;
  const int draws = 20000;
  for (int k = 0; k < draws; ++k) {
    const double u = jitter_unit_offset(5, k % 2, k / 2, k % 3);
    ASSERT_GE(u, -1.0);
    ASSERT_LT(u, 1.0);
    sum += u;
    squares += u * u;
  }
  EXPECT_NEAR(sum / draws, 0.0, 0.02);
  EXPECT_NEAR(squares / draws, 1.0 / 3.0, 0.01);
}

TEST(Jitter, RejectsHalfASpacing) {
  EXPECT_THROW(plate(0.5, 0), InputError);
  EXPECT_THROW(plate(-0.1, 0), InputError);
  Block<1> b;
  b.min = Vec<1>(0.0);
  b.max = Vec<1>(1.0);
  EXPECT_THROW(generate_lattice<1>({b}, 0.1, Vec<1>(0.0), {1000.0}, {0.5, 1}), InputError);
}

// Mean vertical displacement of the top face nodes (which the jitter leaves in place).
double top_settlement(const Simulation<2>& solver) {
  double sum = 0.0;
  int n = 0;
  for (std::size_t i = 0; i < solver.nodes().position.size(); ++i) {
    if (std::abs(solver.nodes().position[i][1] - 1.0) > 1e-9) continue;
    sum += solver.node_displacement()(static_cast<Index>(i), 1);
    ++n;
  }
  return sum / n;
}

TEST(Jitter, AShortElasticRunStaysCloseToTheRegularOne) {
  const test::ThreadCount threads(1);
  const double end = 0.15;  // the load applied over 0.05 s, then about 5 passes of the P wave
  Simulation<2> regular(plate(0.0, 0, 0.1, end));
  Simulation<2> jittered(plate(0.1, 2026, 0.1, end));
  double largest_difference = 0.0, largest = 0.0;
  while (regular.time() < end - 1e-12) {
    regular.step();
    jittered.step();
    const double a = top_settlement(regular), b = top_settlement(jittered);
    largest_difference = std::max(largest_difference, std::abs(a - b));
    largest = std::max(largest, std::abs(a));
  }
  ASSERT_EQ(regular.step_count(), jittered.step_count());
  const double a = top_settlement(regular), b = top_settlement(jittered);
  // Stable: no velocity beyond the regular run's.
  double v_regular = 0.0, v_jittered = 0.0;
  for (Index i = 0; i < regular.nodes().size(); ++i) {
    v_regular = std::max(v_regular, regular.node_velocity().vec(i).norm());
    v_jittered = std::max(v_jittered, jittered.node_velocity().vec(i).norm());
  }
  EXPECT_LT(a, 0.0);
  EXPECT_LT(std::abs(b - a), 0.005 * std::abs(a));
  EXPECT_LT(largest_difference, 0.005 * largest);
  EXPECT_LT(v_jittered, 1.5 * v_regular);
  std::printf(
      "top settlement at %.3f s: regular %.6e m, jitter 0.1 %.6e m (difference %.3g %%); largest difference over "
      "the run %.3g %% of the largest settlement; max |v| %.4g / %.4g m/s\n",
      end, a, b, 100.0 * (b - a) / std::abs(a), 100.0 * largest_difference / largest, v_regular, v_jittered);
  RecordProperty("settlement_difference_percent", fmt::format("{:.3g}", 100.0 * (b - a) / std::abs(a)));
}

}  // namespace
}  // namespace rktsph
