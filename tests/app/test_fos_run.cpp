// `rktsph fos` end to end (app/fos.cpp) on a tiny coarse cut: a 10 m x 5 m block at dx = 0.5 m,
// von Mises, N = gamma H / c = 3.4, whose factor must bracket the limit-analysis N_c (~3.78)
// within what so coarse a lattice resolves; and every error path (no strength to reduce, a
// monitor that is missing, an unreduced run that does not stand, a bracket that does not close)
// stops with its message or exit status and keeps the trials it ran. The load factor
// (fos.mode = "load") on a tiny strip load against Prandtl, and its input errors. Trials run in
// process: each leaves its history (trial_NN.csv) and its last state (trial_NN.vtu), no run
// folder.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "../support/test_util.hpp"
#include "app/fos.hpp"
#include "app/fos_setup.hpp"
#include "case/case_reader.hpp"
#include "core/error.hpp"

namespace rktsph {
namespace {

namespace fs = std::filesystem;

// gamma H / c = 2000 * 9.81 * 5 / 28853 = 3.40. The gravity ramp of 1 s spans about 5 shear
// periods of the block; damping until the kinetic energy is 1e-4 of its peak (at the latest
// 3 s), then 2 s undamped: the last second is the classification window.
const char* kCut = R"(
title = "tiny cut for rktsph fos"
[geometry]
dimension = 2
spacing = 0.5
[[geometry.block]]
min = [0.0, 0.0]
max = [10.0, 5.0]
[material]
model = "perzyna_von_mises"
E = 5.0e7
nu = 0.3
density = 2000.0
cohesion = 28853.0
fluidity = 10.0
[functions.gravity_ramp]
type = "ramp"
duration = 1.0
[body_force]
gravity = [0.0, -9.81]
function = "gravity_ramp"
[damping]
coefficient = 5.0
until_kinetic_ratio = 1.0e-4
kinetic_ratio_from = 1.0
kinetic_ratio_hold = 0.3
until = 3.0
[[boundary]]
name = "base"
y = [0.0, 0.0]
velocity = { x = 0.0, y = 0.0 }
[[boundary]]
name = "left"
x = [0.0, 0.0]
velocity = { x = 0.0 }
[time]
end = 5.0
cfl = 0.9
[output]
interval = 0.0
elements = false
[[probe]]
name = "crest"
position = [10.0, 5.0]
fields = ["ux"]
)";

nlohmann::json read_json(const fs::path& file) {
  std::ifstream in(file);
  return nlohmann::json::parse(in);
}

FosOptions options(const std::string& file, const fs::path& out) {
  FosOptions o;
  o.case_file = file;
  o.out_dir = out.string();
  o.tolerance = 0.05;
  o.jobs = 2;
  o.threads = 2;
  o.quiet = true;
  o.plot = false;
  return o;
}

TEST(FosRun, TinyCutBracketsTheLimitAnalysisValue) {
  test::TempDir dir;
  const std::string file = dir.write("cut.toml", kCut);
  const fs::path out = dir.path() / "fos";
  ASSERT_EQ(run_fos(options(file, out)), 0);
  const nlohmann::json j = read_json(out / "fos.json");
  EXPECT_EQ(j["status"], "converged");
  const double f = j["factor_of_safety"], lo = j["bracket"][0], hi = j["bracket"][1];
  EXPECT_LE(hi - lo, 0.05 * lo);
  EXPECT_DOUBLE_EQ(f, 0.5 * (lo + hi));
  // N_c = 3.4 F: inside Heyman's lower bound 2.83 and the planar-wedge upper bound 4.00 (the
  // lattice is 10 cells tall; docs/fos.md gives the converged figures).
  EXPECT_GT(3.4 * lo, 2.83);
  EXPECT_LT(3.4 * hi, 4.00);
  // Every trial kept, with its history, last state and classification; those on the search's
  // path agree with the bracket. A strength-reduction trial is judged over the hold after
  // time.end (5 s): eight time scales sqrt(5 m / g) by default, in the rate-independent limit.
  EXPECT_NEAR(j["monitor"]["hold_start"].get<double>(), 5.0, 1e-12);
  EXPECT_NEAR(j["monitor"]["hold"].get<double>(), 8.0 * std::sqrt(5.0 / 9.81), 1e-12);
  EXPECT_TRUE(j["rate_independent"].get<bool>());
  ASSERT_GE(j["trials"].size(), j["trials_used"].get<std::size_t>());
  EXPECT_EQ(j["trials"][0]["factor"], 1.0);
  EXPECT_EQ(j["trials"][0]["outcome"], "stable");
  for (const auto& t : j["trials"]) {
    EXPECT_TRUE(fs::exists(out / t["history"].get<std::string>()));
    EXPECT_TRUE(fs::exists(out / t["frame"].get<std::string>())) << t;
    EXPECT_FALSE(t["reduced"].contains("material.fluidity")) << "fluidity is set, not reduced";
    const std::string outcome = t["outcome"];
    if (outcome == "stable") {
      // A trial stands at the end of its hold (the step that reaches it: within one step, dt =
      // 0.9 dx / c_p = 3.7 ms), or collapses as soon as u_c passes 0.05 L.
      const double end = 5.0 + 8.0 * std::sqrt(5.0 / 9.81);
      EXPECT_GE(t["t_end"].get<double>(), end - 1e-9);
      EXPECT_LT(t["t_end"].get<double>(), end + 4e-3);
      EXPECT_LT(t["hold"]["ratio"].get<double>(), 0.95);
    }
    if (!t["used"]) continue;
    const double tf = t["factor"];
    EXPECT_EQ(t["stable"].get<bool>(), tf <= lo) << tf;
  }
  // The reduced cohesion of a trial is c / F.
  const auto& last = j["trials"].back();
  EXPECT_NEAR(last["reduced"]["material.cohesion"].get<double>(), 28853.0 / last["factor"].get<double>(), 1e-9);
}

TEST(FosRun, NoStrengthToReduce) {
  test::TempDir dir;
  std::string elastic = kCut;
  elastic.replace(elastic.find("model = \"perzyna_von_mises\""), 27, "model = \"elastic\"");
  elastic.replace(elastic.find("cohesion = 28853.0\nfluidity = 10.0\n"), 35, "");
  const std::string file = dir.write("elastic.toml", elastic);
  try {
    run_fos(options(file, dir.path() / "fos"));
    FAIL() << "an elastic case was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no material has a strength to reduce"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("elastic.toml"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir.path() / "fos")) << "nothing is written before the input is checked";
}

TEST(FosRun, CamClayHasNoReductionRule) {
  test::TempDir dir;
  const std::string file = dir.write("cc.toml", R"(
[geometry]
dimension = 2
spacing = 1.0
[[geometry.block]]
min = [0.0, 0.0]
max = [2.0, 2.0]
[material]
model = "perzyna_cam_clay"
E = 1.0e7
nu = 0.3
density = 2000.0
M = 1.0
lambda = 0.2
kappa = 0.05
e0 = 1.0
p_c0 = 1.0e5
fluidity = 1.0
[time]
end = 1.0
)");
  try {
    (void)fos::read_strength(load_case_document(file, {}));
    FAIL() << "Cam-Clay was accepted";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("no strength reduction is defined for the model 'perzyna_cam_clay'"), std::string::npos) << m;
    EXPECT_NE(m.find("line 9"), std::string::npos) << m;
    EXPECT_NE(m.find("material.model"), std::string::npos) << m;
  }
}

