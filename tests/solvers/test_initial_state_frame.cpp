// The t = 0 state of the stress points (StaggeredModel::set_initial_state): the initial nodal
// state interpolated to them, so the first elements frame shows an initial stress as the nodes
// frame does (it showed zero before), and the stress points' history starts from the nodes'.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "../support/test_util.hpp"
#include "schemes/simulation.hpp"

namespace rktsph {
namespace {

// Elastic block under a uniform anisotropic initial stress (with shear), its faces loaded by the
// matching tractions so that the nodes' constrained values at t = 0 are the same stress; one
// step is enough.
constexpr const char* kUniformCase = R"(
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
[initial_stress]
type = "uniform"
xx = -5.0e4
yy = -2.0e4
zz = -3.0e4
xy = 4.0e3
[[boundary]]
name = "base"
y = [0.0, 0.0]
velocity = { x = 0.0, y = 0.0 }
[[boundary]]
name = "sides"
x = [0.0, 0.0]
stress = { xx = -5.0e4, xy = 4.0e3 }
[[boundary]]
name = "right"
x = [2.0, 2.0]
stress = { xx = -5.0e4, xy = 4.0e3 }
[[boundary]]
name = "top"
y = [1.0, 1.0]
stress = { yy = -2.0e4, xy = 4.0e3 }
[time]
end = 1.0e-4
cfl = 0.5
[output]
interval = 0.0
elements = true
)";

std::vector<unsigned char> base64_decode(const std::string& text) {
  auto value = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
  };
  std::vector<unsigned char> out;
  std::uint32_t acc = 0;
  int bits = 0;
  for (char c : text) {
    const int v = value(c);
    if (v < 0) continue;  // '=' padding, whitespace
    acc = (acc << 6) | static_cast<std::uint32_t>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<unsigned char>((acc >> bits) & 0xFFu));
    }
  }
  return out;
}

// The values of the Float64 point array `name` of a VTU file written by io::write_vtu (inline
// "binary": a base64 UInt32 byte count, then the base64 data, as two separately padded parts).
std::vector<double> vtu_array(const std::string& file, const std::string& name) {
  const std::string xml = test::read_text(file);
  const std::string tag = fmt::format("Name=\"{}\"", name);
  const auto at = xml.find(tag);
  if (at == std::string::npos) return {};
  const auto begin = xml.find('>', at) + 1;
  const auto end = xml.find("</DataArray>", begin);
  std::string block = xml.substr(begin, end - begin);
  std::erase_if(block, [](char c) { return c == '\n' || c == ' '; });
  // The header is 4 bytes: 8 base64 characters with padding.
  const std::vector<unsigned char> header = base64_decode(block.substr(0, 8));
  std::uint32_t bytes = 0;
  std::memcpy(&bytes, header.data(), sizeof(bytes));
  const std::vector<unsigned char> data = base64_decode(block.substr(8));
  EXPECT_EQ(data.size(), bytes) << name;
  std::vector<double> values(bytes / sizeof(double));
  std::memcpy(values.data(), data.data(), values.size() * sizeof(double));
  return values;
}

TEST(InitialStateFrame, ElementsFrameAtTimeZeroShowsTheUniformInitialStress) {
  test::TempDir dir;
  const std::string file = dir.write("uniform.toml", kUniformCase);
  const std::string out = dir.file("out");
  const auto r =
      test::run_command(fmt::format("\"{}\" run \"{}\" --out \"{}\" -q -j 1 2>&1", RKTSPH_BINARY, file, out));
  ASSERT_EQ(r.status, 0) << r.out;
  const std::pair<const char*, double> expected[] = {{"sxx", -5.0e4}, {"syy", -2.0e4}, {"szz", -3.0e4}, {"sxy", 4.0e3}};
  for (const char* set : {"elements", "nodes"}) {
    const std::string frame = fmt::format("{}/vtu/{}_000000.vtu", out, set);
    for (const auto& [name, value] : expected) {
      const std::vector<double> v = vtu_array(frame, name);
      ASSERT_EQ(v.size(), std::string(set) == "elements" ? 32u : 45u) << set << " " << name;
      for (std::size_t i = 0; i < v.size(); ++i) {
        // Linear-exact interpolation of a constant: exact up to rounding.
        ASSERT_NEAR(v[i], value, 1e-9 * 5.0e4) << set << " " << name << " at point " << i;
      }
    }
  }
}

TEST(InitialStateFrame, StressPointsStartFromTheInterpolatedGeostaticStateAndHistory) {
  // Geostatic stress (linear in y; the rollers and the free top agree with it) and a Cam-Clay
  // history: the stress points at t = 0 carry the linear field at their own height (the
  // corrected interpolation is linear-exact) and the nodes' p_c.
  const test::ThreadCount threads(1);
  test::TempDir dir;
  const std::string text = R"(
[geometry]
dimension = 2
spacing = 0.1
[[geometry.block]]
min = [0.0, 0.0]
max = [1.0, 2.0]
[material]
model = "perzyna_cam_clay"
E = 2.0e7
nu = 0.3
density = 2000.0
M = 1.2
lambda = 0.2
kappa = 0.02
e0 = 1.0
p_c0 = 4.0e5
fluidity = 10.0
[body_force]
gravity = [0.0, -9.81]
[initial_stress]
type = "geostatic"
K0 = 0.5
[[boundary]]
name = "base"
y = [0.0, 0.0]
velocity = { x = 0.0, y = 0.0 }
[[boundary]]
name = "left"
x = [0.0, 0.0]
velocity = { x = 0.0 }
[[boundary]]
name = "right"
x = [1.0, 1.0]
velocity = { x = 0.0 }
[time]
end = 1.0
cfl = 0.5
)";
  CaseSetup<2> setup = test::case_from_string<2>(dir, text);
  Simulation<2> solver(setup);
  const auto& sp = solver.stress_points();
  const auto s = solver.stress_point_stress();
  const HistoryView pc = solver.stress_point_history("p_c");
  const double gamma = 2000.0 * 9.81;
  for (Index e = 0; e < sp.size(); ++e) {
    const double y = sp.position[static_cast<std::size_t>(e)][1];
    const double sv = -gamma * (2.0 - y);
    EXPECT_NEAR(s(e, StressComponent::yy), sv, 1e-9 * gamma * 2.0) << "stress point " << e;
    EXPECT_NEAR(s(e, StressComponent::xx), 0.5 * sv, 1e-9 * gamma * 2.0) << "stress point " << e;
    EXPECT_NEAR(s(e, StressComponent::xy), 0.0, 1e-9 * gamma * 2.0) << "stress point " << e;
    EXPECT_NEAR(pc(e), 4.0e5, 1e-9 * 4.0e5) << "stress point " << e;
  }
}

}  // namespace
}  // namespace rktsph
