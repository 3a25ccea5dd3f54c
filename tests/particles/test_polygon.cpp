// Polygon bodies (particles/polygon.hpp, method-notes §3.9): a rectangle and an L on the lattice
// give the blocks' particles, volumes and faces bit for bit; the volumes of a triangle, a
// trapezoid and a polygon with a hole sum to its area in each set; boundary nodes lie on the
// edges with outward unit normals and tributary lengths that sum to each edge's length; no two
// particles are closer than the stated rule; bad polygons are refused with the reason.
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

#include "core/error.hpp"
#include "particles/polygon.hpp"

namespace rktsph {
namespace {

PolygonBody body_of(Ring outer, std::vector<Ring> holes = {}) {
  PolygonBody b;
  b.outer = std::move(outer);
  b.holes = std::move(holes);
  b.label = "geometry.polygon[0]";
  return b;
}

double volume_sum(const ParticleSet<2>& s) { return std::accumulate(s.volume.begin(), s.volume.end(), 0.0); }

void expect_same_particles(const LatticeParticles<2>& a, const LatticeParticles<2>& b) {
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  EXPECT_EQ(a.nodes.position, b.nodes.position);
  EXPECT_EQ(a.nodes.volume, b.nodes.volume);
  EXPECT_EQ(a.nodes.density, b.nodes.density);
  EXPECT_EQ(a.nodes.material, b.nodes.material);
  ASSERT_EQ(a.stress_points.size(), b.stress_points.size());
  EXPECT_EQ(a.stress_points.position, b.stress_points.position);
  EXPECT_EQ(a.stress_points.volume, b.stress_points.volume);
  EXPECT_EQ(a.stress_points.density, b.stress_points.density);
  // The faces of every node (a polygon also lists its re-entrant corners, on no face).
  EXPECT_EQ(a.boundary.dense_faces(a.nodes.size()), b.boundary.dense_faces(b.nodes.size()));
  for (Index i = 0; i < a.nodes.size(); ++i) EXPECT_EQ(a.boundary.area_of(i), b.boundary.area_of(i)) << "node " << i;
}

TEST(Polygon, ARectangleOnTheLatticeIsTheBlock) {
  for (const double dx : {0.5, 0.1, 0.3}) {
    Block<2> blk;
    blk.min = Vec<2>(-0.9, 0.3);
    blk.max = Vec<2>(-0.9 + 12 * dx, 0.3 + 7 * dx);
    blk.label = "geometry.block[0]";
    const Vec<2> origin(-0.9, 0.3);
    const auto block = generate_lattice<2>({blk}, dx, origin, {1900.0});
    const auto poly = generate_polygon_particles(
        {body_of({blk.min, Vec<2>(blk.max[0], blk.min[1]), blk.max, Vec<2>(blk.min[0], blk.max[1])})}, dx, origin,
        {1900.0});
    SCOPED_TRACE(dx);
    expect_same_particles(block, poly);
    // Every boundary node's faces are normal to an axis.
    for (const FaceCondition f : poly.boundary.condition) EXPECT_EQ(f, FaceCondition::axes);
  }
}

TEST(Polygon, AnLOnTheLatticeIsItsTwoBlocks) {
  Block<2> a, b;
  a.min = Vec<2>(0, 0);
  a.max = Vec<2>(4, 2);
  b.min = Vec<2>(0, 2);
  b.max = Vec<2>(2, 4);
  const auto blocks = generate_lattice<2>({a, b}, 0.5, Vec<2>(0, 0), {2000.0});
  const auto poly = generate_polygon_particles(
      {body_of({Vec<2>(0, 0), Vec<2>(4, 0), Vec<2>(4, 2), Vec<2>(2, 2), Vec<2>(2, 4), Vec<2>(0, 4)})}, 0.5,
      Vec<2>(0, 0), {2000.0});
  expect_same_particles(blocks, poly);
}

// Layers: polygons touching along lattice lines are the blocks of their materials (a seam node
// takes the lattice's material and both densities' mass, and lies on no face), and a layered
// slope sums to its area with the face's normal where a seam meets it.
TEST(Polygon, LayersOnTheLatticeAreTheirBlocks) {
  Block<2> a, b, c;
  a.min = Vec<2>(0, 0);
  a.max = Vec<2>(4, 1.5);
  b.min = Vec<2>(0, 1.5);
  b.max = Vec<2>(4, 2.5);
  b.material = 1;
  c.min = Vec<2>(4, 0);
  c.max = Vec<2>(5, 2.5);
  c.material = 2;
  const std::vector<double> densities{2000.0, 1500.0, 2500.0};
  const auto blocks = generate_lattice<2>({a, b, c}, 0.5, Vec<2>(0, 0), densities);
  auto rect = [](const Block<2>& k) {
    PolygonBody p = body_of({k.min, Vec<2>(k.max[0], k.min[1]), k.max, Vec<2>(k.min[0], k.max[1])});
    p.material = k.material;
    return p;
  };
  const auto poly = generate_polygon_particles({rect(a), rect(b), rect(c)}, 0.5, Vec<2>(0, 0), densities);
  expect_same_particles(blocks, poly);
  EXPECT_EQ(blocks.stress_points.material, poly.stress_points.material);
}

TEST(Polygon, ALayeredSlopeSumsToItsAreaWithTheFaceNormalAtTheSeams) {
  // The 2:1 face y = x/2 from (0, 0) to (8, 4), a layer from y = 1 to 1.5 (lattice lines at 0.25).
  PolygonBody lower = body_of({Vec<2>(0, 0), Vec<2>(12, 0), Vec<2>(12, 1), Vec<2>(2, 1)});
  PolygonBody layer = body_of({Vec<2>(2, 1), Vec<2>(12, 1), Vec<2>(12, 1.5), Vec<2>(3, 1.5)});
  PolygonBody upper = body_of({Vec<2>(3, 1.5), Vec<2>(12, 1.5), Vec<2>(12, 4), Vec<2>(8, 4)});
  layer.material = 1;
  const double dx = 0.25;
  const auto d = generate_polygon_particles({lower, layer, upper}, dx, Vec<2>(0, 0), {2000.0, 1800.0});
  const double area = 12.0 * 4.0 - 0.5 * 8.0 * 4.0;
  EXPECT_NEAR(volume_sum(d.nodes), area, 1e-12 * area);
  EXPECT_NEAR(volume_sum(d.stress_points), area, 1e-12 * area);
  const Vec<2> n = Vec<2>(-1.0, 2.0).normalized();
  int seam_face_nodes = 0;
  for (std::size_t k = 0; k < d.boundary.size(); ++k) {
    const Vec<2> x = d.nodes.position[static_cast<std::size_t>(d.boundary.node[k])];
    // No boundary node inside the union: on a seam only where it meets the face or the side.
    if (std::abs(x[1] - 1.0) < 1e-12 || std::abs(x[1] - 1.5) < 1e-12) {
      EXPECT_TRUE(std::abs(x[1] - 0.5 * x[0]) < 1e-12 || std::abs(x[0] - 12.0) < 1e-12) << x.transpose();
      if (std::abs(x[0] - 12.0) < 1e-12) {
        EXPECT_EQ(d.boundary.faces[k], 0b0010);  // +x only
        EXPECT_NEAR(d.boundary.area[k][1], dx, 1e-12);
      } else {
        ++seam_face_nodes;
        EXPECT_EQ(d.boundary.condition[k], FaceCondition::normal);
        EXPECT_NEAR((d.boundary.normal[k] - n).norm(), 0.0, 1e-14);
      }
    }
  }
  EXPECT_EQ(seam_face_nodes, 2);
  // Nodes of the layer's material: its interior row and the seam y = 1.5 on it (a seam node
  // takes the body below, the lattice's rule).
  for (std::size_t i = 0; i < d.nodes.position.size(); ++i) {
    const Vec<2> x = d.nodes.position[i];
    if (x[0] > 4.0 && x[0] < 11.9) {
      const bool weak = x[1] > 1.01 && x[1] < 1.51;
      EXPECT_EQ(d.nodes.material[i], weak ? 1 : 0) << x.transpose();
    }
  }
}

// Checks that hold for any polygon: volumes, boundary nodes, normals, tributary lengths, spacing.
void check_discretisation(const PolygonBody& body, double dx) {
  const auto d = generate_polygon_particles({body}, dx, Vec<2>(0, 0), {2000.0});
  const double area = polygon_area(body);
  EXPECT_NEAR(volume_sum(d.nodes), area, 1e-12 * area);
  EXPECT_NEAR(volume_sum(d.stress_points), area, 1e-12 * area);
  for (const double v : d.nodes.volume) EXPECT_GT(v, 0.0);
  for (const double v : d.stress_points.volume) EXPECT_GE(v, kMergeFraction * dx * dx * 0.999);
  // Per edge: the tributary lengths of its nodes add up to its length; the nodes lie on it.
  std::vector<std::vector<double>> length(static_cast<std::size_t>(body.rings()));
  for (int r = 0; r < body.rings(); ++r) length[static_cast<std::size_t>(r)].assign(body.ring(r).size(), 0.0);
  ASSERT_TRUE(d.boundary.has_geometry());
  for (std::size_t b = 0; b < d.boundary.size(); ++b) {
    const Vec<2> x = d.nodes.position[static_cast<std::size_t>(d.boundary.node[b])];
    double axis_area = 0.0, axis_expected = 0.0;
    for (const double a : d.boundary.area[b]) axis_area += a;
    Vec<2> inclined_expected = Vec<2>::Zero();
    for (const EdgeRef& e : d.boundary.edges[b]) {
      if (e.edge < 0) continue;
      const Ring& ring = body.ring(e.ring);
      const Vec<2> p = ring[static_cast<std::size_t>(e.edge)];
      const Vec<2> q = ring[(static_cast<std::size_t>(e.edge) + 1) % ring.size()];
      const Vec<2> t = (q - p).normalized();
      const Vec<2> n(t[1], -t[0]);
      EXPECT_NEAR(std::abs((x - p)[0] * t[1] - (x - p)[1] * t[0]), 0.0, 1e-9 * dx) << "off its edge";
      // The share of this edge: half a piece at a vertex, a piece inside.
      const int pieces = static_cast<int>(std::ceil((q - p).norm() / dx - 1e-9));
      const bool vertex = (x - p).norm() < 1e-9 * dx || (x - q).norm() < 1e-9 * dx;
      const double share = (vertex ? 0.5 : 1.0) * (q - p).norm() / pieces;
      length[static_cast<std::size_t>(e.ring)][static_cast<std::size_t>(e.edge)] += share;
      if (n[0] == 0.0 || n[1] == 0.0) {
        axis_expected += share;
      } else {
        inclined_expected += share * n;
      }
    }
    EXPECT_NEAR((d.boundary.inclined[b] - inclined_expected).norm(), 0.0, 1e-12 * dx);
    // A re-entrant corner normal to the axes has no face (as a lattice); else the areas add up.
    if (d.boundary.condition[b] != FaceCondition::axes || d.boundary.faces[b] != 0) {
      EXPECT_NEAR(axis_area, axis_expected, 1e-12 * dx);
    }
    if (d.boundary.condition[b] == FaceCondition::normal) {
      EXPECT_NEAR(d.boundary.normal[b].norm(), 1.0, 1e-14);
      // Outward: a small step along the normal leaves the body, one against it stays inside.
      const Vec<2> n = d.boundary.normal[b];
      PolygonBody probe = body;
      EXPECT_FALSE(point_in_polygon(probe, x + 1e-3 * dx * n)) << x.transpose();
      EXPECT_TRUE(point_in_polygon(probe, x - 1e-3 * dx * n)) << x.transpose();
    }
  }
  for (int r = 0; r < body.rings(); ++r) {
    const Ring& ring = body.ring(r);
    for (std::size_t k = 0; k < ring.size(); ++k)
      EXPECT_NEAR(length[static_cast<std::size_t>(r)][k], (ring[(k + 1) % ring.size()] - ring[k]).norm(), 1e-12);
  }
  // The spacing rule within each set.
  for (const ParticleSet<2>* set : {&d.nodes, &d.stress_points}) {
    double closest = 1e300;
    for (std::size_t i = 0; i < set->position.size(); ++i)
      for (std::size_t j = i + 1; j < set->position.size(); ++j)
        closest = std::min(closest, (set->position[i] - set->position[j]).norm());
    EXPECT_GE(closest, kMinParticleDistance * dx);
    std::printf("%s: %zu particles, closest pair %.3f dx\n", set == &d.nodes ? "nodes" : "stress points",
                set->position.size(), closest / dx);
  }
  std::printf("area %.10g: node volumes %.3g, stress points %.3g off (relative)\n", area,
              volume_sum(d.nodes) / area - 1.0, volume_sum(d.stress_points) / area - 1.0);
}

TEST(Polygon, ATriangleTrapezoidAndHoledPolygonSumToTheirAreas) {
  {
    SCOPED_TRACE("triangle");
    check_discretisation(body_of({Vec<2>(0.1, 0.05), Vec<2>(3.17, 0.4), Vec<2>(0.9, 2.33)}), 0.2);
  }
  {
    SCOPED_TRACE("2:1 trapezoid (a slope)");
    check_discretisation(
        body_of({Vec<2>(0, 0), Vec<2>(8, 0), Vec<2>(8, 2), Vec<2>(5, 2), Vec<2>(1, 0.5), Vec<2>(0, 0.5)}), 0.25);
  }
  {
    SCOPED_TRACE("trapezoid");
    check_discretisation(body_of({Vec<2>(0.05, 0.0), Vec<2>(4.0, 0.0), Vec<2>(3.1, 1.7), Vec<2>(0.6, 1.7)}), 0.2);
  }
  {
    SCOPED_TRACE("square with a rotated square hole");
    const double c = std::cos(0.4), s = std::sin(0.4);
    Ring hole;
    for (int k = 0; k < 4; ++k) {
      const double a = -0.5 * M_PI * k;  // clockwise
      hole.emplace_back(2.0 + 0.8 * (c * std::cos(a) - s * std::sin(a)), 2.0 + 0.8 * (s * std::cos(a) + c * std::sin(a)));
    }
    check_discretisation(body_of({Vec<2>(0, 0), Vec<2>(4, 0), Vec<2>(4, 4), Vec<2>(0, 4)}, {hole}), 0.2);
  }
}

TEST(Polygon, InclinedFacesCarryTheGeometricNormal) {
  // A 2:1 slope face from the crest (6, 3) down to the toe (2, 1): outward normal (-1, 2)/sqrt(5).
  const Ring slope{Vec<2>(0, 0), Vec<2>(10, 0), Vec<2>(10, 3), Vec<2>(6, 3), Vec<2>(2, 1), Vec<2>(0, 1)};
  const auto d = generate_polygon_particles({body_of(slope)}, 0.25, Vec<2>(0, 0), {2000.0});
  const Vec<2> n = Vec<2>(-1.0, 2.0).normalized();
  int on_face = 0;
  for (std::size_t b = 0; b < d.boundary.size(); ++b) {
    const auto& e = d.boundary.edges[b];
    const bool face_only = e[0].edge == 3 && e[1].edge < 0;
    if (!face_only) continue;
    ++on_face;
    EXPECT_EQ(d.boundary.condition[b], FaceCondition::normal);
    EXPECT_NEAR((d.boundary.normal[b] - n).norm(), 0.0, 1e-14);
    EXPECT_EQ(d.boundary.faces[b], 0);
  }
  EXPECT_EQ(on_face, static_cast<int>(std::ceil(std::sqrt(20.0) / 0.25)) - 1);
  // The crest (6, 3) turns by atan(1/2) = 26.6 degrees: one face, the bisector's normal; the toe
  // (2, 1) likewise (re-entrant).
  for (std::size_t b = 0; b < d.boundary.size(); ++b) {
    const Vec<2> x = d.nodes.position[static_cast<std::size_t>(d.boundary.node[b])];
    if ((x - Vec<2>(6, 3)).norm() < 1e-12 || (x - Vec<2>(2, 1)).norm() < 1e-12) {
      EXPECT_EQ(d.boundary.condition[b], FaceCondition::normal);
      EXPECT_NEAR((d.boundary.normal[b] - (n + Vec<2>(0, 1)).normalized()).norm(), 0.0, 1e-14);
    }
    if ((x - Vec<2>(10, 3)).norm() < 1e-12) {
      EXPECT_EQ(d.boundary.faces[b], 0b1010);  // +x and +y, as a block
    }
  }
}

TEST(Polygon, BadPolygonsAreRefusedWithTheReason) {
  auto problem = [](Ring outer, std::vector<Ring> holes = {}) {
    const auto p = polygon_problem(body_of(std::move(outer), std::move(holes)));
    return p ? p->message : std::string();
  };
  EXPECT_EQ(problem({Vec<2>(0, 0), Vec<2>(1, 0), Vec<2>(1, 1), Vec<2>(0, 1)}), "");
  EXPECT_NE(problem({Vec<2>(0, 0), Vec<2>(1, 1), Vec<2>(1, 0), Vec<2>(0, 1)}).find("crosses itself"), std::string::npos);
  EXPECT_NE(problem({Vec<2>(0, 0), Vec<2>(0, 1), Vec<2>(1, 1), Vec<2>(1, 0)}).find("clockwise"), std::string::npos);
  EXPECT_NE(problem({Vec<2>(0, 0), Vec<2>(1, 0)}).find("open"), std::string::npos);
  EXPECT_NE(problem({Vec<2>(0, 0), Vec<2>(1, 0), Vec<2>(2, 0)}).find("no area"), std::string::npos);
  EXPECT_NE(problem({Vec<2>(0, 0), Vec<2>(1, 0), Vec<2>(1, 0), Vec<2>(0, 1)}).find("repeats"), std::string::npos);
  const Ring square{Vec<2>(0, 0), Vec<2>(4, 0), Vec<2>(4, 4), Vec<2>(0, 4)};
  const Ring inside_cw{Vec<2>(1, 1), Vec<2>(1, 2), Vec<2>(2, 2), Vec<2>(2, 1)};
  EXPECT_EQ(problem(square, {inside_cw}), "");
  EXPECT_NE(problem(square, {Ring{Vec<2>(1, 1), Vec<2>(2, 1), Vec<2>(2, 2), Vec<2>(1, 2)}}).find("counter-clockwise"),
            std::string::npos);
  EXPECT_NE(problem(square, {Ring{Vec<2>(5, 1), Vec<2>(5, 2), Vec<2>(6, 2), Vec<2>(6, 1)}}).find("outside"),
            std::string::npos);
  EXPECT_NE(problem(square, {Ring{Vec<2>(3, 1), Vec<2>(3, 2), Vec<2>(5, 2), Vec<2>(5, 1)}}).find("crosses the outer"),
            std::string::npos);
  // A vertex too sharp for the spacing: two nodes closer than the rule.
  EXPECT_THROW(generate_polygon_particles({body_of({Vec<2>(0, 0), Vec<2>(4, 0), Vec<2>(4, 0.3)})}, 0.25,
                                          Vec<2>(0, 0), {2000.0}),
               InputError);
}

}  // namespace
}  // namespace rktsph