TEST(FosRun, StrengthReductionOfEachModel) {
  test::TempDir dir;
  const std::string file = dir.write("mats.toml", R"(
[geometry]
dimension = 2
spacing = 1.0
[[geometry.block]]
min = [0.0, 0.0]
max = [2.0, 2.0]
material = "soil"
[materials.soil]
model = "perzyna_mohr_coulomb"
E = 1.0e7
nu = 0.3
density = 2000.0
cohesion = 10.0e3
friction_angle = 30.0
dilatancy = 20.0
hardening_modulus = -1.0e5
residual_cohesion = 2.0e3
fluidity = 1.0
[materials.clay]
model = "perzyna_von_mises"
E = 1.0e7
nu = 0.3
density = 2000.0
yield_stress = 1.0e5
fluidity = 1.0
[materials.rock]
model = "elastic"
E = 1.0e9
nu = 0.2
density = 2500.0
[time]
end = 1.0
)");
  const fos::StrengthReduction s = fos::read_strength(load_case_document(file, {}));
  ASSERT_EQ(s.materials.size(), 2u);
  ASSERT_EQ(s.unreduced.size(), 1u);
  EXPECT_EQ(s.unreduced[0], "materials.rock");
  std::map<std::string, double> v;
  for (const auto& [k, x] : s.values(2.0)) v[k] = x;
  EXPECT_DOUBLE_EQ(v.at("materials.soil.cohesion"), 5.0e3);
  EXPECT_DOUBLE_EQ(v.at("materials.soil.hardening_modulus"), -0.5e5);
  EXPECT_DOUBLE_EQ(v.at("materials.soil.residual_cohesion"), 1.0e3);
  // tan(phi_F) = tan(30 deg) / 2: phi_F = 16.10 deg; psi = 20 deg exceeds it and is capped.
  EXPECT_NEAR(v.at("materials.soil.friction_angle"), 16.102113751, 1e-8);
  EXPECT_DOUBLE_EQ(v.at("materials.soil.dilatancy"), v.at("materials.soil.friction_angle"));
  EXPECT_DOUBLE_EQ(v.at("materials.clay.yield_stress"), 0.5e5);
  EXPECT_EQ(v.count("materials.clay.residual_yield_stress"), 0u);  // its default follows Y0
  // At F = 1.1 the dilatancy (20 deg) stays below phi_F (27.7 deg).
  for (const auto& [k, x] : s.values(1.1)) v[k] = x;
  EXPECT_DOUBLE_EQ(v.at("materials.soil.dilatancy"), 20.0);
  // The case at F = 3, written into its document: the reader accepts it, with the reduced
  // values and the rate-independent limit of every reduced material (the elastic one untouched).
  CaseDocument doc = load_case_document(file, {});
  s.apply(doc.table, 3.0);
  EXPECT_DOUBLE_EQ(doc.table["materials"]["soil"]["cohesion"].value<double>().value(), 10.0e3 / 3.0);
  EXPECT_EQ(doc.table["materials"]["soil"]["fluidity"].value<double>(), std::numeric_limits<double>::infinity());
  EXPECT_EQ(doc.table["materials"]["clay"]["fluidity"].value<double>(), std::numeric_limits<double>::infinity());
  EXPECT_FALSE(doc.table["materials"]["rock"]["fluidity"]);
  EXPECT_NO_THROW((void)read_case<2>(doc));
  // fos.rate_independent = false keeps the case's fluidity.
  fos::StrengthReduction kept = s;
  kept.rate_independent = false;
  CaseDocument doc_kept = load_case_document(file, {});
  kept.apply(doc_kept.table, 3.0);
  EXPECT_EQ(doc_kept.table["materials"]["soil"]["fluidity"].value<double>(), 1.0);
}

