// Scenario validation: every bad input names the source, the line, the key, what was wrong
// and what is allowed.
#include <gtest/gtest.h>

#include "core/error.hpp"
#include "io/scenario.hpp"

using namespace ff;

namespace {
ParamTable table() {
  ParamTable t;
  t.string("driver", "ucs", "driver").one_of({"ucs", "lbm"});
  t.real("dem.damping", 0.7, "-", "local damping").range(0, 1);
  t.real("sample.radius_min", 0.4e-3, "m", "smallest radius").positive();
  t.real("sample.porosity", 0.1, "-", "target porosity").open_range(0, 1);
  t.integer("sample.seed", 1, "-", "random seed").non_negative();
  t.real("dem.group.*.density", 2600, "kg/m^3", "particle density").positive();
  t.real_list("load.pressures", {1e6}, "Pa", "pressures").positive();
  t.boolean("output.vtk", true, "vtk");
  return t;
}
std::string error_of(const std::string& text, std::vector<std::string> sets = {}) {
  auto t = table();
  try {
    load_scenario(t, "s.toml", text, sets);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(Params, DefaultsAndFileValues) {
  auto t = table();
  Config c = load_scenario(t, "s.toml", "[dem]\ndamping = 0.5\n[dem.group.coal]\ndensity = 1390\n", {});
  EXPECT_DOUBLE_EQ(c.real("dem.damping"), 0.5);
  EXPECT_DOUBLE_EQ(c.real("sample.radius_min"), 0.4e-3);
  EXPECT_DOUBLE_EQ(c.real("dem.group.coal.density"), 1390);
  EXPECT_DOUBLE_EQ(c.real("dem.group.other.density"), 2600);  // wildcard default
  EXPECT_EQ(c.names("dem.group"), std::vector<std::string>{"coal"});
  EXPECT_EQ(c.origin("dem.damping"), "s.toml:2");
  EXPECT_EQ(c.origin("sample.seed"), "default");
}

TEST(Params, IntegerAcceptedForReal) {
  auto t = table();
  Config c = load_scenario(t, "s.toml", "sample.porosity = 0.2\nload.pressures = [1, 2.5e6]\n", {});
  EXPECT_EQ(c.real_list("load.pressures").size(), 2u);
}

TEST(Params, UnknownKeyNamesLineAndSuggests) {
  const auto e = error_of("\n[dem]\ndampng = 0.5\n");
  EXPECT_NE(e.find("s.toml:3"), std::string::npos) << e;
  EXPECT_NE(e.find("unknown key 'dem.dampng'"), std::string::npos) << e;
  EXPECT_NE(e.find("dem.damping"), std::string::npos) << e;
}

TEST(Params, OutOfRangeSaysWhatIsAllowed) {
  const auto e = error_of("sample.radius_min = -1e-3\n");
  EXPECT_NE(e.find("s.toml:1"), std::string::npos) << e;
  EXPECT_NE(e.find("out of range"), std::string::npos) << e;
  EXPECT_NE(e.find("> 0"), std::string::npos) << e;
  EXPECT_NE(error_of("sample.porosity = 1.0\n").find("(0, 1)"), std::string::npos);
  EXPECT_NE(error_of("dem.damping = 1.5\n").find("[0, 1]"), std::string::npos);
}

TEST(Params, WrongTypeAndBadChoice) {
  EXPECT_NE(error_of("sample.seed = 1.5\n").find("wrong type"), std::string::npos);
  EXPECT_NE(error_of("output.vtk = \"yes\"\n").find("wrong type"), std::string::npos);
  const auto e = error_of("driver = \"triax\"\n");
  EXPECT_NE(e.find("not a known choice"), std::string::npos) << e;
  EXPECT_NE(e.find("\"ucs\""), std::string::npos) << e;
}

TEST(Params, SyntaxErrorHasLine) {
  const auto e = error_of("a = 1\nb = = 2\n");
  EXPECT_NE(e.find("s.toml:2"), std::string::npos) << e;
  EXPECT_NE(e.find("syntax"), std::string::npos) << e;
}

TEST(Params, SetOverridesAreValidatedToo) {
  auto t = table();
  Config c = load_scenario(t, "s.toml", "dem.damping = 0.5\n", {"dem.damping=0.2", "driver=lbm"});
  EXPECT_DOUBLE_EQ(c.real("dem.damping"), 0.2);
  EXPECT_EQ(c.string("driver"), "lbm");
  EXPECT_EQ(c.origin("dem.damping"), "--set");
  EXPECT_NE(error_of("", {"dem.damping=2"}).find("--set dem.damping"), std::string::npos);
  EXPECT_NE(error_of("", {"nonsense"}).find("key=value"), std::string::npos);
}

TEST(Params, ByteOrderMarkAndBinaryAreHandled) {
  EXPECT_EQ(error_of("\xEF\xBB\xBF"), "");  // toml++ 3.3.0 crashes on a lone BOM; guarded
  EXPECT_EQ(error_of("\xEF\xBB\xBF" "dem.damping = 0.1\n"), "");
  EXPECT_NE(error_of(std::string("a = 1\n\0", 7)).find("NUL"), std::string::npos);
  EXPECT_NE(error_of("a = \"\xC3\"").find("UTF-8"), std::string::npos);
}

TEST(Params, ResolvedTomlRoundTrips) {
  auto t = table();
  Config c = load_scenario(t, "s.toml", "dem.damping = 0.25\n[dem.group.coal]\ndensity = 1390\n", {});
  Config back = load_scenario(t, "resolved", c.resolved_toml(), {});
  EXPECT_DOUBLE_EQ(back.real("dem.damping"), 0.25);
  EXPECT_DOUBLE_EQ(back.real("dem.group.coal.density"), 1390);
  EXPECT_DOUBLE_EQ(back.real("sample.radius_min"), 0.4e-3);
  EXPECT_EQ(back.real_list("load.pressures"), c.real_list("load.pressures"));
}

TEST(Params, MarkdownListsEveryKey) {
  const auto md = table().markdown();
  const auto t = table();
  for (auto& s : t.specs()) EXPECT_NE(md.find("`" + s.key + "`"), std::string::npos) << s.key;
}
