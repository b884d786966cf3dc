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

// The loop's stop rule (drivers/dem_run_loop.cpp) falls from the quasi-static peak: the rows of a
// saturated specimen's burst before the floored-pore fix (validate-saturated, S 1, water, packing 11,
// rows 776-798: stress in Pa, axial strain, unbalanced-force ratio). Falling from the largest stress of
// all rows, the run stopped at row 798 (777 Pa < 0.6 x the 1494 Pa spike of row 797), its curve still
// rising near equilibrium at 637 Pa; falling from the quasi-static peak (636.6 Pa, row 783) it goes on.
TEST(CurvePeak, TheStopRuleFallsFromTheQuasiStaticPeak) {
  struct Row {
    long row;
    double stress, strain, unbalanced;
  };
  const std::vector<Row> rows = {
      {776, 590.306, 6.66522e-05, 0.00934}, {777, 596.266, 6.67379e-05, 0.00943}, {778, 602.044, 6.68237e-05, 0.00925},
      {779, 608.468, 6.69095e-05, 0.00911}, {780, 615.278, 6.69953e-05, 0.00941}, {781, 622.483, 6.70811e-05, 0.00928},
      {782, 629.784, 6.71668e-05, 0.00925}, {783, 636.592, 6.72526e-05, 0.00929}, {784, 641.494, 6.73384e-05, 0.132},
      {785, 627.842, 6.74242e-05, 0.282},   {786, 617.892, 6.751e-05, 0.385},     {787, 631.593, 6.75958e-05, 0.369},
      {788, 650.911, 6.76815e-05, 0.406},   {789, 650.134, 6.77673e-05, 0.424},   {790, 588.642, 6.78531e-05, 0.428},
      {791, 578.302, 6.79389e-05, 0.427},   {792, 577.963, 6.80247e-05, 0.406},   {793, 549.395, 6.81104e-05, 0.394},
      {794, 487.457, 6.81962e-05, 0.387},   {795, 514.912, 6.8282e-05, 0.372},    {796, 1324.32, 6.83678e-05, 0.427},
      {797, 1494.53, 6.84536e-05, 0.486},   {798, 777.431, 6.85393e-05, 0.548}};
  ff::drivers::StopPeak qs, all;
  long qs_stop = -1, all_stop = -1;
  for (const auto& r : rows) {
    qs.add(r.row, r.stress, r.strain, r.unbalanced < ff::drivers::kQuasiStaticUnbalance);
    all.add(r.row, r.stress, r.strain, true);
    if (qs_stop < 0 && qs.fallen(r.stress, r.strain, 0.6)) qs_stop = r.row;
    if (all_stop < 0 && all.fallen(r.stress, r.strain, 0.6)) all_stop = r.row;
  }
  EXPECT_EQ(all_stop, 798);
  EXPECT_EQ(qs_stop, -1);
  EXPECT_EQ(qs.row, 783);
  EXPECT_DOUBLE_EQ(qs.stress, 636.592);
  // It does stop once a row falls below 0.6 x 636.6 Pa after that peak, and not within the first rows.
  EXPECT_TRUE(qs.fallen(380.0, 7e-5, 0.6));
  EXPECT_FALSE(qs.fallen(390.0, 7e-5, 0.6));
  ff::drivers::StopPeak early;
  early.add(3, 25.4, 3e-6, true);
  EXPECT_FALSE(early.fallen(5.0, 4e-6, 0.6));  // a peak 3 rows into the loading: start-up noise
}
