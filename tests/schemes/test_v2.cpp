// V2 (large deformation, schemes/v2_scheme.cpp): the Jaumann rate rotates a stress objectively
// under a rigid rotation; the operators rebuilt at moved, disordered positions reproduce linear
// fields exactly; a V2 run is bit for bit the same on one and two threads; the continuity
// equation keeps the mass.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <utility>

#include "../support/test_util.hpp"
#include "../support/v2_block.hpp"
#include "case/case_builder.hpp"
#include "core/error.hpp"
#include "io/state_archive.hpp"
#include "materials/perzyna_models.hpp"
#include "operators/corrected_operator.hpp"
#include "operators/corrected_row.hpp"
#include "schemes/motion.hpp"
#include "schemes/simulation.hpp"
#include "schemes/v2_stages.hpp"
#include "validation/analytic.hpp"

namespace rktsph {
namespace {

// A 2 m x 2 m block centred at the origin, V2, no boundary entries (free faces).
CaseBuilder<2> block(double density, double dx = 0.1) {
  CaseBuilder<2> b("v2 block");
  b.spacing(dx).origin(Vec<2>(-1.0, -1.0)).block(Vec<2>(-1.0, -1.0), Vec<2>(1.0, 1.0)).elastic(1.0e7, 0.3, density)
      .scheme("v2");
  return b;
}

// Rigid rotation at omega about the origin, the velocity reset to omega x x before every step: the
// stress of the interior nodes must be the initial one rotated by the angle turned, to round-off.
// A density of 1e20 kg/m^3 leaves the accelerations at 1e-20 of their size, so the particles
// follow the prescribed field and nothing but the Jaumann term changes the stress.
TEST(V2, AUniformStressRotatesObjectivelyOverAQuarterTurn) {
  const test::ThreadCount threads(1);
  const int steps = 400;  // a quarter turn in 1 s
  Simulation<2> sim(block(1.0e20).initial_stress({-1.0e4, -3.0e4, -2.0e4, 5.0e3, 0.0, 0.0}).time_step(1.0, 1.0 / steps).build());
  const test::RotationCheck r = test::spin_rigidly(sim, steps, 0.75);  // faces are traction-free
  ASSERT_NEAR(sim.time(), 1.0, 1e-12);
  ASSERT_GT(r.nodes, 100);
  // The hourglass control's mean-stress diffusion (method-notes eq. (2.6.3)) acts on the jump at
  // the traction-free faces (this held block is not in equilibrium there) at O(c dt) a step and
  // reaches the interior: 5.5e-9 of the stress measured (the simple scheme: round-off, 1e-11;
  // issue 49 asks 1e-6 of the invariants).
  EXPECT_LT(r.worst / 3.0e4, 1e-8) << "max stress error " << r.worst << " Pa";
  const std::vector<Index> at = sim.nodes_by_id();
  // The body turned: a corner node is where the rotation took it (to the first order of dt).
  EXPECT_NEAR(sim.nodes().position[static_cast<std::size_t>(at[0])][0], 1.0, 0.02);
  // solver.sort = "auto": a turning block keeps its neighbours near in memory, no sort.
  EXPECT_EQ(sim.reorders(), 0);
}

// A V2 flow disorders the particles; the operators rebuilt at their positions reproduce a linear
// field and its gradient at every stress point, to round-off.
TEST(V2, RebuiltOperatorsAreExactForLinearFieldsOnMovedParticles) {
  const test::ThreadCount threads(1);
  CaseSetup<2> stored = block(2000.0).time(0.05, 0.5).build();
  stored.operators_on_the_fly = false;  // the weights checked here are those the rebuild stores
  Simulation<2> sim(stored);
  std::mt19937 rng(3);
  std::normal_distribution<double> n01(0.0, 1.0);
  auto v = sim.mutable_node_velocity();
  for (std::size_t i = 0; i < sim.nodes().position.size(); ++i) {
    v(i, 0) = 2.0 * n01(rng);
    v(i, 1) = 2.0 * n01(rng);
  }
  for (int n = 0; n < 30; ++n) sim.step();
  // Disordered: the stress points are off the cell centres by a fair fraction of dx.
  double moved = 0.0;
  for (std::size_t e = 0; e < sim.stress_points().position.size(); ++e) {
    const auto& x = sim.stress_points().position[e];
    const double fx = x[0] / 0.1 - std::floor(x[0] / 0.1) - 0.5, fy = x[1] / 0.1 - std::floor(x[1] / 0.1) - 0.5;
    moved = std::max(moved, std::hypot(fx, fy));
  }
  EXPECT_GT(moved, 0.05);
  RebuildOperators<2> rebuild(sim.model());
  rebuild.run({});
  const auto& op = sim.model().to_stress_points;
  auto f = [](const Vec<2>& x) { return 3.0 + 2.0 * x[0] - 5.0 * x[1]; };
  double worst_value = 0.0, worst_grad = 0.0;
  for (Index e = 0; e < op.rows(); ++e) {
    const auto row = op.row(e);
    double value = 0.0, gx = 0.0, gy = 0.0;
    for (Index k = row.begin; k < row.end; ++k) {
      const double fk = f(sim.nodes().position[static_cast<std::size_t>(op.source(row, k))]);
      value += op.interp[static_cast<std::size_t>(k)] * fk;
      gx += op.grad[static_cast<std::size_t>(k)][0] * fk;
      gy += op.grad[static_cast<std::size_t>(k)][1] * fk;
    }
    worst_value = std::max(worst_value, std::abs(value - f(sim.stress_points().position[static_cast<std::size_t>(e)])));
    worst_grad = std::max({worst_grad, std::abs(gx - 2.0), std::abs(gy + 5.0)});
  }
  ASSERT_EQ(op.rows(), sim.stress_points().size());
  EXPECT_LT(worst_value, 1e-11);
  EXPECT_LT(worst_grad, 1e-9);
  EXPECT_EQ(op.degenerate_rows, 0);
  // The same rows evaluated on the fly (CorrectedRow::apply, as the default V2 step does) over
  // the rebuild's candidate lists, on two fields of two and one components.
  const MovingOperators<2>& mo = rebuild.moving_operators();
  auto g = [](const Vec<2>& x) { return -4.0 + 0.5 * x[0] + 7.0 * x[1]; };
  std::vector<double> two, one;
  for (const auto& x : sim.nodes().position) {
    two.insert(two.end(), {f(x), g(x)});
    one.push_back(g(x));
  }
  CorrectedRow<2> row;
  double fly_value = 0.0, fly_grad = 0.0;
  for (Index e = 0; e < op.rows(); ++e) {
    const auto& xe = sim.stress_points().position[static_cast<std::size_t>(e)];
    ASSERT_TRUE(row.evaluate(mo.nodes_near_stress_points->row(e), xe, sim.nodes().position.data(),
                             sim.nodes().volume.data(), sim.model().kernel, mo.r2));
    ASSERT_EQ(static_cast<Index>(row.size()), op.row(e).end - op.row(e).begin) << "the pairs of the stored row";
    double out2[3][2], out1[3][1];
    row.apply<2, 1>(two.data(), one.data(), out2, out1);
    fly_value =
        std::max({fly_value, std::abs(out2[0][0] - f(xe)), std::abs(out2[0][1] - g(xe)), std::abs(out1[0][0] - g(xe))});
    fly_grad = std::max({fly_grad, std::abs(out2[1][0] - 2.0), std::abs(out2[2][0] + 5.0), std::abs(out2[1][1] - 0.5),
                         std::abs(out2[2][1] - 7.0), std::abs(out1[1][0] - 0.5), std::abs(out1[2][0] - 7.0)});
  }
  EXPECT_LT(fly_value, 1e-11);
  EXPECT_LT(fly_grad, 1e-9);
}

// The Jaumann rotation's sine and cosine by their series below 0.1 rad (schemes/motion.hpp)
// agree with libm's within one unit in the last place (the series' truncation is far below
// it; what remains is rounding), and libm is used from 0.1 rad on.
TEST(V2, SinCosSeriesAgreesWithLibm) {
  auto ulps = [](double a, double b) { return std::abs(a - b) / (std::nextafter(std::abs(b), 2.0) - std::abs(b)); };
  double worst = 0.0;
  for (int k = -1000; k <= 1000; ++k) {
    if (k == 0) continue;
    const double theta = 0.1 * k / 1000.0 * (1.0 - 1e-12);
    double sn, c;
    sin_cos(theta, sn, c);
    worst = std::max({worst, ulps(sn, std::sin(theta)), ulps(c, std::cos(theta))});
  }
  std::printf("sin_cos series against libm below 0.1 rad: worst %.2f ulp\n", worst);
  EXPECT_LE(worst, 1.0);
  double sn, c;
  sin_cos(0.5, sn, c);
  EXPECT_EQ(sn, std::sin(0.5));
  EXPECT_EQ(c, std::cos(0.5));
}

// The default V2 step applies its operators on the fly (method-notes §5.2): M^{-1} sum w f in
// place of sum (M^{-1} w) f, the same sums in another order. A spinning, falling elasto-
// viscoplastic block on a fixed base, with its free surface detected, ends in the same state
// both ways to round-off, the history variables (interpolated with the value row alone) too.
// With the simple scheme's weight below 1 (eq. (2.3.2)) as well: the stored rows' kinds (corrected,
// regularised, degenerate) choose the update as the rows evaluated on the fly do; and with the
// stress points' share of the nodal stress (eq. (2.3.3)), whose interpolated stress both paths give;
// and with the nodal filters (the stress filter, eq. (2.3.4), and V1's velocity filter with the
// Taylor-Galerkin update), which on the fly apply the weights steps 1 and 2 kept as they went.
struct V2Variant {
  double weight = 1.0, stress_weight = 0.0, stress_filter = 0.0;
  StressFilterPart part = StressFilterPart::mean;
  bool taylor_galerkin = false;
};
class V2OnTheFly : public ::testing::TestWithParam<V2Variant> {};

TEST_P(V2OnTheFly, OperatorsOnTheFlyAgreeWithStoredOperators) {
  const test::ThreadCount threads(1);
  const V2Variant variant = GetParam();
  auto run = [variant](bool on_the_fly) {
    VonMisesParameters vm;
    vm.elastic = ElasticConstants::from_E_nu(1.0e7, 0.3, 2000.0);
    vm.yield_stress = 2.0e4;
    vm.hardening_modulus = -1.0e5;
    vm.residual_yield_stress = 1.0e4;
    vm.fluidity = 100.0;
    CaseBuilder<2> b("v2 block, von Mises");
    b.spacing(0.1)
        .origin(Vec<2>(-1.0, -1.0))
        .material(make_perzyna_von_mises(vm))
        .block(Vec<2>(-1.0, -1.0), Vec<2>(1.0, 1.0))
        .scheme("v2")
        .gravity(Vec<2>(0.0, -9.81))
        .fix_velocity(Region<2>::plane(1, -1.0), {0, 1})
        .free_surface(true)
        .initial_velocity(Vec<2>::Zero(), 1.0)
        .time(0.2, 0.5);
    CaseSetup<2> c = b.build();
    c.operators_on_the_fly = on_the_fly;
    c.simple_weight = variant.weight;
    c.simple_stress_weight = variant.stress_weight;
    c.stress_filter = variant.stress_filter;
    c.stress_filter_part = variant.part;
    if (variant.taylor_galerkin) {
      c.simple_velocity = false;
      c.filter = true;
    }
    auto sim = std::make_unique<Simulation<2>>(c);
    while (sim->time() < 0.2 - 1e-12) sim->step();
    return sim;
  };
  const auto fly = run(true), stored = run(false);
  EXPECT_EQ(fly->model().to_nodes.rows(), 0) << "nothing stored on the fly";
  EXPECT_EQ(stored->model().to_nodes.rows(), stored->nodes().size());
  EXPECT_EQ(fly->pairs(), stored->pairs()) << "the same pairs";
  const auto& mf = fly->model();
  const auto& ms = stored->model();
  ASSERT_EQ(mf.nodes.size(), ms.nodes.size());
  auto worst = [](auto a, auto b, int components, double scale) {
    double w = 0.0;
    for (Index i = 0; i < a.size(); ++i) {
      for (int k = 0; k < components; ++k) w = std::max(w, std::abs(a(i, k) - b(i, k)) / scale);
    }
    return w;
  };
  const double sigma_scale = 2.0e4, v_scale = 1.0;
  const auto sf = std::as_const(mf.nodes).view(mf.fields.stress), ss = std::as_const(ms.nodes).view(ms.fields.stress);
  const auto vf = std::as_const(mf.nodes).view(mf.fields.velocity),
             vs = std::as_const(ms.nodes).view(ms.fields.velocity);
  const auto kf = std::as_const(mf.nodes).view(mf.fields.history), ks = std::as_const(ms.nodes).view(ms.fields.history);
  double plastic = 0.0;
  for (Index i = 0; i < kf.size(); ++i) plastic = std::max(plastic, kf(i, 0));
  EXPECT_GT(plastic, 1e-4) << "the block yielded: the history was exercised";
  const double ds = worst(sf, ss, 4, sigma_scale), dv = worst(vf, vs, 2, v_scale),
               dk = worst(kf, ks, kf.components(), 1.0);
  double dx = 0.0;
  for (Index i = 0; i < mf.nodes.size(); ++i) {
    dx = std::max(
        dx, (mf.nodes.position[static_cast<std::size_t>(i)] - ms.nodes.position[static_cast<std::size_t>(i)]).norm());
  }
  std::printf("on the fly vs stored: |ds| %.2e of 2e4 Pa, |dv| %.2e m/s, |dk| %.2e (eps_vp up to %.2e), |dx| %.2e m\n",
              ds, dv, dk, plastic, dx);
  EXPECT_LT(ds, 1e-9);
  EXPECT_LT(dv, 1e-9);
  EXPECT_LT(dk, 1e-9);
  EXPECT_LT(dx, 1e-12);
}

INSTANTIATE_TEST_SUITE_P(Variants, V2OnTheFly,
                         ::testing::Values(V2Variant{}, V2Variant{.weight = 0.5}, V2Variant{.stress_weight = 0.2},
                                           V2Variant{.weight = 0.5, .stress_filter = 0.5},
                                           V2Variant{.stress_filter = 0.5, .part = StressFilterPart::full},
                                           V2Variant{.taylor_galerkin = true}));

// The Verlet lists (searched with a skin, kept while the particles move less than half of it)
// give the operators of a fresh search at the current positions, bit for bit.
TEST(V2, VerletListsGiveTheOperatorsOfAFreshSearch) {
  const test::ThreadCount threads(1);
  CaseSetup<2> stored = block(2000.0).initial_velocity(Vec<2>::Zero(), 2.0).time(0.1, 0.5).build();
  stored.operators_on_the_fly = false;  // compared weight by weight below
  Simulation<2> sim(stored);
  const auto* rebuild = sim.scheme().find<RebuildOperators<2>>();
  ASSERT_NE(rebuild, nullptr);
  for (int n = 0; n < 40; ++n) sim.step();
  EXPECT_GT(rebuild->relation_builds(), 1) << "the lists were searched again as the block turned";
  EXPECT_LT(rebuild->relation_builds(), 40) << "and not every step";
  // The scheme's own stage at the current positions (its lists searched some steps ago) against
  // a fresh search without a skin at the same positions.
  auto* stage = dynamic_cast<RebuildOperators<2>*>(sim.scheme().stages().front().get());
  ASSERT_NE(stage, nullptr);
  const long searches = stage->relation_builds();
  stage->run({});
  EXPECT_EQ(stage->relation_builds(), searches) << "the lists are still valid: no new search";
  StaggeredModel<2>& m = sim.model();
  Relation<2> fresh;
  fresh.build(m.stress_points.position, m.nodes.position, operator_relation_options(m.kernel));
  CorrectedOperator<2> exact;
  rebuild_corrected_operator<2>(fresh, m.stress_points.position, m.nodes, m.kernel, exact);
  EXPECT_EQ(m.to_stress_points.base, exact.base);
  EXPECT_EQ(m.to_stress_points.offset, exact.offset);
  EXPECT_EQ(m.to_stress_points.interp, exact.interp);
  EXPECT_EQ(m.to_stress_points.pattern_start, exact.pattern_start);
}

// A collapsing block under gravity on a fixed base (V2, 3721 nodes: the loops run threaded):
// one and two threads give the same bits, with and without the nodal stress filter (eq.
// (2.3.4), on the weights the steps keep on the fly); the mass of the continuity equation is kept.
TEST(V2, OneAndTwoThreadsGiveBitIdenticalResultsAndTheMassIsKept) {
  for (const double stress_filter : {0.0, 0.5}) {
    auto run = [stress_filter](int threads) {
      const test::ThreadCount guard(threads);
      CaseBuilder<2> b = block(2000.0, 2.0 / 60.0);
      b.gravity(Vec<2>(0.0, -9.81)).fix_velocity(Region<2>::plane(1, -1.0), {0, 1}).time(0.02, 0.5);
      CaseSetup<2> c = b.build();
      c.stress_filter = stress_filter;
      Simulation<2> sim(c);
      double m0 = 0.0;
      for (Index i = 0; i < sim.nodes().size(); ++i) m0 += sim.nodes().mass(i);
      for (int n = 0; n < 40; ++n) sim.step();
      double m = 0.0;
      for (Index i = 0; i < sim.nodes().size(); ++i) m += sim.nodes().mass(i);
      EXPECT_NEAR(m / m0, 1.0, 1e-13);
      std::vector<double> out = values_of(sim.model().nodes.view(sim.model().fields.stress));
      for (const auto& x : sim.nodes().position) out.insert(out.end(), {x[0], x[1]});
      for (double rho : sim.nodes().density) out.push_back(rho);
      return out;
    };
    const auto one = run(1), two = run(2);
    ASSERT_EQ(one.size(), two.size());
    EXPECT_EQ(std::memcmp(one.data(), two.data(), one.size() * sizeof(double)), 0) << "stress filter " << stress_filter;
  }
}

}  // namespace
}  // namespace rktsph

