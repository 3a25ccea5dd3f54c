// Bishop's simplified method and the critical-circle search (lem/bishop.hpp, method-notes §9)
// against a hand computation, the ordinary method where they must agree (phi = 0), Taylor's
// (1937, 1948) stability numbers for phi = 0 and the published value of the 2:1 c-phi slope.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "case/case_reader.hpp"
#include "lem/bishop.hpp"
#include "lem/lem_case.hpp"

namespace rktsph::lem {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = std::numbers::pi;

RigidRegion base_at(double y) {
  RigidRegion r;
  r.lo[1] = r.hi[1] = y;
  return r;
}
RigidRegion wall_at(double x) {
  RigidRegion r;
  r.lo[0] = r.hi[0] = x;
  return r;
}

// A cut of height H = 10 m and face angle beta (degrees) with its toe at (20, 0): the base at
// the toe's level y = 0 is rigid, the soil runs on 40 m behind the crest to a roller wall.
SoilGeometry cut(double beta_deg) {
  const double run = beta_deg == 90.0 ? 0.0 : 10.0 / std::tan(beta_deg * kPi / 180.0);
  Body b;
  b.outer = {{20.0, 0.0}, {60.0 + run, 0.0}, {60.0 + run, 10.0}, {20.0 + run, 10.0}};
  return SoilGeometry({b}, {base_at(0.0), wall_at(60.0 + run)});
}

// The 20 m x 10 m block of thesis case 5: base rigid, x = 0 on rollers, face x = 20 free.
SoilGeometry block_cut() {
  Body b;
  b.outer = {{0.0, 0.0}, {20.0, 0.0}, {20.0, 10.0}, {0.0, 10.0}};
  return SoilGeometry({b}, {base_at(0.0), wall_at(0.0)});
}

// Taylor's stability number N_s = c / (gamma H F) of the critical circle.
double stability_number(const SoilGeometry& g, const Soil& s, double H) {
  const SearchResult r = search_critical_circle(g, s, SearchOptions{});
  EXPECT_TRUE(r.found());
  return s.cohesion / (s.unit_weight * H * r.critical.factor);
}

// One circle by hand (four slices, the block cut, c = 10 kPa, phi = 20 deg, gamma = 20 kN/m^3):
// centre (24, 16), R = 16 m. Entry on the crest y = 10 at x_a = 24 - sqrt(16^2 - 6^2) = 9.16760 m,
// exit on the face x = 20 at y = 16 - sqrt(16^2 - 4^2) = 0.50807 m (above the rigid base), so
// b = (20 - x_a)/4 = 2.70810 m. Per slice, at its centre x_i: base y_i = 16 - sqrt(256 - (x_i - 24)^2),
// h_i = 10 - y_i, W_i = gamma b h_i, sin(alpha_i) = (24 - x_i)/16 (the mass slides towards +x):
//   x_i       y_i       h_i       W_i (N/m)    alpha_i (deg)
//   10.52165  7.37827   2.62173   141997.86    57.39408
//   13.22975  4.16777   5.83223   315885.36    42.30992
//   15.93785  2.17966   7.82034   423565.05    30.25732
//   18.64595  0.92240   9.07760   491661.07    19.54993
// sum(W sin alpha) = 710205.15 N/m. Ordinary method, eq. (9.3): F = 0.790809; Bishop,
// eq. (9.2) iterated from it: F = 0.813169 (a desk computation of the same formulas).
TEST(Bishop, OneCircleAgainstAFourSliceHandComputation) {
  const Soil soil{10.0e3, 20.0 * kPi / 180.0, 20.0e3};
  BishopOptions o;
  o.slices = 4;
  o.tolerance = 1e-13;
  const CircleResult r = evaluate_circle(block_cut(), soil, {{24.0, 16.0}, 16.0}, o, true);
  ASSERT_TRUE(r.valid()) << rejection_name(r.rejection);
  EXPECT_NEAR(r.entry.x, 9.167603025808674, 1e-9);
  EXPECT_NEAR(r.entry.y, 10.0, 1e-9);
  EXPECT_NEAR(r.exit.x, 20.0, 1e-9);
  EXPECT_NEAR(r.exit.y, 16.0 - std::sqrt(240.0), 1e-9);
  EXPECT_EQ(r.direction, 1);
  ASSERT_EQ(r.slices.size(), 4u);
  const double W[] = {141997.863, 315885.356, 423565.054, 491661.069};
  const double alpha[] = {57.394078, 42.309916, 30.257318, 19.549925};
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_NEAR(r.slices[i].weight, W[i], 1e-3) << i;
    EXPECT_NEAR(r.slices[i].alpha * 180.0 / kPi, alpha[i], 1e-6) << i;
    EXPECT_NEAR(r.slices[i].width, 2.7080992435478315, 1e-12);
  }
  EXPECT_NEAR(r.fellenius, 0.7908092687619982, 1e-10);
  EXPECT_NEAR(r.factor, 0.8131691726903231, 1e-10);
}

