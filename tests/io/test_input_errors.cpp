// Every class of bad input makes the real binary exit with status 2 and a message that names
// the file, the line and the dotted key (docs/case-format.md); never a crash.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "../support/test_util.hpp"
#include "case/size_limits.hpp"

namespace rktsph {
namespace {

// A valid 2D case (one step); each test breaks one thing in it.
constexpr const char* kBase = R"(title = "input error base"

[geometry]
dimension = 2
spacing = 0.5

[[geometry.block]]
min = [0.0, 0.0]
max = [2.0, 1.0]

[material]
model = "elastic"
E = 1.0e7
nu = 0.3
density = 2000.0

[[boundary]]
name = "base"
y = [0.0, 0.0]
velocity = { x = 0.0, y = 0.0 }

[time]
end = 0.001
cfl = 0.5

[[probe]]
name = "corner"
position = [2.0, 1.0]
fields = ["vx", "syy"]
)";

std::string replace(std::string text, const std::string& from, const std::string& to) {
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << "test set-up: '" << from << "' not in the base case";
  if (pos != std::string::npos) text.replace(pos, from.size(), to);
  return text;
}

// 1-based line of the first line of `text` that contains `needle`.
int line_of(const std::string& text, const std::string& needle) {
  const auto pos = text.find(needle);
  EXPECT_NE(pos, std::string::npos) << needle;
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(pos), '\n'));
}

struct Outcome {
  int status;
  std::string err;
  std::string file;
};

Outcome run_case_text(const test::TempDir& dir, const std::string& text, const std::vector<std::string>& sets = {}) {
  const std::string file = dir.write("bad_case.toml", text);
  std::string cmd = fmt::format("\"{}\" run \"{}\" --out \"{}\" -q", RKTSPH_BINARY, file, dir.file("out"));
  for (const auto& s : sets) cmd += fmt::format(" --set '{}'", s);
  cmd += " 2>&1 1>/dev/null";
  const auto r = test::run_command(cmd);
  return {r.status, r.out, file};
}

// The common contract: status 2 (not a crash), the file and the dotted key named.
void expect_input_error(const Outcome& o, const std::string& key, const std::vector<std::string>& also = {}) {
  EXPECT_NE(o.status, 134) << "abort: " << o.err;
  EXPECT_NE(o.status, 139) << "segfault: " << o.err;
  EXPECT_EQ(o.status, 2) << o.err;
  EXPECT_NE(o.err.find(o.file), std::string::npos) << "file not named: " << o.err;
  if (!key.empty()) {
    EXPECT_NE(o.err.find("'" + key + "'"), std::string::npos) << "key '" << key << "' not named: " << o.err;
  }
  for (const auto& s : also) EXPECT_NE(o.err.find(s), std::string::npos) << "'" << s << "' missing: " << o.err;
  EXPECT_EQ(o.err.find("terminate"), std::string::npos) << o.err;
}

// Accept "line N," (followed by the key) or "line N:" (syntax errors, missing keys).
bool names_line(const std::string& err, int line) {
  return err.find(fmt::format("line {},", line)) != std::string::npos ||
         err.find(fmt::format("line {}:", line)) != std::string::npos;
}

void expect_error_at(const Outcome& o, int line, const std::string& key, const std::vector<std::string>& also = {}) {
  EXPECT_TRUE(names_line(o.err, line)) << "expected line " << line << ": " << o.err;
  expect_input_error(o, key, also);
}

TEST(InputErrors, BaseCaseRuns) {
  test::TempDir dir;
  const auto o = run_case_text(dir, kBase);
  EXPECT_EQ(o.status, 0) << o.err;
}

TEST(InputErrors, UnknownKeyListsAcceptedKeys) {
  test::TempDir dir;
  const std::string text = replace(kBase, "nu = 0.3\n", "nu = 0.3\nYoungs = 1.0e7\n");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "Youngs"), "material.Youngs",
                  {"unknown key", "accepts", "E", "density", "nu", "model"});
}

TEST(InputErrors, UnknownKeyInAnArrayOfTables) {
  test::TempDir dir;
  const std::string text = replace(kBase, "max = [2.0, 1.0]\n", "max = [2.0, 1.0]\nmaterail = \"soil\"\n");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "materail"), "geometry.block[0].materail", {"unknown key", "min", "max"});
}

TEST(InputErrors, WrongType) {
  test::TempDir dir;
  const std::string text = replace(kBase, "nu = 0.3", "nu = \"0.3\"");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "nu = "), "material.nu", {"must be a number", "string"});
}

TEST(InputErrors, UnknownPressureDivergence) {
  test::TempDir dir;
  const std::string text = replace(kBase, "[time]", "[fluid]\nporosity = 0.3\ndensity = 1000.0\nbulk_modulus = 2.2e9\nconductivity = 1.0e-5\n[solver]\nversion = \"v3\"\npressure_divergence = \"elements\"\n[time]");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "pressure_divergence"), "solver.pressure_divergence",
                  {"consistent", "nodes", "stress_points"});
}

TEST(InputErrors, IncrementalProjectionWithStressPointDivergence) {
  test::TempDir dir;
  const std::string text = replace(
      kBase, "[time]", "[fluid]\nporosity = 0.3\ndensity = 1000.0\nbulk_modulus = 2.2e9\nconductivity = 1.0e-5\n[solver]\nversion = \"v3\"\npressure_divergence = \"stress_points\"\npressure_incremental = true\n[time]");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "pressure_incremental"), "solver.pressure_incremental", {"unstable"});
}

