// Polygon bodies through the case file and the schemes (docs/case-format.md "Polygon bodies",
// method-notes §3.9):
//   * a rectangle given as a polygon, with its boundary entries by edge, runs bit for bit as the
//     block with entries by plane (V1);
//   * the acceptance slope (cases/examples/slope_elastic_2d.toml): an elastic 2:1 slope at rest
//     under gravity, whose inclined face is traction-free by rotation to its geometric normal;
//     the residual |sigma . n| on the face, of the stress points' stress interpolated to the
//     face nodes, stays below 2 % of rho g H away from the crest and the toe;
//   * bad polygons and edge entries fail with the file, the line and the key.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string>

#include <fmt/format.h>

#include "../support/test_util.hpp"
#include "core/error.hpp"
#include "schemes/simulation.hpp"

namespace rktsph {
namespace {

constexpr const char* kPlate = R"(
[material]
model = "elastic"
E = 1.0e7
nu = 0.3
density = 2000.0

[body_force]
gravity = [0.0, -9.81]

[damping]
coefficient = 20.0

[time]
end = 0.05
cfl = 0.5
)";

TEST(PolygonCase, ARectangleWithEdgeEntriesRunsAsTheBlock) {
  const test::ThreadCount threads(1);
  test::TempDir dir;
  const std::string blocks = std::string(R"(
[geometry]
dimension = 2
spacing = 0.25
[[geometry.block]]
min = [0.0, 0.0]
max = [3.0, 1.5]
[[boundary]]
y = [0.0, 0.0]
velocity = { x = 0.0, y = 0.0 }
[[boundary]]
x = [0.0, 0.0]
velocity = { x = 0.0 }
[[boundary]]
y = [1.5, 1.5]
x = [2.0, 3.0]
stress = { yy = -2.0e4 }
)") + kPlate;
  // The same with the edges: 0 base, 3 left side, and the load on the top over x in [2, 3]
  // as its own edge (the top cut at x = 2 by a vertex).
  const std::string polygon = std::string(R"(
[geometry]
dimension = 2
spacing = 0.25
[[geometry.polygon]]
vertices = [[0.0, 0.0], [3.0, 0.0], [3.0, 1.5], [2.0, 1.5], [0.0, 1.5], [0.0, 0.0]]
[[boundary]]
polygon = 0
edge = 0
velocity = { x = 0.0, y = 0.0 }
[[boundary]]
polygon = 0
edge = 4
velocity = { x = 0.0 }
[[boundary]]
polygon = 0
edge = 2
stress = { yy = -2.0e4 }
)") + kPlate;
  Simulation<2> a(test::case_from_string<2>(dir, blocks, {}, "blocks.toml"));
  Simulation<2> b(test::case_from_string<2>(dir, polygon, {}, "polygon.toml"));
  ASSERT_EQ(a.nodes().size(), b.nodes().size());
  EXPECT_EQ(a.nodes().position, b.nodes().position);
  EXPECT_EQ(a.nodes().volume, b.nodes().volume);
  EXPECT_EQ(a.model().constraints.constrained(), b.model().constraints.constrained());
  EXPECT_TRUE(b.model().constraints.rotated().empty());
  while (a.time() < 0.05 - 1e-12) {
    a.step();
    b.step();
  }
  double largest = 0.0;
  for (std::size_t i = 0; i < static_cast<std::size_t>(a.nodes().size()); ++i) {
    for (const StressComponent c : {StressComponent::xx, StressComponent::yy, StressComponent::zz, StressComponent::xy})
      ASSERT_EQ(a.node_stress()(i, c), b.node_stress()(i, c)) << "node " << i;
    for (int d = 0; d < 2; ++d) ASSERT_EQ(a.node_velocity()(i, d), b.node_velocity()(i, d)) << "node " << i;
    largest = std::max(largest, std::abs(a.node_stress()(i, StressComponent::yy)));
  }
  EXPECT_GT(largest, 1.0e4);
}

// The acceptance slope: the residual on the inclined face away from its ends.
TEST(PolygonSlope, TheInclinedFaceIsTractionFreeAtRest) {
  const test::ThreadCount threads(2);
  const std::string path = std::string(RKTSPH_SOURCE_DIR) + "/cases/examples/slope_elastic_2d.toml";
  Simulation<2> sim(read_case<2>(load_case_document(path, {})));
  const StaggeredModel<2>& m = sim.model();
  ASSERT_FALSE(m.constraints.rotated().empty());
  double peak_kinetic = 0.0;
  while (sim.time() < sim.setup().end_time - 1e-9) {
    sim.step();
    if (sim.step_count() % 20 == 0) peak_kinetic = std::max(peak_kinetic, sim.energy().kinetic);
  }
  const double kinetic_ratio = sim.energy().kinetic / peak_kinetic;

  const double rho_g_h = 2000.0 * 9.81 * 10.0;
  const Vec<2> crest(20.0, 10.0), toe(0.0, 0.0);
  const Vec<2> n = Vec<2>(-1.0, 2.0).normalized();
  const double excluded = 2.0;  // m (4 spacings) from the crest and the toe
  const auto sp = sim.stress_point_stress();
  const auto node = sim.node_stress();
  double worst_node = 0.0, worst = 0.0, worst_all = 0.0, peak_speed = 0.0;
  int counted = 0;
  std::string csv = "s,x,y,excluded,node_residual,interp_residual,interp_stt\n";
  for (std::size_t b = 0; b < m.boundary.size(); ++b) {
    const auto& e = m.boundary.edges[b];
    if (e[0].edge != 3 || e[1].edge >= 0) continue;  // nodes inside the face only
    const Index i = m.boundary.node[b];
    const Vec<2> x = sim.nodes().position[static_cast<std::size_t>(i)];
    // The stress points' stress at the node by the corrected interpolation (the field step 2
    // differentiates), and the nodal stress (the condition itself).
    double s[3] = {0.0, 0.0, 0.0};  // xx, yy, xy
    const auto row = m.to_nodes.row(i);
    for (Index k = row.begin; k < row.end; ++k) {
      const double w = m.to_nodes.interp[static_cast<std::size_t>(k)];
      const Index src = m.to_nodes.source(row, k);
      s[0] += w * sp(src, StressComponent::xx);
      s[1] += w * sp(src, StressComponent::yy);
      s[2] += w * sp(src, StressComponent::xy);
    }
    const Vec<2> t_interp(s[0] * n[0] + s[2] * n[1], s[2] * n[0] + s[1] * n[1]);
    const Vec<2> t_node(node(i, StressComponent::xx) * n[0] + node(i, StressComponent::xy) * n[1],
                        node(i, StressComponent::xy) * n[0] + node(i, StressComponent::yy) * n[1]);
    const double stt = s[0] * n[1] * n[1] - 2.0 * s[2] * n[0] * n[1] + s[1] * n[0] * n[0];
    const bool out = (x - crest).norm() < excluded || (x - toe).norm() < excluded;
    const double r = t_interp.norm() / rho_g_h;
    worst_all = std::max(worst_all, r);
    if (!out) {
      worst = std::max(worst, r);
      worst_node = std::max(worst_node, t_node.norm() / rho_g_h);
      ++counted;
    }
    csv += fmt::format("{:.6g},{:.6g},{:.6g},{},{:.6e},{:.6e},{:.6e}\n", (x - toe).norm(), x[0], x[1], out ? 1 : 0,
                       t_node.norm() / rho_g_h, r, stt / rho_g_h);
  }
  Vec<2> peak_at = Vec<2>::Zero();
  for (Index i = 0; i < sim.nodes().size(); ++i) {
    const double speed = std::hypot(sim.node_velocity()(i, 0), sim.node_velocity()(i, 1));
    if (speed > peak_speed) {
      peak_speed = speed;
      peak_at = sim.nodes().position[static_cast<std::size_t>(i)];
    }
  }
  std::printf("slope face: %d nodes beyond %.1f m of the crest and the toe; |sigma.n| / (rho g H): nodal %.2e, "
              "stress points interpolated %.4f (%.4f with the ends); kinetic energy %.2e of its peak, peak speed "
              "%.2e m/s at (%.2f, %.2f), t = %.2f s\n",
              counted, excluded, worst_node, worst, worst_all, kinetic_ratio, peak_speed, peak_at[0], peak_at[1],
              sim.time());
  if (const char* dir = std::getenv("RKTSPH_SLOPE_OUT")) {
    std::filesystem::create_directories(dir);
    std::ofstream(std::string(dir) + "/slope_face.csv") << csv;
    std::string field = "x,y,sxx,syy,sxy,ux,uy\n";
    for (Index i = 0; i < sim.nodes().size(); ++i) {
      const auto& x = sim.nodes().position[static_cast<std::size_t>(i)];
      field += fmt::format("{:.6g},{:.6g},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e}\n", x[0], x[1],
                           node(i, StressComponent::xx), node(i, StressComponent::yy), node(i, StressComponent::xy),
                           sim.node_displacement()(i, 0), sim.node_displacement()(i, 1));
    }
    std::ofstream(std::string(dir) + "/slope_nodes.csv") << field;
  }
  EXPECT_GT(counted, 30);
  EXPECT_LT(worst_node, 1e-12);  // the condition at the nodes themselves
  EXPECT_LT(worst, 0.02);        // the acceptance criterion (issue 16)
  // At rest: the kinetic energy left is the scheme's steady nodal residue (method-notes §0.3
  // item 8; Case 4(a)'s block keeps 2.4e-3 of its peak at t = 2 s).
  EXPECT_LT(kinetic_ratio, 1e-3);
}

// A square turned by 30 degrees under a pressure p on its four (inclined) edges, ramped and
// damped: the static state is the uniform sigma = -p 1 in the plane, every edge loaded through
// the rotation of method-notes §3.7 with a prescribed traction (§3.9).
TEST(PolygonCase, ATurnedSquareUnderPressureReachesTheUniformStress) {
  const test::ThreadCount threads(1);
  test::TempDir dir;
  const double p = 1.0e4;
  std::string vertices;
  for (int k = 0; k < 4; ++k) {
    const double a = M_PI / 6.0 + 0.5 * M_PI * k;
    vertices += fmt::format("{}[{:.17g}, {:.17g}]", k == 0 ? "" : ", ", 2.0 + 1.5 * std::sqrt(2.0) * std::cos(a),
                            2.0 + 1.5 * std::sqrt(2.0) * std::sin(a));
  }
  std::string text = "[geometry]\ndimension = 2\nspacing = 0.25\n[[geometry.polygon]]\nvertices = [" + vertices + "]\n";
  for (int e = 0; e < 4; ++e)
    text += fmt::format("[[boundary]]\npolygon = 0\nedge = {}\ntraction = {{ n = {} }}\nfunction = \"ramp\"\n", e, -p);
  text += R"(
[material]
model = "elastic"
E = 1.0e7
nu = 0.3
density = 2000.0
[functions.ramp]
type = "ramp"
duration = 0.2
[damping]
coefficient = 30.0
[time]
end = 0.8
cfl = 0.5
)";
  Simulation<2> sim(test::case_from_string<2>(dir, text));
  ASSERT_EQ(sim.model().constraints.rotated().size(), sim.model().boundary.size());
  while (sim.time() < 0.8 - 1e-9) sim.step();
  double worst = 0.0, worst_sp = 0.0;
  for (Index i = 0; i < sim.nodes().size(); ++i) {
    worst = std::max({worst, std::abs(sim.node_stress()(i, StressComponent::xx) + p),
                      std::abs(sim.node_stress()(i, StressComponent::yy) + p),
                      std::abs(sim.node_stress()(i, StressComponent::xy))});
  }
  for (Index e = 0; e < sim.stress_points().size(); ++e) {
    worst_sp = std::max({worst_sp, std::abs(sim.stress_point_stress()(e, StressComponent::xx) + p),
                         std::abs(sim.stress_point_stress()(e, StressComponent::yy) + p),
                         std::abs(sim.stress_point_stress()(e, StressComponent::xy))});
  }
  std::printf("turned square under p: largest |sigma + p 1| / p: nodes %.2e, stress points %.2e (%ld steps)\n",
              worst / p, worst_sp / p, sim.step_count());
  EXPECT_LT(worst / p, 2e-3);  // measured 2.7e-4 (nodes), 8.9e-5 (stress points)
  EXPECT_LT(worst_sp / p, 2e-3);
}

