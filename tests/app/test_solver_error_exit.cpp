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

// The 1D bar in uniaxial stress keeps RK4 (no implicit return for that condition,
// method-notes §2.5): at a fluidity of 1e9 1/s its source is refused as too stiff from inside
// the parallel source loop, with exit 3 and the summary kept.
TEST(SolverErrorExit, TooStiffSourceInsideAParallelLoop) {
  for (const int threads : {1, 2}) {
    test::TempDir dir;
    const std::string out = dir.file(fmt::format("out{}", threads));
    const auto r = test::run_command(
        fmt::format("\"{}\" run \"{}/cases/thesis/02_viscoplastic_bar_1d.toml\" --set "
                    "material.fluidity=1e12 --set time.end=0.2 --threads {} --out \"{}\" 2>&1 1>/dev/null",
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

// A material-point path whose every step needed hundreds of thousands of RK4 sub-steps (the fuzz
// test's Mohr-Coulomb triaxial with c = 3 Pa ran for hours, then was refused) is integrated by
// backward Euler (method-notes §2.5): it completes, every step implicit, a few Newton
// iterations a step.
TEST(SolverErrorExit, AMaterialPointPathAtTinyCohesionRunsByBackwardEuler) {
  test::TempDir dir;
  const auto r = test::run_command(
      fmt::format("\"{}\" material-point \"{}/cases/material_point/mohr_coulomb_triaxial.toml\" --set "
                  "material.cohesion=3 --set output.plot=false --out \"{}\" 2>&1",
                  RKTSPH_BINARY, RKTSPH_SOURCE_DIR, dir.file("out")));
  ASSERT_EQ(r.status, 0) << r.out;
  const auto summary = nlohmann::json::parse(test::read_text(dir.file("out") + "/summary.json"));
  const long steps = summary["steps"].get<long>(), implicit = summary["implicit_steps"].get<long>();
  EXPECT_GT(implicit, steps / 2);
  EXPECT_LT(summary["newton_iterations"].get<long>(), 60 * steps);
  EXPECT_LT(summary["rk4_substeps"].get<long>(), 5 * steps);
}

}  // namespace
}  // namespace rktsph
