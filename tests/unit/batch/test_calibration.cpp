// The calibration loop on a stand-in for the UCS run with the relations of seed 000 Sec. 5.2
// plus cross effects, so the algorithm is tested in milliseconds.
#include <gtest/gtest.h>

#include <cmath>

#include "batch/calibration.hpp"
#include "core/error.hpp"

using namespace ff::batch;

namespace {

const MicroParameters kTable7{2.09e9, 2.09e9, 14.65, 14.65, 17.4e6, 4.35e6};

CalibrationSettings table5_targets() {
  CalibrationSettings s;
  s.target = {2.37e9, 0.35, 14.97e6};
  return s;
}

// E linear in emod and a little softer at high kratio; nu = a + b ln(kratio); UCS linear in the
// strengths and a little stronger at high emod. Calibrated to the default sample's E = 0.95 GPa,
// nu = 0.30, UCS = 14.1 MPa at the Table 7 parameters.
MacroProperties stand_in(const MicroParameters& p) {
  const double k1 = 0.95e9 / (2.09e9 * std::pow(14.65, -0.15));
  const double b = 0.09, a = 0.30 - b * std::log(14.65);
  const double k2 = 14.1e6 / 17.4e6;
  return {k1 * p.bond_emod_Pa * std::pow(p.bond_kratio, -0.15), a + b * std::log(p.bond_kratio),
          k2 * p.tensile_strength_Pa * (1 + 0.1 * std::log(p.bond_emod_Pa / 2.09e9))};
}

}  // namespace

TEST(Calibration, StandInModelConvergesWithinTolerancesInFewRuns) {
  const auto s = table5_targets();
  int calls = 0;
  const auto r = calibrate(kTable7, s, [&](const MicroParameters& p, int, bool) {
    ++calls;
    return stand_in(p);
  });
  ASSERT_TRUE(r.converged);
  EXPECT_LE(r.steps.size(), 6u);
  EXPECT_EQ(calls, static_cast<int>(r.steps.size()));
  const auto m = stand_in(r.final_params);
  EXPECT_LT(std::abs(m.youngs_modulus_Pa / 2.37e9 - 1), 0.05);
  EXPECT_LT(std::abs(m.poisson_ratio - 0.35), 0.03);
  EXPECT_LT(std::abs(m.ucs_Pa / 14.97e6 - 1), 0.05);
  // Ratios held fixed by the rules: bond/contact modulus, bond/contact kratio, tensile/cohesion.
  const auto& p = r.final_params;
  EXPECT_NEAR(p.bond_emod_Pa / p.contact_emod_Pa, 1.0, 1e-5);
  EXPECT_NEAR(p.bond_kratio / p.contact_kratio, 1.0, 1e-5);
  EXPECT_NEAR(p.tensile_strength_Pa / p.cohesion_Pa, 4.0, 1e-5);
}

TEST(Calibration, TighterTolerancesStillConverge) {
  auto s = table5_targets();
  s.youngs_modulus_tolerance = s.ucs_tolerance = 0.005;
  s.poisson_tolerance = 0.002;
  const auto r = calibrate(kTable7, s, [](const MicroParameters& p, int, bool) { return stand_in(p); });
  EXPECT_TRUE(r.converged);
  EXPECT_LE(r.steps.size(), 8u);
}

TEST(Calibration, FirstStepUsesTheModulusRatioAndTheSlopeGuess) {
  const auto s = table5_targets();
  CalibrationStep st;
  st.iteration = 1;
  st.params = kTable7;
  st.measured = {0.95e9, 0.30, 14.1e6};
  score_step(st, s);
  const std::vector<CalibrationStep> h = {st};
  const auto p = next_parameters(h, s);
  EXPECT_NEAR(p.bond_emod_Pa, 2.09e9 * 2.37 / 0.95, 1.0);
  EXPECT_NEAR(p.contact_emod_Pa, 2.09e9 * 2.37 / 0.95, 1.0);
  EXPECT_NEAR(p.bond_kratio, 14.65 * std::exp(0.05 / s.poisson_slope_guess), 1e-9);
  EXPECT_NEAR(p.tensile_strength_Pa, 17.4e6 * 14.97 / 14.1, 1e-3);
  EXPECT_NEAR(p.cohesion_Pa, 4.35e6 * 14.97 / 14.1, 1e-3);
}