TEST(InputErrors, ConsistentStorageRateNeedsTheIncrementalProjection) {
  test::TempDir dir;
  const std::string text = replace(
      kBase, "[time]", "[fluid]\nporosity = 0.3\ndensity = 1000.0\nbulk_modulus = 2.2e9\nconductivity = 1.0e-5\n[solver]\nversion = \"v3\"\npressure_incremental = false\n[time]");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "pressure_incremental"), "solver.pressure_incremental",
                  {"consistent", "pressure_divergence = \"nodes\""});
}

TEST(InputErrors, FreeSurfaceDetectionNeedsV2) {
  test::TempDir dir;
  const std::string text = replace(kBase, "[time]", "[solver]\nfree_surface = \"detect\"\n[time]");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "free_surface"), "solver.free_surface", {"v2"});
}

TEST(InputErrors, UnknownFreeSurface) {
  test::TempDir dir;
  const std::string text = replace(kBase, "[time]", "[solver]\nversion = \"v2\"\nfree_surface = \"auto\"\n[time]");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "free_surface"), "solver.free_surface", {"detect", "faces"});
}

TEST(InputErrors, UnknownReseedSetting) {
  test::TempDir dir;
  const std::string text = replace(kBase, "[time]", "[solver]\nversion = \"v2\"\nreseed = \"always\"\n[time]");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "reseed"), "solver.reseed", {"off", "auto", "periodic"});
}

TEST(InputErrors, ReseedingNeedsV2) {
  test::TempDir dir;
  const std::string text = replace(kBase, "[time]", "[solver]\nreseed = \"auto\"\n[time]");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "reseed"), "solver.reseed", {"v2"});
}

TEST(InputErrors, ReseedFillOutOfRange) {
  test::TempDir dir;
  const std::string text =
      replace(kBase, "[time]", "[solver]\nversion = \"v2\"\nreseed = \"auto\"\nreseed_fill = 1.5\n[time]");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "reseed_fill"), "solver.reseed_fill", {"(0, 1]"});
}

TEST(InputErrors, GradientFloorOutOfRange) {
  test::TempDir dir;
  const std::string text = replace(kBase, "[time]", "[solver]\nversion = \"v2\"\ngradient_floor = -0.1\n[time]");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "gradient_floor"), "solver.gradient_floor", {"[0, 0.5]"});
}

// The simple scheme's weights and the nodal stress filter are retired (method-notes §2.6): each
// is refused with the reason, naming its line and key.
TEST(InputErrors, RetiredStabilisationKeysAreRefusedWithTheReason) {
  test::TempDir dir;
  for (const char* entry : {"simple_weight = 0.5", "simple_stress_weight = 0.2", "stress_filter = 0.5",
                            "stress_filter_part = \"mean\""}) {
    const std::string key = std::string(entry).substr(0, std::string(entry).find(' '));
    const std::string text =
        replace(kBase, "[time]", fmt::format("[solver]\nversion = \"v2\"\nvelocity_update = \"simple\"\n{}\n[time]", entry));
    const auto o = run_case_text(dir, text);
    expect_error_at(o, line_of(text, key), "solver." + key, {"retired", "velocity_update = \"hourglass\""});
  }
}

TEST(InputErrors, ShiftingNeedsV2WithTheDetectedSurface) {
  test::TempDir dir;
  const std::string text =
      replace(kBase, "[time]", "[solver]\nversion = \"v2\"\nfree_surface = \"faces\"\nshift = \"auto\"\n[time]");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "shift"), "solver.shift", {"detect"});
}

TEST(InputErrors, ShiftStrengthOutOfRange) {
  test::TempDir dir;
  const std::string text =
      replace(kBase, "[time]", "[solver]\nversion = \"v2\"\nshift = \"periodic\"\nshift_strength = 0.5\n[time]");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "shift_strength"), "solver.shift_strength", {"(0, 0.1]"});
}

TEST(InputErrors, ParticleSortUnknownOrOutsideV2) {
  test::TempDir dir;
  const std::string unknown = replace(kBase, "[time]", "[solver]\nversion = \"v2\"\nsort = \"hilbert\"\n[time]");
  expect_error_at(run_case_text(dir, unknown), line_of(unknown, "sort"), "solver.sort", {"auto", "always", "off"});
  const std::string v1 = replace(kBase, "[time]", "[solver]\nsort = \"always\"\n[time]");
  expect_error_at(run_case_text(dir, v1), line_of(v1, "sort"), "solver.sort", {"v2"});
}

TEST(InputErrors, OperatorStorageUnknownOrOutsideV2) {
  test::TempDir dir;
  const std::string unknown = replace(kBase, "[time]", "[solver]\nversion = \"v2\"\noperators = \"cached\"\n[time]");
  expect_error_at(run_case_text(dir, unknown), line_of(unknown, "operators"), "solver.operators",
                  {"auto", "on_the_fly", "stored"});
  const std::string v1 = replace(kBase, "[time]", "[solver]\noperators = \"stored\"\n[time]");
  expect_error_at(run_case_text(dir, v1), line_of(v1, "operators"), "solver.operators", {"v2"});
}