TEST(FosRun, MonitorMissingOrOffTheBody) {
  test::TempDir dir;
  const std::string file = dir.write("cut.toml", kCut);
  const fs::path out = dir.path() / "fos";
  FosOptions o = options(file, out);
  o.overrides = {"fos.monitor=\"top\""};
  try {
    run_fos(o);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no probe named 'top' in the case (its probes: crest)"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("fos.monitor"), std::string::npos) << e.what();
  }
  o.overrides = {"fos.monitor=[12.0, 5.0]"};
  try {
    run_fos(o);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("is not on the body"), std::string::npos) << e.what();
  }
  // The load factor's window is not a key of strength reduction, whose trials are judged over
  // the hold after time.end.
  o.overrides = {"fos.window=1.0"};
  try {
    run_fos(o);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("fos.window"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("fos.hold"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("cut.toml"), std::string::npos) << e.what();
  }
  o.overrides = {"fos.hold=-1.0"};
  EXPECT_THROW(run_fos(o), InputError);
  o.overrides = {"fos.rate_independent=1"};
  EXPECT_THROW(run_fos(o), InputError);
  o.overrides = {"fos.typo=1"};
  EXPECT_THROW(run_fos(o), InputError);
  EXPECT_FALSE(fs::exists(out));
}

TEST(FosRun, UnreducedRunThatCollapses) {
  test::TempDir dir;
  const std::string file = dir.write("cut.toml", kCut);
  const fs::path out = dir.path() / "fos";
  FosOptions o = options(file, out);
  o.overrides = {"material.cohesion=10000", "geometry.spacing=1.0"};  // N = 9.8
  o.jobs = 1;
  EXPECT_EQ(run_fos(o), kExitNoFactor);
  const nlohmann::json j = read_json(out / "fos.json");
  EXPECT_EQ(j["status"], "unreduced_fails");
  EXPECT_TRUE(j["factor_of_safety"].is_null());
  ASSERT_EQ(j["trials"].size(), 1u);
  EXPECT_NE(j["trials"][0]["outcome"], "stable");
  EXPECT_TRUE(fs::exists(out / "trial_01.csv"));
}