// With two runs at different kratio the slope comes from them: for an exactly logarithmic
// nu(kratio) the next kratio hits the target.
TEST(Calibration, SecondStepUsesTheMeasuredSlope) {
  const auto s = table5_targets();
  std::vector<CalibrationStep> h(2);
  const double b = 0.12, a = 0.30 - b * std::log(10.0);
  for (int i = 0; i < 2; ++i) {
    h[i].iteration = i + 1;
    h[i].params = kTable7;
    h[i].params.bond_kratio = h[i].params.contact_kratio = i == 0 ? 10.0 : 20.0;
    h[i].measured = {2e9, a + b * std::log(h[i].params.bond_kratio), 14e6};
    score_step(h[i], s);
  }
  const auto p = next_parameters(h, s);
  EXPECT_NEAR(a + b * std::log(p.bond_kratio), 0.35, 1e-12);
}

TEST(Calibration, StepsAreLimited) {
  const auto s = table5_targets();
  CalibrationStep st;
  st.params = kTable7;
  st.measured = {0.01e9, 0.0, 100e6};  // far off: each factor is clamped to [1/4, 4]
  const std::vector<CalibrationStep> h = {st};
  const auto p = next_parameters(h, s);
  EXPECT_NEAR(p.bond_emod_Pa / kTable7.bond_emod_Pa, 4.0, 1e-12);
  EXPECT_NEAR(p.bond_kratio / kTable7.bond_kratio, 4.0, 1e-12);
  EXPECT_NEAR(p.tensile_strength_Pa / kTable7.tensile_strength_Pa, 0.25, 1e-12);  // 14.97/100 clamped
}

TEST(Calibration, NotConvergedReturnsTheClosestRun) {
  auto s = table5_targets();
  s.max_iterations = 2;
  const auto r = calibrate(kTable7, s, [](const MicroParameters& p, int, bool) { return stand_in(p); });
  EXPECT_FALSE(r.converged);
  ASSERT_EQ(r.steps.size(), 2u);
  EXPECT_EQ(r.chosen, 1);  // the second run is closer than the Table 7 start
  EXPECT_EQ(r.final_params.bond_emod_Pa, r.steps[1].params.bond_emod_Pa);
}

TEST(Calibration, BadInputIsAnInputError) {
  auto s = table5_targets();
  s.target.poisson_ratio = 0.6;
  EXPECT_THROW(calibrate(kTable7, s, [](const MicroParameters& p, int, bool) { return stand_in(p); }), ff::InputError);
  s = table5_targets();
  s.max_iterations = 0;
  EXPECT_THROW(check_calibration_input(kTable7, s), ff::InputError);
}

TEST(Calibration, FailedMeasurementStopsWithAnError) {
  const auto s = table5_targets();
  EXPECT_THROW(calibrate(kTable7, s, [](const MicroParameters&, int, bool) { return MacroProperties{std::nan(""), 0.3, 1e7}; }),
               ff::Error);
}

TEST(Calibration, ParametersAreRoundedToShortNumbers) {
  const auto p = rounded({2.0912345678e9, 1, 14.6512345, 1, 17.4e6, 4.35e6});
  EXPECT_EQ(p.bond_emod_Pa, 2.09123e9);
  EXPECT_EQ(p.bond_kratio, 14.6512);
}

