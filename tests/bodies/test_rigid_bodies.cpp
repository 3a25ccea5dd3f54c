// Rigid bodies in V2 (method-notes §4.5) on whole runs:
//   - a smooth plate compressing an elastic block between a smooth base and smooth (roller)
//     walls at a prescribed velocity: the reactions against the exact oedometric solution, the
//     plate's reaction against a section cut and against the power balance;
//   - a force-driven plate settling on the same block to the exact settlement;
//   - a rough footing pushed into a block: bit-identical on 1 and 2 threads;
//   - the [[body]] keys of the case file, their errors, and bodies.csv from the command line.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "../support/test_util.hpp"
#include "../support/v2_block.hpp"
#include "case/case_builder.hpp"
#include "core/error.hpp"
#include "schemes/simulation.hpp"
#include "schemes/v2_stages.hpp"

namespace rktsph {
namespace {

constexpr double kE = 1.0e7, kNu = 0.3, kRho = 2000.0;
const double kOedometric = kE * (1.0 - kNu) / ((1.0 + kNu) * (1.0 - 2.0 * kNu));  // lambda + 2G

BodySpec plane_body(const std::string& name, const Vec<2>& point, const Vec<2>& normal, ContactLaw law) {
  BodySpec b;
  b.name = name;
  b.where = "test";
  b.shape = BodyShape::plane;
  b.points = {point};
  b.normal = normal;
  b.law = law;
  return b;
}

int function_named(const CaseSetup<2>& c, const std::string& name) {
  for (std::size_t k = 0; k < c.function_names.size(); ++k) {
    if (c.function_names[k] == name) return static_cast<int>(k);
  }
  return -1;
}

const RigidContact& contact_of(const Simulation<2>& sim) {
  const auto* stage = sim.scheme().find<ContactEnforce>();
  if (stage == nullptr) throw std::runtime_error("no contact stage");
  return stage->contact();
}

// The unit block [0, 1]^2 at dx = 0.1 between a smooth base and smooth walls, with a smooth
// top plate; `plate` says how the plate moves.
// No damping: the velocity damping of the stress points' half step is a splitting error of
// order c_d dt against a kinematically driven boundary (the plate moves the contact nodes at V,
// the stress sees the damped velocities): 2.6 % low in sigma_yy here with c_d = 100 1/s,
// dt = 0.6 ms. The loads rise over about one period of the block's first mode instead, and the
// quasi-static values are the means over the last periods.
CaseSetup<2> oedometer(double end, const std::function<void(CaseBuilder<2>&)>& functions,
                       const std::function<void(CaseSetup<2>&, BodySpec&)>& plate) {
  CaseBuilder<2> b("oedometer with rigid bodies");
  b.spacing(0.1)
      .block(Vec<2>(0.0, 0.0), Vec<2>(1.0, 1.0))
      .elastic(kE, kNu, kRho)
      .scheme("v2")
      .free_surface(true)
      .time(end, 0.5);
  functions(b);
  CaseSetup<2> c = b.build();
  c.bodies.push_back(plane_body("base", Vec<2>(0.0, 0.0), Vec<2>(0.0, 1.0), ContactLaw::smooth));
  c.bodies.push_back(plane_body("left", Vec<2>(0.0, 0.0), Vec<2>(1.0, 0.0), ContactLaw::smooth));
  c.bodies.push_back(plane_body("right", Vec<2>(1.0, 0.0), Vec<2>(-1.0, 0.0), ContactLaw::smooth));
  BodySpec top = plane_body("plate", Vec<2>(0.0, 1.0), Vec<2>(0.0, -1.0), ContactLaw::smooth);
  plate(c, top);
  c.bodies.push_back(top);
  return c;
}

// The section cut y = y0 over the whole width: F = -sum sigma_yy V / dx over the stress points
// of the slab |y - y0| < dx/2 (method-notes §4.5, "Section cut"), compressive positive.
double section_cut(const Simulation<2>& sim, double y0, double dx) {
  const auto s = sim.stress_point_stress();
  const auto& x = sim.stress_points().position;
  double f = 0.0;
  for (std::size_t e = 0; e < x.size(); ++e) {
    if (std::abs(x[e][1] - y0) < 0.5 * dx) f -= s(e, StressComponent::yy) * sim.stress_points().volume[e] / dx;
  }
  return f;
}

// Means of a body's reaction, displacement and of a section cut over the steps from `from`.
struct Means {
  double force = 0.0, force_x_left = 0.0, force_x_right = 0.0, base = 0.0, settlement = 0.0, cut = 0.0;
  long samples = 0;
  double deepest_gap = 0.0;  // m: the most negative gap before a projection, over every step
};

Means run_and_average(Simulation<2>& sim, double end, double from) {
  Means m;
  while (sim.time() < end - 1e-12) {
    sim.step();
    for (const BodyState& b : contact_of(sim).state()) m.deepest_gap = std::min(m.deepest_gap, b.min_gap);
    if (sim.time() < from) continue;
    const auto& st = contact_of(sim).state();
    m.base += st[0].force[1];
    m.force_x_left += st[1].force[0];
    m.force_x_right += st[2].force[0];
    m.force += st[3].force[1];
    m.settlement -= st[3].offset[1];
    m.cut += section_cut(sim, 0.45, 0.1);
    ++m.samples;
  }
  const double n = static_cast<double>(m.samples);
  m.base /= n;
  m.force_x_left /= n;
  m.force_x_right /= n;
  m.force /= n;
  m.settlement /= n;
  m.cut /= n;
  return m;
}

// The oedometer with its plate pushed 1 mm in all (strain 1e-3): the velocity rises linearly
// over 0.05 s (about the period 4H/c = 0.049 s of the first mode, which a ramp of one period
// leaves almost unexcited), is held, and falls again by 0.3 s; `more` adds to the case.
CaseSetup<2> pushed_oedometer(double end, const std::function<void(CaseBuilder<2>&)>& more = {}) {
  const double v0 = 1.0e-3 / 0.25;
  return oedometer(
      end,
      [&](CaseBuilder<2>& b) {
        TimeFunction f;
        f.kind = TimeFunction::Kind::table;
        f.times = {0.0, 0.05, 0.25, 0.30};
        f.values = {0.0, 1.0, 1.0, 0.0};
        b.function("push", f);
        if (more) more(b);
      },
      [&](CaseSetup<2>& setup, BodySpec& top) {
        top.velocity = {0.0, -v0};
        top.velocity_function = {-1, function_named(setup, "push")};
      });
}

TEST(RigidBodies, SmoothPlateCompressesABlockToTheOedometricSolution) {
  const test::ThreadCount threads(1);
  // The plate pushed 1 mm (pushed_oedometer), then at rest.
  CaseSetup<2> c = pushed_oedometer(0.5);
  Simulation<2> sim(std::move(c));
  const Means mean = run_and_average(sim, 0.5, 0.35);
  const RigidContact& contact = contact_of(sim);
  const BodyState& base = contact.state()[0];
  const BodyState& plate = contact.state()[3];
  const double settlement = -plate.offset[1];
  EXPECT_NEAR(settlement, 1.0e-3, 1e-9);
  // The contact pressure profile (contact.csv) integrates to the plate's reaction: per body,
  // sum of the normal stress times the width along the normal, and the widths to the width.
  for (int b = 0; b < 4; ++b) {
    Vec<2> sum = Vec<2>::Zero();
    double width = 0.0;
    for (const ContactPoint& p : contact.profile()) {
      if (p.body != b) continue;
      sum += p.width * (p.normal_stress * p.normal + p.shear_stress * body_tangent(p.normal));
      width += p.width;
    }
    const BodyState& st = contact.state()[static_cast<std::size_t>(b)];
    EXPECT_NEAR(width, st.width, 1e-12) << "body " << b;
    EXPECT_NEAR((sum - st.force).norm(), 0.0, 1e-9 * std::max(1.0, st.force.norm())) << "body " << b;
  }
  const double exact = kOedometric * settlement / 1.0 * 1.0;  // N/m: M (delta / H) W
  const double plate_error = std::abs(mean.force - exact) / exact;
  const double base_error = std::abs(-mean.base - exact) / exact;
  // The walls carry sigma_xx = nu / (1 - nu) sigma_yy over the (compressed) height.
  const double wall_exact = kNu / (1.0 - kNu) * exact * (1.0 - settlement);
  const double wall_error =
      std::max(std::abs(-mean.force_x_left - wall_exact), std::abs(mean.force_x_right - wall_exact)) / wall_exact;
  const double cut_error = std::abs(mean.cut - mean.force) / exact;
  // The power balance: the work of the soil on the plate is minus the work the contacts did on
  // the soil (its energy account), which is the strain and kinetic energy; the elastic energy
  // of the compressed block is 1/2 F delta.
  const EnergyBalance e = sim.energy();
  const double work_error = std::abs(e.external_work + plate.work) / std::abs(plate.work);
  const double elastic = 0.5 * exact * settlement;
  const double energy_error = std::abs((e.strain - e.initial_strain + e.kinetic) - elastic) / elastic;
  const double imbalance = std::abs(e.imbalance()) / std::abs(e.external_work);
  std::fprintf(stderr,
               "oedometer: mean F = %.6g N/m (exact %.6g, error %.2e), base %.2e, walls %.2e, cut %.2e, "
               "work %.2e, energy %.2e, imbalance %.2e, contact nodes %ld/%ld, width %.4f, projections %ld\n",
               mean.force, exact, plate_error, base_error, wall_error, cut_error, work_error, energy_error, imbalance,
               plate.contact_nodes, base.contact_nodes, plate.width, plate.node_projections);
  EXPECT_LT(plate_error, 5e-3);
  EXPECT_LT(base_error, 5e-3);
  EXPECT_LT(wall_error, 1e-2);
  EXPECT_LT(cut_error, 5e-3);
  EXPECT_LT(work_error, 1e-3);
  EXPECT_LT(energy_error, 1e-2);
  EXPECT_LT(imbalance, 1e-2);
  EXPECT_EQ(plate.contact_nodes, 11);
  EXPECT_EQ(base.contact_nodes, 11);
  EXPECT_NEAR(plate.width, 1.0, 1e-9);
  // No node enters a body beyond round-off: the side walls' nodes slide along them, and V2's
  // hourglass control (method-notes §2.6) leaves their normal velocity at round-off rather than
  // exactly zero, so a few are put back by 1e-13 m (6 projections, deepest -5.3e-13 m).
  EXPECT_GT(mean.deepest_gap, -1e-9 * 0.1);
  // No node of the confined block is taken for free surface.
  const Field<double, 1> flags = sim.nodes().template find<double, 1>("free_surface");
  double flagged = 0.0;
  for (Index i = 0; i < sim.nodes().size(); ++i) flagged += sim.nodes().view(flags)(i, 0);
  EXPECT_EQ(flagged, 0.0);
}

// A node that a [[boundary]] entry selects keeps the traction-free rule of its lattice faces;
// where a rigid body presses one of them the contact makes that face's normal stress a reaction
// (StaggeredModel::released_by_contact, method-notes §4.5). The oedometer with its left wall a
// symmetry entry (v_x = 0 on x = 0) instead of a body: the corner node (0, 1) under the plate is
// selected by the entry, and must carry the plate's uniform sigma_yy like the nodes beside it
// (before the release it held 0 there, as the node on the axis under a footing did).
TEST(RigidBodies, ANodeAnEntrySelectsCarriesTheBodysPressure) {
  const test::ThreadCount threads(1);
  CaseSetup<2> c = pushed_oedometer(0.3, [](CaseBuilder<2>& b) { b.fix_velocity(Region<2>::plane(0, 0.0), {0}); });
  c.bodies.erase(c.bodies.begin() + 1);  // the left wall: the entry holds that face instead
  Simulation<2> sim(std::move(c));
  while (sim.time() < 0.3 - 1e-12) sim.step();
  const auto s = sim.node_stress();
  const auto& x = sim.nodes().position;
  auto syy_at = [&](double x0) {
    std::size_t best = 0;
    for (std::size_t i = 1; i < x.size(); ++i) {
      if ((x[i] - Vec<2>(x0, 1.0)).norm() < (x[best] - Vec<2>(x0, 1.0)).norm()) best = i;
    }
    return s(best, StressComponent::yy);
  };
  const double corner = syy_at(0.0), middle = syy_at(0.5);
  std::printf("sigma_yy under the plate at (0, 1) / (0.5, 1): %.1f / %.1f Pa (oedometric %.1f Pa)\n", corner, middle,
              -kOedometric * 1.0e-3);
  EXPECT_LT(middle, -0.8 * kOedometric * 1.0e-3);
  EXPECT_NEAR(corner / middle, 1.0, 0.1);
}

TEST(RigidBodies, ForceDrivenPlateSettlesToTheExactSettlement) {
  const test::ThreadCount threads(1);
  const double load = 1.3e4;  // N/m over the 1 m wide plate
  // The load rises linearly over 0.1 s, about two periods of the plate on the block.
  CaseSetup<2> c = oedometer(
      0.6, [&](CaseBuilder<2>& b) { b.function("load", TimeFunction::ramp(0.1)); },
      [&](CaseSetup<2>& setup, BodySpec& top) {
        top.force_driven = {false, true};
        top.force = {0.0, -load};
        top.force_function = {-1, function_named(setup, "load")};
        top.mass = 100.0;  // kg/m, a twentieth of the block
      });
  Simulation<2> sim(std::move(c));
  const Means mean = run_and_average(sim, 0.6, 0.2);
  const double exact = load * 1.0 / (1.0 * kOedometric);  // P H / (W M)
  const double error = std::abs(mean.settlement - exact) / exact;
  const double force_error = std::abs(mean.force - load) / load;
  const double cut_error = std::abs(mean.cut - load) / load;
  std::fprintf(stderr, "force-driven plate: mean settlement %.6g m (exact %.6g, error %.2e), reaction %.2e, cut %.2e\n",
               mean.settlement, exact, error, force_error, cut_error);
  EXPECT_LT(error, 5e-3);
  EXPECT_LT(force_error, 5e-3);
  EXPECT_LT(cut_error, 5e-3);
}

// A rough footing pushed into a block with a rough base and smooth walls.
CaseSetup<2> footing_case() {
  CaseBuilder<2> b("rough footing");
  b.spacing(0.1)
      .block(Vec<2>(0.0, 0.0), Vec<2>(2.0, 1.0))
      .elastic(kE, kNu, kRho)
      .scheme("v2")
      .free_surface(true)
      .time(0.04, 0.5);
  CaseSetup<2> c = b.build();
  c.bodies.push_back(plane_body("base", Vec<2>(0.0, 0.0), Vec<2>(0.0, 1.0), ContactLaw::rough));
  c.bodies.push_back(plane_body("axis", Vec<2>(0.0, 0.0), Vec<2>(1.0, 0.0), ContactLaw::smooth));
  BodySpec f;
  f.name = "footing";
  f.where = "test";
  f.shape = BodyShape::segment;
  f.points = {Vec<2>(0.55, 1.0), Vec<2>(0.0, 1.0)};
  f.law = ContactLaw::coulomb;
  f.friction = 0.3;
  f.velocity = {0.0, -0.05};
  c.bodies.push_back(f);
  return c;
}

TEST(RigidBodies, FootingRunIsBitIdenticalOnOneAndTwoThreads) {
  auto run = [](int n) {
    const test::ThreadCount threads(n);
    Simulation<2> sim(footing_case());
    while (sim.time() < 0.04 - 1e-12) sim.step();
    return std::make_pair(sim.nodes().position, contact_of(sim).state()[2].force);
  };
  const auto one = run(1);
  const auto two = run(2);
  ASSERT_EQ(one.first.size(), two.first.size());
  for (std::size_t i = 0; i < one.first.size(); ++i) {
    ASSERT_EQ(one.first[i][0], two.first[i][0]) << "node " << i;
    ASSERT_EQ(one.first[i][1], two.first[i][1]) << "node " << i;
  }
  EXPECT_EQ(one.second[0], two.second[0]);
  EXPECT_EQ(one.second[1], two.second[1]);
  EXPECT_GT(one.second[1], 0.0);  // the soil pushes the footing up
}

// The contact slots follow the nodes when they are sorted (RigidContact::reorder_nodes): a
// footing pushed fast into the block, so that the particles are sorted again while in contact,
// gives the same reaction and the same nodes sorted and unsorted (to round-off).
TEST(RigidBodies, SortingTheParticlesLeavesTheFootingRunUnchanged) {
  const test::ThreadCount threads(1);
  auto run = [](bool sort) {
    CaseSetup<2> c = footing_case();
    c.bodies[2].velocity = {0.0, -2.0};  // m/s: 8 cm in the 0.04 s, across a row of sort cells
    c.sort = sort ? SortSetting::always : SortSetting::off;
    auto sim = std::make_unique<Simulation<2>>(c);
    while (sim->time() < 0.04 - 1e-12) sim->step();
    return sim;
  };
  const auto sorted = run(true), plain = run(false);
  EXPECT_GT(sorted->reorders(), 1);
  EXPECT_EQ(plain->reorders(), 0);
  const Vec<2> fa = contact_of(*sorted).state()[2].force, fb = contact_of(*plain).state()[2].force;
  EXPECT_GT(fb[1], 0.0);
  EXPECT_NEAR(fa[0], fb[0], 1e-9 * fb.norm());
  EXPECT_NEAR(fa[1], fb[1], 1e-9 * fb.norm());
  EXPECT_EQ(contact_of(*sorted).state()[2].contact_nodes, contact_of(*plain).state()[2].contact_nodes);
  const std::vector<Index> a = sorted->nodes_by_id(), b = plain->nodes_by_id();
  double dx = 0.0;
  long contact_differs = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    const auto i = static_cast<std::size_t>(a[k]), j = static_cast<std::size_t>(b[k]);
    dx = std::max(dx, (sorted->nodes().position[i] - plain->nodes().position[j]).norm());
    contact_differs += contact_of(*sorted).in_contact()[i] != contact_of(*plain).in_contact()[j] ? 1 : 0;
    for (int slot = 0; slot < RigidContact::kMaxContacts; ++slot) {
      contact_differs += contact_of(*sorted).contact_body(i, slot) != contact_of(*plain).contact_body(j, slot) ? 1 : 0;
      contact_differs += contact_of(*sorted).slip(i, slot) != contact_of(*plain).slip(j, slot) ? 1 : 0;
    }
  }
  EXPECT_LT(dx, 1e-12);
  EXPECT_EQ(contact_differs, 0);
  std::printf("footing sorted %ld times: force %.10g vs %.10g N/m, max node offset %.2e m\n", sorted->reorders(),
              fa[1], fb[1], dx);
}

constexpr const char* kBodyCase = R"(
[geometry]
dimension = 2
spacing = 0.1
[[geometry.block]]
min = [0.0, 0.0]
max = [1.0, 0.5]
[material]
model = "elastic"
E = 1.0e7
nu = 0.3
density = 2000.0
[functions]
push = { type = "ramp", duration = 0.01, scale = -0.05 }
[solver]
version = "v2"
[[body]]
name = "base"
plane = { point = [0.0, 0.0], normal = [0.0, 1.0] }
contact = "coulomb"
friction = 0.4
adhesion = 5.0e3
[[body]]
name = "footing"
segment = { a = [0.3, 0.5], b = [0.0, 0.5] }
contact = "rough"
velocity = { y = "push" }
[[body]]
name = "wall"
polyline = [[1.0, 0.0], [1.0, 1.0]]
contact = "smooth"
force = { x = -100.0 }
mass = 50.0
[time]
end = 2.0e-3
cfl = 0.5
[output]
interval = 1.0e-3
)";

