// geometry.particles (case/particle_file_reader.hpp, docs/case-format.md "Particles from
// files"): a lattice written out to CSV files and read back is the block case's particle sets
// bit for bit, and a V2 run on it gives the block case's result bit for bit; every bad file
// makes the binary exit with status 2 naming the case file, the key, the CSV file, its line
// and its column.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "../support/test_util.hpp"
#include "schemes/simulation.hpp"

namespace rktsph {
namespace {

// A V2 column on a fixed base under gravity. The base is selected by a thin box, not a plane: a
// plane would also make the lattice faces' traction-free components at the base corners
// prescribed, which particles from files do not have (they lie on no lattice face).
constexpr const char* kMaterialAndLoads = R"(
[material]
model = "elastic"
E = 1.0e7
nu = 0.3
density = 2000.0

[body_force]
gravity = [0.0, -9.81]

[[boundary]]
name = "base"
y = [-0.01, 0.01]
velocity = { x = 0.0, y = 0.0 }

[solver]
version = "v2"

[time]
end = 0.02
cfl = 0.5
)";

std::string block_case() {
  return std::string(R"(title = "block column"
[geometry]
dimension = 2
spacing = 0.25
[[geometry.block]]
min = [0.0, 0.0]
max = [2.0, 1.0]
)") + kMaterialAndLoads;
}

std::string file_case(const std::string& nodes = "nodes.csv", const std::string& stress_points = "sp.csv") {
  return fmt::format(R"(title = "column from files"
[geometry]
dimension = 2
spacing = 0.25
[[geometry.particles]]
nodes = "{}"
stress_points = "{}"
)",
                     nodes, stress_points) +
         kMaterialAndLoads;
}

// The set as CSV, with every double written to round trip exactly; with `faces`, the nodes'
// face areas too.
std::string csv_of(const ParticleSet<2>& set, bool with_density, const BoundaryNodes<2>* faces = nullptr) {
  std::string out = with_density ? "x,y,volume,material,density" : "x,y,volume,material";
  out += faces != nullptr ? ",face_-x,face_+x,face_-y,face_+y\n" : "\n";
  for (Index i = 0; i < set.size(); ++i) {
    const auto u = static_cast<std::size_t>(i);
    out += fmt::format("{:.17g},{:.17g},{:.17g},material", set.position[u][0], set.position[u][1], set.volume[u]);
    if (with_density) out += fmt::format(",{:.17g}", set.density[u]);
    if (faces != nullptr) {
      for (const double a : faces->area_of(i)) out += fmt::format(",{:.17g}", a);
    }
    out += "\n";
  }
  return out;
}

void expect_same_set(const ParticleSet<2>& a, const ParticleSet<2>& b) {
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(a.position, b.position);
  EXPECT_EQ(a.volume, b.volume);
  EXPECT_EQ(a.density, b.density);
  EXPECT_EQ(a.material, b.material);
  EXPECT_EQ(a.global_id, b.global_id);
  EXPECT_EQ(a.fingerprint(), b.fingerprint());
}

TEST(ParticleFiles, ALatticeWrittenOutIsTheBlockCaseBitForBit) {
  const test::ThreadCount threads(1);
  test::TempDir dir;
  Simulation<2> blocks(test::case_from_string<2>(dir, block_case(), {}, "blocks.toml"));
  dir.write("nodes.csv", csv_of(blocks.nodes(), true));
  dir.write("sp.csv", csv_of(blocks.stress_points(), false));  // density from the material
  Simulation<2> files(test::case_from_string<2>(dir, file_case(), {}, "files.toml"));
  expect_same_set(blocks.nodes(), files.nodes());
  expect_same_set(blocks.stress_points(), files.stress_points());
  EXPECT_EQ(files.model().boundary.size(), 0u);  // no lattice faces
  EXPECT_EQ(blocks.model().constraints.constrained(), files.model().constraints.constrained());

  while (blocks.time() < 0.02 - 1e-12) {
    blocks.step();
    files.step();
  }
  ASSERT_EQ(blocks.step_count(), files.step_count());
  const auto n = static_cast<std::size_t>(blocks.nodes().size());
  double largest = 0.0, largest_stress = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_EQ(blocks.nodes().position[i], files.nodes().position[i]) << "node " << i;
    for (const StressComponent c : {StressComponent::xx, StressComponent::yy, StressComponent::zz, StressComponent::xy})
      EXPECT_EQ(blocks.node_stress()(i, c), files.node_stress()(i, c)) << "node " << i;
    for (int d = 0; d < 2; ++d) EXPECT_EQ(blocks.node_velocity()(i, d), files.node_velocity()(i, d));
    largest = std::max(largest, std::abs(blocks.node_displacement()(i, 1)));
    largest_stress = std::max(largest_stress, std::abs(blocks.node_stress()(i, StressComponent::yy)));
  }
  EXPECT_GT(largest, 0.0);  // the run did something
  EXPECT_GT(largest_stress, 100.0);
  std::printf("%ld V2 steps: largest settlement %.4g m, largest |syy| %.4g Pa, identical in both runs\n",
              blocks.step_count(), largest, largest_stress);
}

