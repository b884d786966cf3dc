// `fracflow validate-hydrofrac` end to end on a small sweep (2 values of sigma_h, one packing,
// the unit tests' 560-disk block): it measures T by direct tension, runs the six blocks (sleeve,
// penetration, LBM fluid) and writes the report with the table, the fits and the figure's CSV.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "../../unit/program_runner.hpp"

namespace fs = std::filesystem;

TEST(ValidateHydrofrac, SmallSweepWritesTheReport) {
  ff::test::TestScratch s("validate-hydrofrac");
  const fs::path doc = s / "doc" / "hydrofrac.md", out = s / "runs";
  const auto r = ff::test::run_program("validate-hydrofrac --out " + out.string() + " --doc " + doc.string() +
                                       " --packings 1 --sigma-h 1e6,4e6 --width 24e-3 --radius-min 0.4e-3 "
                                       "--radius-max 0.6e-3 --hole 2.5e-3");
  ASSERT_EQ(r.code, 0) << r.output;
  std::ifstream f(doc);
  std::stringstream ss;
  ss << f.rdbuf();
  const std::string text = ss.str();
  for (const char* part : {"T = ", "| 4.00 | 1.00 |", "| 4.00 | 4.00 |", "initiation, sleeve (vs H&W)",
                           "breakdown, penetration (vs H&F, eta = 0)", "breakdown, LBM fluid (vs H&F, eta = 0)",
                           "**LBM fluid.**", "Why the DEM differs"})
    EXPECT_NE(text.find(part), std::string::npos) << part << "\n" << text;
  EXPECT_TRUE(fs::exists(out / "tension" / "summary.json"));
  EXPECT_TRUE(fs::exists(out / "breakdown.csv"));
  // A second call refuses to overwrite without --overwrite, naming the folder.
  const auto again = ff::test::run_program("validate-hydrofrac --out " + out.string() + " --doc " + doc.string() +
                                           " --packings 1 --sigma-h 1e6");
  EXPECT_NE(again.code, 0);
  EXPECT_NE(again.output.find("--overwrite"), std::string::npos) << again.output;
}

// --overwrite replaces only a folder of ours: someone else's files are refused and left whole (they
// were deleted with the folder before).
TEST(ValidateHydrofrac, OverwriteNeverDeletesAForeignFolder) {
  ff::test::TestScratch s("validate-hydrofrac-foreign");
  const fs::path out = s / "mine";
  fs::create_directories(out);
  { std::ofstream(out / "core_logs.csv") << "depth,UCS\n"; }
  const auto r = ff::test::run_program("validate-hydrofrac --overwrite --out " + out.string() + " --doc " +
                                       (s / "doc.md").string() + " --packings 1 --sigma-h 1e6");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("holds no fracflow results"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::exists(out / "core_logs.csv"));
  EXPECT_FALSE(fs::exists(s / "doc.md"));
}