TEST(RigidBodies, CaseFileKeys) {
  test::TempDir dir;
  const CaseSetup<2> c = test::case_from_string<2>(dir, kBodyCase);
  ASSERT_EQ(c.bodies.size(), 3u);
  EXPECT_EQ(c.bodies[0].shape, BodyShape::plane);
  EXPECT_EQ(c.bodies[0].law, ContactLaw::coulomb);
  EXPECT_DOUBLE_EQ(c.bodies[0].friction, 0.4);
  EXPECT_DOUBLE_EQ(c.bodies[0].adhesion, 5.0e3);
  EXPECT_EQ(c.bodies[1].shape, BodyShape::segment);
  EXPECT_EQ(c.bodies[1].velocity_function[1], function_named(c, "push"));
  EXPECT_DOUBLE_EQ(c.bodies[1].velocity[1], 1.0);  // the function's value is the velocity
  EXPECT_EQ(c.bodies[2].shape, BodyShape::polyline);
  EXPECT_TRUE(c.bodies[2].force_driven[0]);
  EXPECT_FALSE(c.bodies[2].force_driven[1]);
  EXPECT_DOUBLE_EQ(c.bodies[2].force[0], -100.0);
  EXPECT_DOUBLE_EQ(c.bodies[2].mass, 50.0);
}