// An entry by a hole's edge selects the nodes on that edge, its two vertices included.
TEST(PolygonCase, AHoleEdgeEntrySelectsTheNodesOnIt) {
  test::TempDir dir;
  const std::string text = std::string(R"(
[geometry]
dimension = 2
spacing = 0.25
[[geometry.polygon]]
vertices = [[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]]
holes = [[[1.0, 1.0], [1.3, 2.9], [3.1, 2.6], [2.7, 1.2]]]
[[boundary]]
polygon = 0
hole = 0
edge = 1
velocity = { x = 0.0, y = 0.0 }
)") + kPlate;
  Simulation<2> sim(test::case_from_string<2>(dir, text));
  const Vec<2> a(1.3, 2.9), b(3.1, 2.6);
  const Vec<2> t = (b - a).normalized();
  std::size_t selected = 0;
  for (const Index i : sim.model().constraints.constrained()) {
    bool fixed = false;
    for (Index k = sim.model().constraints.begin(i); k < sim.model().constraints.end(i); ++k)
      fixed = fixed || sim.model().constraints[k].component < 2;
    if (!fixed) continue;
    ++selected;
    const Vec<2> x = sim.nodes().position[static_cast<std::size_t>(i)] - a;
    EXPECT_NEAR(x[0] * t[1] - x[1] * t[0], 0.0, 1e-12);  // on the edge's line
    EXPECT_GE(x.dot(t), -1e-12);
    EXPECT_LE(x.dot(t), (b - a).norm() + 1e-12);
  }
  EXPECT_EQ(selected, static_cast<std::size_t>(std::ceil((b - a).norm() / 0.25)) + 1);
}

