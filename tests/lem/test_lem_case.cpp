// Reading the limit-equilibrium problem from a case (lem/lem_case.hpp) and the `rktsph lem`
// command: bodies from polygons and blocks, the soil's c, phi and weight, and every bad input
// as one error with file, line and key (exit status 2).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <numbers>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "../support/test_util.hpp"
#include "case/case_reader.hpp"
#include "core/error.hpp"
#include "lem/lem_case.hpp"

namespace rktsph::lem {
namespace {

const std::string kMohrCoulomb = R"(
[materials.soil]
model = "perzyna_mohr_coulomb"
E = 1.0e8
nu = 0.3
density = 2000.0
cohesion = 10.0e3
friction_angle = 20.0
fluidity = 10.0
)";

const std::string kGravity = "\n[body_force]\ngravity = [0.0, -10.0]\n";

std::string polygon(const std::string& vertices, const std::string& extra = "") {
  return fmt::format("[geometry]\ndimension = 2\nspacing = 0.5\n\n[[geometry.polygon]]\nvertices = {}\nmaterial = "
                     "\"soil\"\n{}\n",
                     vertices, extra);
}

const std::string kSlope = "[[0.0, 0.0], [40.0, 0.0], [40.0, 10.0], [20.0, 10.0], [0.0, 0.0]]";

LemProblem read(const std::string& text) { return read_lem_problem(parse_case_document(text, "lem_test.toml", {})); }

// The error's message, which must name the file, a line and `key`.
std::string error_of(const std::string& text, const std::string& key) {
  try {
    read(text);
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("lem_test.toml"), std::string::npos) << m;
    EXPECT_NE(m.find("line"), std::string::npos) << m;
    EXPECT_NE(m.find(key), std::string::npos) << m;
    return m;
  }
  ADD_FAILURE() << "no error for:\n" << text;
  return {};
}

TEST(LemCase, PolygonWithMohrCoulombSoil) {
  const LemProblem p = read(polygon(kSlope) + kMohrCoulomb + kGravity);
  EXPECT_EQ(p.geometry.bodies().size(), 1u);
  EXPECT_EQ(p.geometry.bodies()[0].outer.size(), 4u);  // closed ring: the repeated point dropped
  EXPECT_DOUBLE_EQ(p.soil.cohesion, 10.0e3);
  EXPECT_DOUBLE_EQ(p.soil.friction_angle, 20.0 * std::numbers::pi / 180.0);
  EXPECT_DOUBLE_EQ(p.soil.unit_weight, 20.0e3);
  // No [[boundary]] with a velocity: the lowest level is the rigid base, and it says so.
  ASSERT_EQ(p.geometry.rigid_regions().size(), 1u);
  EXPECT_TRUE(p.geometry.on_rigid({13.0, 0.0}));
  EXPECT_FALSE(p.geometry.on_rigid({13.0, 0.5}));
  EXPECT_NE(p.notes.front().find("rigid base"), std::string::npos);
}

TEST(LemCase, VonMisesAndDruckerPragerStrengths) {
  const std::string vm = R"(
[material]
model = "perzyna_von_mises"
E = 5.0e7
nu = 0.3
density = 2000.0
yield_stress = 100.0e3
fluidity = 10.0
)";
  const std::string blocks = "[geometry]\ndimension = 2\nspacing = 0.5\n[[geometry.block]]\nmin = [0.0, 0.0]\nmax = "
                             "[10.0, 5.0]\n[[geometry.block]]\nmin = [10.0, 0.0]\nmax = [20.0, 10.0]\n";
  const LemProblem p = read(blocks + vm + kGravity);
  EXPECT_NEAR(p.soil.cohesion, 100.0e3 / std::sqrt(3.0), 1e-9);
  EXPECT_EQ(p.soil.friction_angle, 0.0);
  EXPECT_EQ(p.geometry.bodies().size(), 2u);
  EXPECT_DOUBLE_EQ(p.geometry.soil_above(5.0, 0.0), 5.0);
  EXPECT_DOUBLE_EQ(p.geometry.soil_above(15.0, 0.0), 10.0);
  std::string dp = kMohrCoulomb;
  dp.replace(dp.find("perzyna_mohr_coulomb"), 20, "perzyna_drucker_prager");
  const LemProblem q = read(polygon(kSlope) + dp + kGravity);
  EXPECT_DOUBLE_EQ(q.soil.friction_angle, 20.0 * std::numbers::pi / 180.0);
}

TEST(LemCase, HolesAreSoilLeftOut) {
  const LemProblem p =
      read(polygon(kSlope, "holes = [[[30.0, 4.0], [34.0, 4.0], [34.0, 6.0], [30.0, 6.0]]]") + kMohrCoulomb + kGravity);
  EXPECT_DOUBLE_EQ(p.geometry.soil_above(32.0, 0.0), 8.0);
}