namespace rktsph {
namespace {

// Sorting the particles into Morton order (solver.sort, method-notes §3.8) changes where they
// are stored, not what they do: a spinning square with its free surface detected, run sorted
// and unsorted, ends with the same state particle by particle (by global id) to round-off.
// Case 7's pushed bar in 3D (docs/cases.md Case 7): a prism 10 m x 0.1 m x 0.1 m, dx = 0.05 m,
// rollers on its four long faces (uniaxial strain), pushed at v0 = 0.2 C0 at x = 0 and fixed at
// x = 10 m, run by V2 to 0.12 s. Its centre line must carry Case 7's exact shock (sigma = M ln
// lambda, lambda1 = 0.81008, S = 1.0531 C0) as the 1D bar does: the same acceptance (shock
// within 2 dx, plateau lambda and sigma within 2 %) and, point by point, the 1D run's profile.
TEST(V2, ALargeStrainBarIn3DCarriesTheExactShock) {
  const test::ThreadCount threads(2);
  const test::TempDir dir;
  const double M = 1.0e7, rho = 2000.0, c0 = std::sqrt(M / rho), v0 = 0.2 * c0, dx = 0.05, end = 0.12;
  const std::string materials = R"(
[material]
model = "elastic"
E = 1.0e7
nu = 0.0
density = 2000.0
[solver]
version = "v2"
velocity_update = "simple"
[time]
end = 0.12
cfl = 0.5
)";
  // The thesis's simple scheme: the point here is the 3D machinery against 1D and the exact shock;
  // V2's default (the hourglass control, method-notes §2.6) leaves a shock's front 2-3 dx behind
  // (Case 7's known deviation, eq. (2.6.4)).
  const std::string bar_3d = fmt::format(R"(
[geometry]
dimension = 3
spacing = {dx}
[[geometry.block]]
min = [0.0, 0.0, 0.0]
max = [10.0, 0.1, 0.1]
[[boundary]]
name = "piston"
x = [0.0, 0.0]
velocity = {{ x = {v0:.17g} }}
[[boundary]]
name = "fixed end"
x = [10.0, 10.0]
velocity = {{ x = 0.0 }}
[[boundary]]
y = [0.0, 0.0]
velocity = {{ y = 0.0 }}
[[boundary]]
y = [0.1, 0.1]
velocity = {{ y = 0.0 }}
[[boundary]]
z = [0.0, 0.0]
velocity = {{ z = 0.0 }}
[[boundary]]
z = [0.1, 0.1]
velocity = {{ z = 0.0 }}
)",
                                         fmt::arg("dx", dx), fmt::arg("v0", v0)) +
                             materials;
  const std::string bar_1d = fmt::format(R"(
[geometry]
dimension = 1
spacing = {dx}
[[geometry.block]]
min = [0.0]
max = [10.0]
[[boundary]]
name = "piston"
x = [0.0, 0.0]
velocity = {{ x = {v0:.17g} }}
[[boundary]]
name = "fixed end"
x = [10.0, 10.0]
velocity = {{ x = 0.0 }}
)",
                                         fmt::arg("dx", dx), fmt::arg("v0", v0)) +
                             materials;
  // The profile along the bar: X (initial x), x, sigma_xx of the nodes that `on_line` selects by
  // their initial position, in order of X.
  struct Line {
    std::vector<double> X, x, sigma;
  };
  auto line_of = [](const auto& sim, const auto& made, auto&& on_line) {
    std::vector<std::pair<double, std::size_t>> pick;
    const auto& nodes = sim.nodes();
    for (std::size_t i = 0; i < nodes.position.size(); ++i) {
      const auto& x0 = made[static_cast<std::size_t>(nodes.global_id[i])];
      if (on_line(x0)) pick.emplace_back(x0[0], i);
    }
    std::sort(pick.begin(), pick.end());
    Line l;
    for (const auto& [X, i] : pick) {
      l.X.push_back(X);
      l.x.push_back(nodes.position[i][0]);
      l.sigma.push_back(sim.node_stress()(i, StressComponent::xx));
    }
    return l;
  };
  Simulation<3> sim3(test::case_from_string<3>(dir, bar_3d));
  const std::vector<Vec<3>> made3 = sim3.nodes().position;
  while (sim3.time() < end - 1e-12) sim3.step();
  const Line l3 = line_of(sim3, made3,
                          [](const Vec<3>& p) { return std::abs(p[1] - 0.05) < 1e-9 && std::abs(p[2] - 0.05) < 1e-9; });
  Simulation<1> sim1(test::case_from_string<1>(dir, bar_1d));
  const std::vector<Vec<1>> made1 = sim1.nodes().position;
  while (sim1.time() < end - 1e-12) sim1.step();
  const Line l1 = line_of(sim1, made1, [](const Vec<1>&) { return true; });
  ASSERT_EQ(l3.X.size(), 201u);
  ASSERT_EQ(l1.X.size(), 201u);
  EXPECT_EQ(sim3.time(), sim1.time());

  const analytic::LargeStrainBar exact{M, rho, v0};
  const double lambda1 = exact.lambda_behind(), sigma1 = M * std::log(lambda1), shock = exact.shock_speed() * end;
  // The front: where sigma first rises above half the jump, from the piston.
  auto front = [&](const Line& l) {
    for (std::size_t k = 0; k + 1 < l.X.size(); ++k) {
      const double a = l.sigma[k] / sigma1, b = l.sigma[k + 1] / sigma1;
      if (a >= 0.5 && b < 0.5) return l.X[k] + (a - 0.5) / (a - b) * (l.X[k + 1] - l.X[k]);
    }
    return std::numeric_limits<double>::quiet_NaN();
  };
  // The plateau between 1 m and 1 m behind the shock: lambda by central differences, sigma.
  auto plateau = [&](const Line& l, double& lam, double& sig) {
    double sl = 0.0, ss = 0.0;
    int n = 0;
    for (std::size_t k = 1; k + 1 < l.X.size(); ++k) {
      if (l.X[k] < 1.0 || l.X[k] > shock - 1.0) continue;
      sl += (l.x[k + 1] - l.x[k - 1]) / (l.X[k + 1] - l.X[k - 1]);
      ss += l.sigma[k];
      ++n;
    }
    lam = sl / n;
    sig = ss / n;
  };
  double lam3 = 0.0, sig3 = 0.0, lam1 = 0.0, sig1 = 0.0;
  plateau(l3, lam3, sig3);
  plateau(l1, lam1, sig1);
  // The whole profile against the exact one: the mean |sigma - sigma_exact| along the bar over
  // the jump, the two end nodes left out (as by Case 7's density criterion), for both runs.
  auto l1_error = [&](const Line& l) {
    double sum = 0.0;
    for (std::size_t k = 1; k + 1 < l.X.size(); ++k) sum += std::abs(l.sigma[k] - exact.stress(l.X[k], end));
    return sum / static_cast<double>(l.X.size() - 2) / std::abs(sigma1);
  };
  std::printf(
      "3D bar at %.2f s: shock at %.4f m (exact %.4f, 1D %.4f), %.2f dx off; plateau lambda %.5f (exact %.5f, 1D "
      "%.5f), "
      "sigma %.4f MPa (exact %.4f, 1D %.4f); mean |sigma - exact| / jump %.4f (1D %.4f)\n",
      end, front(l3), shock, front(l1), std::abs(front(l3) - shock) / dx, lam3, lambda1, lam1, sig3 / 1e6, sigma1 / 1e6,
      sig1 / 1e6, l1_error(l3), l1_error(l1));
  EXPECT_LT(std::abs(front(l3) - shock), 2.0 * dx);
  EXPECT_LT(std::abs(lam3 / lambda1 - 1.0), 0.02);
  EXPECT_LT(std::abs(sig3 / sigma1 - 1.0), 0.02);
  EXPECT_LT(std::abs(front(l3) - front(l1)), 0.5 * dx);
  EXPECT_LT(l1_error(l3), 1.1 * l1_error(l1));
}

