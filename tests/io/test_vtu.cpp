// ParaView output read back by an independent reader (meshio), and the .pvd collection.
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <regex>
#include <sstream>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "../support/test_util.hpp"

namespace rktsph {
namespace {

constexpr const char* kPython = "/usr/bin/python3";

// 8 x 4 cells: 45 nodes, 32 elements; gravity and a fixed base so that the fields move.
constexpr const char* kCase = R"(
[geometry]
dimension = 2
spacing = 0.25
[[geometry.block]]
min = [0.0, 0.0]
max = [2.0, 1.0]
[material]
model = "elastic"
E = 1.0e7
nu = 0.3
density = 2000.0
[body_force]
gravity = [0.0, -9.81]
[[boundary]]
name = "base"
y = [0.0, 0.0]
velocity = { x = 0.0, y = 0.0 }
[time]
end = 0.02
cfl = 0.8
[output]
interval = 0.005
)";

struct VtuInfo {
  long points = -1;
  std::map<std::string, std::string> shapes;  // field -> "n" or "n c"
  double max_x = 0, max_y = 0, max_abs_z = 0;
};

// A scalar field: meshio gives shape (n,) or (n, 1) (NumberOfComponents="1").
bool is_scalar(const std::string& shape, long n) {
  return shape == std::to_string(n) || shape == std::to_string(n) + " 1";
}

bool have_meshio() { return test::run_command(fmt::format("{} -c 'import meshio' 2>/dev/null", kPython)).status == 0; }

VtuInfo read_vtu(const std::string& path) {
  const std::string script =
      "import sys, meshio\n"
      "m = meshio.read(sys.argv[1])\n"
      "print('points', len(m.points))\n"
      "print('bounds', m.points[:, 0].max(), m.points[:, 1].max(), abs(m.points[:, 2]).max())\n"
      "for k, v in m.point_data.items(): print('field', k, *v.shape)\n";
  const auto r = test::run_command(fmt::format("{} -c \"{}\" '{}' 2>&1", kPython, script, path));
  EXPECT_EQ(r.status, 0) << r.out;
  VtuInfo info;
  std::istringstream in(r.out);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::string tag;
    ls >> tag;
    if (tag == "points") ls >> info.points;
    if (tag == "bounds") ls >> info.max_x >> info.max_y >> info.max_abs_z;
    if (tag == "field") {
      std::string name, rest, part;
      ls >> name;
      while (ls >> part) rest += (rest.empty() ? "" : " ") + part;
      info.shapes[name] = rest;
    }
  }
  return info;
}

TEST(VtuOutput, ReadBackByMeshioAndPvdListsEveryFrame) {
  if (!have_meshio()) GTEST_SKIP() << kPython << " has no meshio (apt install python3-meshio)";
  const test::ThreadCount threads(1);
  test::TempDir dir;
  const std::string file = dir.write("tiny.toml", kCase);
  const std::string out = dir.file("out");
  const auto r =
      test::run_command(fmt::format("\"{}\" run \"{}\" --out \"{}\" -q -j 1 2>&1", RKTSPH_BINARY, file, out));
  ASSERT_EQ(r.status, 0) << r.out;

  const auto summary = nlohmann::json::parse(test::read_text(out + "/summary.json"));
  const long nodes = summary.at("nodes").get<long>();
  const long elements = summary.at("stress_points").get<long>();
  const int frames = summary.at("output_frames").get<int>();
  EXPECT_EQ(nodes, 45);
  EXPECT_EQ(elements, 32);
  EXPECT_GE(frames, 5);  // t = 0, 0.005, 0.01, 0.015, 0.02

  // Nodes: every field with the right shape, the right number of points, z = 0 in 2D.
  for (const std::string& name : {std::string("nodes_000000.vtu"), fmt::format("nodes_{:06d}.vtu", frames - 1)}) {
    VtuInfo v = read_vtu(out + "/vtu/" + name);
    EXPECT_EQ(v.points, nodes) << name;
    EXPECT_DOUBLE_EQ(v.max_x, 2.0);
    EXPECT_DOUBLE_EQ(v.max_y, 1.0);
    EXPECT_EQ(v.max_abs_z, 0.0);
    const std::string n = std::to_string(nodes);
    EXPECT_EQ(v.shapes["velocity"], n + " 3") << name;
    EXPECT_EQ(v.shapes["displacement"], n + " 3") << name;
    for (const char* s : {"sxx", "syy", "szz", "sxy", "p", "q"}) {
      EXPECT_TRUE(is_scalar(v.shapes[s], nodes)) << name << " " << s << ": shape " << v.shapes[s];
    }
  }
  // Elements: no displacement, the stress fields.
  VtuInfo e = read_vtu(out + "/vtu/elements_000000.vtu");
  EXPECT_EQ(e.points, elements);
  EXPECT_EQ(e.shapes.count("displacement"), 0u);
  EXPECT_TRUE(is_scalar(e.shapes["sxy"], elements)) << e.shapes["sxy"];
  EXPECT_EQ(e.shapes["velocity"], std::to_string(elements) + " 3");

  // The collection lists every frame once, in time order, and every file exists.
  for (const std::string& set : {std::string("nodes"), std::string("elements")}) {
    const std::string pvd = test::read_text(out + "/" + set + ".pvd");
    const std::regex entry("timestep=\"([^\"]+)\"[^>]*file=\"([^\"]+)\"");
    int count = 0;
    double last_t = -1.0;
    for (auto it = std::sregex_iterator(pvd.begin(), pvd.end(), entry); it != std::sregex_iterator(); ++it) {
      const double t = std::stod((*it)[1].str());
      const std::string f = (*it)[2].str();
      EXPECT_EQ(f, fmt::format("vtu/{}_{:06d}.vtu", set, count));
      EXPECT_TRUE(std::filesystem::exists(out + "/" + f)) << f;
      EXPECT_GT(t, last_t);
      last_t = t;
      ++count;
    }
    EXPECT_EQ(count, frames) << pvd;
    EXPECT_NEAR(last_t, 0.02, 0.005);
  }
}

}  // namespace
}  // namespace rktsph
