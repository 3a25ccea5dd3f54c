// `rktsph check` (app/check_case.hpp): a sound case gets one "ok" line with its particles and
// steps and exit 0; a case that `run` would refuse gets the same error, naming file, line and key,
// and exit 2; the other files of the call are still checked. Nothing is written.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include <fmt/format.h>

#include "../support/test_util.hpp"

namespace rktsph {
namespace {

TEST(CheckCase, SoundAndUnsoundFilesEachGetTheirLine) {
  test::TempDir dir;
  const std::string good = fmt::format("{}/cases/thesis/09_low_cohesion_slope_2d.toml", RKTSPH_SOURCE_DIR);
  const std::string point = fmt::format("{}/cases/material_point/von_mises_shear.toml", RKTSPH_SOURCE_DIR);
  // The case with its probe moved off the body: `run` refuses it after building the particles.
  std::string text = test::read_text(good);
  const std::string at = "position = [5.0, 10.0]";
  ASSERT_NE(text.find(at), std::string::npos);
  text.replace(text.find(at), at.size(), "position = [9.0, 9.0]");
  const std::string bad = dir.write("probe_outside.toml", text);

  const auto ok = test::run_command(
      fmt::format("cd \"{}\" && \"{}\" check \"{}\" \"{}\" 2>&1", dir.path().string(), RKTSPH_BINARY, good, point));
  EXPECT_EQ(ok.status, 0) << ok.out;
  EXPECT_NE(ok.out.find("ok    " + good + ": v2 2D, 3321 nodes, 3200 stress points, 2 rigid bodies"), std::string::npos)
      << ok.out;
  EXPECT_NE(ok.out.find("58704 steps to 20 s"), std::string::npos) << ok.out;
  // The run-time estimate from trial steps, with the plastic bound of a Perzyna material.
  EXPECT_NE(ok.out.find("estimate: "), std::string::npos) << ok.out;
  EXPECT_NE(ok.out.find("if every particle flows plastically"), std::string::npos) << ok.out;
  EXPECT_NE(ok.out.find("ok    " + point + ": material point, simple_shear path"), std::string::npos) << ok.out;
  EXPECT_NE(ok.out.find("2 of 2 case files sound"), std::string::npos) << ok.out;

  const auto mixed = test::run_command(fmt::format("cd \"{}\" && \"{}\" check --no-estimate \"{}\" \"{}\" --set time.cfl=0.25 2>&1",
                                                   dir.path().string(), RKTSPH_BINARY, bad, good));
  EXPECT_EQ(mixed.status, 2) << mixed.out;
  EXPECT_NE(mixed.out.find("error " + bad + ", line"), std::string::npos) << mixed.out;
  EXPECT_NE(mixed.out.find("key 'probe[0].position': probe 'crest' at [9, 9] lies outside the body"), std::string::npos)
      << mixed.out;
  EXPECT_NE(mixed.out.find("117408 steps to 20 s"), std::string::npos) << mixed.out;  // --set reaches every file
  EXPECT_NE(mixed.out.find("1 of 2 case files sound"), std::string::npos) << mixed.out;
  EXPECT_EQ(mixed.out.find("estimate: "), std::string::npos) << mixed.out;
  // Nothing written: no out/ folder beside the call.
  EXPECT_FALSE(std::filesystem::exists(dir.file("out")));
}

}  // namespace
}  // namespace rktsph