TEST(V2Sort, SortedAndUnsortedRunsAgreeParticleByParticle) {
  const test::ThreadCount threads(1);
  auto run = [](bool sort) {
    CaseBuilder<2> b = block(2000.0);
    b.free_surface(true).initial_velocity(Vec<2>::Zero(), 2.0).time(0.5, 0.5);
    CaseSetup<2> c = b.build();
    c.sort = sort ? SortSetting::always : SortSetting::off;
    auto sim = std::make_unique<Simulation<2>>(c);
    while (sim->time() < 0.5 - 1e-12) sim->step();
    return sim;
  };
  const auto sorted = run(true), plain = run(false);
  EXPECT_EQ(plain->reorders(), 0);
  EXPECT_GT(sorted->reorders(), 3);  // the corners move 0.8 spacings a step... several searches
  const auto* rebuild = sorted->scheme().find<RebuildOperators<2>>();
  ASSERT_NE(rebuild, nullptr);
  EXPECT_EQ(rebuild->sorts(), sorted->reorders());
  const std::vector<Index> a = sorted->nodes_by_id(), b = plain->nodes_by_id();
  ASSERT_EQ(a.size(), b.size());
  const auto va = sorted->node_velocity(), vb = plain->node_velocity();
  const auto sa = sorted->node_stress(), sb = plain->node_stress();
  const auto fa = sorted->nodes().find<double, 1>("free_surface"), fb = plain->nodes().find<double, 1>("free_surface");
  double dx = 0.0, dv = 0.0, ds = 0.0, vmax = 0.0, smax = 0.0;
  long flags_differ = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    const Index i = a[k], j = b[k];
    dx = std::max(dx, (sorted->nodes().position[static_cast<std::size_t>(i)] -
                       plain->nodes().position[static_cast<std::size_t>(j)])
                          .norm());
    dv = std::max(dv, (va.vec(i) - vb.vec(j)).norm());
    vmax = std::max(vmax, vb.vec(j).norm());
    for (const auto c : {StressComponent::xx, StressComponent::yy, StressComponent::xy}) {
      ds = std::max(ds, std::abs(sa(i, c) - sb(j, c)));
      smax = std::max(smax, std::abs(sb(j, c)));
    }
    flags_differ += sorted->nodes().view(fa)(i, 0) != plain->nodes().view(fb)(j, 0) ? 1 : 0;
  }
  std::printf("sorted vs unsorted after %ld sorts: |dx| %.2e m, |dv| %.2e of %.2e m/s, |ds| %.2e of %.2e Pa\n",
              sorted->reorders(), dx, dv, vmax, ds, smax);
  EXPECT_LT(dx, 1e-12);
  EXPECT_LT(dv, 1e-10 * vmax);
  EXPECT_LT(ds, 1e-8 * smax);
  EXPECT_EQ(flags_differ, 0);
  EXPECT_NEAR(sorted->total_mass(), plain->total_mass(), 1e-13 * plain->total_mass());
}

}  // namespace
}  // namespace rktsph