TEST(InputErrors, SurfaceRefreshOutOfRangeOrWithoutDetection) {
  test::TempDir dir;
  const std::string negative = replace(kBase, "[time]", "[solver]\nversion = \"v2\"\nsurface_refresh = -0.1\n[time]");
  expect_error_at(run_case_text(dir, negative), line_of(negative, "surface_refresh"), "solver.surface_refresh",
                  {"[0, 0.5]"});
  const std::string faces =
      replace(kBase, "[time]", "[solver]\nversion = \"v2\"\nfree_surface = \"faces\"\nsurface_refresh = 0.1\n[time]");
  expect_error_at(run_case_text(dir, faces), line_of(faces, "surface_refresh"), "solver.surface_refresh", {"detect"});
}

TEST(InputErrors, SurfaceMirrorsNeedTheDetectedSurface) {
  test::TempDir dir;
  const std::string v1 = replace(kBase, "[time]", "[solver]\nsurface_mirrors = true\n[time]");
  expect_error_at(run_case_text(dir, v1), line_of(v1, "surface_mirrors"), "solver.surface_mirrors", {"detect"});
  const std::string word = replace(kBase, "[time]", "[solver]\nversion = \"v2\"\nsurface_mirrors = \"yes\"\n[time]");
  expect_error_at(run_case_text(dir, word), line_of(word, "surface_mirrors"), "solver.surface_mirrors", {});
}

TEST(InputErrors, DomainBoxNeedsBothCorners) {
  test::TempDir dir;
  const std::string text = replace(kBase, "[time]", "[solver]\nversion = \"v2\"\ndomain_min = [-1.0, -1.0]\n[time]");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "domain_min"), "solver.domain_min", {"domain_max"});
}

TEST(InputErrors, DomainBoxNeedsV2) {
  test::TempDir dir;
  const std::string text =
      replace(kBase, "[time]", "[solver]\ndomain_min = [-1.0, -1.0]\ndomain_max = [5.0, 5.0]\n[time]");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "domain_min"), "solver.domain_min", {"v2"});
}

TEST(InputErrors, DomainBoxMaxBelowMin) {
  test::TempDir dir;
  const std::string text = replace(
      kBase, "[time]", "[solver]\nversion = \"v2\"\ndomain_min = [-1.0, -1.0]\ndomain_max = [5.0, -2.0]\n[time]");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "domain_max"), "solver.domain_max", {"axis y"});
}

TEST(InputErrors, DomainBoxThatCutsTheBody) {
  test::TempDir dir;
  const std::string text = replace(
      kBase, "[time]", "[solver]\nversion = \"v2\"\ndomain_min = [-1.0, -1.0]\ndomain_max = [1.0, 5.0]\n[time]");
  const auto o = run_case_text(dir, text);
  // Found once the particles exist: the message names the key's line and the first particle out.
  EXPECT_NE(o.status, 0);
  EXPECT_TRUE(names_line(o.err, line_of(text, "domain_min"))) << o.err;
  EXPECT_NE(o.err.find("outside the domain box"), std::string::npos) << o.err;
}

TEST(InputErrors, StepFromTheCurrentStateNeedsV2) {
  test::TempDir dir;
  const std::string text = replace(kBase, "cfl = 0.5", "cfl = 0.5\ndt_rule = \"current\"");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "dt_rule"), "time.dt_rule", {"v2"});
}

TEST(InputErrors, StepFromTheCurrentStateWithAFixedStep) {
  test::TempDir dir;
  const std::string text = replace(replace(kBase, "cfl = 0.5", "dt = 1e-5\ndt_rule = \"current\""), "[time]",
                                   "[solver]\nversion = \"v2\"\n[time]");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "dt_rule"), "time.dt_rule", {"time.cfl"});
}

TEST(InputErrors, UnknownStepRule) {
  test::TempDir dir;
  const std::string text = replace(kBase, "cfl = 0.5", "cfl = 0.5\ndt_rule = \"adaptive\"");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "dt_rule"), "time.dt_rule", {"adaptive", "current"});
}

// A V2 case with the keys of V3: the [fluid] table, a pore-pressure condition, a pressure-solve
// option; each named at its line, none silently dropped.
TEST(InputErrors, V2CaseWithV3Keys) {
  const std::string v2 = replace(kBase, "[time]", "[solver]\nversion = \"v2\"\n[time]");
  {
    test::TempDir dir;
    const std::string text = replace(v2, "[solver]", "[solver]\npressure_faces = \"implicit\"");
    expect_error_at(run_case_text(dir, text), line_of(text, "pressure_faces"), "solver.pressure_faces", {"v3"});
  }
  {
    test::TempDir dir;
    const std::string text = replace(v2, "[time]", "[fluid]\nporosity = 0.3\nbulk_modulus = 2.2e9\n[time]");
    expect_error_at(run_case_text(dir, text), line_of(text, "porosity"), "fluid.porosity", {"v3"});
  }
  {
    test::TempDir dir;
    const std::string text = replace(v2, "name = \"base\"", "name = \"base\"\nimpermeable = true");
    const auto o = run_case_text(dir, text);
    EXPECT_NE(o.status, 0);
    EXPECT_NE(o.err.find("v3"), std::string::npos) << o.err;
  }
}