namespace {

// With the triaxial slope of the peak differential stress: b = 0.4 + 4.6 tan(phi_b), a little
// less at high strength (the two runs measured on the C1-like example: 4 deg -> 0.73, 30 deg ->
// 3.05), and the UCS rising with
// phi_b as the compressed bonds' shear strength grows.
MacroProperties stand_in_with_slope(const MicroParameters& p) {
  MacroProperties m = stand_in(p);
  const double t = std::tan(p.friction_angle_deg * 3.14159265358979 / 180);
  m.ucs_Pa *= 1 + 0.4 * t;
  m.slope_b = 0.4 + 4.6 * t - 0.05 * std::log(p.tensile_strength_Pa / 17.4e6);
  return m;
}

MicroParameters table7_with_angle() {
  MicroParameters p = kTable7;
  p.friction_angle_deg = 4;
  return p;
}

}  // namespace

TEST(Calibration, TriaxialSlopeIsReachedThroughTheBondFrictionAngle) {
  auto s = table5_targets();
  s.target.slope_b = 3.54;  // seed 000 Eq. 1
  const auto r = calibrate(table7_with_angle(), s, [](const MicroParameters& p, int, bool) { return stand_in_with_slope(p); });
  ASSERT_TRUE(r.converged);
  EXPECT_LE(r.steps.size(), 8u);
  const auto m = stand_in_with_slope(r.final_params);
  EXPECT_LT(std::abs(m.slope_b / 3.54 - 1), 0.10);
  EXPECT_LT(std::abs(m.ucs_Pa / 14.97e6 - 1), 0.05);
  EXPECT_GT(r.final_params.friction_angle_deg, 25);
  EXPECT_LT(r.final_params.friction_angle_deg, 40);
}

TEST(Calibration, FirstSlopeStepUsesTheGradientGuess) {
  auto s = table5_targets();
  s.target.slope_b = 3.54;
  CalibrationStep st;
  st.iteration = 1;
  st.params = table7_with_angle();
  st.measured = {2.37e9, 0.35, 14.97e6, 0.73};
  st.slope_measured = true;
  score_step(st, s);
  EXPECT_FALSE(st.converged);
  const auto p = next_parameters(std::span<const CalibrationStep>(&st, 1), s);
  const double expect = std::atan(std::tan(4 * 3.14159265358979 / 180) + (3.54 - 0.73) / 4.6) * 180 / 3.14159265358979;
  EXPECT_NEAR(p.friction_angle_deg, expect, 1e-9);
}

TEST(Calibration, WithoutTargetSlopeTheAngleIsLeftAlone) {
  const auto s = table5_targets();
  const auto r = calibrate(table7_with_angle(), s, [](const MicroParameters& p, int, bool) { return stand_in_with_slope(p); });
  for (auto& st : r.steps) EXPECT_EQ(st.params.friction_angle_deg, 4);
}

TEST(Calibration, BadSlopeTargetOrMeasurementIsReported) {
  auto s = table5_targets();
  s.target.slope_b = -0.5;  // strength falling with confinement
  EXPECT_THROW(check_calibration_input(table7_with_angle(), s), ff::InputError);
  s.target.slope_b = 3.54;
  EXPECT_THROW(calibrate(table7_with_angle(), s,
                         [](const MicroParameters& p, int, bool) {
                           auto m = stand_in(p);
                           m.slope_b = std::nan("");
                           return m;
                         }),
               ff::Error);
}

