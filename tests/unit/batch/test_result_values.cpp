// Results that cannot be trusted are not reported as results (issue 12, part 6), and the notice
// of a very long run (part 8), on hand-made inputs: the elastic fit and the peak check the UCS
// and triaxial drivers use, summary.json readers meeting null, and the step/time estimate.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "batch/calibration.hpp"
#include "batch/run_case.hpp"
#include "batch/triaxial_validation.hpp"
#include "core/error.hpp"
#include "drivers/run_estimate.hpp"
#include "drivers/summary_values.hpp"
#include "drivers/ucs/ucs_measure.hpp"

using namespace ff;
using namespace ff::drivers;
namespace fs = std::filesystem;

namespace {
bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }
}  // namespace

TEST(ElasticFit, LinearCurveGivesItsSlopeAndPoissonRatio) {
  std::vector<Real> e, s, l;
  for (int k = 0; k <= 10; ++k) e.push_back(1e-3 * k), s.push_back(2e9 * 1e-3 * k), l.push_back(-0.25e-3 * k);
  const ElasticFit f = fit_elastic(e, s, l, 10);
  ASSERT_TRUE(f.ok()) << f.reason;
  EXPECT_EQ(f.points, 4);  // stresses 20%, 30%, 40%, 50% of the peak
  EXPECT_NEAR(f.youngs_modulus, 2e9, 1);
  EXPECT_NEAR(f.poisson_ratio, 0.25, 1e-12);
}

TEST(ElasticFit, EmptyWindowGivesNoValueAndAReasonNeverZero) {
  // Three rows: 10%, 60%, 100% of the peak, none between 20% and 50%.
  const std::vector<Real> e = {1e-4, 6e-4, 1e-3}, s = {1e6, 6e6, 10e6}, l = {0, -1e-4, -2e-4};
  const ElasticFit f = fit_elastic(e, s, l, 2);
  EXPECT_FALSE(f.ok());
  EXPECT_EQ(f.points, 0);
  EXPECT_TRUE(std::isnan(f.youngs_modulus));
  EXPECT_TRUE(std::isnan(f.poisson_ratio));
  EXPECT_TRUE(has(f.reason, "0 points")) << f.reason;
  EXPECT_TRUE(has(f.reason, "20%-50%")) << f.reason;
  // One point is not a line either.
  const ElasticFit one = fit_elastic({1e-4, 3e-4, 1e-3}, {1e6, 3e6, 10e6}, {0, 0, 0}, 2);
  EXPECT_FALSE(one.ok());
  EXPECT_EQ(one.points, 1);
  EXPECT_TRUE(has(one.reason, "1 point ")) << one.reason;
  // No curve at all, and a curve that never carried load.
  EXPECT_FALSE(fit_elastic({}, {}, {}, 0).ok());
  EXPECT_FALSE(fit_elastic({1e-4, 2e-4}, {0, 0}, {0, 0}, 0).ok());
}

TEST(ElasticFit, SummaryHoldsNullAndTheReason) {
  nlohmann::json j;
  put_elastic_fit(j, fit_elastic({1e-4, 6e-4, 1e-3}, {1e6, 6e6, 10e6}, {0, 0, 0}, 2), "method text");
  EXPECT_TRUE(j["youngs_modulus_Pa"].is_null());
  EXPECT_TRUE(j["poisson_ratio"].is_null());
  EXPECT_EQ(j["elastic_fit"]["points"], 0);
  EXPECT_TRUE(j["elastic_fit"]["reason"].is_string());
  nlohmann::json ok;
  std::vector<Real> e, s, l;
  for (int k = 0; k <= 10; ++k) e.push_back(1e-3 * k), s.push_back(1e6 * k), l.push_back(0);
  put_elastic_fit(ok, fit_elastic(e, s, l, 10), "method text");
  EXPECT_TRUE(ok["youngs_modulus_Pa"].is_number());
  EXPECT_FALSE(ok["elastic_fit"].contains("reason"));
}

TEST(PeakCheck, StillRisingAtTheStrainCapIsNoPeak) {
  EXPECT_EQ(peak_problem(10e6, 5, 20, false, "ucs.max_strain"), "");  // stopped after softening
  EXPECT_EQ(peak_problem(10e6, 5, 20, true, "ucs.max_strain"), "");   // peaked, then capped
  const std::string rising = peak_problem(10e6, 19, 20, true, "ucs.max_strain");
  EXPECT_TRUE(has(rising, "still rising")) << rising;
  EXPECT_TRUE(has(rising, "raise ucs.max_strain")) << rising;
  EXPECT_NE(peak_problem(0, 0, 20, false, "ucs.max_strain"), "");
  EXPECT_NE(peak_problem(1e6, 0, 0, false, "ucs.max_strain"), "");
}

