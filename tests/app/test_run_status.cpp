// The status a run ends with: an energy that overflows while the velocities stay finite is an
// unstable run (exit 3, summary "unstable"), never a completed one.
#include <gtest/gtest.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "../support/test_util.hpp"

namespace rktsph {
namespace {

// Every input lies within the reader's bound of 1e100 in magnitude, yet the strain energy,
// sigma^2 / E times a 1.6e11 m^2 body, is ~1e311: it overflows while velocities stay finite.
TEST(RunStatus, AnInfiniteEnergyIsAnUnstableRun) {
  test::TempDir dir;
  const std::string file = dir.write("case.toml", R"(
[geometry]
dimension = 2
spacing = 1.0e5
[[geometry.block]]
min = [0.0, 0.0]
max = [4.0e5, 4.0e5]
[material]
model = "elastic"
E = 1.0e-100
nu = 0.3
density = 2000.0
[initial_stress]
type = "uniform"
xx = 1.0e100
yy = 1.0e100
zz = 1.0e100
[time]
end = 0.01
)");
  const auto r = test::run_command(
      fmt::format("\"{}\" run \"{}\" --out \"{}\" -q -j 1 2>&1", RKTSPH_BINARY, file, dir.file("out")));
  EXPECT_EQ(r.status, 3) << r.out;
  EXPECT_NE(r.out.find("non-finite"), std::string::npos) << r.out;
  const auto s = nlohmann::json::parse(test::read_text(dir.file("out/summary.json")));
  EXPECT_EQ(s.at("status"), "unstable");
}

}  // namespace
}  // namespace rktsph
