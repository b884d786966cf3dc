// Reliability of DEM runs (issue 2, item 10): a run resumed from a checkpoint produces exactly
// the same files as an uninterrupted run, and 1 and 2 OpenMP threads give identical results.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>

#include "io/checkpoint.hpp"
#include "ucs_test_support.hpp"

using namespace ff;

TEST(UcsReliability, ResumeEqualsUninterruptedRunBitForBit) {
  const std::string text = test::small_ucs_scenario(2);
  const auto a = test::scratch("whole"), b = test::scratch("resumed");
  ASSERT_EQ(test::run_scenario(text, {}, a, 1), RunStatus::Finished);
  const auto whole = test::collect(a);
  const long steps = whole.summary["steps"];
  // Stop in the middle of the softening branch (cracks are being created), then resume.
  ASSERT_EQ(test::run_scenario(text, {}, b, 1, steps * 3 / 4), RunStatus::Interrupted);
  ASSERT_EQ(test::run_scenario(text, {}, b, 1, 0, true), RunStatus::Finished);
  const auto resumed = test::collect(b);
  EXPECT_TRUE(whole.series_text == resumed.series_text);
  EXPECT_TRUE(whole.cracks_text == resumed.cracks_text);
  EXPECT_GT(whole.summary["cracks"]["total"].get<long>(), 0);
  for (const char* key : {"ucs_Pa", "youngs_modulus_Pa", "poisson_ratio", "strain_at_peak", "steps"})
    EXPECT_EQ(whole.summary[key], resumed.summary[key]) << key;
  EXPECT_EQ(whole.summary["cracks"], resumed.summary["cracks"]);
  std::filesystem::remove_all(a);
  std::filesystem::remove_all(b);
}

TEST(UcsReliability, OneAndTwoThreadsGiveIdenticalResults) {
  const std::string text = test::small_ucs_scenario(3);
  const auto a = test::scratch("t1"), b = test::scratch("t2");
  // 3000 steps cover the elastic stage; enough to expose any order-dependent sum.
  // Every loop goes parallel (dem.parallel_min = 0), however small the sample.
  test::run_scenario(text, {"dem.parallel_min=0"}, a, 1, 3000);
  test::run_scenario(text, {"dem.parallel_min=0"}, b, 2, 3000);
  EXPECT_TRUE(test::slurp(a / "series.csv") == test::slurp(b / "series.csv"));
  // The full particle state at the end, compared bit for bit.
  CheckpointReader ra(a / "checkpoint" / "state.ffcp"), rb(b / "checkpoint" / "state.ffcp");
  for (const char* tag : {"dem.pos", "dem.vel", "dem.omega"}) {
    std::vector<Vec3> va, vb;
    ra.get(tag, va);
    rb.get(tag, vb);
    ASSERT_EQ(va.size(), vb.size());
    EXPECT_EQ(std::memcmp(va.data(), vb.data(), va.size() * sizeof(Vec3)), 0) << tag;
  }
  std::filesystem::remove_all(a);
  std::filesystem::remove_all(b);
}