// With phi = 0, m_alpha = cos(alpha) and Bishop's F is the ordinary method's, circle by circle
// (both are the moment balance c R L / (W lever arm) on the slices).
TEST(Bishop, PhiZeroEqualsTheOrdinaryMethod) {
  const Soil soil{20.0e3, 0.0, 18.0e3};
  const SoilGeometry g = cut(60.0);
  int checked = 0;
  for (const Circle& c : {Circle{{25.0, 15.0}, 14.0}, Circle{{30.0, 20.0}, 19.0}, Circle{{22.0, 12.0}, 11.5},
                          Circle{{35.0, 25.0}, 24.0}}) {
    const CircleResult r = evaluate_circle(g, soil, c, BishopOptions{});
    EXPECT_TRUE(r.valid()) << c.centre.x << " " << c.centre.y << ": " << rejection_name(r.rejection);
    if (!r.valid()) continue;
    ++checked;
    EXPECT_NEAR(r.factor, r.fellenius, 1e-12 * r.factor);
    EXPECT_EQ(r.limited_slices, 0u);
  }
  EXPECT_EQ(checked, 4);
  // And with friction they differ (Bishop's normal force includes the interslice shear balance).
  const CircleResult rf = evaluate_circle(g, {20.0e3, 25.0 * kPi / 180.0, 18.0e3}, {{25.0, 15.0}, 14.0}, BishopOptions{});
  ASSERT_TRUE(rf.valid());
  EXPECT_GT(std::abs(rf.factor - rf.fellenius), 1e-3 * rf.factor);
}

// Taylor's chart for phi = 0 (Taylor 1937, J. Boston Soc. Civ. Eng. 24(3); Taylor 1948,
// Fundamentals of Soil Mechanics, Fig. 16.x): toe circles for beta > 53 deg, N_s = 0.261 (a
// vertical cut, gamma H / c = 3.83), 0.219 at 75 deg, 0.191 at 60 deg. Read from the chart to
// three figures: tolerance 1 %.
TEST(BishopSearch, TaylorStabilityNumbersForPhiZero) {
  const Soil soil{10.0e3, 0.0, 20.0e3};
  EXPECT_NEAR(stability_number(cut(90.0), soil, 10.0), 0.261, 0.01 * 0.261);
  EXPECT_NEAR(stability_number(cut(75.0), soil, 10.0), 0.219, 0.01 * 0.219);
  EXPECT_NEAR(stability_number(cut(60.0), soil, 10.0), 0.191, 0.01 * 0.191);
}

// The critical circle of a phi = 0 vertical cut passes through the toe (the rigid base stops
// deeper ones) and its F does not depend on the scale (N_s is a number).
TEST(BishopSearch, VerticalCutCriticalCircleIsAToeCircle) {
  const SearchResult r = search_critical_circle(block_cut(), {10.0e3, 0.0, 20.0e3}, SearchOptions{});
  ASSERT_TRUE(r.found());
  EXPECT_NEAR(r.critical.exit.x, 20.0, 1e-6);
  EXPECT_NEAR(r.critical.exit.y, 0.0, 0.02);
  EXPECT_EQ(r.critical.direction, 1);
  EXPECT_GT(r.circles_valid, 1000u);
  const SearchResult r2 = search_critical_circle(block_cut(), {20.0e3, 0.0, 20.0e3}, SearchOptions{});
  EXPECT_NEAR(r2.critical.factor, 2.0 * r.critical.factor, 1e-3 * r.critical.factor);
}

