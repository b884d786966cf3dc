// ParaView .pvd series: rewritten after each add, resumable up to a given time.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include "core/error.hpp"
#include "io/pvd.hpp"
#include "scratch_dir.hpp"

using namespace ff;

TEST(io_pvd, AddRewritesTheCollection) {
  test::ScratchDir d;
  const auto p = d / "run/particles.pvd";
  PvdSeries s;
  s.open(p);
  EXPECT_EQ(parse_pvd(test::slurp(p), "p").size(), 0u);  // readable from the start
  s.add(0.0, "vtk/p_000000.vtp");
  s.add(1.0 / 3.0, "vtk/p_000001.vtp");
  s.add(1.0 / 3.0, "vtk/walls_000001.vtp", 1);
  const std::string text = test::slurp(p);
  EXPECT_NE(text.find("<VTKFile type=\"Collection\""), std::string::npos);
  EXPECT_NE(text.find("<DataSet timestep=\"0.3333333333333333\" group=\"\" part=\"0\" file=\"vtk/p_000001.vtp\"/>"),
            std::string::npos) << text;
  const auto e = parse_pvd(text, p.string());
  ASSERT_EQ(e.size(), 3u);
  EXPECT_EQ(e[1].time, 1.0 / 3.0);  // exact: a resume compares times exactly
  EXPECT_EQ(e[2].part, 1);
  EXPECT_EQ(e[2].file, "vtk/walls_000001.vtp");
}

TEST(io_pvd, ResumeKeepsEntriesUpToTime) {
  test::ScratchDir d;
  const auto p = d / "s.pvd";
  {
    PvdSeries s;
    s.open(p);
    for (int i = 0; i < 5; ++i) s.add(0.1 * i, fmt::format("f{} & <odd>\".vtp", i));
  }
  PvdSeries s;
  s.open(p, true, 0.1 * 2);
  ASSERT_EQ(s.entries().size(), 3u);
  EXPECT_EQ(s.entries()[2].file, "f2 & <odd>\".vtp");  // escaped on write, unescaped on read
  s.add(0.3, "g3.vtp");
  EXPECT_EQ(parse_pvd(test::slurp(p), "p").size(), 4u);
  PvdSeries fresh;
  fresh.open(p);  // no resume: starts empty
  EXPECT_TRUE(fresh.entries().empty());
  EXPECT_TRUE(parse_pvd(test::slurp(p), "p").empty());
  PvdSeries none;
  none.open(d / "absent.pvd", true, 1.0);  // resume without a file: empty series
  EXPECT_TRUE(none.entries().empty());
}

TEST(io_pvd, BrokenFileIsAnInputError) {
  test::ScratchDir d;
  test::spit(d / "b.pvd", "<VTKFile><Collection><DataSet timestep=\"x\" file=\"a.vtp\"/></Collection></VTKFile>");
  PvdSeries s;
  try {
    s.open(d / "b.pvd", true);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("b.pvd"), std::string::npos) << e.what();
  }
  PvdSeries closed;
  EXPECT_THROW(closed.add(0, "x.vtp"), Error);
}