TEST(PolygonCase, BadPolygonsAndEdgesNameTheFileLineAndKey) {
  test::TempDir dir;
  auto error_of = [&](const std::string& geometry, const std::string& boundary = "") {
    const std::string text = "[geometry]\ndimension = 2\nspacing = 0.25\n" + geometry + boundary + kPlate;
    try {
      (void)test::case_from_string<2>(dir, text);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string square = "[[geometry.polygon]]\nvertices = [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]]\n";
  struct Bad {
    std::string geometry, boundary, key, reason;
  };
  const std::vector<Bad> bad{
      {"[[geometry.polygon]]\nvertices = [[0.0, 0.0], [2.0, 2.0], [2.0, 0.0], [0.0, 2.0]]\n", "",
       "geometry.polygon[0].vertices", "crosses itself"},
      {"[[geometry.polygon]]\nvertices = [[0.0, 0.0], [2.0, 0.0], [0.0, 0.0]]\n", "", "geometry.polygon[0].vertices",
       "open"},
      {"[[geometry.polygon]]\nvertices = [[0.0, 0.0], [0.0, 2.0], [2.0, 2.0], [2.0, 0.0]]\n", "",
       "geometry.polygon[0].vertices", "clockwise"},
      {square + "holes = [[[3.0, 1.0], [3.0, 1.5], [3.5, 1.5]]]\n", "", "geometry.polygon[0].holes", "outside"},
      {square + "holes = [[[1.0, 0.5], [1.0, 1.5], [2.5, 1.0]]]\n", "", "geometry.polygon[0].holes", "crosses"},
      {square, "[[boundary]]\npolygon = 0\nedge = 4\nvelocity = { x = 0.0 }\n", "boundary[0].edge", "no edge 4"},
      {square, "[[boundary]]\npolygon = 1\nedge = 0\nvelocity = { x = 0.0 }\n", "boundary[0].polygon", "no polygon 1"},
      {square, "[[boundary]]\npolygon = 0\nedge = 0\nx = [0.0, 1.0]\nvelocity = { x = 0.0 }\n", "boundary[0].x",
       "not both"},
      {"[[geometry.block]]\nmin = [0.0, 0.0]\nmax = [1.0, 1.0]\n", "[[boundary]]\nedge = 0\nvelocity = { x = 0.0 }\n",
       "boundary[0].edge", "no [[geometry.polygon]]"},
      {square + "[[geometry.block]]\nmin = [0.0, 0.0]\nmax = [1.0, 1.0]\n", "", "geometry.polygon[0]", "not both"},
      {square, "[[boundary]]\npolygon = 0\nhole = 0\nedge = 0\nvelocity = { x = 0.0 }\n", "boundary[0].hole",
       "no hole 0"},
      {square, "[[boundary]]\npolygon = 0\nedge = 1\ntraction = { n = -1.0 }\n", "boundary[0].traction",
       "normal to no axis"},
      {"[[geometry.block]]\nmin = [0.0, 0.0]\nmax = [1.0, 1.0]\n", "[[boundary]]\ny = [0.0, 0.0]\ntraction = { n = -1.0 }\n",
       "boundary[0].traction", "polygon edge"},
  };
  for (const Bad& b : bad) {
    const std::string e = error_of(b.geometry, b.boundary);
    EXPECT_NE(e.find("case.toml, line "), std::string::npos) << e;
    EXPECT_NE(e.find("'" + b.key + "'"), std::string::npos) << e;
    EXPECT_NE(e.find(b.reason), std::string::npos) << e;
  }
}

}  // namespace
}  // namespace rktsph
