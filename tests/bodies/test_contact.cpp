// Rigid bodies and the contact laws (method-notes §4.5) on small configurations, without a
// solver: the geometry (signed distance, normal, extent), Coulomb's stick/slip switch at the
// limit ratio, release under tension beyond the adhesion, the projection of a node that crossed
// a body, the laws' constraints with a moving body, and the reaction with tributary lengths.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "bodies/contact.hpp"
#include "bodies/rigid_body.hpp"

namespace rktsph {
namespace {

constexpr double kDx = 0.1;

BodySpec plane(const Vec<2>& point, const Vec<2>& normal, ContactLaw law) {
  BodySpec b;
  b.name = "plane";
  b.where = "test";
  b.shape = BodyShape::plane;
  b.points = {point};
  b.normal = normal;
  b.law = law;
  return b;
}

double unit_function(int, double) { return 1.0; }

// A few nodes with their velocity and stress (slots xx, yy, zz, xy), and the calls of one step.
struct Nodes {
  std::vector<Vec<2>> x;
  std::vector<double> v, s, u;
  std::vector<Vec<2>> stress_points;
  explicit Nodes(std::vector<Vec<2>> positions)
      : x(std::move(positions)), v(2 * x.size(), 0.0), s(4 * x.size(), 0.0), u(2 * x.size(), 0.0) {}
  FieldView<double, 2> vel() { return {v.data(), static_cast<Index>(x.size()), 2}; }
  FieldView<double, 4> str() { return {s.data(), static_cast<Index>(x.size()), 4}; }
  FieldView<double, 2> disp() { return {u.data(), static_cast<Index>(x.size()), 2}; }
  void begin(RigidContact& c, double t, double dt) {
    c.begin_step(t, dt, 0.0, x, ConstFieldView<double, 2>(v.data(), static_cast<Index>(x.size()), 2),
                 ConstFieldView<double, 4>(s.data(), static_cast<Index>(x.size()), 4));
  }
  void end(RigidContact& c, double dt) { c.end_step(dt, x, vel(), str(), disp(), stress_points); }
};

TEST(RigidBody, PlaneSegmentAndPolylineGaps) {
  const RigidBody base(plane(Vec<2>(0.0, 1.0), Vec<2>(0.0, 2.0), ContactLaw::rough));
  BodyGap g = base.gap(Vec<2>(3.0, 1.25), Vec<2>::Zero(), kDx);
  EXPECT_DOUBLE_EQ(g.g, 0.25);
  EXPECT_TRUE(g.within);
  EXPECT_DOUBLE_EQ(g.normal[1], 1.0);                      // normalised
  g = base.gap(Vec<2>(3.0, 1.25), Vec<2>(0.0, 0.5), kDx);  // the body moved up by 0.5
  EXPECT_DOUBLE_EQ(g.g, -0.25);

  // A footing from (1, 0) to (0, 0): soil on the left of a -> b, i.e. below, n = (0, -1).
  BodySpec s;
  s.shape = BodyShape::segment;
  s.points = {Vec<2>(1.0, 0.0), Vec<2>(0.0, 0.0)};
  const RigidBody footing(s);
  g = footing.gap(Vec<2>(0.25, -0.3), Vec<2>::Zero(), kDx);
  EXPECT_DOUBLE_EQ(g.g, 0.3);
  EXPECT_DOUBLE_EQ(g.normal[1], -1.0);
  EXPECT_DOUBLE_EQ(g.s, 0.75);
  EXPECT_TRUE(g.within);
  EXPECT_FALSE(footing.gap(Vec<2>(1.2, -0.3), Vec<2>::Zero(), kDx).within);  // past its edge
  EXPECT_FALSE(footing.gap(Vec<2>(0.5, 0.3), Vec<2>::Zero(), kDx).within);   // behind it, beyond the depth
  EXPECT_TRUE(footing.gap(Vec<2>(0.5, 0.05), Vec<2>::Zero(), kDx).within);   // behind it, crossed
  EXPECT_DOUBLE_EQ(footing.s_end(), 1.0);

  // A V-shaped valley: (0, 1) -> (1, 0) -> (2, 1), soil above; a point above the vertex belongs to
  // the nearer face.
  BodySpec p;
  p.shape = BodyShape::polyline;
  p.points = {Vec<2>(0.0, 1.0), Vec<2>(1.0, 0.0), Vec<2>(2.0, 1.0)};
  const RigidBody valley(p);
  g = valley.gap(Vec<2>(1.6, 1.0), Vec<2>::Zero(), kDx);
  const double r = std::sqrt(0.5);
  EXPECT_NEAR(g.g, 0.4 * r, 1e-12);  // to the face y = x - 1 (the other face is 1.6 r away)
  EXPECT_NEAR(g.normal[0], -r, 1e-15);
  EXPECT_NEAR(g.normal[1], r, 1e-15);
  EXPECT_NEAR(g.s, std::sqrt(2.0) + 1.6 * r, 1e-12);
}

// One node resting on a Coulomb base (n = (0, 1), t = (1, 0)) under sigma_yy = -100 Pa, with
// mu = 0.5 and adhesion 10 Pa: tau_max = 60 Pa. A trial shear just under it sticks (the node
// takes the body's velocity, the shear is the reaction); just over it slips (the shear is held
// at the limit, the tangential velocity is free); the slip goes on while the relative velocity
// keeps its sign and sticks again when it reverses.
TEST(Contact, CoulombStickSlipSwitchAtTheLimitRatio) {
  BodySpec spec = plane(Vec<2>(0.0, 0.0), Vec<2>(0.0, 1.0), ContactLaw::coulomb);
  spec.friction = 0.5;
  spec.adhesion = 10.0;
  for (const double ratio : {0.999, 1.001}) {
    RigidContact contact({spec}, 1, 0, kDx, unit_function);
    Nodes n({Vec<2>(0.0, 0.0)});
    n.s[1] = -100.0;
    n.begin(contact, 0.0, 1e-3);
    ASSERT_EQ(contact.in_contact()[0], 1);
    // Step 2 left a tangential velocity and a shear of ratio * tau_max.
    n.v[0] = 0.3;
    n.s[3] = ratio * 60.0;
    n.end(contact, 1e-3);
    if (ratio < 1.0) {
      EXPECT_EQ(contact.slip(0, 0), 0);
      EXPECT_EQ(n.v[0], 0.0);
      EXPECT_DOUBLE_EQ(n.s[3], ratio * 60.0);
    } else {
      EXPECT_EQ(contact.slip(0, 0), 1);
      EXPECT_EQ(n.v[0], 0.3);
      EXPECT_DOUBLE_EQ(n.s[3], 60.0);
      // The friction on the soil (-sigma_nt along t) opposes its slip: it dissipates.
      EXPECT_LT(-n.s[3] * n.v[0], 0.0);
    }
    EXPECT_DOUBLE_EQ(n.s[1], -100.0);  // the contact pressure is not touched
    EXPECT_EQ(n.v[1], 0.0);
  }
  // Slip continuing, then reversing.
  RigidContact contact({spec}, 1, 0, kDx, unit_function);
  Nodes n({Vec<2>(0.0, 0.0)});
  n.s[1] = -100.0;
  n.begin(contact, 0.0, 1e-3);
  n.v[0] = 0.3;
  n.s[3] = 80.0;
  n.end(contact, 1e-3);
  ASSERT_EQ(contact.slip(0, 0), 1);
  n.begin(contact, 1e-3, 1e-3);
  n.v[0] = 0.2;
  n.s[3] = 30.0;  // under the limit, but the node still slides forward: the slip goes on
  n.end(contact, 1e-3);
  EXPECT_EQ(contact.slip(0, 0), 1);
  EXPECT_DOUBLE_EQ(n.s[3], 60.0);
  EXPECT_EQ(n.v[0], 0.2);
  n.begin(contact, 2e-3, 1e-3);
  n.v[0] = -0.05;  // reversed: stick
  n.s[3] = 30.0;
  n.end(contact, 1e-3);
  EXPECT_EQ(contact.slip(0, 0), 0);
  EXPECT_EQ(n.v[0], 0.0);
  EXPECT_DOUBLE_EQ(n.s[3], 30.0);
  // A larger normal pressure raises the limit in proportion: mu |sigma_n| + a.
  n.begin(contact, 3e-3, 1e-3);
  n.s[1] = -300.0;
  n.s[3] = -159.0;  // under 0.5 * 300 + 10 = 160
  n.v[0] = -0.1;
  n.end(contact, 1e-3);
  EXPECT_EQ(contact.slip(0, 0), 0);
  n.begin(contact, 4e-3, 1e-3);
  n.s[3] = -161.0;
  n.v[0] = -0.1;
  n.end(contact, 1e-3);
  EXPECT_EQ(contact.slip(0, 0), -1);
  EXPECT_DOUBLE_EQ(n.s[3], -160.0);
}

// Separation: a contact under tension beyond the adhesion is released at the next selection,
// one under less tension is kept; a bonded contact holds any tension.
TEST(Contact, SeparationUnderTension) {
  struct Case {
    ContactLaw law;
    double adhesion, syy;
    bool kept;
  };
  for (const Case& k : {Case{ContactLaw::rough, 0.0, 1.0, false}, Case{ContactLaw::smooth, 0.0, 1.0, false},
                        Case{ContactLaw::coulomb, 5.0, 4.0, true}, Case{ContactLaw::coulomb, 5.0, 6.0, false},
                        Case{ContactLaw::rough, 5.0, 4.0, true}, Case{ContactLaw::bonded, 0.0, 1e6, true},
                        Case{ContactLaw::rough, 0.0, -1.0, true}}) {
    BodySpec spec = plane(Vec<2>(0.0, 0.0), Vec<2>(0.0, 1.0), k.law);
    spec.adhesion = k.adhesion;
    RigidContact contact({spec}, 1, 0, kDx, unit_function);
    Nodes n({Vec<2>(0.0, 0.0)});
    n.s[1] = -10.0;
    n.begin(contact, 0.0, 1e-3);
    ASSERT_EQ(contact.in_contact()[0], 1);
    n.s[1] = k.syy;
    n.end(contact, 1e-3);
    n.begin(contact, 1e-3, 1e-3);
    EXPECT_EQ(contact.in_contact()[0] != 0, k.kept) << "law " << static_cast<int>(k.law) << ", sigma_yy " << k.syy;
  }
  // A released node moving away does not join again, one at rest under no tension does.
  RigidContact contact({plane(Vec<2>(0.0, 0.0), Vec<2>(0.0, 1.0), ContactLaw::rough)}, 2, 0, kDx, unit_function);
  Nodes n({Vec<2>(0.0, 0.0), Vec<2>(1.0, 0.0)});
  n.v[1] = 0.1;  // node 0 leaves the base
  n.begin(contact, 0.0, 1e-3);
  EXPECT_EQ(contact.in_contact()[0], 0);
  EXPECT_EQ(contact.in_contact()[1], 1);
}

// A node that crosses a body it is not in contact with is put back on its surface, its closing
// velocity removed, and counted; a stress point likewise.
TEST(Contact, ProjectionOfACrossingNodeIsCounted) {
  BodySpec spec = plane(Vec<2>(0.0, 0.0), Vec<2>(0.0, 1.0), ContactLaw::smooth);
  RigidContact contact({spec}, 2, 1, kDx, unit_function);
  Nodes n({Vec<2>(0.0, 0.02), Vec<2>(0.5, 0.5)});
  n.stress_points = {Vec<2>(0.3, 0.01)};
  n.v[1] = -1.0;
  n.v[3] = -1.0;
  n.begin(contact, 0.0, 0.05);
  EXPECT_EQ(contact.in_contact()[0], 0);  // 0.2 dx away: not touching
  n.x[0][1] = -0.03;                      // the step moved it through the base
  n.u[1] = -0.05;
  n.x[1][1] = 0.45;
  n.stress_points[0][1] = -0.04;
  n.end(contact, 0.05);
  EXPECT_DOUBLE_EQ(n.x[0][1], 0.0);
  EXPECT_DOUBLE_EQ(n.u[1], -0.02);
  EXPECT_EQ(n.v[1], 0.0);   // the closing velocity removed
  EXPECT_EQ(n.v[3], -1.0);  // the other node untouched
  EXPECT_DOUBLE_EQ(n.stress_points[0][1], 0.0);
  EXPECT_EQ(contact.state()[0].node_projections, 1);
  EXPECT_EQ(contact.state()[0].stress_point_projections, 1);
  EXPECT_DOUBLE_EQ(contact.state()[0].min_gap, -0.03);
  // On the surface now, still closing: it joins at the next step.
  n.v[1] = -0.5;
  n.begin(contact, 0.05, 0.05);
  EXPECT_EQ(contact.in_contact()[0], 1);
}

// The laws' kinematics with a moving body: the normal motion is the body's for every law, the
// tangential one for rough and bonded; smooth frees it and zeroes the shear.
TEST(Contact, LawsFollowAMovingBody) {
  const double dt = 0.01;
  const Vec<2> body_v(0.2, -0.1);  // m/s
  for (const ContactLaw law : {ContactLaw::rough, ContactLaw::smooth, ContactLaw::bonded}) {
    // A plate on top of the soil: normal (0, -1) into the soil below it.
    BodySpec spec = plane(Vec<2>(0.0, 1.0), Vec<2>(0.0, -1.0), law);
    spec.velocity = {body_v[0], body_v[1]};
    RigidContact contact({spec}, 1, 0, kDx, unit_function);
    Nodes n({Vec<2>(0.4, 1.0)});
    n.s[1] = -50.0;
    n.s[3] = 7.0;
    n.begin(contact, 0.0, dt);
    ASSERT_EQ(contact.in_contact()[0], 1);
    // Step 2 moved the node with its own velocity (0.05, 0.03).
    n.v[0] = 0.05;
    n.v[1] = 0.03;
    n.x[0] += dt * Vec<2>(0.05, 0.03);
    n.u[0] += dt * 0.05;
    n.u[1] += dt * 0.03;
    n.end(contact, dt);
    EXPECT_NEAR(n.x[0][1], 1.0 + dt * body_v[1], 1e-15);  // on the plate
    EXPECT_DOUBLE_EQ(n.v[1], body_v[1]);
    EXPECT_NEAR(contact.state()[0].offset[1], dt * body_v[1], 1e-15);
    if (law == ContactLaw::smooth) {
      EXPECT_DOUBLE_EQ(n.v[0], 0.05);
      EXPECT_NEAR(n.x[0][0], 0.4 + dt * 0.05, 1e-15);
      EXPECT_NEAR(n.s[3], 0.0, 1e-15);
    } else {
      EXPECT_DOUBLE_EQ(n.v[0], body_v[0]);
      EXPECT_NEAR(n.x[0][0], 0.4 + dt * body_v[0], 1e-15);
      EXPECT_DOUBLE_EQ(n.s[3], 7.0);
    }
    EXPECT_DOUBLE_EQ(n.s[1], -50.0);
    EXPECT_NEAR(n.u[0], n.x[0][0] - 0.4, 1e-15);
    EXPECT_NEAR(n.u[1], n.x[0][1] - 1.0, 1e-15);
  }
}

// The reaction F = sum sigma n A with tributary lengths: a uniform pressure p over a row of
// nodes at spacing dx on a base plane gives p times the row's length (half a segment at each
// end, where the soil ends); on a footing segment whose edge falls between two nodes, the last
// node in contact carries up to the edge.
TEST(Contact, ReactionWithTributaryLengths) {
  const double p = 1.0e3;
  {
    RigidContact contact({plane(Vec<2>(0.0, 0.0), Vec<2>(0.0, 1.0), ContactLaw::smooth)}, 6, 0, kDx, unit_function);
    std::vector<Vec<2>> x;
    for (int k = 0; k <= 5; ++k) x.emplace_back(k * kDx, 0.0);
    Nodes n(x);
    for (int k = 0; k <= 5; ++k) {
      n.s[4 * static_cast<std::size_t>(k) + 1] = -p;
      n.v[2 * static_cast<std::size_t>(k)] = 0.01 * k;  // sliding freely: no power on the smooth base
    }
    contact.select_now(0.0, n.x, ConstFieldView<double, 2>(n.v.data(), 6, 2),
                       ConstFieldView<double, 4>(n.s.data(), 6, 4));
    EXPECT_NEAR(contact.state()[0].width, 5 * kDx, 1e-14);
    EXPECT_NEAR(contact.state()[0].force[1], -p * 5 * kDx, 1e-10);  // the soil pushes the base down
    EXPECT_NEAR(contact.state()[0].force[0], 0.0, 1e-12);
    EXPECT_EQ(contact.state()[0].contact_nodes, 6);
    EXPECT_NEAR(contact.power(), 0.0, 1e-12);
  }
  {
    // A footing from x = 0.27 to x = 0 on top of the soil (normal (0, -1)): nodes at 0, 0.1, 0.2
    // touch it, the one at 0.3 is past its edge.
    BodySpec s;
    s.name = "footing";
    s.shape = BodyShape::segment;
    s.points = {Vec<2>(0.27, 1.0), Vec<2>(0.0, 1.0)};
    s.law = ContactLaw::rough;
    s.velocity = {0.0, -0.01};
    RigidContact contact({s}, 4, 0, kDx, unit_function);
    Nodes n({Vec<2>(0.0, 1.0), Vec<2>(0.1, 1.0), Vec<2>(0.2, 1.0), Vec<2>(0.3, 1.0)});
    for (std::size_t k = 0; k < 4; ++k) {
      n.s[4 * k + 1] = -p;
      n.v[2 * k + 1] = -0.01;
    }
    contact.select_now(0.0, n.x, ConstFieldView<double, 2>(n.v.data(), 4, 2),
                       ConstFieldView<double, 4>(n.s.data(), 4, 4));
    EXPECT_EQ(contact.state()[0].contact_nodes, 3);
    // Along the footing (s from x = 0.27): the node at x = 0.2 carries 0.05 inwards and the 0.07
    // to the edge; the one at x = 0 sits on the other end, with nothing beyond.
    EXPECT_NEAR(contact.state()[0].width, 0.27, 1e-14);
    EXPECT_NEAR(contact.state()[0].force[1], p * 0.27, 1e-10);  // upward on the footing
    // The footing pushes the soil down at 0.01 m/s: its power on the soil is F_y * 0.01.
    EXPECT_NEAR(contact.power(), p * 0.27 * 0.01, 1e-12);
  }
}

// An odd-even mode in the nodal stress of a row of contact nodes (sigma_yy = -p (1 + a (-1)^k),
// as under a footing in V2) must neither bias the reaction nor release nodes inside the
// compressed patch: the half-spacing sum cancels the mode, an end length carries the mean of
// the patch's last two nodes, and a release is decided on the 1-2-1 mean of sigma_nn along the
// patch. A patch ending between dx and 2 dx short of the footing's edge reaches the edge only
// where the soil goes on past it (docs/VALIDATION.md Case 12).
TEST(Contact, OddEvenNodalStressNeitherBiasesNorReleasesAFooting) {
  const double p = 1.0e3, a = 0.5;
  BodySpec s;
  s.name = "footing";
  s.shape = BodyShape::segment;
  s.points = {Vec<2>(0.85, 1.0), Vec<2>(0.0, 1.0)};  // soil below, edge at x = 0.85
  s.law = ContactLaw::smooth;
  s.release_on_patch_mean = true;
  auto row = [&](int last, bool beyond) {
    std::vector<Vec<2>> x;
    for (int k = 0; k <= last; ++k) x.emplace_back(k * kDx, 1.0);
    if (beyond) x.emplace_back(0.92, 1.0);  // past the edge: the soil goes on
    Nodes n(x);
    for (int k = 0; k <= last; ++k) n.s[4 * static_cast<std::size_t>(k) + 1] = -p * (1.0 + a * ((k % 2) ? -1.0 : 1.0));
    return n;
  };
  auto measure = [&](Nodes& n) {
    RigidContact contact({s}, n.x.size(), 0, kDx, unit_function);
    const auto nn = static_cast<Index>(n.x.size());
    contact.select_now(0.0, n.x, ConstFieldView<double, 2>(n.v.data(), nn, 2),
                       ConstFieldView<double, 4>(n.s.data(), nn, 4));
    return contact.state()[0];
  };
  {
    // Nodes 0 ... 0.8 touch it, the last 0.05 short of the edge: F = p * 0.85 (the node alone at
    // the end would have carried 0.05 * 1.5 p there, 3 % too much).
    Nodes n = row(8, false);
    const BodyState st = measure(n);
    EXPECT_EQ(st.contact_nodes, 9);
    EXPECT_NEAR(st.width, 0.85, 1e-14);
    EXPECT_NEAR(st.force[1], p * 0.85, 1e-9);
  }
  {
    // The last contact node 0.15 short of the edge (it slid inwards) with soil past the edge: the
    // patch reaches the edge; without soil there it ends at the node.
    Nodes n = row(7, true);
    BodyState st = measure(n);
    EXPECT_EQ(st.contact_nodes, 8);
    EXPECT_NEAR(st.width, 0.85, 1e-14);
    EXPECT_NEAR(st.force[1], p * 0.85, 1e-9);
    Nodes m = row(7, false);
    st = measure(m);
    EXPECT_NEAR(st.width, 0.7, 1e-14);
    EXPECT_NEAR(st.force[1], p * 0.7, 1e-9);
  }
  {
    // One node's sigma_yy of the mode turns tensile (+0.2 p between neighbours at -1.6 p): kept,
    // the patch is compressed; the whole row in tension: every node released.
    Nodes n = row(8, false);
    RigidContact contact({s}, n.x.size(), 0, kDx, unit_function);
    n.begin(contact, 0.0, 1e-3);
    for (std::size_t k = 0; k <= 8; ++k) ASSERT_EQ(contact.in_contact()[k], 1);
    for (std::size_t k = 0; k <= 8; ++k) n.s[4 * k + 1] = k % 2 ? 0.2 * p : -1.6 * p;
    n.end(contact, 1e-3);
    n.begin(contact, 1e-3, 1e-3);
    for (std::size_t k = 0; k <= 8; ++k) EXPECT_EQ(contact.in_contact()[k], 1) << "node " << k;
    for (std::size_t k = 0; k <= 8; ++k) n.s[4 * k + 1] = k % 2 ? 2.0 * p : 0.5 * p;
    n.end(contact, 1e-3);
    n.begin(contact, 2e-3, 1e-3);
    for (std::size_t k = 0; k <= 8; ++k) EXPECT_EQ(contact.in_contact()[k], 0) << "node " << k;
  }
}

// The reaction that drives a force-driven body is measured on the contact set's geometry of t^n,
// as the contact set was chosen: a node stuck at the body's edge that step 2 carried a hair past
// it stays in the sum. Before, the balance took the positions of step 2, dropped that node and
// gave its length to its neighbour's end length (the mean traction of the last two nodes), while
// the reaction reported after the step counted it: a rough footing held on the c-phi soil of
// strip_footing_cphi20_load_2d.toml (V2, B/10), whose edge node had relaxed to sigma_yy ~ 0,
// was balanced by 150 kN/m and reported 134.8, and the node's membership flipping with round-off
// kicked the footing into a growing vibration (docs/VALIDATION.md, "V2 with a rigid footing").
TEST(Contact, ABodysBalanceCountsTheNodesItsContactSetHolds) {
  const double p = 1.0e5, dt = 1e-4;
  BodySpec spec;
  spec.name = "footing";
  spec.shape = BodyShape::segment;
  spec.points = {Vec<2>(0.3, 1.0), Vec<2>(0.0, 1.0)};  // the soil below
  spec.law = ContactLaw::rough;
  spec.force_driven = {false, true};
  spec.force = {0.0, -p * 0.3};
  spec.mass = 1.0e3;
  RigidContact contact({spec}, 4, 0, kDx, unit_function);
  Nodes n({Vec<2>(0.0, 1.0), Vec<2>(0.1, 1.0), Vec<2>(0.2, 1.0), Vec<2>(0.3, 1.0)});
  for (std::size_t k = 0; k < 3; ++k) n.s[4 * k + 1] = -p;
  n.s[4 * 3 + 1] = 0.0;  // the edge node, relaxed
  n.begin(contact, 0.0, dt);
  ASSERT_EQ(contact.in_contact()[3], 1);
  n.x[3][0] += 1e-9;  // step 2 carries the edge node past the body's end
  const double v0 = contact.state()[0].velocity[1];
  n.end(contact, dt);
  // The body's acceleration follows the reaction it reports (the edge node's half length at 0).
  const double reported = contact.state()[0].force[1];
  EXPECT_NEAR(reported, p * 0.25, 1e-6 * p);
  EXPECT_NEAR((contact.state()[0].velocity[1] - v0) * spec.mass / dt, spec.force[1] + reported, 1e-6 * p);
}

// Load control: a force-driven body accelerates by (F_applied + F_reaction) / M.
TEST(Contact, ForceDrivenBodyFollowsItsForceBalance) {
  BodySpec spec = plane(Vec<2>(0.0, 1.0), Vec<2>(0.0, -1.0), ContactLaw::smooth);
  spec.force_driven = {false, true};
  spec.force = {0.0, -30.0};
  spec.mass = 2.0;
  RigidContact contact({spec}, 1, 0, kDx, unit_function);
  Nodes n({Vec<2>(0.0, -5.0)});  // far below it: no contact
  const double dt = 0.1;
  for (int k = 0; k < 10; ++k) {
    n.begin(contact, k * dt, dt);
    n.end(contact, dt);
  }
  // a = -15 m/s^2 from rest over 1 s: v = -15 m/s, u = -7.5 m (exact for a constant force).
  EXPECT_NEAR(contact.state()[0].velocity[1], -15.0, 1e-12);
  EXPECT_NEAR(contact.state()[0].offset[1], -7.5, 1e-12);
  EXPECT_EQ(contact.state()[0].velocity[0], 0.0);
}

}  // namespace
}  // namespace rktsph