TEST(FosRun, BracketThatDoesNotCloseKeepsItsTrials) {
  test::TempDir dir;
  const std::string file = dir.write("cut.toml", kCut);
  const fs::path out = dir.path() / "fos";
  FosOptions o = options(file, out);
  o.max_trials = 2;  // F = 1 stands, F = 1.25 does not: the bracket is 25 % wide
  EXPECT_EQ(run_fos(o), kExitNoFactor);
  const nlohmann::json j = read_json(out / "fos.json");
  EXPECT_EQ(j["status"], "bracket_open");
  EXPECT_EQ(j["bracket"][0], 1.0);
  EXPECT_EQ(j["bracket"][1], 1.25);
  EXPECT_EQ(j["trials"].size(), 2u);
  EXPECT_TRUE(fs::exists(out / "trial_02.csv"));
  // A second search into the same folder replaces the first one's trials.
  o.max_trials = 12;
  o.overrides = {"geometry.spacing=1.0", "material.cohesion=10000"};
  o.jobs = 1;
  EXPECT_EQ(run_fos(o), kExitNoFactor);
  EXPECT_FALSE(fs::exists(out / "trial_02.csv"));
}

// A weightless von Mises block, 3 m x 1.5 m at dx = 0.25 m, under a smooth rigid strip footing
// pushed by a force (load control, method-notes §4.6) on the half-width B/2 = 0.5 m (symmetry at
// x = 0): nominal 150 kPa (75 kN/m on the half), c = 50 kPa, so that Prandtl's (2 + pi) c =
// 257.08 kPa is a load factor of 1.7139. The classification reads the stress points' kinetic
// energy: the nodes keep a steady velocity beside the footing's edge that the stress points do
// not see (method-notes §5.1, "Displacements"; here 28 % of the nodes' peak at rest, against
// 1e-4 on the stress points), and no trial would ever stand on the nodes' energy.
const char* kStripLoad = R"(
title = "tiny strip load for the load factor of rktsph fos"
[geometry]
dimension = 2
spacing = 0.25
[[geometry.block]]
min = [0.0, 0.0]
max = [3.0, 1.5]
[material]
model = "perzyna_von_mises"
E = 5.0e7
nu = 0.3
density = 2000.0
cohesion = 50.0e3
fluidity = 10.0
[functions.load]
type = "ramp"
duration = 0.3
scale = -75.0e3
[damping]
coefficient = 5.0
until_kinetic_ratio = 1.0e-3
kinetic_ratio_from = 0.3
kinetic_ratio_hold = 0.2
until = 1.0
[[boundary]]
name = "symmetry"
x = [0.0, 0.0]
velocity = { x = 0.0 }
[[boundary]]
name = "far_side"
x = [3.0, 3.0]
velocity = { x = 0.0 }
[[boundary]]
name = "base"
y = [0.0, 0.0]
velocity = { x = 0.0, y = 0.0 }
[[body]]
name = "footing"
segment = { a = [0.5, 1.5], b = [0.0, 1.5] }
contact = "smooth"
force = { y = "load" }
mass = 500.0
[time]
end = 2.3
cfl = 0.3
[output]
interval = 0.0
elements = false
[[probe]]
name = "centre"
position = [0.0, 1.5]
fields = ["uy"]
[fos]
mode = "load"
load_functions = ["load"]
monitor = "centre"
direction = [0.0, -1.0]
length = 1.0
kinetic = "stress_points"
)";

