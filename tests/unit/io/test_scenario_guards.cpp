// Guards in front of toml++ 3.3.0 and the resolved-TOML round trip (each case was a crash or
// a failed round trip found by tests/fuzz/fuzz_scenario.cpp).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "core/error.hpp"
#include "io/scenario.hpp"

using namespace ff;

namespace {
ParamTable table() {
  ParamTable t;
  t.string("output.name", "run", "run name");
  t.string_list("notes", {}, "free text");
  t.real("dem.damping", 0.7, "-", "local damping").range(0, 1);
  t.real("dem.group.*.density", 2600, "kg/m^3", "particle density").positive();
  return t;
}
std::string error_of(const std::string& text, std::vector<std::string> sets = {}) {
  const auto t = table();
  try {
    load_scenario(t, "s.toml", text, sets);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(io_scenario, NonAsciiInStringsAndQuotedKeysIsKept) {
  const auto t = table();
  const Config c = load_scenario(t, "s.toml",
                                 "output.name = 'C:\\runs\\gr\xC3\xA8s \"q\"'\n"
                                 "notes = ['''\nline \"1\" \xCE\xB1\nend''''', \"\xE2\x82\xAC \\u00e8\", \"\xF0\x9F\x98\x80\"]\n"
                                 "[dem.group.\"gr\xC3\xA8s\"] # \xC3\xA9t\xC3\xA9\n"
                                 "density = 2650\n",
                                 {});
  EXPECT_EQ(c.string("output.name"), "C:\\runs\\gr\xC3\xA8s \"q\"");  // literal string: no escapes
  EXPECT_EQ(c.string_list("notes"),
            (std::vector<std::string>{"line \"1\" \xCE\xB1\nend''", "\xE2\x82\xAC \xC3\xA8", "\xF0\x9F\x98\x80"}));
  EXPECT_DOUBLE_EQ(c.real("dem.group.gr\xC3\xA8s.density"), 2650);
  EXPECT_EQ(c.origin("dem.group.gr\xC3\xA8s.density"), "s.toml:6");  // line numbers unchanged
}

TEST(io_scenario, NonAsciiOutsideStringsIsAnErrorWithItsLine) {
  // U+0454 and U+00E9 sent toml++ 3.3.0 into TOML_UNREACHABLE.
  auto e = error_of("dem.damping = 0.5\n[g\xC3\xA9o]\n");
  EXPECT_NE(e.find("s.toml:2"), std::string::npos) << e;
  EXPECT_NE(e.find("non-ASCII"), std::string::npos) << e;
  EXPECT_NE(error_of("dem.damping = 1\xD1\x94\n").find("non-ASCII"), std::string::npos);
  EXPECT_NE(error_of("output.name = 1\"\xD1\x94\"\n").find("s.toml:1"), std::string::npos);  // toml++ sees 1"\u0454"
  EXPECT_NE(error_of("output.name = \"\\\xC3\xA9\"\n").find("escape"), std::string::npos);
  EXPECT_NE(error_of("output.name = \"\xC0\x80\"\n").find("UTF-8"), std::string::npos);  // overlong NUL
  // Line numbers still count every newline of a multi-line string.
  e = error_of("notes = ['''\n\xC3\xA9\n''']\ndem.damping = = 1\n");
  EXPECT_NE(e.find("s.toml:4"), std::string::npos) << e;
}

TEST(io_scenario, LineEndingBackslashBeforeNonAscii) {
  const auto t = table();
  const Config c = load_scenario(t, "s.toml", "output.name = \"\"\"\\\n   \xC2\xA7 x\"\"\"\n", {});
  EXPECT_EQ(c.string("output.name"), "\xC2\xA7 x");
}

TEST(io_scenario, BadKeysAndOverridesAreInputErrors) {
  EXPECT_NE(error_of("[[`em.group]]\n").find("s.toml:1"), std::string::npos);  // toml++ debug assertion
  EXPECT_NE(error_of("dem.group.\"a.b\".density = 1\n").find("contain a dot"), std::string::npos);
  EXPECT_NE(error_of("dem.group.\"\".density = 1\n").find("empty"), std::string::npos);
  EXPECT_NE(error_of("", {"notes={}"}).find("one number, string"), std::string::npos);
  EXPECT_NE(error_of("", {"dem.damping=1\nx=2"}).find("one number, string"), std::string::npos);
  EXPECT_NE(error_of("", {"dem.group..density=1"}).find("empty name"), std::string::npos);
}

TEST(io_scenario, ResolvedTomlRoundTripsAnyString) {
  const auto t = table();
  const Config c = load_scenario(t, "s.toml",
                                 "output.name = \"tab\\tnl\\nctl\\u0001del\\u007fq\\\"bs\\\\\"\n"
                                 "[dem.group.\"rock/rock\"]\ndensity = 1\n[dem.group.\"a b\"]\ndensity = 2\n",
                                 {});
  const std::string resolved = c.resolved_toml();
  const Config back = load_scenario(t, "s.toml", resolved, {});
  EXPECT_EQ(back.string("output.name"), "tab\tnl\nctl\x01" "del\x7Fq\"bs\\");
  EXPECT_DOUBLE_EQ(back.real("dem.group.rock/rock.density"), 1);
  EXPECT_DOUBLE_EQ(back.real("dem.group.a b.density"), 2);
  EXPECT_EQ(back.resolved_toml(), resolved);
  EXPECT_NE(resolved.find("dem.group.\"rock/rock\".density = 1.0"), std::string::npos) << resolved;
}

// An ifstream opens a folder and reads it as empty text: it used to run the default scenario.
TEST(io_scenario, FolderGivenAsScenarioIsRefusedWithItsPath) {
  const auto dir = std::filesystem::temp_directory_path() / ("fracflow_guard_dir_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  try {
    read_text_file(dir.string());
    ADD_FAILURE() << "a folder was read as a scenario";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'" + dir.string() + "' is a folder"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
  EXPECT_THROW(read_text_file((dir / "missing.toml").string()), InputError);
}

// Scanning for the key count must not count '=' inside strings or comments.
TEST(io_scenario, KeyLimitCountsOnlyKeyValuePairs) {
  std::string text = "output.name = \"" + std::string(kMaxScenarioKeys + 10, '=') + "\"\n# " +
                     std::string(kMaxScenarioKeys + 10, '=') + "\n";
  EXPECT_EQ(error_of(text), "");
  std::string many;
  for (std::size_t i = 0; i <= kMaxScenarioKeys; ++i) {
    many += 'x';
    many += std::to_string(i);
    many += " = 1\n";
  }
  EXPECT_NE(error_of(many).find("the limit is 200000"), std::string::npos);
}
