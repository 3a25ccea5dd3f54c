// The status a run ends with: an energy that overflows while the velocities stay finite is an
// unstable run (exit 3, summary "unstable"), never a completed one.
#include <gtest/gtest.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "../support/test_util.hpp"

namespace rktsph {
namespace {

TEST(RunStatus, AnInfiniteEnergyIsAnUnstableRun) {
  test::TempDir dir;
  const std::string file = dir.write("case.toml", R"(
[geometry]
dimension = 2
spacing = 0.5
[[geometry.block]]
min = [0.0, 0.0]
max = [2.0, 2.0]
[material]
model = "elastic"
E = 1.0e7
nu = 0.3
density = 2000.0
[initial_stress]
type = "uniform"
xx = 1.0e308
yy = 1.0e308
zz = 1.0e308
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
