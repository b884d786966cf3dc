// The strength of a loading curve is its quasi-static peak (drivers/curve_peak.hpp): a crack
// burst's one-row platen spike does not count. The rows below are those of a saturated 2D
// specimen (validate-saturated, S 1, water, packing 7; series.csv steps 1,393,800-1,409,400,
// stress in kPa): loading near equilibrium up to 7.670 kPa, then the burst's rows with an
// unbalanced-force ratio of 0.2-1.5 and the 20.680 kPa spike.
#include <gtest/gtest.h>

#include <vector>

#include "drivers/curve_peak.hpp"

using ff::drivers::quasi_static_peak;

TEST(CurvePeak, TheBurstSpikeIsNotTheStrength) {
  const std::vector<double> stress = {7.524, 7.670, 7.645, 7.568, 7.159, 7.813, 9.185, 20.680, 18.310, 6.0};
  const std::vector<double> unbalanced = {0.0815, 0.0329, 0.0481, 0.0734, 0.206, 0.298, 0.673, 1.355, 1.54, 0.09};
  const auto k = quasi_static_peak(stress, unbalanced, 0.1);
  ASSERT_TRUE(k.has_value());
  EXPECT_EQ(*k, 1u);  // 7.670 kPa, not 20.680
  // Without the filter (a threshold above every ratio) the spike is the peak: the filter decides.
  EXPECT_EQ(*quasi_static_peak(stress, unbalanced, 10.0), 7u);
}

TEST(CurvePeak, NoRowNearEquilibriumGivesNone) {
  const std::vector<double> stress = {1, 2, 3};
  const std::vector<double> unbalanced = {0.5, 0.6, 0.7};
  EXPECT_FALSE(quasi_static_peak(stress, unbalanced, 0.1).has_value());
  EXPECT_FALSE(quasi_static_peak({}, {}, 0.1).has_value());
}

TEST(CurvePeak, TiesKeepTheFirstRow) {
  const std::vector<double> stress = {1, 3, 3, 2};
  const std::vector<double> unbalanced = {0, 0, 0, 0};
  EXPECT_EQ(*quasi_static_peak(stress, unbalanced, 0.1), 1u);
}