// V1 on a plate with plane boundary entries, a partial load and free faces: with the nodes'
// faces in the file, the lattice's face rules, segment averaging and traction work all hold.
std::string plate_case(const std::string& geometry) {
  return R"(title = "loaded plate"
[geometry]
dimension = 2
spacing = 0.25
)" + geometry +
         R"(
[material]
model = "elastic"
E = 1.0e7
nu = 0.3
density = 2000.0
[[boundary]]
name = "base"
y = [0.0, 0.0]
velocity = { x = 0.0, y = 0.0 }
[[boundary]]
name = "left wall"
x = [0.0, 0.0]
velocity = { x = 0.0 }
[[boundary]]
name = "footing"
x = [0.0, 0.6]
y = [1.0, 1.0]
stress = { yy = -2.0e4 }
function = "load"
[functions.load]
type = "smoothstep"
duration = 0.01
[time]
end = 0.03
cfl = 0.5
)";
}

TEST(ParticleFiles, NodesWithTheirFacesRunAsTheBlockCaseInV1) {
  const test::ThreadCount threads(1);
  test::TempDir dir;
  Simulation<2> blocks(test::case_from_string<2>(
      dir, plate_case("[[geometry.block]]\nmin = [0.0, 0.0]\nmax = [2.0, 1.0]\n"), {}, "blocks.toml"));
  dir.write("nodes.csv", csv_of(blocks.nodes(), false, &blocks.model().boundary));
  dir.write("sp.csv", csv_of(blocks.stress_points(), false));
  Simulation<2> files(test::case_from_string<2>(
      dir, plate_case("[[geometry.particles]]\nnodes = \"nodes.csv\"\nstress_points = \"sp.csv\"\n"), {},
      "files.toml"));
  expect_same_set(blocks.nodes(), files.nodes());
  expect_same_set(blocks.stress_points(), files.stress_points());
  const auto& a = blocks.model().boundary;
  const auto& b = files.model().boundary;
  EXPECT_EQ(a.node, b.node);
  EXPECT_EQ(a.faces, b.faces);
  EXPECT_EQ(a.area, b.area);
  EXPECT_EQ(blocks.model().constraints.constrained(), files.model().constraints.constrained());
  while (blocks.time() < 0.03 - 1e-12) {
    blocks.step();
    files.step();
  }
  ASSERT_EQ(blocks.step_count(), files.step_count());
  double largest = 0.0;
  for (Index i = 0; i < blocks.nodes().size(); ++i) {
    for (const StressComponent c : {StressComponent::xx, StressComponent::yy, StressComponent::zz, StressComponent::xy})
      EXPECT_EQ(blocks.node_stress()(i, c), files.node_stress()(i, c)) << "node " << i;
    for (int d = 0; d < 2; ++d) EXPECT_EQ(blocks.node_displacement()(i, d), files.node_displacement()(i, d));
    largest = std::max(largest, std::abs(blocks.node_displacement()(i, 1)));
  }
  EXPECT_EQ(blocks.clock().external_work(), files.clock().external_work());
  EXPECT_GT(largest, 1e-5);
  std::printf("%ld V1 steps: largest settlement %.4g m, external work %.4g J/m, identical in both runs\n",
              blocks.step_count(), largest, blocks.clock().external_work());
}

TEST(ParticleFiles, PathsAreRelativeToTheCaseFile) {
  test::TempDir dir;
  std::filesystem::create_directories(dir.path() / "case" / "particles");
  Simulation<2> blocks(test::case_from_string<2>(dir, block_case(), {}, "blocks.toml"));
  dir.write("case/particles/n.csv", csv_of(blocks.nodes(), false));
  dir.write("case/particles/s.csv", csv_of(blocks.stress_points(), false));
  const auto setup =
      test::case_from_string<2>(dir, file_case("particles/n.csv", "particles/s.csv"), {}, "case/files.toml");
  ASSERT_TRUE(setup.imported.has_value());
  EXPECT_EQ(setup.imported->nodes.size(), blocks.nodes().size());
}