TEST(SummaryValues, NumberOrNullAndTypedParameters) {
  EXPECT_TRUE(number_or_null(std::nan("")).is_null());
  EXPECT_TRUE(number_or_null(HUGE_VAL).is_null());
  EXPECT_EQ(number_or_null(2.5).get<double>(), 2.5);
}

// A summary.json with null E and nu (and a UCS run's null peak) reads as NaN with the reasons,
// and a calibration step never gets 0 from it: the update refuses it.
TEST(ReadRunSummary, NullValuesReadAsNaNWithTheirReasons) {
  const auto dir = fs::temp_directory_path() / "fracflow_test_null_summary";
  fs::create_directories(dir);
  std::ofstream(dir / "summary.json") << R"({"driver":"ucs","ucs_Pa":null,"youngs_modulus_Pa":null,
      "poisson_ratio":null,"peak":{"reached":false,"reason":"still rising"},
      "elastic_fit":{"points":0,"reason":"0 points in the window"}})";
  const batch::RunSummary s = batch::read_run_summary(dir);
  EXPECT_TRUE(std::isnan(s.ucs_Pa));
  EXPECT_TRUE(std::isnan(s.youngs_modulus_Pa));
  EXPECT_TRUE(std::isnan(s.poisson_ratio));
  EXPECT_FALSE(batch::peak_strength(s));
  EXPECT_TRUE(has(s.missing, "still rising")) << s.missing;
  EXPECT_TRUE(has(s.missing, "0 points in the window")) << s.missing;

  batch::CalibrationSettings cs;
  cs.target = {2.37e9, 0.35, 14.97e6, 0};
  batch::CalibrationStep st;
  st.iteration = 1;
  st.params = {2e9, 2e9, 10, 10, 10e6, 3e6, 0};
  st.measured = {s.youngs_modulus_Pa, s.poisson_ratio, 14e6, 0};
  batch::score_step(st, cs);
  EXPECT_FALSE(st.converged);
  const std::vector<batch::CalibrationStep> history = {st};
  EXPECT_THROW(batch::next_parameters(history, cs), Error);
  fs::remove_all(dir);
}

TEST(ReadRunSummary, TriaxialResultWithNullPeakAndFitIsNaNNotAnError) {
  const auto dir = fs::temp_directory_path() / "fracflow_test_null_triaxial";
  fs::create_directories(dir);
  std::ofstream(dir / "summary.json") << R"({"driver":"triaxial","lateral":"membrane","confining_pressure_Pa":5e6,
      "peak_differential_stress_Pa":null,"strain_at_peak":null,"confinement_at_peak_Pa":null,
      "youngs_modulus_Pa":null,"poisson_ratio":null,"cracks":{"total":0,"tensile":0,"shear":0},
      "isotropic_stage":{"largest_sphere_deviation":0.01},"sample":{"particles":100}})";
  const batch::TriaxialRunResult r = batch::read_triaxial_result(dir, "C1");
  EXPECT_TRUE(std::isnan(r.peak_differential_Pa));
  EXPECT_TRUE(std::isnan(r.youngs_modulus_Pa));
  EXPECT_EQ(r.sigma3_Pa, 5e6);
  fs::remove_all(dir);
}

TEST(LongRunEstimate, ShortRunsSayNothing) {
  EXPECT_EQ(long_run_notice(9e5, 1000, "ucs.max_strain"), "");
  EXPECT_EQ(long_run_notice(kLongRunSteps, 1000, "ucs.max_strain"), "");
}

TEST(LongRunEstimate, NamesStepsTimeAndTheKeysThatShortenIt) {
  const std::string m = long_run_notice(4.2e6, 2000, "ucs.platen_velocity or ucs.max_strain");
  EXPECT_EQ(m, "this run needs up to 4.2 million steps; at the measured ~2000 steps/s that is about 35 min; "
               "ucs.platen_velocity or ucs.max_strain shorten it");
  const std::string unmeasured = long_run_notice(4.2e6, 0, "run.end_time");
  EXPECT_TRUE(has(unmeasured, "4.2 million steps")) << unmeasured;
  EXPECT_TRUE(has(unmeasured, "run.end_time shorten it")) << unmeasured;
  EXPECT_TRUE(has(long_run_notice(2.3e7, 2000, "x"), "about 3 h 11 min"));
  EXPECT_TRUE(has(long_run_notice(3e9, 1000, "x"), "3.0 billion steps"));
}

TEST(LongRunEstimate, DurationText) {
  EXPECT_EQ(duration_text(40), "about 40 s");
  EXPECT_EQ(duration_text(12 * 60 + 10), "about 12 min");
  EXPECT_EQ(duration_text(3 * 3600 + 10 * 60 + 5), "about 3 h 10 min");
  EXPECT_EQ(duration_text(2 * 86400 + 5 * 3600), "about 2 d 5 h");
  EXPECT_EQ(duration_text(std::nan("")), "an unknown time");
}