TEST(FosRun, LoadFactorOfATinyStripLoadBracketsPrandtl) {
  test::TempDir dir;
  const std::string file = dir.write("strip.toml", kStripLoad);
  const fs::path out = dir.path() / "fos";
  ASSERT_EQ(run_fos(options(file, out)), 0);
  const nlohmann::json j = read_json(out / "fos.json");
  EXPECT_EQ(j["status"], "converged");
  EXPECT_EQ(j["mode"], "load");
  // The resolution the factor belongs to (spacing 0.25 m, the default h = 1.2 dx).
  EXPECT_DOUBLE_EQ(j["spacing"].get<double>(), 0.25);
  EXPECT_DOUBLE_EQ(j["smoothing_length"].get<double>(), 1.2 * 0.25);
  EXPECT_TRUE(j["factor_of_safety"].is_null() || !j.contains("factor_of_safety"));
  const double f = j["load_factor"], lo = j["bracket"][0], hi = j["bracket"][1];
  EXPECT_DOUBLE_EQ(j["factor"].get<double>(), f);
  EXPECT_LE(hi - lo, 0.05 * lo);
  // The collapse pressure 150 kPa x F against (2 + pi) c, with two cells under the half-width and
  // V1's static deficit under a held rigid footing (docs/VALIDATION.md, "Bearing capacity of c–φ
  // soil": 0.79 q_u at B/10 on c–φ soil): a band around what this lattice gives, below Prandtl.
  const double prandtl = (2.0 + std::numbers::pi) * 50.0e3 / 150.0e3;
  EXPECT_GT(lo, 0.6 * prandtl);
  EXPECT_LT(hi, 1.05 * prandtl);
  EXPECT_DOUBLE_EQ(j["load_functions"]["functions.load.scale"].get<double>(), -75.0e3);
  for (const auto& t : j["trials"]) {
    // Each trial multiplies the function's own scale by F.
    EXPECT_DOUBLE_EQ(t["scaled"]["functions.load.scale"].get<double>(), -75.0e3 * t["factor"].get<double>());
    if (!t["used"]) continue;
    EXPECT_EQ(t["stable"].get<bool>(), t["factor"].get<double>() <= lo) << t["factor"];
  }
  // Why the case reads the stress points' kinetic energy (its comment, docs/fos.md): at the end
  // of the standing trial F = 1 the nodes' energy is still a large part of its peak, the stress
  // points' has died away (trial_01.csv: both, and the one the classification read).
  std::ifstream history(out / "trial_01.csv");
  std::string line;
  std::getline(history, line);
  ASSERT_EQ(line, "t,u_c,kinetic,kinetic_nodes,kinetic_stress_points,plastic_dissipation");
  double peak_nodes = 0.0, peak_sp = 0.0, end_nodes = 0.0, end_sp = 0.0;
  while (std::getline(history, line)) {
    std::vector<double> row;
    std::stringstream cells(line);
    std::string cell;
    while (std::getline(cells, cell, ',')) row.push_back(std::stod(cell));
    ASSERT_EQ(row.size(), 6u) << line;
    EXPECT_EQ(row[2], row[4]) << "the classification reads the stress points' energy";
    end_nodes = row[3];
    end_sp = row[4];
    peak_nodes = std::max(peak_nodes, end_nodes);
    peak_sp = std::max(peak_sp, end_sp);
  }
  EXPECT_GT(end_nodes, 0.1 * peak_nodes);
  EXPECT_LT(end_sp, 1e-3 * peak_sp);
}