// ---- bad files, through the binary

struct Outcome {
  int status;
  std::string err;
  std::string file;
};

Outcome run(const test::TempDir& dir, const std::string& case_text, const std::string& nodes_csv,
            const std::string& sp_csv = "x,y,volume,material\n0.5,0.5,1.0,material\n") {
  dir.write("nodes.csv", nodes_csv);
  dir.write("sp.csv", sp_csv);
  const std::string file = dir.write("case.toml", case_text);
  const auto r = test::run_command(
      fmt::format("\"{}\" run \"{}\" --out \"{}\" -q 2>&1 1>/dev/null", RKTSPH_BINARY, file, dir.file("out")));
  return {r.status, r.out, file};
}

// Status 2, and the case file, its line of the key, the key and every `also` named.
void expect_error(const Outcome& o, const std::string& key, int case_line, const std::vector<std::string>& also) {
  EXPECT_EQ(o.status, 2) << o.err;
  EXPECT_NE(o.err.find(o.file), std::string::npos) << "case file not named: " << o.err;
  EXPECT_NE(o.err.find(fmt::format("line {}, key '{}'", case_line, key)), std::string::npos)
      << "line " << case_line << " and key '" << key << "' not named: " << o.err;
  for (const auto& s : also) EXPECT_NE(o.err.find(s), std::string::npos) << "'" << s << "' missing: " << o.err;
  EXPECT_EQ(o.err.find("terminate"), std::string::npos) << o.err;
}

// A 2 x 1 m body of two cells (dx = 1 m) as nodes (the six vertices) and stress points.
constexpr const char* kNodes =
    "x,y,volume,material\n"
    "0,0,0.25,material\n"
    "1,0,0.5,material\n"
    "2,0,0.25,material\n"
    "0,1,0.25,material\n"
    "1,1,0.5,material\n"
    "2,1,0.25,material\n";
constexpr const char* kStressPoints = "x,y,volume,material\n0.5,0.5,1.0,material\n1.5,0.5,1.0,material\n";

std::string small_case(const std::string& solver = "version = \"v2\"", double spacing = 1.0) {
  return fmt::format(R"(title = "bad particle files"
[geometry]
dimension = 2
spacing = {:.2f}
[[geometry.particles]]
nodes = "nodes.csv"
stress_points = "sp.csv"
[material]
model = "elastic"
E = 1.0e7
nu = 0.3
density = 2000.0
[solver]
{}
[time]
end = 0.001
cfl = 0.5
)",
                     spacing, solver);
}
constexpr int kNodesLine = 6, kStressPointsLine = 7, kEntryLine = 5;

// The lattice of [0, 2] x [0, 1] m at spacing dx, as the two CSV files (written by hand here, not
// by the generator, with the tributary volumes of docs/case-format.md).
std::pair<std::string, std::string> lattice_files(double dx) {
  const int nx = static_cast<int>(std::lround(2.0 / dx)), ny = static_cast<int>(std::lround(1.0 / dx));
  std::string nodes = "# nodes\nx,y,volume,material\n", stress_points = "material,volume,y,x\n";
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) {
      const double share = (i == 0 || i == nx ? 0.5 : 1.0) * (j == 0 || j == ny ? 0.5 : 1.0);
      nodes += fmt::format("{},{},{},material\n", i * dx, j * dx, share * dx * dx);
      if (i < nx && j < ny)
        stress_points += fmt::format("material,{},{},{}\n", dx * dx, (j + 0.5) * dx, (i + 0.5) * dx);
    }
  }
  return {nodes, stress_points};
}

TEST(ParticleFiles, AGoodCaseRuns) {
  test::TempDir dir;
  const auto [nodes, stress_points] = lattice_files(0.25);
  const auto o = run(dir, small_case("version = \"v2\"", 0.25), nodes, stress_points);
  EXPECT_EQ(o.status, 0) << o.err;
  // The particles the reader made: the counts and the total volume of each set.
  const auto setup = test::case_from_string<2>(dir, small_case("version = \"v2\"", 0.25));
  ASSERT_TRUE(setup.imported.has_value());
  EXPECT_EQ(setup.imported->nodes.size(), 9 * 5);
  EXPECT_EQ(setup.imported->stress_points.size(), 8 * 4);
  for (const auto* set : {&setup.imported->nodes, &setup.imported->stress_points}) {
    double volume = 0.0;
    for (const double v : set->volume) volume += v;
    EXPECT_NEAR(volume, 2.0, 1e-12);
    for (const double rho : set->density) EXPECT_EQ(rho, 2000.0);
  }
  // A setup changed in code is checked by the model as the reader checks a file.
  auto without_detection = setup;
  without_detection.detect_free_surface = false;
  EXPECT_THROW(StaggeredModel<2>{without_detection}, InputError);
}