// Fifty slices (the default) against 400 on the critical circle: the slice count is converged.
TEST(BishopSearch, FiftySlicesAreConverged) {
  const Soil soil{10.0e3, 20.0 * kPi / 180.0, 20.0e3};
  Body b;
  b.outer = {{0.0, 0.0}, {40.0, 0.0}, {40.0, 10.0}, {20.0, 10.0}};
  const SoilGeometry g({b}, {base_at(0.0), wall_at(40.0)});
  const SearchResult r = search_critical_circle(g, soil, SearchOptions{});
  ASSERT_TRUE(r.found());
  BishopOptions fine;
  fine.slices = 400;
  const CircleResult f = evaluate_circle(g, soil, r.circle, fine);
  ASSERT_TRUE(f.valid());
  EXPECT_NEAR(r.critical.factor, f.factor, 0.002 * f.factor);
}

// Item 5(b) of issue 16: the 2:1 slope, H = 10 m, gamma = 20 kN/m^3, c' = 10 kPa, phi' = 20 deg
// on a rigid base at the toe (cases/examples/slope_2to1_c10_phi20.toml, read as a case): Bishop
// and Morgenstern's (1960) charts give 1.38 (Griffiths & Lane 1999, Geotechnique 49(3), example
// 1, where finite elements give 1.4). Criterion: within 3 %.
TEST(BishopSearch, TwoToOneSlopeAgainstThePublishedChartValue) {
  const CaseDocument doc =
      load_case_document(std::string(RKTSPH_SOURCE_DIR) + "/cases/examples/slope_2to1_c10_phi20.toml", {});
  const LemProblem p = read_lem_problem(doc);
  EXPECT_NEAR(p.soil.unit_weight, 20.0e3, 1e-6);
  EXPECT_NEAR(p.soil.cohesion, 10.0e3, 0.0);
  EXPECT_NEAR(p.soil.friction_angle, 20.0 * kPi / 180.0, 1e-15);
  const SearchResult r = search_critical_circle(p.geometry, p.soil, SearchOptions{});
  ASSERT_TRUE(r.found());
  EXPECT_NEAR(r.critical.factor, 1.38, 0.03 * 1.38);
  // The mass slides towards the toe (-x), exits near the toe and enters behind the crest.
  EXPECT_EQ(r.critical.direction, -1);
  EXPECT_LT(r.critical.exit.x, 2.0);
  EXPECT_GT(r.critical.entry.x, 20.0);
  EXPECT_LT(r.critical.entry.x, 30.0);
  EXPECT_EQ(r.critical.limited_slices, 0u);
}

// The same slope facing the other way (x -> 40 - x): the same F, sliding towards +x.
TEST(BishopSearch, MirroredSlopeGivesTheSameFactor) {
  const Soil soil{10.0e3, 20.0 * kPi / 180.0, 20.0e3};
  Body left, right;
  left.outer = {{0.0, 0.0}, {40.0, 0.0}, {40.0, 10.0}, {20.0, 10.0}};
  right.outer = {{0.0, 0.0}, {40.0, 0.0}, {20.0, 10.0}, {0.0, 10.0}};
  const SearchResult a = search_critical_circle(SoilGeometry({left}, {base_at(0.0), wall_at(40.0)}), soil, {});
  const SearchResult b = search_critical_circle(SoilGeometry({right}, {base_at(0.0), wall_at(0.0)}), soil, {});
  ASSERT_TRUE(a.found() && b.found());
  EXPECT_NEAR(a.critical.factor, b.critical.factor, 1e-6 * a.critical.factor);
  EXPECT_EQ(a.critical.direction, -1);
  EXPECT_EQ(b.critical.direction, 1);
  EXPECT_NEAR(b.critical.exit.x, 40.0 - a.critical.exit.x, 1e-3);
}

// Thesis case 5 through the block path: N = gamma H / c = 3.40 (c = 57.71 kPa, rho = 2000 kg/m^3,
// g = 9.81 m/s^2), so Taylor's N_s = 0.261 gives F = c / (0.261 gamma H) = 1.127.
TEST(BishopSearch, ThesisCase5CutThroughTheBlockGeometry) {
  const CaseDocument doc =
      load_case_document(std::string(RKTSPH_SOURCE_DIR) + "/cases/thesis/05_viscoplastic_cut_2d.toml", {});
  const LemProblem p = read_lem_problem(doc);
  EXPECT_EQ(p.soil.friction_angle, 0.0);
  EXPECT_EQ(p.geometry.rigid_regions().size(), 2u);  // the base and the rollers
  const SearchResult r = search_critical_circle(p.geometry, p.soil, SearchOptions{});
  ASSERT_TRUE(r.found());
  const double taylor = 57710.0 / (0.261 * 2000.0 * 9.81 * 10.0);
  EXPECT_NEAR(r.critical.factor, taylor, 0.01 * taylor);
}

