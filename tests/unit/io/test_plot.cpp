// PNG plots through scripts/plot_series.py; skipped where python3 + matplotlib are absent.
#include <gtest/gtest.h>

#include <cstdlib>

#include "io/csv.hpp"
#include "io/plot.hpp"
#include "scratch_dir.hpp"

using namespace ff;

namespace {
bool have_matplotlib() {
  static const bool ok = std::system("/usr/bin/python3 -c 'import matplotlib, numpy' >/dev/null 2>&1") == 0;
  return ok;
}
bool is_png(const std::filesystem::path& p) {
  return test::slurp(p).rfind("\x89PNG\r\n\x1a\n", 0) == 0;
}
// Sets an environment variable for the scope of one test.
struct ScopedEnv {
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old, had_ = true;
    ::setenv(name, value, 1);
  }
  ~ScopedEnv() { had_ ? (void)::setenv(name_, old_.c_str(), 1) : (void)::unsetenv(name_); }
  const char* name_;
  std::string old_;
  bool had_ = false;
};
}  // namespace

TEST(io_plot, WritesPngWithBothAxesAndReference) {
  if (!have_matplotlib()) GTEST_SKIP() << "/usr/bin/python3 with matplotlib and numpy is not available";
  test::ScratchDir d;
  {
    CsvWriter w;
    w.open(d / "s.csv", {"strain", "stress", "bonds"});
    for (int i = 0; i <= 20; ++i) w.row({1e-4 * i, 2e9 * 1e-4 * i, 1000.0 - i});
  }
  test::spit(d / "ref.csv", "# digitised reference\nstrain,stress\n0.001,2.1e6\n0.0015,3e6\n");
  PlotSpec s;
  s.title = "UCS test";
  s.x = "strain";
  s.y = {"stress"};
  s.y2 = {"bonds"};
  s.y_scale = 1e-6;
  s.ylabel = "stress [MPa]";
  s.y2label = "intact bonds [-]";
  s.reference_csv = d / "ref.csv";
  s.ref_x = "strain";
  s.ref_y = "stress";
  s.ref_label = "reference";
  EXPECT_TRUE(plot_series(d / "s.csv", d / "s.png", s));
  EXPECT_TRUE(is_png(d / "s.png"));
}

TEST(io_plot, SeveralFiguresInOneRunAndBadOneFailsAlone) {
  if (!have_matplotlib()) GTEST_SKIP() << "/usr/bin/python3 with matplotlib and numpy is not available";
  test::ScratchDir d;
  test::spit(d / "s.csv", "time,load,bonds\n1,2,3\n2,4,nan\n3,8,5\n");
  PlotSpec s;
  s.x = "time";
  s.y = {"load"};
  s.y2 = {"bonds"};
  PlotSpec bad = s;
  bad.y = {"no_such_column"};
  const std::vector<PlotJob> jobs{{d / "s.csv", d / "log.png", [&] { auto t = s; t.logy = true; t.y2.clear(); return t; }()},
                                  {d / "s.csv", d / "bad.png", bad}};
  EXPECT_EQ(plot_series(jobs), 1);
  EXPECT_TRUE(is_png(d / "log.png"));
  EXPECT_FALSE(std::filesystem::exists(d / "bad.png"));
}

TEST(io_plot, MissingScriptReturnsFalseWithoutThrowing) {
  test::ScratchDir d;
  ScopedEnv env("FRACFLOW_SCRIPTS", (d / "no-scripts-here").c_str());
  EXPECT_EQ(scripts_dir(), d / "no-scripts-here");
  PlotSpec s;
  s.x = "time";
  s.y = {"load"};
  EXPECT_FALSE(plot_series(d / "s.csv", d / "s.png", s));
  EXPECT_FALSE(std::filesystem::exists(d / "s.png"));
}
