// Size guards (case/size_limits.hpp): the estimate of the particle counts from the blocks, the
// memory, lattice and step checks, and StaggeredModel's own checks for cases built in code.
#include <gtest/gtest.h>

#include <string>

#include "../support/test_util.hpp"
#include "case/case_builder.hpp"
#include "case/size_limits.hpp"
#include "schemes/simulation.hpp"

namespace rktsph {
namespace {

CaseBuilder<2> block_case(double dx) {
  CaseBuilder<2> b("size test");
  b.spacing(dx).elastic(1.0e7, 0.3, 2000.0).time(0.01);
  return b;
}

TEST(SizeLimits, EstimateIsExactForSeparateBlocksAndAnUpperBoundOtherwise) {
  test::ThreadCount one(1);
  // An L: two blocks that share a face but no cell (the shared face's nodes counted twice).
  const CaseSetup<2> l =
      block_case(0.5).block(Vec<2>(0.0, 0.0), Vec<2>(4.0, 1.0)).block(Vec<2>(0.0, 1.0), Vec<2>(1.0, 3.0)).build();
  const SizeEstimate e = estimate_size(l, false);
  const Simulation<2> sim(l);
  EXPECT_EQ(e.stress_points, static_cast<double>(sim.stress_points().size()));  // 16 + 8 cells
  EXPECT_GE(e.nodes, static_cast<double>(sim.nodes().size()));
  EXPECT_LE(e.nodes, static_cast<double>(sim.nodes().size()) + 3.0);  // the 3 shared nodes
  EXPECT_EQ(e.lattice_cells, 8.0 * 6.0);
  EXPECT_DOUBLE_EQ(e.bytes, e.nodes * bytes_per_node(2, false) + 48.0 * sizeof(int));
  // An inclusion inside a block: capped by the bounding box.
  const CaseSetup<2> inc =
      block_case(0.5).block(Vec<2>(0.0, 0.0), Vec<2>(2.0, 2.0)).block(Vec<2>(0.5, 0.5), Vec<2>(1.5, 1.5)).build();
  const SizeEstimate ei = estimate_size(inc, true);
  EXPECT_EQ(ei.stress_points, 16.0);
  EXPECT_EQ(ei.nodes, 25.0);
  EXPECT_GT(bytes_per_node(2, true), bytes_per_node(2, false));
  EXPECT_GT(bytes_per_node(2, false), bytes_per_node(1, false));
}

TEST(SizeLimits, MemoryAndParticleChecks) {
  const CaseSetup<2> c = block_case(0.5).block(Vec<2>(0.0, 0.0), Vec<2>(2.0, 1.0)).build();
  EXPECT_FALSE(memory_problem(c, false, 15.0, 8.0, 8.0, 1.0e9));
  const auto p = memory_problem(c, false, 1.0e6, 1.0e6, 1.0e6, 1.0e8);  // 700 MB against 100 MB
  ASSERT_TRUE(p);
  EXPECT_EQ(p->full_key(), "geometry.spacing");
  EXPECT_NE(p->message.find("1e+06 nodes"), std::string::npos) << p->message;
  EXPECT_NE(p->message.find("95.4 MiB of memory"), std::string::npos) << p->message;
  EXPECT_NE(p->message.find("dry (V1)"), std::string::npos) << p->message;
  const auto q = memory_problem(c, true, 3.0e9, 3.0e9, 3.0e9, 0.0);  // memory unknown: particles only
  ASSERT_TRUE(q);
  EXPECT_NE(q->message.find("2147483647 particles"), std::string::npos) << q->message;
  EXPECT_FALSE(memory_problem(c, true, 1.0e9, 1.0e9, 1.0e9, 0.0));
  EXPECT_GT(physical_memory_bytes(), 0.0);
}

TEST(SizeLimits, LatticeAndStepChecks) {
  {
    const CaseSetup<2> c = block_case(1.0e-12).block(Vec<2>(0.0, 0.0), Vec<2>(2.0, 1.0)).build();
    const auto p = lattice_size_problem(c);
    ASSERT_TRUE(p);
    EXPECT_EQ(p->full_key(), "geometry.spacing");
  }
  {
    const CaseSetup<2> c =
        block_case(0.5).origin(Vec<2>(-1.0e9, 0.0)).block(Vec<2>(0.0, 0.0), Vec<2>(2.0, 1.0)).build();
    const auto p = lattice_size_problem(c);
    ASSERT_TRUE(p);
    EXPECT_EQ(p->full_key(), "geometry.block[0].min");
  }
  EXPECT_FALSE(step_count_problem(1.0, 1.0e-8, 1.0e8, "dt"));
  const auto s = step_count_problem(1.0, 1.0e-9, 1.0e8, "dt");
  ASSERT_TRUE(s);
  EXPECT_EQ(s->full_key(), "time.end");
  EXPECT_NE(s->message.find("time.max_steps (>= 1e+09)"), std::string::npos) << s->message;
  const auto inf = step_count_problem(1.0, 0.0, 1.0e8, "dt");  // dt = 0 (c overflowed): infinite
  ASSERT_TRUE(inf);
  EXPECT_NE(inf->message.find("no run may take more than 1e+15 steps"), std::string::npos) << inf->message;
}

TEST(SizeLimits, ModelBuiltInCodeChecksTheLatticeBeforeGeneratingIt) {
  // A case built in code skips the reader; the model refuses it before the lattice generator
  // converts the corners to int coordinates (which used to overflow).
  const CaseSetup<2> c = block_case(1.0e-12).block(Vec<2>(0.0, 0.0), Vec<2>(2.0, 1.0)).build();
  try {
    const Simulation<2> sim(c);
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("<size test>, key 'geometry.spacing'"), std::string::npos) << what;
    EXPECT_NE(what.find("cells per axis"), std::string::npos) << what;
  }
}

TEST(SizeLimits, ReaderKeepsMaxSteps) {
  test::TempDir dir;
  const std::string text = R"(
[geometry]
dimension = 1
spacing = 0.1
[[geometry.block]]
min = [0.0]
max = [1.0]
[material]
model = "elastic"
E = 1.0e7
nu = 0.0
density = 2000.0
[time]
end = 0.01
max_steps = 2.5e8
)";
  EXPECT_EQ(test::case_from_string<1>(dir, text).max_steps, 2.5e8);
  EXPECT_EQ(test::case_from_string<1>(dir, text, {"time.max_steps=20"}).max_steps, 20.0);
}

}  // namespace
}  // namespace rktsph