namespace {

// A stand-in fitted to the six calibration runs of the 25 x 50 mm coal matrix sample
// (validate-triaxial, 2026-11-22; within ~10% of each measured E, nu, UCS and b): damage inside
// the 20-50% fit window makes E, nu and UCS depend on the bond friction angle once kratio is above
// ~10 (kratio 30: nu 0.35 at 40 deg, 0.48 at 50 deg, 0.66-0.73 at 60 deg), and b falls with
// kratio. Moving all four parameters at once, the rules before 2026-11-22 oscillated on it for 16
// runs (E -8% / +9% alternately) as they did on the real sample.
MacroProperties coupled_coal_matrix(const MicroParameters& p) {
  const double t = std::tan(p.friction_angle_deg * 3.14159265358979 / 180), t15 = std::pow(t, 1.5);
  const double damage = std::max(0.0, std::log(p.bond_kratio / 10));
  MacroProperties m;
  m.youngs_modulus_Pa = 0.42 * p.bond_emod_Pa * std::exp(-0.354 * t15 * damage);
  m.poisson_ratio = -0.14 * t15 + (0.06 + 0.1 * t15) * std::log(p.bond_kratio);
  m.ucs_Pa = 0.45 * p.tensile_strength_Pa * std::exp(-0.1 * t15 * damage);
  m.slope_b = 1.0 + 1.2 * t * std::pow(10 / p.bond_kratio, 0.45);
  return m;
}

// validate-triaxial's starting point.
const MicroParameters kValidationStart{5e9, 5e9, 30, 30, 22e6, 5.5e6, 40};

CalibrationSettings table5_and_slope(double b) {
  auto s = table5_targets();
  s.target.slope_b = b;
  s.max_iterations = 16;
  return s;
}

}  // namespace

// b = 3.0 is reached near 57 deg on the stand-in: converged, the angle moved only after runs with
// E, nu and UCS in tolerance, and b measured only beside runs that followed one within twice the
// tolerances.
TEST(Calibration, StrongCrossEffectsConvergeBlockByBlock) {
  const auto s = table5_and_slope(3.0);
  std::vector<bool> asked;
  const auto r = calibrate(kValidationStart, s, [&](const MicroParameters& p, int, bool measure_slope) {
    asked.push_back(measure_slope);
    return coupled_coal_matrix(p);
  });
  ASSERT_TRUE(r.converged) << r.stop_reason;
  EXPECT_LE(r.steps.size(), 14u);
  const auto m = coupled_coal_matrix(r.final_params);
  EXPECT_LT(std::abs(m.youngs_modulus_Pa / 2.37e9 - 1), 0.05);
  EXPECT_LT(std::abs(m.poisson_ratio - 0.35), 0.03);
  EXPECT_LT(std::abs(m.ucs_Pa / 14.97e6 - 1), 0.05);
  EXPECT_LT(std::abs(m.slope_b / 3.0 - 1), 0.10);
  EXPECT_FALSE(asked.front());  // the first run is far from E, nu and UCS
  for (std::size_t i = 1; i < r.steps.size(); ++i) {
    const auto& prev = r.steps[i - 1];
    EXPECT_EQ(asked[i], worst_scaled_error_without_slope(prev, s) < 2) << "run " << i + 1;
    EXPECT_EQ(r.steps[i].slope_measured, asked[i]);
    if (r.steps[i].params.friction_angle_deg != prev.params.friction_angle_deg) {
      EXPECT_LT(worst_scaled_error_without_slope(prev, s), 1) << "run " << i + 1;
      EXPECT_TRUE(prev.slope_measured);
      EXPECT_EQ(r.steps[i].params.bond_emod_Pa, prev.params.bond_emod_Pa);  // nothing else moves with it
      EXPECT_EQ(r.steps[i].params.tensile_strength_Pa, prev.params.tensile_strength_Pa);
    }
  }
}

// Seed 000's b = 3.54 (-10%: 3.19) lies beyond the stand-in's reach (b ~3.1 where nu = 0.35 at
// the 60 deg cap): the calibration stops as soon as it knows, with E, nu and UCS in tolerance.
TEST(Calibration, SlopeOutOfReachStopsWithTheOtherTargetsMet) {
  const auto s = table5_and_slope(3.54);
  const auto r = calibrate(kValidationStart, s,
                           [](const MicroParameters& p, int, bool) { return coupled_coal_matrix(p); });
  EXPECT_FALSE(r.converged);
  EXPECT_NE(r.stop_reason.find("out of reach"), std::string::npos) << r.stop_reason;
  EXPECT_LT(r.steps.size(), 16u);
  const auto& chosen = r.steps[r.chosen];
  EXPECT_TRUE(chosen.slope_measured);
  EXPECT_LT(worst_scaled_error_without_slope(chosen, s), 1);
  EXPECT_EQ(chosen.params.friction_angle_deg, 60);
  EXPECT_GT(chosen.measured.slope_b, 2.8);
}