namespace rktsph {
namespace {

// StaggeredModel::reorder moves the tables it keeps by node index with their nodes: node k
// after the reordering has the constraints, boundary faces and source runs of node order[k]
// before it, and the constrained list stays ascending.
TEST(V2Sort, ReorderingMovesTheConstraintsAndFacesWithTheirNodes) {
  CaseBuilder<2> b = block(2000.0);
  b.time(0.01, 0.5)
      .fix_velocity(Region<2>::box(Vec<2>(-1.0, -1.0), Vec<2>(1.0, -0.95)), {1})
      .prescribe_velocity(Region<2>::box(Vec<2>(-1.0, -1.0), Vec<2>(-0.95, 1.0)), {{0, 0.25}});
  Simulation<2> sim(b.build());
  StaggeredModel<2>& m = sim.model();
  const Index n = m.nodes.size();
  const auto faces = m.boundary.dense_faces(n);
  std::vector<std::vector<std::pair<int, double>>> before(static_cast<std::size_t>(n));
  for (Index i = 0; i < n; ++i) {
    for (Index k = m.constraints.begin(i); k < m.constraints.end(i); ++k)
      before[static_cast<std::size_t>(i)].emplace_back(m.constraints[k].component, m.constraints[k].value);
  }
  ASSERT_GT(m.constraints.constrained().size(), 20u);
  Reordering r;
  r.nodes.resize(static_cast<std::size_t>(n));
  for (Index k = 0; k < n; ++k) r.nodes[static_cast<std::size_t>(k)] = (k * 8 + 3) % n;  // n = 441 = 3^2 7^2: 8 coprime
  sim.reorder(r);
  const auto faces_after = m.boundary.dense_faces(n);
  for (Index k = 0; k < n; ++k) {
    const auto old = static_cast<std::size_t>(r.nodes[static_cast<std::size_t>(k)]);
    std::vector<std::pair<int, double>> now;
    for (Index c = m.constraints.begin(k); c < m.constraints.end(k); ++c)
      now.emplace_back(m.constraints[c].component, m.constraints[c].value);
    ASSERT_EQ(now, before[old]) << "node " << k;
    ASSERT_EQ(faces_after[static_cast<std::size_t>(k)], faces[old]);
    ASSERT_EQ(m.nodes.global_id[static_cast<std::size_t>(k)], static_cast<std::int64_t>(old));
    if (!now.empty()) {
      ASSERT_EQ(m.constraints.constrained()[static_cast<std::size_t>(m.constraints.constrained_row(k))], k);
    }
  }
  EXPECT_TRUE(std::is_sorted(m.constraints.constrained().begin(), m.constraints.constrained().end()));
  EXPECT_EQ(sim.reorders(), 1);
  // The run goes on from the reordered state: the prescribed nodes move at their velocity.
  sim.step();
  const auto v = sim.node_velocity();
  for (Index k = 0; k < n; ++k) {
    const Vec<2>& x0 = m.nodes.position[static_cast<std::size_t>(k)] - sim.node_displacement().vec(k);
    if (x0[0] < -0.95) {
      EXPECT_DOUBLE_EQ(v(k, 0), 0.25) << k;
    }
  }
}

}  // namespace
}  // namespace rktsph

