// --set overrides (load_case_document) and io::Section: nested keys, array-of-tables indices,
// type checks like the file, and the file/line/key in every message.
#include <gtest/gtest.h>

#include <string>

#include "../support/test_util.hpp"
#include "core/error.hpp"
#include "io/section.hpp"

namespace rktsph {
namespace {

const std::string kBar = std::string(RKTSPH_SOURCE_DIR) + "/cases/thesis/01_elastic_bar_1d.toml";

std::string error_of(const std::vector<std::string>& sets) {
  try {
    const auto doc = load_case_document(kBar, sets);
    (void)read_case<1>(doc);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError for the overrides";
  return {};
}

TEST(SetOverride, ArrayOfTablesIndexAndNestedKey) {
  const auto plain = read_case<1>(load_case_document(kBar, {}));
  ASSERT_EQ(plain.boundaries.size(), 2u);
  ASSERT_EQ(plain.boundaries[1].stress.size(), 1u);
  EXPECT_EQ(plain.boundaries[1].stress[0].second, 1.0e4);

  const auto c = read_case<1>(
      load_case_document(kBar, {"boundary.1.stress.xx=-2.5e4", "functions.load.type=smoothstep",
                                "functions.load.duration=0.04", "geometry.spacing=0.05", "material.E=2e7"}));
  ASSERT_EQ(c.boundaries.size(), 2u);
  EXPECT_EQ(c.boundaries[1].stress[0].first, 0);  // xx
  EXPECT_EQ(c.boundaries[1].stress[0].second, -2.5e4);
  EXPECT_EQ(c.boundaries[0].velocity.size(), 1u) << "the other boundary is untouched";
  EXPECT_EQ(c.dx, 0.05);
  EXPECT_EQ(c.materials[0]->elastic().E, 2e7);
  // smoothstep of duration 0.04: half way at t = 0.02, complete at 0.04 (a step would be 1).
  const int f = c.boundaries[1].function;
  ASSERT_GE(f, 0);
  EXPECT_NEAR(c.function_value(f, 0.02), 0.5, 1e-12);
  EXPECT_NEAR(c.function_value(f, 0.01), 0.103515625, 1e-12);
  EXPECT_EQ(c.function_value(f, 0.05), 1.0);
}

TEST(SetOverride, CreatesMissingTablesAndBareWordsAreStrings) {
  // [solver] is absent from the bar case: --set creates it; 'false' is a TOML boolean.
  const auto c = read_case<1>(load_case_document(kBar, {"solver.filter=false", "solver.scheme=collocated"}));
  EXPECT_FALSE(c.filter);
  EXPECT_EQ(c.layout, ParticleLayout::collocated);
}

TEST(SetOverride, TypeCheckedLikeTheFile) {
  const std::string e1 = error_of({"material.E=stiff"});
  EXPECT_NE(e1.find(kBar), std::string::npos) << e1;
  EXPECT_NE(e1.find("command line"), std::string::npos) << e1;
  EXPECT_NE(e1.find("'material.E'"), std::string::npos) << e1;
  EXPECT_NE(e1.find("must be a number, got a string"), std::string::npos) << e1;

  const std::string e2 = error_of({"boundary.1.stress.xx=[1, 2]"});
  EXPECT_NE(e2.find("'boundary[1].stress.xx'"), std::string::npos) << e2;
  EXPECT_NE(e2.find("got an array"), std::string::npos) << e2;

  const std::string e3 = error_of({"solver.filter=1"});
  EXPECT_NE(e3.find("'solver.filter'"), std::string::npos) << e3;
  EXPECT_NE(e3.find("true or false"), std::string::npos) << e3;

  // Values are checked like the file's: E <= 0.
  const std::string e4 = error_of({"material.E=-1"});
  EXPECT_NE(e4.find("'material.E'"), std::string::npos) << e4;
  EXPECT_NE(e4.find("> 0"), std::string::npos) << e4;

  // A misspelt key is an unknown key, with the accepted keys listed.
  const std::string e5 = error_of({"material.youngs=1e7"});
  EXPECT_NE(e5.find("'material.youngs'"), std::string::npos) << e5;
  EXPECT_NE(e5.find("unknown key"), std::string::npos) << e5;
  EXPECT_NE(e5.find("density"), std::string::npos) << e5;
}

TEST(SetOverride, BadPaths) {
  const std::string past = error_of({"boundary.5.stress.xx=1"});
  EXPECT_NE(past.find("past the end"), std::string::npos) << past;
  EXPECT_NE(past.find("2 entries"), std::string::npos) << past;
  const std::string index = error_of({"boundary.first.stress.xx=1"});
  EXPECT_NE(index.find("must be a whole number"), std::string::npos) << index;
  EXPECT_NE(index.find("01_elastic_bar_1d.toml: --set 'boundary.first.stress.xx=1'"), std::string::npos) << index;
  const std::string no_eq = error_of({"material.E"});
  EXPECT_NE(no_eq.find("key=value"), std::string::npos) << no_eq;
  const std::string scalar_parent = error_of({"material.E.x=1"});
  EXPECT_NE(scalar_parent.find("not a table"), std::string::npos) << scalar_parent;
}

TEST(Section, WhereNamesFileLineAndDottedKey) {
  test::TempDir dir;
  const std::string path =
      dir.write("s.toml", "a = 1\n\n[outer]\nx = 2.5\n\n[[outer.list]]\ny = \"s\"\n\n[[outer.list]]\ny = 3\n");
  const auto doc = load_case_document(path, {});
  io::Section root(doc.table, "", doc.file_label);
  EXPECT_EQ(root.where("a"), path + ", line 1, key 'a'");
  const io::Section outer = root.table("outer");
  EXPECT_EQ(outer.where("x"), path + ", line 4, key 'outer.x'");
  EXPECT_EQ(outer.number("x"), 2.5);
  const auto list = outer.tables("list");
  ASSERT_EQ(list.size(), 2u);
  EXPECT_EQ(list[1].path(), "outer.list[1]");
  EXPECT_EQ(list[1].where("y"), path + ", line 10, key 'outer.list[1].y'");
  EXPECT_EQ(list[1].integer("y"), 3);
  try {
    (void)list[0].number("y");
    FAIL() << "a string read as a number must throw";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), path + ", line 7, key 'outer.list[0].y': must be a number, got a string");
  }
  // Integers are accepted as numbers; numbers are not accepted as integers.
  EXPECT_EQ(root.number("a"), 1.0);
  EXPECT_THROW((void)outer.integer("x"), InputError);
  // A key never read is reported by finish(), with the keys this table accepts.
  list[0].string("y");
  EXPECT_NO_THROW(list[0].finish());
  try {
    root.finish();  // 'outer' and 'a' were read
  } catch (const InputError& e) {
    FAIL() << e.what();
  }
  io::Section fresh(doc.table, "", doc.file_label);
  (void)fresh.number("a");
  try {
    fresh.finish();
    FAIL() << "'outer' was never read";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("line 3, key 'outer': unknown key (this table accepts: a)"), std::string::npos) << msg;
  }
  // An override has no line: the message says so.
  const auto over = load_case_document(path, {"outer.x=7"});
  io::Section r2(over.table, "", over.file_label);
  EXPECT_EQ(r2.table("outer").where("x"), path + " (value set on the command line), key 'outer.x'");
  EXPECT_EQ(r2.table("outer").number("x"), 7.0);
}

}  // namespace
}  // namespace rktsph