// Each bad [[body]] gets an InputError naming the file, the line and the key.
TEST(RigidBodies, CaseFileErrorsNameFileLineAndKey) {
  struct Bad {
    std::string from, to, expect;
  };
  const std::vector<Bad> bad = {
      {"polyline = [[1.0, 0.0], [1.0, 1.0]]", "polyline = [[1.0, 0.0]]", "key 'body[2].polyline': has no segment"},
      {"contact = \"smooth\"", "contact = \"sticky\"", "key 'body[2].contact': unknown contact law 'sticky'"},
      {"friction = 0.4", "friction = -0.1", "key 'body[0].friction': must be >= 0"},
      {"version = \"v2\"", "version = \"v2\"\nfree_surface = \"faces\"",
       "key 'body': rigid bodies need solver.free_surface = \"detect\""},
      {"mass = 50.0\n", "", "missing required key 'body[2].mass'"},
      {"segment = { a = [0.3, 0.5], b = [0.0, 0.5] }", "segment = { a = [0.3, 0.5], b = [0.3, 0.5] }",
       "key 'body[1].segment.b': coincides with a"},
      {"contact = \"rough\"", "contact = \"rough\"\nfriction = 0.2",
       "key 'body[1].friction': a friction coefficient needs"},
      {"contact = \"smooth\"", "contact = \"smooth\"\nrelease = \"mean\"",
       "key 'body[2].release': unknown release rule 'mean'"},
  };
  for (const Bad& b : bad) {
    std::string text = kBodyCase;
    const auto at = text.find(b.from);
    ASSERT_NE(at, std::string::npos) << b.from;
    text.replace(at, b.from.size(), b.to);
    test::TempDir dir;
    try {
      (void)test::case_from_string<2>(dir, text);
      ADD_FAILURE() << "no error for: " << b.to;
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find("case.toml, line "), std::string::npos) << message;
      EXPECT_NE(message.find(b.expect), std::string::npos) << message;
    }
  }
}

