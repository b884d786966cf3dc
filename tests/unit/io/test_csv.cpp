// CSV time series: shortest round-trip numbers, resume by truncation, reading with comments.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/error.hpp"
#include "io/csv.hpp"
#include "scratch_dir.hpp"

using namespace ff;
using ff::test::slurp;
using ff::test::spit;

namespace {
std::string error_of(auto&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(io_csv, HeaderAndShortestRoundTripValues) {
  test::ScratchDir d;
  const auto p = d / "out/series.csv";
  CsvWriter w;
  EXPECT_FALSE(w.is_open());
  w.open(p, {"t", "stress", "n"});
  EXPECT_TRUE(w.is_open());
  const std::vector<double> r1{0.1, 1.0 / 3.0, 1e-300};
  w.row(r1);
  w.row({-2.5e6, std::numeric_limits<double>::infinity(), 42});
  EXPECT_EQ(w.rows(), 2u);
  // Written and flushed immediately: another process can read it while the run goes on.
  EXPECT_EQ(slurp(p), "t,stress,n\n0.1,0.3333333333333333,1e-300\n-2500000,inf,42\n");
  const CsvTable t = read_csv(p);
  ASSERT_EQ(t.rows(), 2u);
  EXPECT_EQ(t.column("stress")[0], 1.0 / 3.0);  // exact, not approximately
  EXPECT_EQ(t.column("n")[0], 1e-300);
  EXPECT_TRUE(std::isinf(t.column("stress")[1]));
  EXPECT_THROW(w.row({1.0, 2.0}), Error);  // wrong number of values
}

TEST(io_csv, ReopenKeepsRowsAndDropsLaterOnes) {
  test::ScratchDir d;
  const auto p = d / "s.csv";
  {
    CsvWriter w;
    w.open(p, {"a", "b"});
    for (int i = 0; i < 5; ++i) w.row({double(i), 0.5 * i});
  }
  CsvWriter w;
  w.reopen(p, {"a", "b"}, 3);
  EXPECT_EQ(w.rows(), 3u);
  w.row({3.0, 1.5});
  EXPECT_EQ(w.rows(), 4u);
  w.close();
  EXPECT_EQ(slurp(p), "a,b\n0,0\n1,0.5\n2,1\n3,1.5\n");
  w.reopen(p, {"a", "b"}, 0);  // restart from the very beginning
  EXPECT_EQ(slurp(p), "a,b\n");
  w.close();
  w.reopen(d / "missing.csv", {"a", "b"}, 0);  // nothing to resume: a new file
  EXPECT_EQ(slurp(d / "missing.csv"), "a,b\n");
}

TEST(io_csv, ReopenErrorsNameTheFile) {
  test::ScratchDir d;
  const auto p = d / "s.csv";
  spit(p, "a,b\n0,0\n1,0.5\n2,");
  CsvWriter w;
  auto e = error_of([&] { w.reopen(p, {"a", "c"}, 1); });
  EXPECT_NE(e.find(p.string()), std::string::npos) << e;
  EXPECT_NE(e.find("header"), std::string::npos) << e;
  e = error_of([&] { w.reopen(p, {"a", "b"}, 5); });
  EXPECT_NE(e.find("incomplete"), std::string::npos) << e;  // the cut last line is reported
  e = error_of([&] { w.reopen(d / "none.csv", {"a", "b"}, 2); });
  EXPECT_NE(e.find("missing"), std::string::npos) << e;
  spit(p, "a,b\n0,0\n");
  e = error_of([&] { w.reopen(p, {"a", "b"}, 2); });
  EXPECT_NE(e.find("holds 1 data rows"), std::string::npos) << e;
  spit(p, "a,b\n0,0\n1,");
  w.reopen(p, {"a", "b"}, 1);  // a partial line after the kept rows is dropped silently
  EXPECT_EQ(w.rows(), 1u);
  EXPECT_EQ(slurp(p), "a,b\n0,0\n");
}

TEST(io_csv, ReadSkipsCommentsAndMarksNonNumbers) {
  test::ScratchDir d;
  const auto p = d / "ref.csv";
  spit(p, "# Reference: Potyondy & Cundall (2004), Fig. 9\n# units: strain [-], stress [MPa]\n"
          "strain, \"stress\"\r\n0.001, +12.5\r\n\n0.002,n/a\n# trailing comment\n0.003,-1e3\n");
  const CsvTable t = read_csv(p);
  EXPECT_EQ(t.columns, (std::vector<std::string>{"strain", "stress"}));
  ASSERT_EQ(t.rows(), 3u);
  EXPECT_EQ(t.column("stress")[0], 12.5);
  EXPECT_TRUE(std::isnan(t.column("stress")[1]));
  EXPECT_EQ(t.column("stress")[2], -1e3);
  EXPECT_TRUE(t.has("strain"));
  EXPECT_FALSE(t.has("time"));
  EXPECT_NE(error_of([&] { (void)t.column("time"); }).find("strain, stress"), std::string::npos);
}

TEST(io_csv, RaggedRowNamesFileAndLine) {
  test::ScratchDir d;
  const auto p = d / "bad.csv";
  spit(p, "# c\nx,y\n1,2\n3\n");
  const auto e = error_of([&] { read_csv(p); });
  EXPECT_NE(e.find(p.string() + ":4"), std::string::npos) << e;
  EXPECT_NE(error_of([&] { read_csv(d / "nope.csv"); }).find("nope.csv"), std::string::npos);
  EXPECT_NE(error_of([&] { parse_csv("# only comments\n", "c.csv"); }).find("no header"), std::string::npos);
}