// Touching blocks make one soil: the seam between them is not a slip-surface crossing.
TEST(SoilGeometry, TwoTouchingBlocksActAsOne) {
  Body left, right;
  left.outer = {{0.0, 0.0}, {10.0, 0.0}, {10.0, 10.0}, {0.0, 10.0}};
  right.outer = {{10.0, 0.0}, {20.0, 0.0}, {20.0, 10.0}, {10.0, 10.0}};
  const SoilGeometry two({left, right}, {base_at(0.0), wall_at(0.0)});
  const SoilGeometry one = block_cut();
  const Soil soil{10.0e3, 20.0 * kPi / 180.0, 20.0e3};
  for (const Circle& c : {Circle{{24.0, 16.0}, 16.0}, Circle{{15.0, 14.0}, 8.0}, Circle{{30.0, 20.0}, 22.0}}) {
    const CircleResult a = evaluate_circle(one, soil, c, BishopOptions{});
    const CircleResult b = evaluate_circle(two, soil, c, BishopOptions{});
    EXPECT_EQ(a.rejection, b.rejection);
    if (a.valid()) {
      EXPECT_NEAR(a.factor, b.factor, 1e-12 * a.factor);
    }
  }
  EXPECT_DOUBLE_EQ(two.soil_above(10.0, 2.5), 7.5);
  EXPECT_DOUBLE_EQ(two.soil_above(5.0, -1.0), 10.0);
}

// A layered column: each body's length above the base times its own unit weight, the later
// body where two overlap; the base takes the soil of the body it lies in (the upper at a seam).
TEST(SoilGeometry, LayersWeighAndStrengthenByTheirOwnSoil) {
  Body lower, upper, lens;
  lower.outer = {{0.0, 0.0}, {20.0, 0.0}, {20.0, 4.0}, {0.0, 4.0}};
  lower.soil = Soil{10.0e3, 0.3, 20.0e3};
  upper.outer = {{0.0, 4.0}, {20.0, 4.0}, {20.0, 10.0}, {0.0, 10.0}};
  upper.soil = Soil{5.0e3, 0.1, 16.0e3};
  lens.outer = {{8.0, 6.0}, {12.0, 6.0}, {12.0, 7.0}, {8.0, 7.0}};  // inside `upper`, listed later
  lens.soil = Soil{1.0e3, 0.0, 22.0e3};
  const Soil fallback{99.0, 0.9, 1.0};
  const SoilGeometry g({lower, upper, lens}, {base_at(0.0)});
  EXPECT_TRUE(g.layered());
  EXPECT_DOUBLE_EQ(g.weight_above(5.0, 1.0, fallback), 3.0 * 20.0e3 + 6.0 * 16.0e3) << "no lens at x = 5";
  EXPECT_DOUBLE_EQ(g.weight_above(10.0, 1.0, fallback), 3.0 * 20.0e3 + 5.0 * 16.0e3 + 1.0 * 22.0e3);
  EXPECT_DOUBLE_EQ(g.weight_above(10.0, 6.5, fallback), 0.5 * 22.0e3 + 3.0 * 16.0e3);
  EXPECT_DOUBLE_EQ(g.soil_at({5.0, 2.0}, fallback).cohesion, 10.0e3);
  EXPECT_DOUBLE_EQ(g.soil_at({5.0, 4.0}, fallback).cohesion, 5.0e3);  // on the seam: the upper
  EXPECT_DOUBLE_EQ(g.soil_at({10.0, 6.5}, fallback).cohesion, 1.0e3);
  EXPECT_DOUBLE_EQ(g.soil_at({30.0, 6.5}, fallback).cohesion, 99.0);  // outside: the fallback
  // Bodies without a soil of their own take the one given.
  Body plain = lower;
  plain.soil.reset();
  const SoilGeometry h({plain}, {});
  EXPECT_FALSE(h.layered());
  EXPECT_DOUBLE_EQ(h.weight_above(5.0, 1.0, fallback), 3.0);
}

