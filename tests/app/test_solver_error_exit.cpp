// A solver error thrown inside a parallel particle loop reaches the caller (core/execution.hpp):
// the run stops with exit status 3 and its diagnosis, on one thread and on two, instead of
// aborting inside the OpenMP runtime (it used to exit 134, with no summary.json); a material-point
// path too stiff in all stops in seconds.
#include <gtest/gtest.h>

#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "../support/test_util.hpp"

namespace rktsph {
namespace {

TEST(SolverErrorExit, TooStiffSourceInsideAParallelLoop) {
  for (const int threads : {1, 2}) {
    test::TempDir dir;
    const std::string out = dir.file(fmt::format("out{}", threads));
    const auto r = test::run_command(
        fmt::format("\"{}\" run \"{}/cases/thesis/05_viscoplastic_cut_2d.toml\" --set geometry.spacing=0.5 --set "
                    "material.fluidity=1e9 --set time.end=3.0 --threads {} --out \"{}\" 2>&1 1>/dev/null",
                    RKTSPH_BINARY, RKTSPH_SOURCE_DIR, threads, out));
    EXPECT_EQ(r.status, 3) << threads << " threads: " << r.out;
    EXPECT_NE(r.out.find("the viscoplastic source is too stiff"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("reduce the fluidity or the time step"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("terminate"), std::string::npos) << r.out;
    // The summary says why, and the output so far is kept.
    const auto summary = nlohmann::json::parse(test::read_text(out + "/summary.json"));
    EXPECT_EQ(summary["status"], "unstable");
    EXPECT_NE(summary["message"].get<std::string>().find("too stiff"), std::string::npos);
  }
}

// A material-point path whose every step needs hundreds of thousands of sub-steps (the fuzz
// test's Mohr-Coulomb triaxial with c = 3 Pa ran for hours) is refused once the path has
// used 1e7 sub-steps in all, with exit 3 and what to change.
TEST(SolverErrorExit, AMaterialPointPathTooStiffInAllStopsWithItsDiagnosis) {
  test::TempDir dir;
  const auto r = test::run_command(
      fmt::format("\"{}\" material-point \"{}/cases/material_point/mohr_coulomb_triaxial.toml\" --set "
                  "material.cohesion=3 --set output.plot=false --out \"{}\" 2>&1",
                  RKTSPH_BINARY, RKTSPH_SOURCE_DIR, dir.file("out")));
  EXPECT_EQ(r.status, 3) << r.out;
  EXPECT_NE(r.out.find("RK4 sub-steps in all"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("reduce the fluidity or path.dt"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace rktsph