TEST(LemCase, BadGeometryIsAnErrorWithFileLineAndKey) {
  const std::string rest = kMohrCoulomb + kGravity;
  EXPECT_NE(error_of(polygon("[[0.0, 0.0], [20.0, 10.0], [40.0, 10.0], [40.0, 0.0]]") + rest, "vertices")
                .find("clockwise"),
            std::string::npos);
  EXPECT_NE(error_of(polygon("[[0.0, 0.0], [10.0, 10.0], [10.0, 0.0], [0.0, 10.0]]") + rest, "vertices")
                .find("intersects itself"),
            std::string::npos);
  EXPECT_NE(error_of(polygon("[[0.0, 0.0], [10.0, 0.0]]") + rest, "vertices").find("at least 3"), std::string::npos);
  EXPECT_NE(error_of(polygon("[[0.0, 0.0], [10.0, 0.0], [5.0]]") + rest, "vertices").find("point 2"),
            std::string::npos);
  EXPECT_NE(error_of(polygon(kSlope, "holes = [[[50.0, 4.0], [54.0, 4.0], [54.0, 6.0]]]") + rest, "holes")
                .find("outside"),
            std::string::npos);
  EXPECT_NE(error_of("[geometry]\ndimension = 2\nspacing = 0.5\n" + rest, "geometry").find("no bodies"),
            std::string::npos);
  EXPECT_NE(error_of(polygon(kSlope).replace(polygon(kSlope).find("\"soil\""), 6, "\"clay\"") + rest, "material")
                .find("unknown material 'clay'"),
            std::string::npos);
  EXPECT_NE(error_of(polygon(kSlope) + kMohrCoulomb, "body_force").find("gravity"), std::string::npos);
  EXPECT_NE(error_of(polygon(kSlope) + rest + "[[boundary]]\nedge = 0\nvelocity = { x = 0.0 }\n", "boundary[0]")
                .find("selects no x/y box"),
            std::string::npos);
  EXPECT_NE(error_of(polygon(kSlope) + kMohrCoulomb + "\n[body_force]\ngravity = [1.0, -10.0]\n", "gravity")
                .find("vertical"),
            std::string::npos);
}

TEST(LemCase, MaterialsWithoutCPhiStrengthAreErrors) {
  const std::string geo = polygon(kSlope);
  const std::string elastic = "[materials.soil]\nmodel = \"elastic\"\nE = 1e8\nnu = 0.3\ndensity = 2000.0\n";
  EXPECT_NE(error_of(geo + elastic + kGravity, "model").find("no strength"), std::string::npos);
  const std::string cam = R"(
[materials.soil]
model = "perzyna_cam_clay"
E = 1e8
nu = 0.3
density = 2000.0
M = 1.2
lambda = 0.2
kappa = 0.04
e0 = 1.0
p_c0 = 1e5
fluidity = 1.0
)";
  EXPECT_NE(error_of(geo + cam + kGravity, "model").find("Cam-Clay has no cohesion"), std::string::npos);
  std::string vm0 = "[materials.soil]\nmodel = \"perzyna_von_mises\"\nE = 1e8\nnu = 0.3\ndensity = 2000.0\ncohesion "
                    "= 0.0\nfluidity = 1.0\n";
  EXPECT_NE(error_of(geo + vm0 + kGravity, "cohesion").find("no strength"), std::string::npos);
  std::string mc0 = kMohrCoulomb;
  mc0.replace(mc0.find("cohesion = 10.0e3"), 17, "cohesion = 0.0");
  mc0.replace(mc0.find("friction_angle = 20.0"), 21, "friction_angle = 0.0");
  EXPECT_NE(error_of(geo + mc0 + kGravity, "cohesion").find("no strength"), std::string::npos);
  // A misspelt key of the material is reported as the particle solver reports it.
  std::string typo = kMohrCoulomb;
  typo.replace(typo.find("fluidity"), 8, "fludity");
  error_of(geo + typo + kGravity, "materials.soil");
}

// Bodies of different materials each carry their own soil (a layered slope).
TEST(LemCase, EachBodyCarriesItsMaterialsSoil) {
  std::string two = "[geometry]\ndimension = 2\nspacing = 0.5\n[[geometry.block]]\nmin = [0.0, 0.0]\nmax = [10.0, "
                    "5.0]\nmaterial = \"soil\"\n[[geometry.block]]\nmin = [10.0, 0.0]\nmax = [20.0, 10.0]\nmaterial = "
                    "\"stiff\"\n" +
                    kMohrCoulomb + kMohrCoulomb;
  two.replace(two.rfind("[materials.soil]"), 16, "[materials.stiff]");
  two.replace(two.rfind("cohesion = 10.0e3"), 17, "cohesion = 20.0e3");
  two.replace(two.rfind("density = 2000.0"), 16, "density = 1800.0");
  const LemProblem p = read(two + kGravity);
  ASSERT_EQ(p.geometry.bodies().size(), 2u);
  EXPECT_TRUE(p.geometry.layered());
  const auto& a = p.geometry.bodies()[0];
  const auto& b = p.geometry.bodies()[1];
  ASSERT_TRUE(a.soil && b.soil);
  EXPECT_EQ(a.material, "soil");
  EXPECT_EQ(b.material, "stiff");
  EXPECT_DOUBLE_EQ(a.soil->cohesion, 10.0e3);
  EXPECT_DOUBLE_EQ(b.soil->cohesion, 20.0e3);
  EXPECT_DOUBLE_EQ(a.soil->unit_weight, 20.0e3);
  EXPECT_DOUBLE_EQ(b.soil->unit_weight, 18.0e3);
  // One material: one soil, not layered.
  EXPECT_FALSE(read(polygon(kSlope) + kMohrCoulomb + kGravity).geometry.layered());
}