// A resumed run reads the particle files again from beside the original case file (not from
// the working folder), and refuses files that have changed since the checkpoint.
TEST(ParticleFiles, AResumedRunReadsTheFilesBesideTheCaseFile) {
  test::TempDir dir;
  std::filesystem::create_directories(dir.path() / "case");
  const auto [nodes, stress_points] = lattice_files(0.25);
  dir.write("case/nodes.csv", nodes);
  dir.write("case/sp.csv", stress_points);
  const std::string file = dir.write("case/case.toml", small_case("version = \"v2\"", 0.25));
  const std::string bin = RKTSPH_BINARY;
  auto command = [&](const std::string& args) {
    // From the root folder: a path resolved against the working folder would not be found.
    return test::run_command(fmt::format("cd / && \"{}\" {} -q 2>&1", bin, args));
  };
  auto r = command(fmt::format("run \"{}\" --out \"{}\" --set time.end=0.01", file, dir.file("run")));
  ASSERT_EQ(r.status, 0) << r.out;
  r = command(fmt::format("resume \"{}\" --set time.end=0.02", dir.file("run")));
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(test::read_text(dir.file("run/summary.json")).find("\"time\": 0.02"), std::string::npos)
      << test::read_text(dir.file("run/summary.json"));
  std::string changed = nodes;
  changed.replace(changed.find(",0.015625,"), 10, ",0.015626,");  // one corner's volume
  dir.write("case/nodes.csv", changed);
  r = command(fmt::format("resume \"{}\" --set time.end=0.03", dir.file("run")));
  EXPECT_EQ(r.status, 2) << r.out;
}