// From the command line: bodies.csv has a row per body at every output step, summary.json the
// reactions and counts.
TEST(RigidBodies, RunWritesBodiesCsvAndSummary) {
  test::TempDir dir;
  const std::string file = dir.write("case.toml", kBodyCase);
  const auto result =
      test::run_command(fmt::format("{} run {} --out {} -q -j 1 2>&1", RKTSPH_BINARY, file, dir.file("out")));
  ASSERT_EQ(result.status, 0) << result.out;
  const std::string csv = test::read_text(dir.file("out/bodies.csv"));
  EXPECT_EQ(csv.rfind("t,body,ux,uy,vx,vy,Fx,Fy,contact_width,contact_nodes,", 0), 0u);
  int rows = 0;
  for (const char ch : csv) rows += ch == '\n' ? 1 : 0;
  EXPECT_EQ(rows, 1 + 3 * 3);  // header, then 3 bodies at t = 0, 1e-3, 2e-3
  EXPECT_NE(csv.find(",footing,"), std::string::npos);
  const auto summary = nlohmann::json::parse(test::read_text(dir.file("out/summary.json")));
  const auto& stage = summary.at("stages").at("contact_enforce");
  EXPECT_GT(stage.at("footing.Fy").get<double>(), 0.0);
  EXPECT_EQ(stage.at("footing.contact_nodes").get<double>(), 4.0);
  EXPECT_TRUE(stage.contains("base.node_projections"));
  // The contact pressure profile: one row per contact node of every body at every output step.
  const std::string profile = test::read_text(dir.file("out/contact.csv"));
  EXPECT_EQ(profile.rfind("t,body,node,s,x,y,nx,ny,width,normal_stress,shear_stress\n", 0), 0u);
  EXPECT_NE(profile.find(",footing,"), std::string::npos);
}

}  // namespace
}  // namespace rktsph