TEST(InputErrors, PressureFilterOutOfRange) {
  test::TempDir dir;
  const std::string text = replace(kBase, "[time]", "[fluid]\nporosity = 0.3\ndensity = 1000.0\nbulk_modulus = 2.2e9\nconductivity = 1.0e-5\n[solver]\nversion = \"v3\"\npressure_filter = -1.0\n[time]");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "pressure_filter"), "solver.pressure_filter", {"[0, 10]"});
}

TEST(InputErrors, UnknownPressureFilterGradient) {
  test::TempDir dir;
  const std::string text = replace(kBase, "[time]", "[fluid]\nporosity = 0.3\ndensity = 1000.0\nbulk_modulus = 2.2e9\nconductivity = 1.0e-5\n[solver]\nversion = \"v3\"\npressure_filter_gradient = \"cubic\"\n[time]");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "pressure_filter_gradient"), "solver.pressure_filter_gradient",
                  {"quadratic_drained", "quadratic", "linear"});
}

TEST(InputErrors, OddEvenFilterOutOfRange) {
  test::TempDir dir;
  const std::string text = replace(kBase, "[time]", "[fluid]\nporosity = 0.3\ndensity = 1000.0\nbulk_modulus = 2.2e9\nconductivity = 1.0e-5\n[solver]\nversion = \"v3\"\npressure_odd_even_filter = 1.5\n[time]");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "pressure_odd_even_filter"), "solver.pressure_odd_even_filter", {"[0, 1]"});
}

TEST(InputErrors, WrongTypeOfAnArray) {
  test::TempDir dir;
  const std::string text = replace(kBase, "min = [0.0, 0.0]", "min = 0.0");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "min = 0.0"), "geometry.block[0].min", {"array"});
}

TEST(InputErrors, MissingRequiredKey) {
  test::TempDir dir;
  const std::string text = replace(kBase, "density = 2000.0\n", "");
  const auto o = run_case_text(dir, text);
  // The error points at the table that lacks the key.
  expect_error_at(o, line_of(text, "[material]"), "material.density", {"missing"});
}

TEST(InputErrors, NonPositiveYoungsModulus) {
  test::TempDir dir;
  for (const char* bad : {"E = 0.0", "E = -1.0e7"}) {
    const std::string text = replace(kBase, "E = 1.0e7", bad);
    const auto o = run_case_text(dir, text);
    expect_error_at(o, line_of(text, bad), "material.E", {"> 0"});
  }
}

TEST(InputErrors, PoissonRatioOutOfRange) {
  test::TempDir dir;
  for (const char* bad : {"nu = 0.5", "nu = -1.0", "nu = 0.7"}) {
    const std::string text = replace(kBase, "nu = 0.3", bad);
    const auto o = run_case_text(dir, text);
    expect_error_at(o, line_of(text, bad), "material.nu", {"(-1, 0.5)"});
  }
}

TEST(InputErrors, NonPositiveDensity) {
  test::TempDir dir;
  const std::string text = replace(kBase, "density = 2000.0", "density = 0");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "density = 0"), "material.density", {"> 0"});
}

TEST(InputErrors, NonPositiveSpacing) {
  test::TempDir dir;
  const std::string text = replace(kBase, "spacing = 0.5", "spacing = -0.5");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "spacing"), "geometry.spacing", {"> 0"});
}

TEST(InputErrors, MisalignedBlock) {
  test::TempDir dir;
  const std::string text = replace(kBase, "max = [2.0, 1.0]", "max = [2.2, 1.0]");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "[[geometry.block]]"), "geometry.block[0]", {"lattice"});
}

TEST(InputErrors, JitterOfHalfASpacingOrMore) {
  test::TempDir dir;
  {
    const std::string text = replace(kBase, "spacing = 0.5\n", "spacing = 0.5\njitter = 0.5\n");
    const auto o = run_case_text(dir, text);
    expect_error_at(o, line_of(text, "jitter"), "geometry.jitter", {"[0, 0.5)", "got 0.5"});
  }
  {
    const std::string text = replace(kBase, "spacing = 0.5\n", "spacing = 0.5\njitter = 0.1\njitter_seed = -3\n");
    const auto o = run_case_text(dir, text);
    expect_error_at(o, line_of(text, "jitter_seed"), "geometry.jitter_seed", {">= 0"});
  }
  {
    const std::string text = replace(kBase, "spacing = 0.5\n", "spacing = 0.5\njitter = 0.2\njitter_seed = 9\n");
    EXPECT_EQ(run_case_text(dir, text).status, 0);
  }
}

TEST(InputErrors, ProbeOutsideTheBody) {
  test::TempDir dir;
  const std::string text = replace(kBase, "position = [2.0, 1.0]", "position = [5.0, 1.0]");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "position = "), "probe[0].position", {"outside", "corner"});
}

// The message names the line and key of the fields (it named the position's line and a second,
// undotted key before).
TEST(InputErrors, UnknownProbeField) {
  test::TempDir dir;
  const std::string text = replace(kBase, "fields = [\"vx\", \"syy\"]", "fields = [\"vx\", \"velocity\"]");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "fields = "), "probe[0].fields", {"velocity", "available", "sxy"});
  EXPECT_EQ(o.err.find("probe[0].position"), std::string::npos) << o.err;
}