namespace rktsph {
namespace {

// solver.sort = "auto" (method-notes §3.8, "Storage order"): a lattice keeps the order it was
// made in (its rows beat Morton order), a set stored in no order (shuffled) is sorted at the
// first search, and the storage gap falls from about a third of the set to a few rows.
TEST(V2Sort, AutoSortsAShuffledSetAndKeepsALattice) {
  const test::ThreadCount threads(1);
  auto gap_after_first_step = [](bool shuffle, long& sorts) {
    CaseBuilder<2> b = block(2000.0);
    b.time(0.01, 0.5);
    Simulation<2> sim(b.build());
    if (shuffle) sim.reorder(shuffled_orders(sim.nodes().size(), sim.stress_points().size(), 3));
    sim.step();
    const auto* rebuild = sim.scheme().find<RebuildOperators<2>>();
    sorts = rebuild->sorts();
    for (const auto& [key, value] : rebuild->report()) {
      if (key == "storage_gap_last_search") return value;
    }
    return -1.0;
  };
  long sorts_lattice = -1, sorts_shuffled = -1;
  const double lattice = gap_after_first_step(false, sorts_lattice);
  const double shuffled = gap_after_first_step(true, sorts_shuffled);
  std::printf("storage gap after the first search: lattice %.1f (%ld sorts), shuffled %.1f (%ld sorts)\n", lattice,
              sorts_lattice, shuffled, sorts_shuffled);
  EXPECT_EQ(sorts_lattice, 0);
  EXPECT_EQ(sorts_shuffled, 1);
  EXPECT_GT(lattice, 0.0);
  EXPECT_LT(lattice, 30.0);   // a row of the 21 x 21 lattice and a bit
  EXPECT_LT(shuffled, 45.0);  // sorted: Morton's gap, against ~147 (a third of 441) shuffled
}

}  // namespace
}  // namespace rktsph