namespace rktsph {
namespace {

// Coulomb at the scale of a run: an elastic block pressed onto a Coulomb base by a rough plate
// pushed down with a force P, then dragged sideways by the plate. The base holds the block
// until the shear reaches mu P + a W, then the block slides and the plate's horizontal
// reaction stays at that limit. The block is low (H = W/5) so that the overturning moment of the
// drag, mu P H, keeps the base in compression (eccentricity mu H = W/17 < W/6).
//
// Light dynamic relaxation (c_d = 10 1/s, c_d dt = 0.003) takes out the block's shear mode,
// which the start of the slip excites and which the undamped run keeps (the base then sticks and
// reverses now and then, and its mean shear is 3.6 % under the limit); the damping's drag on the
// sliding block, c_d rho W H V, is added to the limit. Before the free corners of method-notes
// eq. (4.5.8), the corner nodes kept the sigma_xx that the overturning moment puts there
// (-30 kPa at the leading one), a lateral force that no face of the block can carry: the plate
// pulled 16 % more than mu P + a W.
// The drag rig: the block W x H = 1 x 0.2 m, Delta x = 0.05 m, pressed by the plate (mass
// plate_mass, force-driven vertically, ramped over 0.05 s) and dragged from t = 0.1 s.
constexpr double kDragLoad = 1.0e4, kDragMu = 0.3, kDragAdhesion = 500.0;  // N/m, -, Pa
constexpr double kDragDamping = 10.0, kDragSpeed = 0.005;                  // 1/s, m/s
constexpr double kDragBlockMass = kRho * 1.0 * 0.2;                        // kg/m

// The contact machinery's tests below run the thesis's simple scheme for step 2's velocity
// (solver.velocity_update = "simple"). With V2's default hourglass control (method-notes §2.6)
// the free faces beside the bodies keep an edge mode the simple scheme's viscosity absorbed: the
// bonded block's kinetic energy grows as t^2 (0.06 J at 0.33 s against the 1.7e-3 J of its
// shear flow), the dragged blocks' free corners come and go, and under the heavy plate the base
// carries 9.7 % less than the friction limit (docs/VALIDATION.md, "V2's hourglass control").
CaseSetup<2> drag_rig(double plate_mass, double end) {
  CaseBuilder<2> b("block dragged over a Coulomb base");
  b.spacing(0.05)
      .block(Vec<2>(0.0, 0.0), Vec<2>(1.0, 0.2))
      .elastic(kE, kNu, kRho)
      .scheme("v2")
      .free_surface(true)
      .time(end, 0.5);
  TimeFunction press = TimeFunction::ramp(0.05);
  TimeFunction drag = TimeFunction::ramp(0.05, 0.1);  // from t = 0.1 s
  b.function("press", press).function("drag", drag);
  CaseSetup<2> c = test::simple_scheme(b.build());
  c.damping = kDragDamping;
  c.damping_until = 2.0;
  BodySpec base = plane_body("base", Vec<2>(0.0, 0.0), Vec<2>(0.0, 1.0), ContactLaw::coulomb);
  base.friction = kDragMu;
  base.adhesion = kDragAdhesion;
  c.bodies.push_back(base);
  BodySpec plate;
  plate.name = "plate";
  plate.where = "test";
  plate.shape = BodyShape::segment;
  plate.points = {Vec<2>(1.0, 0.2), Vec<2>(0.0, 0.2)};  // soil below
  plate.law = ContactLaw::rough;
  plate.velocity = {kDragSpeed, 0.0};
  plate.velocity_function = {function_named(c, "drag"), -1};
  plate.force_driven = {false, true};
  plate.force = {0.0, -kDragLoad};
  plate.force_function = {-1, function_named(c, "press")};
  plate.mass = plate_mass;
  c.bodies.push_back(plate);
  return c;
}

TEST(RigidBodies, BlockDraggedOverACoulombBaseSlidesAtTheFrictionLimit) {
  const test::ThreadCount threads(1);
  const double load = kDragLoad, mu = kDragMu, adhesion = kDragAdhesion;
  const double damping = kDragDamping, speed = kDragSpeed, block_mass = kDragBlockMass;
  Simulation<2> sim(drag_rig(200.0, 0.4));
  double shear = 0.0, base_shear = 0.0, pressure = 0.0, plate_load = 0.0, width = 0.0, base_slip = 0.0;
  long samples = 0;
  std::vector<Vec<2>> start;
  while (sim.time() < 0.4 - 1e-12) {
    sim.step();
    if (sim.time() >= 0.2 && start.empty()) start = sim.nodes().position;
    if (sim.time() < 0.25) continue;
    const auto& st = contact_of(sim).state();
    shear -= st[1].force[0];
    base_shear += st[0].force[0];
    pressure -= st[0].force[1];
    plate_load += st[1].force[1];
    width += st[0].width;
    EXPECT_EQ(st[0].free_corners + st[1].free_corners, 4) << "t = " << sim.time();
    ++samples;
  }
  const auto n = static_cast<double>(samples);
  shear /= n;
  base_shear /= n;
  pressure /= n;
  plate_load /= n;
  width /= n;
  // The block's base moved with the plate: it slides.
  const auto& x = sim.nodes().position;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (start[i][1] < 1e-9) base_slip = std::max(base_slip, x[i][0] - start[i][0]);
  }
  const double limit = mu * pressure + adhesion * width;
  const double expected = limit + damping * block_mass * speed;
  const double base_error = std::abs(base_shear - limit) / limit;
  const double error = std::abs(shear - expected) / expected;
  std::fprintf(stderr,
               "Coulomb drag: plate shear %.6g N/m, limit mu P + a W = %.6g (+ drag %.3g), base shear %.6g "
               "(P = %.6g, plate %.6g, W = %.4g), errors: plate %.2e, base %.2e; base slip over 0.2 s %.4g m\n",
               shear, limit, expected - limit, base_shear, pressure, plate_load, width, error, base_error, base_slip);
  EXPECT_NEAR(pressure, load, 0.02 * load);
  EXPECT_NEAR(plate_load, load, 0.02 * load);
  EXPECT_NEAR(width, 1.0, 1e-3);
  EXPECT_LT(base_error, 0.01);
  EXPECT_LT(error, 0.02);
  EXPECT_GT(base_slip, 0.5 * speed * 0.2);
}

// The same rig for a second, under a plate of 2000 kg/m: the sliding stays steady. Under the
// 200 kg/m plate of the test above a vibration grows from ~0.35 s (plate shear swinging by
// +-3 kN/m by 0.4 s): the plate's vertical mode (54 Hz with mu = 0) and the block's shear mode
// (51 Hz, the quarter wave c_s/4H) lock to one frequency through the friction mu sigma_nn and
// grow, a mode-coupling (flutter) instability of Coulomb friction with a constant coefficient
// (docs/VALIDATION.md, "Rigid bodies"). The heavy plate's vertical mode (27 Hz) is far from the
// shear mode, and the vibration of the start of the drag decays: what is left is the contact
// law itself over a long slide.
TEST(RigidBodies, BlockDraggedUnderAHeavyPlateSlidesSteadilyForASecond) {
  const test::ThreadCount threads(1);
  Simulation<2> sim(drag_rig(2000.0, 1.2));
  double shear = 0.0, base_shear = 0.0, pressure = 0.0, width = 0.0;
  double shear_min = 1e300, shear_max = -1e300;
  long samples = 0;
  while (sim.time() < 1.2 - 1e-12) {
    sim.step();
    if (sim.time() < 0.8) continue;
    const auto& st = contact_of(sim).state();
    shear -= st[1].force[0];
    shear_min = std::min(shear_min, -st[1].force[0]);
    shear_max = std::max(shear_max, -st[1].force[0]);
    base_shear += st[0].force[0];
    pressure -= st[0].force[1];
    width += st[0].width;
    ++samples;
  }
  const auto n = static_cast<double>(samples);
  shear /= n;
  base_shear /= n;
  pressure /= n;
  width /= n;
  const double limit = kDragMu * pressure + kDragAdhesion * width;
  const double expected = limit + kDragDamping * kDragBlockMass * kDragSpeed;
  std::fprintf(stderr,
               "Heavy plate, 0.8-1.2 s: plate shear %.6g N/m (swing %.3g), base shear %.6g, limit %.6g (+ drag "
               "%.3g), P = %.6g, W = %.4g; base projections %ld\n",
               shear, shear_max - shear_min, base_shear, limit, expected - limit, pressure, width,
               contact_of(sim).state()[0].node_projections);
  EXPECT_NEAR(pressure, kDragLoad, 0.01 * kDragLoad);
  EXPECT_NEAR(width, 1.0, 1e-3);
  EXPECT_LT(std::abs(base_shear - limit) / limit, 1e-3);
  EXPECT_LT(std::abs(shear - expected) / expected, 0.02);
  EXPECT_LT(shear_max - shear_min, 0.01 * limit);  // steady: no growing vibration
  EXPECT_EQ(contact_of(sim).state()[0].node_projections, 0);
}

// Free corners (method-notes eq. (4.5.8)): on the case of RunWritesBodiesCsvAndSummary, the
// block's left face meets the base and the footing: those patch ends have sigma_tt = 0. Not
// corners: the footing's inner end (the surface goes on past it), the base's end in the corner
// with the wall (a node on two bodies), the wall's end below a node that has come off it. With a symmetry roller
// on x = 0 the base's and the footing's ends there are not corners either.
TEST(RigidBodies, FreeCornersWhereTheSoilEndsOnABody) {
  for (const bool symmetry : {false, true}) {
    test::TempDir dir;
    std::string text = kBodyCase;
    if (symmetry) {
      const std::string roller = "[[boundary]]\nname = \"axis\"\nx = [0.0, 0.0]\nvelocity = { x = 0.0 }\n";
      text.replace(text.find("[time]"), 0, roller);
    }
    Simulation<2> sim(test::simple_scheme(test::case_from_string<2>(dir, text)));  // see drag_rig
    for (int k = 0; k < 20; ++k) sim.step();  // the footing's push has reached the corners
    const auto& st = contact_of(sim).state();
    EXPECT_EQ(st[0].free_corners, symmetry ? 0 : 1) << "base, symmetry " << symmetry;
    EXPECT_EQ(st[1].free_corners, symmetry ? 0 : 1) << "footing, symmetry " << symmetry;
    // The wall's top node has come off it (its sigma_nn pulls): a free node at the block's
    // corner, which the detection gives no in-plane stress; the patch's end below it has soil past
    // it and keeps its sigma_yy.
    EXPECT_EQ(st[2].free_corners, 0) << "wall, symmetry " << symmetry;
    const auto s = sim.node_stress();
    const auto& x = sim.nodes().position;
    for (std::size_t i = 0; i < x.size(); ++i) {
      const bool left_bottom = x[i][0] < 0.01 && x[i][1] < 0.01, left_top = x[i][0] < 0.01 && x[i][1] > 0.49;
      const bool wall_top = x[i][0] > 0.99 && x[i][1] > 0.49,
                 wall_end = x[i][0] > 0.99 && std::abs(x[i][1] - 0.4) < 0.01;
      const bool inner_end = std::abs(x[i][0] - 0.3) < 0.01 && x[i][1] > 0.49;
      if (left_bottom || left_top) {
        if (symmetry) {
          EXPECT_NE(s(i, StressComponent::xx), 0.0) << "axis node at " << x[i].transpose();
        } else {
          EXPECT_EQ(s(i, StressComponent::xx), 0.0) << "corner at " << x[i].transpose();
        }
      }
      if (wall_top) {
        EXPECT_EQ(s(i, StressComponent::yy), 0.0) << "corner at " << x[i].transpose();
      }
      if (wall_end) {
        EXPECT_NE(s(i, StressComponent::yy), 0.0) << "patch end at " << x[i].transpose();
      }
      if (inner_end) {
        EXPECT_NE(s(i, StressComponent::xx), 0.0) << "footing edge at " << x[i].transpose();
      }
    }
  }
}

// solver.surface_mirrors (method-notes §3.6 item 6): a block at rest on a rough base, its bottom
// row in contact. Mirrored are the nodes farther from the base than the keep distance (dx/2) and
// within the support 2h = 0.24 m, beside a contact node: the rows y = 0.1 and 0.2, 22 nodes.
// Flagged are the sides above the base and the top, exactly, with the sides' normals down to
// the base; without the option the same (the rule of §4.5 finds nothing to remove here).
TEST(RigidBodies, MirrorImagesAtTheBaseLeaveTheSidesAndTopFlagged) {
  for (const bool mirrors : {false, true}) {
    CaseBuilder<2> b("block on a base");
    b.spacing(0.1).block(Vec<2>(0.0, 0.0), Vec<2>(1.0, 1.0)).elastic(kE, kNu, kRho).scheme("v2").free_surface(true);
    b.time(0.01, 0.5);
    CaseSetup<2> c = b.build();
    c.surface_mirrors = mirrors;
    c.bodies.push_back(plane_body("base", Vec<2>(0.0, 0.0), Vec<2>(0.0, 1.0), ContactLaw::rough));
    Simulation<2> sim(std::move(c));
    for (int k = 0; k < 3; ++k) sim.step();
    const auto* detect = sim.scheme().find<DetectFreeSurface<2>>();
    ASSERT_NE(detect, nullptr);
    double mirrored = -1.0;
    for (const auto& [key, value] : detect->report()) {
      if (key == "mirrored_nodes_last_step") mirrored = value;
    }
    EXPECT_EQ(mirrored, mirrors ? 22.0 : 0.0);
    const auto flags = sim.nodes().view(sim.nodes().template find<double, 1>("free_surface"));
    const auto normals = sim.nodes().view(sim.nodes().template find<double, 2>("normal"));
    const auto& x = sim.nodes().position;
    for (std::size_t i = 0; i < x.size(); ++i) {
      const bool side = (x[i][0] < 1e-6 || x[i][0] > 1.0 - 1e-6) && x[i][1] > 0.05, top = x[i][1] > 1.0 - 1e-6;
      EXPECT_EQ(flags(i, 0) != 0.0, side || top) << "node at " << x[i].transpose() << ", mirrors " << mirrors;
      if (side && !top) {
        EXPECT_NEAR(normals(i, 0), x[i][0] < 0.5 ? -1.0 : 1.0, 1e-9) << x[i].transpose();
        EXPECT_NEAR(normals(i, 1), 0.0, 1e-9) << x[i].transpose();
      }
    }
  }
}

}  // namespace
}  // namespace rktsph