TEST(InputErrors, CourantNumberAboveLimit) {
  test::TempDir dir;
  {
    const std::string text = replace(kBase, "cfl = 0.5", "cfl = 1.35");
    const auto o = run_case_text(dir, text);
    expect_error_at(o, line_of(text, "cfl = "), "time.cfl", {"1.3"});
  }
  {
    // Through dt: c = 82.04 m/s, dx = 0.5 m -> C = 1.64 for dt = 0.01 s.
    const std::string text = replace(kBase, "cfl = 0.5", "dt = 0.01");
    const auto o = run_case_text(dir, text);
    expect_error_at(o, line_of(text, "dt = "), "time.dt", {"1.641"});
  }
  {
    // Just below the limit is accepted.
    const auto o = run_case_text(dir, replace(kBase, "cfl = 0.5", "cfl = 1.25"));
    EXPECT_EQ(o.status, 0) << o.err;
  }
}

TEST(InputErrors, UnknownMaterialModelListsKnownModels) {
  test::TempDir dir;
  const std::string text = replace(kBase, "model = \"elastic\"", "model = \"mohr_coulomb\"");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "model = "), "material.model",
                  {"mohr_coulomb", "elastic", "perzyna_von_mises", "perzyna_cam_clay", "perzyna_drucker_prager",
                   "perzyna_mohr_coulomb"});
}

TEST(InputErrors, FrictionalMaterialOutOfRange) {
  test::TempDir dir;
  const std::string dp = replace(kBase, "model = \"elastic\"",
                                 "model = \"perzyna_drucker_prager\"\ncohesion = 1.0e4\nfriction_angle = 30.0\n"
                                 "dilatancy = 10.0\nfluidity = 1.0");
  EXPECT_EQ(run_case_text(dir, dp).status, 0);
  {
    const std::string text = replace(dp, "friction_angle = 30.0", "friction_angle = 95.0");
    expect_error_at(run_case_text(dir, text), line_of(text, "friction_angle = "), "material.friction_angle",
                    {"[0, 90)", "95"});
  }
  {
    const std::string text = replace(dp, "dilatancy = 10.0", "dilatancy = 40.0");
    expect_error_at(run_case_text(dir, text), line_of(text, "dilatancy = "), "material.dilatancy", {"40"});
  }
  {
    const std::string text = replace(dp, "cohesion = 1.0e4", "cohesion = -1.0");
    expect_error_at(run_case_text(dir, text), line_of(text, "cohesion = "), "material.cohesion", {"> 0 Pa"});
  }
}

TEST(InputErrors, InvalidTomlSyntax) {
  test::TempDir dir;
  const std::string text = replace(kBase, "E = 1.0e7", "E = = 1.0e7");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "E = = "), "", {"not valid TOML"});
}

TEST(InputErrors, SetOverrideWithWrongType) {
  test::TempDir dir;
  {
    const auto o = run_case_text(dir, kBase, {"material.E=stiff"});
    expect_input_error(o, "material.E", {"command line", "must be a number", "string"});
  }
  {
    const auto o = run_case_text(dir, kBase, {"time.cfl=[0.5]"});
    expect_input_error(o, "time.cfl", {"command line", "array"});
  }
  {
    // A misspelt --set key is an unknown key like one in the file.
    const auto o = run_case_text(dir, kBase, {"material.Ee=1.0e7"});
    expect_input_error(o, "material.Ee", {"unknown key", "command line"});
  }
  {
    // A good override runs.
    const auto o = run_case_text(dir, kBase, {"material.E=2.0e7"});
    EXPECT_EQ(o.status, 0) << o.err;
  }
}

// ---- size guards (case/size_limits.hpp, docs/case-format.md "Size limits")

TEST(InputErrors, StepCountBeyondMaxSteps) {
  test::TempDir dir;
  {
    // Used to overflow the step count: 0 steps, "completed".
    const auto o = run_case_text(dir, kBase, {"time.end=1e30"});
    expect_input_error(o, "time.end", {"command line", "steps", "time.max_steps", "1e+15"});
  }
  {
    // A light material: c = 4e13 m/s, 1.5e11 steps (used to run until killed).
    const auto o = run_case_text(dir, kBase, {"material.density=1e-20"});
    expect_error_at(o, line_of(kBase, "end = "), "time.end", {"steps", "c = ", "time.max_steps"});
  }
}

TEST(InputErrors, MaxStepsAllowsALongerRun) {
  test::TempDir dir;
  // dt = 0.5 * 0.5 m / 82.04 m/s = 3.047e-3 s: 0.05 s is 16.4 steps.
  {
    const auto o = run_case_text(dir, kBase, {"time.end=0.05", "time.max_steps=10"});
    expect_input_error(o, "time.end", {"16.4", "time.max_steps (>= 17)"});
  }
  {
    const auto o = run_case_text(dir, kBase, {"time.end=0.05", "time.max_steps=17"});
    EXPECT_EQ(o.status, 0) << o.err;
  }
  for (const char* bad : {"time.max_steps=0", "time.max_steps=1e16", "time.max_steps=-5"}) {
    const auto o = run_case_text(dir, kBase, {bad});
    expect_input_error(o, "time.max_steps", {"[1, 1e+15]"});
  }
}

TEST(InputErrors, TinySpacingNamesTheSpacing) {
  test::TempDir dir;
  // Used to overflow the lattice's int coordinates and report a misaligned block.
  const std::string text = replace(kBase, "spacing = 0.5", "spacing = 1.0e-12");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "spacing"), "geometry.spacing", {"geometry.block[0]", "cells per axis"});
}