// The command: lem.json with F and the critical circle; a bad case exits 2 with one line.
TEST(LemCommand, WritesLemJsonAndExitsTwoOnBadInput) {
  test::TempDir dir;
  const std::string out = dir.file("out");
  const auto ok = test::run_command(fmt::format(
      "\"{}\" lem \"{}/cases/examples/slope_2to1_c10_phi20.toml\" --no-plot --grid 11 --levels 4 --out \"{}\" 2>&1",
      RKTSPH_BINARY, RKTSPH_SOURCE_DIR, out));
  ASSERT_EQ(ok.status, 0) << ok.out;
  const auto j = nlohmann::json::parse(test::read_text(out + "/lem.json"));
  EXPECT_NEAR(j["factor_of_safety"].get<double>(), 1.38, 0.03 * 1.38);
  EXPECT_EQ(j["slices"].size(), 50u);
  EXPECT_EQ(j["search"]["grid_per_axis"], 11);
  EXPECT_EQ(j["first_grid"].size(), 121u);
  EXPECT_EQ(j["exit"].size(), 2u);
  const std::string bad = dir.write("bad.toml", polygon("[[0.0, 0.0], [20.0, 10.0], [40.0, 10.0], [40.0, 0.0]]") +
                                                    kMohrCoulomb + kGravity);
  const auto r = test::run_command(fmt::format("\"{}\" lem \"{}\" --no-plot --out \"{}\" 2>&1", RKTSPH_BINARY, bad,
                                               dir.file("bad_out")));
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("clockwise"), std::string::npos) << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
  // Every face rigid: no admissible circle, exit status 3 with the search box named.
  const std::string boxed =
      dir.write("boxed.toml", polygon(kSlope) + kMohrCoulomb + kGravity +
                                  "[[boundary]]\nx = [-100.0, 100.0]\ny = [-100.0, 100.0]\nvelocity = { x = 0.0 }\n");
  const auto none = test::run_command(
      fmt::format("\"{}\" lem \"{}\" --no-plot --grid 5 --levels 1 --out \"{}\" 2>&1", RKTSPH_BINARY, boxed,
                  dir.file("boxed_out")));
  EXPECT_EQ(none.status, 3) << none.out;
  EXPECT_NE(none.out.find("no admissible slip circle"), std::string::npos) << none.out;
  // A bad --centres box is an input error.
  const auto box = test::run_command(fmt::format(
      "\"{}\" lem \"{}/cases/examples/slope_2to1_c10_phi20.toml\" --no-plot --centres 10 0 10 40 --out \"{}\" 2>&1",
      RKTSPH_BINARY, RKTSPH_SOURCE_DIR, dir.file("box_out")));
  EXPECT_EQ(box.status, 2) << box.out;
  EXPECT_NE(box.out.find("--centres"), std::string::npos) << box.out;
}

// With matplotlib, the command draws lem.png; a given centre box is used and reported.
TEST(LemCommand, PlotAndAGivenCentreBox) {
  if (std::system("/usr/bin/python3 -c 'import matplotlib' >/dev/null 2>&1") != 0) {
    GTEST_SKIP() << "no /usr/bin/python3 with matplotlib";
  }
  test::TempDir dir;
  const std::string out = dir.file("case5");
  const auto ok = test::run_command(
      fmt::format("\"{}\" lem \"{}/cases/thesis/05_viscoplastic_cut_2d.toml\" --grid 11 --levels 4 --centres 20 50 "
                  "10 40 --out \"{}\" 2>&1",
                  RKTSPH_BINARY, RKTSPH_SOURCE_DIR, out));
  ASSERT_EQ(ok.status, 0) << ok.out;
  EXPECT_TRUE(std::filesystem::exists(out + "/lem.png")) << ok.out;
  const auto j = nlohmann::json::parse(test::read_text(out + "/lem.json"));
  EXPECT_EQ(j["search"]["first_box"]["x"][0], 20.0);
  EXPECT_EQ(j["search"]["first_box"]["y"][1], 40.0);
  const double taylor = 57710.0 / (0.261 * 2000.0 * 9.81 * 10.0);
  EXPECT_NEAR(j["factor_of_safety"].get<double>(), taylor, 0.01 * taylor);
}

}  // namespace
}  // namespace rktsph::lem