// A weak layer in the block cut: slices whose bases lie in it take its c and phi, all slices
// weigh the layer with its own unit weight. Checked against eq. (9.2) summed over the returned
// slices with the soils set by hand, and against the homogeneous cut (a weaker layer with the
// same weight lowers F; the same soil in both bodies gives the homogeneous F).
TEST(Bishop, ALayerSetsTheStrengthOfTheBasesInIt) {
  const Soil soil{10.0e3, 20.0 * kPi / 180.0, 20.0e3};
  const Soil weak{4.0e3, 10.0 * kPi / 180.0, 20.0e3};
  const Circle circle{{24.0, 16.0}, 16.0};
  Body below, layer, above;
  below.outer = {{0.0, 0.0}, {20.0, 0.0}, {20.0, 2.0}, {0.0, 2.0}};
  layer.outer = {{0.0, 2.0}, {20.0, 2.0}, {20.0, 4.0}, {0.0, 4.0}};
  above.outer = {{0.0, 4.0}, {20.0, 4.0}, {20.0, 10.0}, {0.0, 10.0}};
  below.soil = above.soil = soil;
  layer.soil = soil;
  const std::vector<RigidRegion> rigid{base_at(0.0), wall_at(0.0)};
  BishopOptions o;
  o.tolerance = 1e-13;
  const CircleResult same = evaluate_circle(SoilGeometry({below, layer, above}, rigid), soil, circle, o);
  const CircleResult homogeneous = evaluate_circle(block_cut(), soil, circle, o);
  ASSERT_TRUE(same.valid() && homogeneous.valid());
  EXPECT_NEAR(same.factor, homogeneous.factor, 1e-12);
  layer.soil = weak;
  const CircleResult r = evaluate_circle(SoilGeometry({below, layer, above}, rigid), soil, circle, o, true);
  ASSERT_TRUE(r.valid()) << rejection_name(r.rejection);
  EXPECT_LT(r.factor, homogeneous.factor - 0.02);
  std::size_t in_layer = 0;
  double resisting = 0.0, driving = 0.0;
  for (const Slice& s : r.slices) {
    const bool weak_base = s.base_y >= 2.0 && s.base_y < 4.0;
    in_layer += weak_base ? 1 : 0;
    const Soil& at = weak_base ? weak : soil;
    EXPECT_DOUBLE_EQ(s.cohesion, at.cohesion) << s.x;
    EXPECT_NEAR(s.weight, 20.0e3 * s.width * s.height, 1e-6 * s.weight);
    const double t = std::tan(at.friction_angle);
    resisting += (at.cohesion * s.width + s.weight * t) / (std::cos(s.alpha) + std::sin(s.alpha) * t / r.factor);
    driving += s.weight * std::sin(s.alpha);
  }
  EXPECT_GT(in_layer, 3u);
  EXPECT_NEAR(resisting / driving, r.factor, 1e-9 * r.factor);
}

TEST(SoilGeometry, SectionsSkipHoles) {
  Body b;
  b.outer = {{0.0, 0.0}, {10.0, 0.0}, {10.0, 10.0}, {0.0, 10.0}};
  b.holes = {{{4.0, 4.0}, {6.0, 4.0}, {6.0, 7.0}, {4.0, 7.0}}};
  const SoilGeometry g({b}, {});
  EXPECT_DOUBLE_EQ(g.soil_above(5.0, 1.0), 6.0);  // 9 m minus the 3 m hole
  EXPECT_DOUBLE_EQ(g.soil_above(5.0, 5.0), 3.0);
  EXPECT_DOUBLE_EQ(g.soil_above(2.0, 5.0), 5.0);
  EXPECT_FALSE(g.contains({5.0, 5.0}));
  EXPECT_TRUE(g.contains({5.0, 8.0}));
}

// The admissible circles: not through a rigid region, not re-entering, not missing the soil,
// the lower half only.
TEST(Bishop, InadmissibleCirclesAreRejected) {
  const Soil soil{10.0e3, 20.0 * kPi / 180.0, 20.0e3};
  const SoilGeometry g = block_cut();
  EXPECT_EQ(evaluate_circle(g, soil, {{24.0, 16.0}, 17.0}, {}).rejection, Rejection::rigid);  // below the toe
  EXPECT_EQ(evaluate_circle(g, soil, {{10.0, 30.0}, 5.0}, {}).rejection, Rejection::no_soil);
  EXPECT_EQ(evaluate_circle(g, soil, {{10.0, 8.0}, 3.0}, {}).rejection, Rejection::extends_above);
  EXPECT_EQ(evaluate_circle(g, soil, {{-3.0, 14.0}, 6.0}, {}).rejection, Rejection::rigid);  // through the rollers
  // A notch in the crest: the circle leaves the soil and enters it again.
  Body notched;
  notched.outer = {{0.0, 0.0}, {20.0, 0.0}, {20.0, 10.0}, {12.0, 10.0}, {11.0, 7.0}, {10.0, 10.0}, {0.0, 10.0}};
  const SoilGeometry gn({notched}, {base_at(0.0), wall_at(0.0)});
  EXPECT_EQ(evaluate_circle(gn, soil, {{11.0, 20.0}, 12.5}, {}).rejection, Rejection::not_two_crossings);
}

