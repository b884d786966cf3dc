// `fracflow validate-saturated` end to end on a tiny study (dry and saturated, one packing of a
// 4 x 8 mm specimen): the report with its table and trend lines, and --resume (finished runs read
// as they are, a run whose folder is gone run again, a study started with other options refused).
// The dry run of this specimen once stopped with "ideal-gas density asked at p = -1.7e9 Pa": a dry
// pore below the vapour pressure was given vapour that later condensed into liquid.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "../../unit/program_runner.hpp"

namespace fs = std::filesystem;

namespace {
std::string slurp(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}
}  // namespace

TEST(ValidateSaturated, TinyStudyWritesTheReportAndResumes) {
  ff::test::TestScratch s("validate-saturated");
  const fs::path doc = s / "doc" / "saturated.md", out = s / "runs";
  const std::string opts = " --saturations 0 1 --viscosities 0.001 --packings 1 --width 4e-3 --height 8e-3 "
                           "--velocity 0.02";
  const std::string base = "validate-saturated --out " + out.string() + " --doc " + doc.string();
  const auto r = ff::test::run_program(base + opts);
  ASSERT_EQ(r.code, 0) << r.output;
  const std::string text = slurp(doc);
  for (const char* part : {"| 0 | - |", "| 1 | 0.001 |", "dry specimen the strongest", "`S1_mu0.001_seed7`",
                           "fluid.pressure_forces = void_gradient"})
    EXPECT_NE(text.find(part), std::string::npos) << part << "\n" << text;
  EXPECT_EQ(text.find("--resume"), std::string::npos);
  // The header gives the command as it can be typed again: every option that differs from its default.
  const std::string cmd = "`fracflow validate-saturated --saturations 0,1 --viscosities 0.001 --width 0.004 "
                          "--height 0.008 --velocity 0.02 --packings 1`";
  EXPECT_NE(text.find(cmd), std::string::npos) << text.substr(0, 400);
  const std::string dry = slurp(out / "S0_mu0.001_seed7" / "summary.json");
  EXPECT_NE(dry.find("\"cavitations\": 0"), std::string::npos) << dry;

  // Again without a flag: refused, naming both ways on.
  const auto again = ff::test::run_program(base + opts);
  EXPECT_NE(again.code, 0);
  EXPECT_NE(again.output.find("--resume"), std::string::npos) << again.output;
  // --resume with other options: refused, the study untouched.
  const auto other = ff::test::run_program(base + " --resume --saturations 0 1 --viscosities 0.001 --packings 1 "
                                                  "--width 4e-3 --height 8e-3 --velocity 0.01");
  EXPECT_NE(other.code, 0);
  EXPECT_NE(other.output.find("specimen.toml"), std::string::npos) << other.output;
  EXPECT_TRUE(fs::exists(out / "S1_mu0.001_seed7" / "summary.json"));
  // --resume: the dry run read as it is (its series untouched), the saturated one (folder gone) run
  // again to the same result.
  const std::string dry_series = slurp(out / "S0_mu0.001_seed7" / "series.csv");
  const std::string wet_series = slurp(out / "S1_mu0.001_seed7" / "series.csv");
  fs::remove_all(out / "S1_mu0.001_seed7");
  const auto resumed = ff::test::run_program(base + opts + " --resume");
  ASSERT_EQ(resumed.code, 0) << resumed.output;
  EXPECT_NE(resumed.output.find("finished before"), std::string::npos) << resumed.output;
  EXPECT_EQ(slurp(out / "S0_mu0.001_seed7" / "series.csv"), dry_series);
  EXPECT_EQ(slurp(out / "S1_mu0.001_seed7" / "series.csv"), wet_series);
  const std::string text2 = slurp(doc);
  EXPECT_NE(text2.find("1 run(s) read as finished before, 0 continued"), std::string::npos) << text2;
}

// --overwrite replaces only a study of ours: a folder of someone else's files is refused and left
// whole (it was deleted with everything in it before).
TEST(ValidateSaturated, OverwriteNeverDeletesAForeignFolder) {
  ff::test::TestScratch s("validate-saturated-foreign");
  const fs::path out = s / "mine";
  fs::create_directories(out);
  { std::ofstream(out / "thesis.tex") << "years of work\n"; }
  const auto r = ff::test::run_program("validate-saturated --quick --overwrite --out " + out.string() + " --doc " +
                                       (s / "doc.md").string());
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("holds no fracflow results"), std::string::npos) << r.output;
  EXPECT_EQ(slurp(out / "thesis.tex"), "years of work\n");
  EXPECT_FALSE(fs::exists(s / "doc.md"));
}