TEST(InputErrors, BlockFarFromTheOrigin) {
  test::TempDir dir;
  const auto o = run_case_text(dir, kBase, {"geometry.origin=[1.0e12, 0.0]"});
  expect_error_at(o, line_of(kBase, "min = "), "geometry.block[0].min", {"spacings", "geometry.origin"});
}

TEST(InputErrors, BlocksSpanningTooManyCells) {
  test::TempDir dir;
  // Each block is small and near enough to the origin, but together they span 6e8 cells.
  const std::string text = replace(replace(kBase, "spacing = 0.5", "spacing = 1.0"), "[material]",
                                   "[[geometry.block]]\nmin = [-3.0e8, 0.0]\nmax = [-2.99999998e8, 1.0]\n\n"
                                   "[[geometry.block]]\nmin = [3.0e8, 0.0]\nmax = [3.00000002e8, 1.0]\n\n[material]");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "spacing"), "geometry.spacing", {"blocks together span 6e+08 cells", "per axis"});
}

TEST(InputErrors, TooManyParticles) {
  test::TempDir dir;
  // 2e5 x 1e5 cells: 2e10 particles, more than a 32-bit index.
  const std::string text = replace(kBase, "spacing = 0.5", "spacing = 1.0e-5");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "spacing"), "geometry.spacing", {"2147483647 particles"});
}

TEST(InputErrors, MemoryEstimateAboveThePhysicalMemory) {
  test::TempDir dir;
  // 4e4 x 2e4 cells: 8e8 nodes, about 520 GiB at 700 bytes per node (a dry 2D case).
  const double need = 8.0e8 * bytes_per_node(2, false);
  if (physical_memory_bytes() >= need) GTEST_SKIP() << "this machine has more than " << need << " bytes";
  const std::string text = replace(kBase, "spacing = 0.5", "spacing = 5.0e-5");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "spacing"), "geometry.spacing",
                  {"8e+08 nodes", "GiB", "bytes per node", "memory", "larger spacing"});
}

// ---- numbers

TEST(InputErrors, IntegerBeyondADoubleIsANumber) {
  test::TempDir dir;
  // An integer a double does not hold exactly used to be "not a number" (and, in an array, an
  // uncaught std::bad_optional_access, exit 1).
  const std::string text = replace(kBase, "min = [0.0, 0.0]", "min = [9223372036854775807, 0.0]");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "min = "), "geometry.block[0].min", {"spacings"});
  const auto e = run_case_text(dir, replace(kBase, "E = 1.0e7", "E = 9223372036854775807"), {"time.max_steps=10"});
  expect_input_error(e, "time.end", {"steps"});
}

TEST(InputErrors, NumbersBeyondThePhysicalRange) {
  test::TempDir dir;
  for (const char* bad : {"E = 1.0e300", "E = -1.0e101"}) {
    const std::string text = replace(kBase, "E = 1.0e7", bad);
    const auto o = run_case_text(dir, text);
    expect_error_at(o, line_of(text, bad), "material.E", {"1e+100"});
  }
  const std::string text = replace(kBase, "position = [2.0, 1.0]", "position = [2.0, 1e200]");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "position = "), "probe[0].position", {"1e+100"});
}

TEST(InputErrors, IntegersBeyondTheirRange) {
  test::TempDir dir;
  {
    // 2^32 + 1 used to wrap to 1.
    const std::string text = replace(kBase, "[[probe]]", "[output]\nprobe_every = 4294967297\n\n[[probe]]");
    const auto o = run_case_text(dir, text);
    expect_error_at(o, line_of(text, "probe_every"), "output.probe_every", {"2147483647"});
  }
  {
    const std::string text =
        replace(kBase, "[time]", "[fluid]\nporosity = 0.3\ndensity = 1000.0\nbulk_modulus = 2.2e9\nconductivity = 1.0e-5\n[solver]\nversion = \"v3\"\npressure_max_iterations = 9223372036854775807\n[time]");
    const auto o = run_case_text(dir, text);
    expect_error_at(o, line_of(text, "pressure_max_iterations"), "solver.pressure_max_iterations", {"2147483647"});
  }
}

// ---- output

TEST(InputErrors, OutputIntervalFarBelowTheStep) {
  test::TempDir dir;
  // The frame clock would need 1e297 rounds (and stall below the clock's rounding): a hang.
  const std::string text = replace(kBase, "[[probe]]", "[output]\ninterval = 1.0e-300\n\n[[probe]]");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "interval"), "output.interval", {"time.max_steps", "time step"});
}

