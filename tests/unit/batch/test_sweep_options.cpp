#include <gtest/gtest.h>

#include "batch/sweep.hpp"
#include "core/error.hpp"

using namespace ff::batch;

TEST(SweepOptions, VaryParsesKeyAndValues) {
  const auto a = parse_vary("triaxial.confining_pressure=2.5e6, 5e6,7.5e6");
  EXPECT_EQ(a.key, "triaxial.confining_pressure");
  ASSERT_EQ(a.values.size(), 3u);
  EXPECT_EQ(a.values[0], "2.5e6");
  EXPECT_EQ(a.values[1], "5e6");
  EXPECT_EQ(a.values[2], "7.5e6");
}

TEST(SweepOptions, CommasInsideListsBelongToTheValue) {
  const auto a = parse_vary("dem.gravity=[0,0,-9.81],[0,0,0]");
  ASSERT_EQ(a.values.size(), 2u);
  EXPECT_EQ(a.values[0], "[0,0,-9.81]");
  EXPECT_EQ(a.values[1], "[0,0,0]");
}

TEST(SweepOptions, BadVaryOptionsNameTheOption) {
  // The last two: a value given twice ran the same case twice under two names (fuzzed 2026-11-30).
  for (const char* bad : {"nokey", "=1,2", "ucs.platen_velocity=", "ucs.platen_velocity=0.1,,0.2",
                          "sample.porosity=0.4,0.4", "ucs.platen_velocity=0.1,0.2,1e-1"}) {
    try {
      parse_vary(bad);
      FAIL() << bad;
    } catch (const ff::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("--vary"), std::string::npos) << e.what();
    }
  }
}

TEST(SweepOptions, CartesianProductFirstAxisSlowest) {
  const std::vector<SweepAxis> axes = {{"a", {"1", "2"}}, {"b", {"x", "y", "z"}}};
  const auto cases = cartesian_product(axes);
  ASSERT_EQ(cases.size(), 6u);
  const std::vector<std::pair<std::string, std::string>> first = {{"a", "1"}, {"b", "x"}};
  const std::vector<std::pair<std::string, std::string>> fourth = {{"a", "2"}, {"b", "x"}};
  const std::vector<std::pair<std::string, std::string>> last = {{"a", "2"}, {"b", "z"}};
  EXPECT_EQ(cases[0], first);
  EXPECT_EQ(cases[3], fourth);
  EXPECT_EQ(cases[5], last);
}

TEST(SweepOptions, KeyVariedTwiceIsAnError) {
  const std::vector<SweepAxis> axes = {{"a", {"1"}}, {"a", {"2"}}};
  EXPECT_THROW(cartesian_product(axes), ff::InputError);
}

TEST(SweepOptions, CaseNamesAreZeroPadded) {
  EXPECT_EQ(case_name(0, 3), "case_000");
  EXPECT_EQ(case_name(12, 100), "case_012");
  EXPECT_EQ(case_name(7, 2000), "case_0007");
}