namespace rktsph {
namespace {

// Simple shear of a 1 x 0.2 m block between a fixed bonded base and a bonded plate moving at
// 5 mm/s: stable (before the contact nodes' velocity entered their own gradient, method-notes
// §4.5, this run grew without bound, the shear doubling every 0.036 s), the plate's and the
// base's shear reactions balance, and the mean shear stays below G gamma (the free sides carry
// no shear) but near it.
TEST(RigidBodies, SimpleShearBetweenBondedPlatesIsStable) {
  const test::ThreadCount threads(1);
  CaseBuilder<2> b("simple shear");
  b.spacing(0.05)
      .block(Vec<2>(0.0, 0.0), Vec<2>(1.0, 0.2))
      .elastic(kE, kNu, kRho)
      .scheme("v2")
      .free_surface(true)
      .time(0.33, 0.5)
      .function("drag", TimeFunction::ramp(0.05));
  CaseSetup<2> c = test::simple_scheme(b.build());  // see drag_rig
  c.bodies.push_back(plane_body("base", Vec<2>(0.0, 0.0), Vec<2>(0.0, 1.0), ContactLaw::bonded));
  BodySpec plate = plane_body("plate", Vec<2>(0.0, 0.2), Vec<2>(0.0, -1.0), ContactLaw::bonded);
  plate.velocity = {0.005, 0.0};
  plate.velocity_function = {function_named(c, "drag"), -1};
  c.bodies.push_back(plate);
  Simulation<2> sim(std::move(c));
  double kinetic = 0.0;
  while (sim.time() < 0.33 - 1e-12) {
    sim.step();
    kinetic = std::max(kinetic, sim.energy().kinetic);
  }
  const auto& st = contact_of(sim).state();
  const double shear_modulus = kE / (2.0 * (1.0 + kNu));
  const double gamma = st[1].offset[0] / 0.2;
  const double ratio = -st[1].force[0] / (shear_modulus * gamma * 1.0);
  const double balance = std::abs(st[0].force[0] + st[1].force[0]) / std::abs(st[1].force[0]);
  std::fprintf(stderr, "simple shear: plate F_x %.6g N/m, G gamma W %.6g, ratio %.4f, balance %.2e, peak K %.3g J\n",
               -st[1].force[0], shear_modulus * gamma, ratio, balance, kinetic);
  EXPECT_LT(balance, 1e-3);
  EXPECT_GT(ratio, 0.7);
  EXPECT_LT(ratio, 1.0);
  EXPECT_LT(kinetic, 0.01);  // the block's own motion, 1/2 m (v/2)^2 = 1.25e-3 J
}

}  // namespace
}  // namespace rktsph