// nu's slope against ln(kratio) comes from the runs at the current friction angle, not from a
// fit that mixes angles.
TEST(Calibration, PoissonSlopeComesFromTheRunsAtTheCurrentAngle) {
  const auto s = table5_and_slope(3.0);
  std::vector<CalibrationStep> h(4);
  const double angle[] = {40, 40, 60, 60}, kratio[] = {10, 20, 10, 20};
  for (int i = 0; i < 4; ++i) {
    h[i].iteration = i + 1;
    h[i].params = kValidationStart;
    h[i].params.friction_angle_deg = angle[i];
    h[i].params.bond_kratio = h[i].params.contact_kratio = kratio[i];
    // nu rises 0.1 per ln unit at 40 deg, 0.3 at 60 deg; E far off so nothing converges.
    h[i].measured = {1e9, (angle[i] == 40 ? 0.1 : 0.3) * std::log(kratio[i]) + (angle[i] == 40 ? 0.05 : -0.4), 10e6};
    score_step(h[i], s);
  }
  const auto p = next_parameters(h, s);
  EXPECT_EQ(p.friction_angle_deg, 60);
  EXPECT_NEAR(0.3 * std::log(p.bond_kratio) - 0.4, 0.35, 1e-12);
}

// Not converged with b calibrated: the run with E, nu and UCS in tolerance is reported, even when
// another one is closer in the worst scaled error. The scripted errors are the last three runs of
// validate-triaxial's calibration on 2026-11-22 (there the old choice took E +5.6%).
TEST(Calibration, NotConvergedPrefersTheRunWithEnuAndUcsInTolerance) {
  auto s = table5_and_slope(3.54);
  s.max_iterations = 3;
  MicroParameters start = kValidationStart;
  start.friction_angle_deg = 50;
  const MacroProperties scripted[] = {{2.37e9 * 0.945, 0.370, 14.97e6 * 0.990, 3.115},
                                      {2.37e9 * 1.056, 0.334, 14.97e6 * 1.006, 3.211},
                                      {2.37e9 * 0.984, 0.351, 14.97e6 * 0.989, 3.124}};
  const auto r = calibrate(start, s, [&](const MicroParameters&, int it, bool) { return scripted[it - 1]; });
  ASSERT_EQ(r.steps.size(), 3u);
  EXPECT_FALSE(r.converged);
  EXPECT_TRUE(r.steps[1].slope_measured && r.steps[2].slope_measured);
  EXPECT_LT(worst_scaled_error(r.steps[1], s), worst_scaled_error(r.steps[2], s));  // 1.12 against 1.18
  EXPECT_EQ(r.chosen, 2);
}

// A run with E, nu and UCS in tolerance that did not measure b is repeated as it was, with b.
TEST(Calibration, RunInToleranceWithoutSlopeIsRepeatedWithIt) {
  const auto s = table5_and_slope(3.54);
  CalibrationStep st;
  st.iteration = 10;
  st.params = kValidationStart;
  st.measured = {2.37e9 * 1.002, 0.334, 14.97e6 * 0.973};
  score_step(st, s);
  ASSERT_FALSE(st.slope_measured);
  const std::span<const CalibrationStep> h(&st, 1);
  const auto p = next_parameters(h, s);
  EXPECT_EQ(p.bond_emod_Pa, st.params.bond_emod_Pa);
  EXPECT_EQ(p.bond_kratio, st.params.bond_kratio);
  EXPECT_EQ(p.tensile_strength_Pa, st.params.tensile_strength_Pa);
  EXPECT_EQ(p.friction_angle_deg, st.params.friction_angle_deg);
  EXPECT_TRUE(next_run_measures_slope(h, s));
}