TEST(InputErrors, SnapshotTimesPastTheEndWarn) {
  test::TempDir dir;
  const std::string text = replace(kBase, "[[probe]]", "[output]\ntimes = [0.0005, 5.0, 2.0]\n\n[[probe]]");
  const std::string file = dir.write("late.toml", text);
  const auto r = test::run_command(
      fmt::format("\"{}\" run \"{}\" --out \"{}\" -q 2>&1 1>/dev/null", RKTSPH_BINARY, file, dir.file("out")));
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("warning: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(file), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(fmt::format("line {}, key 'output.times'", line_of(text, "times = "))), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("2 of the snapshot times (2, 5 s) are past time.end = 0.001 s"), std::string::npos) << r.out;
  // The reader keeps the warning for callers that print their own.
  const auto setup = test::case_from_string<2>(dir, text);
  ASSERT_EQ(setup.warnings.size(), 1u);
}

TEST(InputErrors, NegativeSnapshotTime) {
  test::TempDir dir;
  const std::string text = replace(kBase, "[[probe]]", "[output]\ntimes = [0.0005, -1.0]\n\n[[probe]]");
  const auto o = run_case_text(dir, text);
  expect_error_at(o, line_of(text, "times = "), "output.times", {">= 0"});
}

TEST(InputErrors, ProbeNamesThatBreakTheCsvHeader) {
  test::TempDir dir;
  const std::vector<std::pair<std::string, std::string>> bad = {
      {R"(name = "a,b")", "a comma"},
      {R"(name = "a\"b")", "a double quote"},
      {R"(name = "a\nb")", "a control character (code 10)"},
      {R"(name = "a\tb")", "a control character (code 9)"},
      {R"(name = "")", "must not be empty"},
  };
  for (const auto& [line, why] : bad) {
    const std::string text = replace(kBase, "name = \"corner\"", line);
    const auto o = run_case_text(dir, text);
    expect_error_at(o, line_of(text, line), "probe[0].name", {why, "probes.csv"});
  }
  // Dots, blanks and other printable characters are fine.
  const auto o = run_case_text(dir, replace(kBase, "name = \"corner\"", "name = \"top corner (x=2).v\""));
  EXPECT_EQ(o.status, 0) << o.err;
}

// ---- --set

TEST(InputErrors, SetWithTextAfterTheValue) {
  test::TempDir dir;
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"time.end=1.0abc", "'1.0' is a value but 'abc' follows it"},
      {"solver.version=\"v1\"x", "'\"v1\"' is a value but 'x' follows it"},
      {"geometry.origin=[0.0, 0.0]x", "'[0.0, 0.0]' is a value but 'x' follows it"},
      {"time.end=0.001 # a comment", "text after the value: '# a comment'"},
      {"time.end=0.001\nmaterial.E=1", "text after the value: 'material.E=1'"},
      {"time.end=", "no value after '='"},
      {"geometry.origin=[0.0, 0.0", "is not a valid TOML value"},
      {"title=\"unclosed", "is not a valid TOML value"},
  };
  for (const auto& [set, why] : bad) {
    const auto o = run_case_text(dir, kBase, {set});
    expect_input_error(o, "", {"--set '", why});
  }
  // A bare word is still a string, and blanks around a value are fine.
  for (const char* good : {"solver.version=v1", "title=a bare title", "time.end= 0.001 "}) {
    const auto o = run_case_text(dir, kBase, {good});
    EXPECT_EQ(o.status, 0) << good << ": " << o.err;
  }
}

TEST(InputErrors, SetKeyPaths) {
  test::TempDir dir;
  {
    const auto o = run_case_text(dir, kBase, {"time.end.x=1.0"});
    expect_input_error(
        o, "", {"--set '", fmt::format("'time.end' is a value (line {}), not a table", line_of(kBase, "end = "))});
  }
  {
    // std::stoul read "0x" as 0.
    const auto o = run_case_text(dir, kBase, {"boundary.0x.name=a"});
    expect_input_error(o, "", {"--set '", "'0x' indexes an array and must be a whole number"});
  }
  {
    const auto o = run_case_text(dir, kBase, {"boundary.3.name=a"});
    expect_input_error(o, "", {"--set '", "index 3 is past the end of the array (1 entries)"});
  }
  for (const char* bad : {"time..end=1.0", ".time.end=1.0", "time.end.=1.0", "time. end=1.0"}) {
    const auto o = run_case_text(dir, kBase, {bad});
    expect_input_error(o, "", {"--set '", "empty or blank-padded part"});
  }
}

// ---- material-point inputs (case/material_point_reader.cpp)

constexpr const char* kMaterialPoint = R"([material]
model = "perzyna_von_mises"
E = 1.0e7
nu = 0.3
density = 2000.0
cohesion = 5.0e4
fluidity = 1.0

[initial]
stress = { xx = -1.0e5, yy = -1.0e5, zz = -1.0e5 }

[path]
type = "simple_shear"
shear_strain_rate = 0.01
duration = 1.0
dt = 0.01

[output]
plot = false
)";

Outcome run_material_point_text(const test::TempDir& dir, const std::string& text,
                                const std::vector<std::string>& sets = {}) {
  const std::string file = dir.write("bad_point.toml", text);
  std::string cmd = fmt::format("\"{}\" material-point \"{}\" --out \"{}\"", RKTSPH_BINARY, file, dir.file("out"));
  for (const auto& s : sets) cmd += fmt::format(" --set '{}'", s);
  cmd += " 2>&1 1>/dev/null";
  const auto r = test::run_command(cmd);
  return {r.status, r.out, file};
}

TEST(InputErrors, MaterialPointBaseRuns) {
  test::TempDir dir;
  const auto o = run_material_point_text(dir, kMaterialPoint);
  EXPECT_EQ(o.status, 0) << o.err;
}