// fos.kinetic = "auto" (the default) reads the stress points' kinetic energy for a V2 trial,
// whose nodes keep a kinetic energy above the stable rule's 1e-2 of its peak while the material
// is at rest (docs/fos.md, "Which kinetic energy"), and the nodes' for V1; a key given wins.
TEST(FosRun, KineticEnergyAutoReadsTheStressPointsOfV2Trials) {
  test::TempDir dir;
  std::string text = kStripLoad;
  const std::string line = "kinetic = \"stress_points\"\n";
  text.erase(text.find(line), line.size());
  const std::string file = dir.write("strip.toml", text);
  auto column = [&](const std::vector<std::string>& overrides) {
    const CaseDocument doc = load_case_document(file, overrides);
    return fos::resolve_monitor(doc, fos::read_fos_table(doc)).kinetic_column;
  };
  EXPECT_EQ(column({}), "kinetic");
  EXPECT_EQ(column({"solver.version=\"v2\""}), "kinetic_stress_points");
  EXPECT_EQ(column({"solver.version=\"v2\"", "fos.kinetic=\"nodes\""}), "kinetic");
  EXPECT_EQ(column({"fos.kinetic=\"stress_points\""}), "kinetic_stress_points");
  EXPECT_EQ(column({"fos.kinetic=\"auto\""}), "kinetic");
}

TEST(FosRun, LoadFactorInputErrors) {
  test::TempDir dir;
  using Edits = std::vector<std::pair<std::string, std::string>>;
  // Every string of `what` must appear in the message.
  auto expect_input_error_after = [&](const Edits& edits, const std::vector<std::string>& what) {
    std::string text = kStripLoad;
    for (const auto& [from, to] : edits) {
      const auto at = text.find(from);
      ASSERT_NE(at, std::string::npos) << from;
      text.replace(at, from.size(), to);
    }
    const std::string file = dir.write("bad.toml", text);
    try {
      (void)run_fos(options(file, dir.path() / "fos"));
      ADD_FAILURE() << "no error for " << edits.back().second;
    } catch (const InputError& e) {
      for (const std::string& w : what) EXPECT_NE(std::string(e.what()).find(w), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("bad.toml, line"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(dir.path() / "fos")) << "nothing is written before the input is checked";
  };
  auto expect_input_error = [&](const std::string& from, const std::string& to, const std::string& what) {
    expect_input_error_after({{from, to}}, {what});
  };
  expect_input_error("mode = \"load\"", "mode = \"loads\"", "unknown mode 'loads'");
  expect_input_error("load_functions = [\"load\"]", "", "mode = \"load\" needs load_functions");
  expect_input_error("load_functions = [\"load\"]", "load_functions = [\"push\"]",
                     "no time function 'push' in the case (its functions: load)");
  expect_input_error("kinetic = \"stress_points\"", "kinetic = \"fluid\"",
                     "unknown kinetic energy 'fluid': \"auto\", \"nodes\" or \"stress_points\"");
  expect_input_error("mode = \"load\"", "mode = \"strength\"",
                     "the time functions of the loads are scaled only with mode = \"load\"");
  // Keys of strength reduction are refused in load mode, naming the key.
  expect_input_error("length = 1.0", "length = 1.0\nhold = 2.0", "fos.hold");
  expect_input_error("length = 1.0", "length = 1.0\nrate_independent = false", "fos.rate_independent");
  // An all-elastic body has no strength to reduce, but its load can be scaled: the search then
  // never sees a collapse and says so (exit status 5), after the trials it was allowed.
  std::string elastic = kStripLoad;
  auto replace = [&](const std::string& from, const std::string& to) {
    elastic.replace(elastic.find(from), from.size(), to);
  };
  replace("model = \"perzyna_von_mises\"", "model = \"elastic\"");
  replace("cohesion = 50.0e3", "");
  replace("fluidity = 10.0", "");
  const std::string file = dir.write("elastic.toml", elastic);
  FosOptions o = options(file, dir.path() / "fos_elastic");
  o.max_trials = 2;
  o.jobs = 1;
  EXPECT_EQ(run_fos(o), kExitNoFactor);
  const nlohmann::json j = read_json(dir.path() / "fos_elastic" / "fos.json");
  EXPECT_EQ(j["status"], "bracket_open");
  EXPECT_TRUE(j["load_factor"].is_null());
}

}  // namespace
}  // namespace rktsph