TEST(ParticleFiles, BadFilesNameTheFileLineAndColumn) {
  test::TempDir dir;
  const std::string key = "geometry.particles[0].nodes";
  const std::string good = kNodes;
  auto with_line = [&](int line, const std::string& text) {  // replace line `line` (1 = header)
    std::vector<std::string> lines;
    std::size_t start = 0;
    while (start < good.size()) {
      const auto nl = good.find('\n', start);
      lines.push_back(good.substr(start, nl - start));
      start = nl + 1;
    }
    lines[static_cast<std::size_t>(line - 1)] = text;
    std::string out;
    for (const auto& l : lines) out += l + "\n";
    return out;
  };
  struct Bad {
    std::string what, csv;
    std::vector<std::string> also;
  };
  const std::vector<Bad> cases = {
      {"missing column",
       with_line(1, "x,y,material"),
       {"nodes.csv, line 1, column 'volume'", "missing from the header"}},
      {"unknown column",
       with_line(1, "x,y,z,volume,material"),
       {"nodes.csv, line 1, column 'z'", "unknown column", "x, y, volume, material, density"}},
      {"non-numeric value",
       with_line(3, "1,zero,0.5,material"),
       {"nodes.csv, line 3, column 'y'", "'zero' is not a number"}},
      {"trailing text", with_line(3, "1,0m,0.5,material"), {"nodes.csv, line 3, column 'y'", "'0m' is not a number"}},
      {"NaN", with_line(4, "2,0,nan,material"), {"nodes.csv, line 4, column 'volume'", "not a finite number"}},
      {"infinite", with_line(4, "inf,0,0.25,material"), {"nodes.csv, line 4, column 'x'", "not a finite number"}},
      {"zero volume", with_line(5, "0,1,0,material"), {"nodes.csv, line 5, column 'volume'", "must be > 0"}},
      {"negative volume", with_line(5, "0,1,-0.25,material"), {"nodes.csv, line 5, column 'volume'", "got -0.25"}},
      {"unknown material",
       with_line(6, "1,1,0.5,clay"),
       {"nodes.csv, line 6, column 'material'", "no material named 'clay'", "defined: material"}},
      {"wrong value count", with_line(7, "2,1,0.25"), {"nodes.csv, line 7:", "3 values, but the header has 4 columns"}},
      {"duplicate position",
       with_line(7, "1.0000000001,0,0.25,material"),
       {"nodes.csv, line 7: the particle at (1.0000000001, 0) coincides with the one of nodes.csv, line 3"}},
      {"empty file", "", {"nodes.csv, line 1", "no header line"}},
      {"header only", "x,y,volume,material\n", {"nodes.csv, line 1", "no particle after the header"}},
  };
  for (const Bad& b : cases) {
    SCOPED_TRACE(b.what);
    const auto o = run(dir, small_case(), b.csv, kStressPoints);
    expect_error(o, key, kNodesLine, b.also);
  }
  // The face columns: all or none, not negative, and only in a node file.
  {
    const auto o = run(dir, small_case(), "x,y,volume,material,face_-x,face_+x,face_-y\n0,0,0.25,material,0.5,0,0.5\n",
                       kStressPoints);
    expect_error(o, key, kNodesLine, {"nodes.csv, line 1, column 'face_+y'", "all together"});
  }
  {
    const auto o =
        run(dir, small_case(), "x,y,volume,material,face_-x,face_+x,face_-y,face_+y\n0,0,0.25,material,0.5,0,-0.5,0\n",
            kStressPoints);
    expect_error(o, key, kNodesLine, {"nodes.csv, line 2, column 'face_-y'", "must be >= 0", "got -0.5"});
  }
  {
    const auto o = run(dir, small_case(), kNodes, "x,y,volume,material,face_-x\n0.5,0.5,1.0,material,0\n");
    expect_error(o, "geometry.particles[0].stress_points", kStressPointsLine,
                 {"sp.csv, line 1, column 'face_-x'", "unknown column"});
  }
  // The density column, when given, is checked like the volume.
  {
    const auto o = run(dir, small_case(), "x,y,volume,material,density\n0,0,0.25,material,-1\n", kStressPoints);
    expect_error(o, key, kNodesLine, {"nodes.csv, line 2, column 'density'", "must be > 0"});
  }
  // The stress-point file is checked the same way, under its own key.
  {
    const auto o = run(dir, small_case(), kNodes, "x,y,volume,material\n0.5,0.5,1.0,material\n0.5,0.5,1.0,material\n");
    expect_error(o, "geometry.particles[0].stress_points", kStressPointsLine,
                 {"sp.csv, line 3: the particle at (0.5, 0.5) coincides with the one of sp.csv, line 2"});
  }
  // A file that is not there.
  {
    dir.write("case.toml", small_case());
    std::filesystem::remove(dir.file("nodes.csv"));
    const auto r = test::run_command(fmt::format("\"{}\" run \"{}\" --out \"{}\" -q 2>&1 1>/dev/null", RKTSPH_BINARY,
                                                 dir.file("case.toml"), dir.file("out")));
    EXPECT_EQ(r.status, 2) << r.out;
    EXPECT_NE(r.out.find("cannot open the particle file nodes.csv"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find(fmt::format("line {}, key '{}'", kNodesLine, key)), std::string::npos) << r.out;
  }
}

TEST(ParticleFiles, TheCaseKeysAreChecked) {
  test::TempDir dir;
  {
    // Without a detected free surface nothing would make the surface traction-free.
    const auto o = run(dir, small_case("version = \"v1\""), kNodes, kStressPoints);
    expect_error(o, "geometry.particles[0]", kEntryLine, {"lie on no lattice face", "solver.free_surface"});
  }
  {
    const auto o = run(dir, small_case("version = \"v2\"\nfree_surface = \"faces\""), kNodes, kStressPoints);
    expect_error(o, "geometry.particles[0]", kEntryLine, {"detect"});
  }
  {
    std::string text = small_case();
    text.replace(text.find("spacing = 1.00\n"), 15, "spacing = 1.00\njitter = 0.1\n");
    const auto o = run(dir, text, kNodes, kStressPoints);
    expect_error(o, "geometry.jitter", 5, {"not to particles from files"});
  }
  {
    std::string text = small_case();
    text.replace(text.find("[[geometry.particles]]"), 22,
                 "[[geometry.block]]\nmin = [0.0, 0.0]\nmax = [2.0, 1.0]\n"
                 "[[geometry.particles]]");
    const auto o = run(dir, text, kNodes, kStressPoints);
    expect_error(o, "geometry.particles[0]", 8, {"either [[geometry.block]] or [[geometry.particles]]"});
  }
  {
    std::string text = small_case();
    text.replace(text.find("stress_points = \"sp.csv\"\n"), 25, "");
    const auto o = run(dir, text, kNodes, kStressPoints);
    EXPECT_EQ(o.status, 2) << o.err;
    EXPECT_NE(o.err.find("geometry.particles[0].stress_points"), std::string::npos) << o.err;
  }
}

}  // namespace
}  // namespace rktsph