TEST(InputErrors, MaterialPointStepsAndRows) {
  test::TempDir dir;
  {
    // 1e300 steps used to run until killed.
    const std::string text = replace(kMaterialPoint, "dt = 0.01", "dt = 1.0e-300");
    const auto o = run_material_point_text(dir, text);
    expect_error_at(o, line_of(text, "dt = "), "path.dt", {"steps", "larger dt"});
  }
  {
    // 5e7 steps, each a row: 5e7 rows held in memory and written.
    const std::string text = replace(kMaterialPoint, "dt = 0.01", "dt = 2.0e-8");
    const auto o = run_material_point_text(dir, text);
    expect_input_error(o, "path.output_every", {"rows of path.csv", "raise output_every"});
  }
  {
    const std::string text = replace(kMaterialPoint, "dt = 0.01", "dt = 0.01\noutput_every = 4294967297");
    const auto o = run_material_point_text(dir, text);
    expect_error_at(o, line_of(text, "output_every"), "path.output_every", {"2147483647"});
  }
}

TEST(InputErrors, MaterialPointSetIsCheckedLikeRun) {
  test::TempDir dir;
  {
    const auto o = run_material_point_text(dir, kMaterialPoint, {"material.E=1.0e7abc"});
    expect_input_error(o, "", {"--set '", "'1.0e7' is a value but 'abc' follows it"});
  }
  {
    // Array-of-tables entries and plain keys work as with run.
    const auto o = run_material_point_text(dir, kMaterialPoint, {"material.E=2.0e7", "path.duration=0.5"});
    EXPECT_EQ(o.status, 0) << o.err;
  }
}

// The base case as a 3D block (geometry.dimension = 3).
std::string base_3d() {
  std::string t = replace(kBase, "dimension = 2", "dimension = 3");
  t = replace(t, "min = [0.0, 0.0]", "min = [0.0, 0.0, 0.0]");
  t = replace(t, "max = [2.0, 1.0]", "max = [2.0, 1.0, 1.0]");
  t = replace(t, "y = [0.0, 0.0]\nvelocity = { x = 0.0, y = 0.0 }",
              "z = [0.0, 0.0]\nvelocity = { x = 0.0, y = 0.0, z = 0.0 }");
  return replace(t, "position = [2.0, 1.0]", "position = [2.0, 1.0, 1.0]");
}

TEST(InputErrors, ThreeDimensionalCases) {
  test::TempDir dir;
  {
    const auto o = run_case_text(dir, base_3d());
    EXPECT_EQ(o.status, 0) << o.err;
  }
  {
    const std::string text = replace(kBase, "dimension = 2", "dimension = 4");
    const auto o = run_case_text(dir, text);
    expect_error_at(o, line_of(text, "dimension = "), "geometry.dimension", {"must be 1, 2 or 3", "got 4"});
  }
  {
    // A 2D probe position in a 3D case.
    const std::string text = replace(base_3d(), "position = [2.0, 1.0, 1.0]", "position = [2.0, 1.0]");
    const auto o = run_case_text(dir, text);
    expect_error_at(o, line_of(text, "position = [2.0, 1.0]"), "probe[0].position", {"3 coordinates", "3D"});
  }
  {
    // A 2D block corner in a 3D case.
    const std::string text = replace(base_3d(), "max = [2.0, 1.0, 1.0]", "max = [2.0, 1.0]");
    const auto o = run_case_text(dir, text);
    expect_error_at(o, line_of(text, "max = [2.0, 1.0]"), "geometry.block[0].max", {"3"});
  }
  {
    const std::string text =
        replace(base_3d(), "velocity = { x = 0.0, y = 0.0, z = 0.0 }", "velocity = { x = 0.0, w = 0.0 }");
    const auto o = run_case_text(dir, text);
    expect_input_error(o, "boundary[0].velocity.w", {"unknown velocity component", "x, y, z"});
  }
  {
    // A 3D face takes every stress component; 2D (plane strain) not zz, which acts on no face.
    const std::string face =
        "[[boundary]]\nname = \"top\"\nz = [1.0, 1.0]\nstress = { zz = -1.0e3, yz = 0.0, xz = 0.0 }\n";
    EXPECT_EQ(run_case_text(dir, base_3d() + face).status, 0);
    const std::string text =
        std::string(kBase) + "[[boundary]]\nname = \"top\"\ny = [1.0, 1.0]\nstress = { zz = -1.0e3 }\n";
    const auto o = run_case_text(dir, text);
    expect_input_error(o, "boundary[1].stress.zz", {"can be prescribed in 2D", "xx, yy, xy"});
  }
  {
    const std::string text = base_3d() + "[[body]]\nname = \"plate\"\n";
    const auto o = run_case_text(dir, text);
    expect_input_error(o, "body", {"2D only"});
  }
  {
    std::string text = replace(base_3d(), "[[geometry.block]]\nmin = [0.0, 0.0, 0.0]\nmax = [2.0, 1.0, 1.0]\n",
                               "[[geometry.polygon]]\nvertices = [[0.0, 0.0], [2.0, 0.0], [2.0, 1.0]]\n");
    const auto o = run_case_text(dir, text);
    expect_input_error(o, "geometry.polygon[0]", {"two-dimensional", "geometry.dimension = 2"});
  }
  {
    // 3D: the angular velocity is a vector.
    EXPECT_EQ(run_case_text(dir, base_3d() + "[initial_velocity]\nangular_velocity = [0.0, 0.0, 1.0]\n").status, 0);
    const std::string text = base_3d() + "[initial_velocity]\nangular_velocity = 1.0\n";
    const auto o = run_case_text(dir, text);
    expect_input_error(o, "initial_velocity.angular_velocity", {"3"});
  }
}

}  // namespace
}  // namespace rktsph