// A circle through a vertex: centre (5, 25), R = sqrt(450) meets the 2:1 face y = x/2 at x = 8
// and at the crest corner (20, 10) (1.25 x^2 - 35 x + 200 = 0), and the crest nowhere else; at
// the toe wedge (0, 0) the vertex is found by either edge too.
TEST(SoilGeometry, CrossingsAtVerticesAreFoundOnce) {
  Body b;
  b.outer = {{0.0, 0.0}, {40.0, 0.0}, {40.0, 10.0}, {20.0, 10.0}};
  const SoilGeometry g({b}, {base_at(0.0), wall_at(40.0)});
  const auto x = g.lower_crossings({5.0, 25.0}, std::sqrt(450.0));
  ASSERT_EQ(x.size(), 2u);
  EXPECT_NEAR(x[0].p.x, 8.0, 1e-9);
  EXPECT_NEAR(x[0].p.y, 4.0, 1e-9);
  EXPECT_NEAR(x[1].p.x, 20.0, 1e-9);
  EXPECT_NEAR(x[1].p.y, 10.0, 1e-9);
  const CircleResult r = evaluate_circle(g, {10.0e3, 0.3, 20.0e3}, {{5.0, 25.0}, std::sqrt(450.0)}, {});
  EXPECT_TRUE(r.valid()) << rejection_name(r.rejection);
  // Centre (-2, 20) through the toe (0, 0): the toe is found, and it is on the rigid base.
  const auto t = g.lower_crossings({-2.0, 20.0}, std::sqrt(404.0));
  ASSERT_FALSE(t.empty());
  EXPECT_NEAR(t[0].p.x, 0.0, 1e-9);
  EXPECT_NEAR(t[0].p.y, 0.0, 1e-9);
  EXPECT_TRUE(t[0].rigid);
}

// The m_alpha safeguard, eq. (9.6): a toe slice with alpha = -70 deg and phi = 40 deg has
// m_alpha = 0.342 - 0.789/F, below 0.2 for F < 5.6 (here F = 2.4); it is raised to 0.2 and counted.
TEST(Bishop, MAlphaFloorOnTheToeSide) {
  const Soil soil{5.0e3, 40.0 * kPi / 180.0, 20.0e3};
  std::vector<Slice> s(3);
  const double alphas[] = {50.0, 20.0, -70.0};
  for (std::size_t i = 0; i < 3; ++i) {
    s[i].width = 1.0;
    s[i].weight = i == 2 ? 5.0e3 : 60.0e3;
    s[i].alpha = alphas[i] * kPi / 180.0;
    s[i].base_length = 1.0 / std::cos(s[i].alpha);
  }
  BishopOptions o;
  o.tolerance = 1e-13;
  int iterations = 0;
  std::size_t limited = 0;
  const auto F = bishop_factor(s, soil, o, &iterations, &limited);
  ASSERT_TRUE(F.has_value());
  EXPECT_EQ(limited, 1u);
  EXPECT_TRUE(s[2].m_alpha_limited);
  EXPECT_DOUBLE_EQ(s[2].m_alpha, 0.2);
  EXPECT_LT(std::cos(s[2].alpha) + std::sin(s[2].alpha) * std::tan(soil.friction_angle) / *F, 0.2);
  // F is the fixed point of eq. (9.2) with the floored m_alpha.
  double resisting = 0.0, driving = 0.0;
  for (const Slice& q : s) {
    const double m = q.m_alpha_limited ? 0.2 : std::cos(q.alpha) + std::sin(q.alpha) * std::tan(soil.friction_angle) / *F;
    resisting += (soil.cohesion * q.width + q.weight * std::tan(soil.friction_angle)) / m;
    driving += q.weight * std::sin(q.alpha);
  }
  EXPECT_NEAR(*F, resisting / driving, 1e-10 * *F);
  EXPECT_LT(iterations, 50);
}

}  // namespace
}  // namespace rktsph::lem