namespace rktsph {
namespace {

// Sorting is part of the step's arithmetic order: a run sorted at every search is bit for bit
// the same on one and two threads (the order depends on positions and ids only).
TEST(V2Sort, SortedRunIsBitIdenticalOnOneAndTwoThreads) {
  auto run = [](int threads) {
    const test::ThreadCount count(threads);
    CaseBuilder<2> b = block(2000.0);
    b.free_surface(true).initial_velocity(Vec<2>::Zero(), 2.0).time(0.2, 0.5);
    CaseSetup<2> c = b.build();
    c.sort = SortSetting::always;
    Simulation<2> sim(c);
    while (sim.time() < 0.2 - 1e-12) sim.step();
    const auto s = sim.node_stress();
    std::vector<double> state;
    for (std::size_t i = 0; i < sim.nodes().position.size(); ++i) {
      state.push_back(sim.nodes().position[i][0]);
      state.push_back(sim.nodes().position[i][1]);
      state.push_back(static_cast<double>(sim.nodes().global_id[i]));
      state.push_back(s(static_cast<Index>(i), StressComponent::xy));
    }
    return std::make_pair(state, sim.reorders());
  };
  const auto one = run(1), two = run(2);
  EXPECT_GT(one.second, 3);
  EXPECT_EQ(one.second, two.second);
  ASSERT_EQ(one.first.size(), two.first.size());
  EXPECT_EQ(0, std::memcmp(one.first.data(), two.first.data(), one.first.size() * sizeof(double)));
}

// A resume restores the checkpoint's storage order and the Verlet reference, so a run sorted at
// every search continues bit for bit (sorting at the same steps as the uninterrupted run).
TEST(V2Sort, ASortedRunResumesBitForBit) {
  const test::ThreadCount threads(1);
  CaseBuilder<2> b = block(2000.0);
  b.free_surface(true).initial_velocity(Vec<2>::Zero(), 2.0).time(0.2, 0.5);
  CaseSetup<2> c = b.build();
  c.sort = SortSetting::always;
  Simulation<2> straight(c);
  for (int k = 0; k < 300; ++k) straight.step();
  Simulation<2> first(c);
  for (int k = 0; k < 170; ++k) first.step();
  io::StateArchive archive;
  first.save_state(archive);
  Simulation<2> resumed(c);
  resumed.load_state(archive);
  EXPECT_EQ(resumed.nodes().global_id, first.nodes().global_id);
  for (int k = 170; k < 300; ++k) resumed.step();
  EXPECT_GT(first.reorders(), 3);
  EXPECT_GT(straight.reorders(), first.reorders());  // sorts after the checkpoint too
  EXPECT_EQ(resumed.nodes().global_id, straight.nodes().global_id);
  EXPECT_EQ(resumed.nodes().position, straight.nodes().position);
  for (Index i = 0; i < straight.nodes().size(); ++i) {
    ASSERT_EQ(resumed.node_velocity().vec(i), straight.node_velocity().vec(i)) << i;
  }
}

// A node that moves more than one particle spacing in a step (|v| > dx / dt = c / C, the step
// set by the wave speed) stops the run with a diagnosis naming the count, the limit and the
// fastest node, and under V2's simple scheme the likely remedy; a block translating at
// 0.9 of that speed runs, and so does one at twice it when the case fixes the step itself.
TEST(V2, ANodeOutrunningItsStepStopsTheRun) {
  auto run = [](double speed_over_limit, bool fixed_step, bool simple = false) {
    CaseBuilder<2> b = test::v2_block("v2 block translating");
    CaseSetup<2> probe = b.build();
    Simulation<2> reference(probe);
    const double limit = probe.dx / reference.dt();
    b.initial_velocity(Vec<2>(speed_over_limit * limit, 0.0));
    if (fixed_step) b.time_step(1.0, reference.dt());
    Simulation<2> sim(simple ? test::simple_scheme(b.build()) : b.build());
    for (int n = 0; n < 3; ++n) sim.step();
  };
  for (const bool simple : {false, true}) {
    try {
      run(2.0, false, simple);
      ADD_FAILURE() << "no error";
    } catch (const SolverError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("nodes moved more than one particle spacing"), std::string::npos) << m;
      EXPECT_NE(m.find("the run is unstable"), std::string::npos) << m;
      EXPECT_EQ(m.find("velocity_update = \"hourglass\" (the default)") != std::string::npos, simple) << m;
      EXPECT_NE(m.find("The fastest node is at"), std::string::npos) << m;
    }
  }
  EXPECT_NO_THROW(run(0.9, false));
  EXPECT_NO_THROW(run(2.0, true));
}

}  // namespace
}  // namespace rktsph
