#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <vector>

#include "batch/mohr_coulomb.hpp"
#include "batch/run_case.hpp"
#include "core/error.hpp"

using namespace ff::batch;

// phi = 30 deg: sin phi = 1/2, so b = (1 + 1/2)/(1 - 1/2) = 3 and a = 2 c cos30 / (1/2) = 2 sqrt(3) c.
TEST(MohrCoulomb, ExactLineGivesFrictionAngleAndCohesion) {
  const double c = 5e6, a = 2 * std::sqrt(3.0) * c;
  std::vector<StrengthPoint> pts;
  for (double s3 : {0.0, 2.5e6, 5e6, 7.5e6}) pts.push_back({s3, a + 3 * s3});
  const auto f = fit_mohr_coulomb(pts);
  EXPECT_NEAR(f.slope, 3.0, 1e-12);
  EXPECT_NEAR(f.intercept_Pa / a, 1.0, 1e-12);
  EXPECT_NEAR(f.friction_angle_deg, 30.0, 1e-12);
  EXPECT_NEAR(f.cohesion_Pa / c, 1.0, 1e-12);
  EXPECT_NEAR(f.r_squared, 1.0, 1e-12);
  EXPECT_EQ(f.points, 4);
}

TEST(MohrCoulomb, PeakFormulaRoundTrips) {
  std::vector<StrengthPoint> pts;
  for (double s3 : {1e6, 3e6, 9e6}) pts.push_back({s3, mohr_coulomb_peak(s3, 37.0, 2.2e6)});
  const auto f = fit_mohr_coulomb(pts);
  EXPECT_NEAR(f.friction_angle_deg, 37.0, 1e-10);
  EXPECT_NEAR(f.cohesion_Pa / 2.2e6, 1.0, 1e-12);
}

// Two points above, two below a line: the least-squares line is known by hand.
// Points (0,10), (0,12), (2,20), (2,22) MPa: line through the means (0,11) and (2,21): a = 11, b = 5;
// residuals +-1 MPa: SS_res = 4, SS_tot = 4 * 25 + 4 = 104, R^2 = 1 - 4/104.
TEST(MohrCoulomb, ScatterGivesLeastSquaresLineAndRSquared) {
  const std::vector<StrengthPoint> pts = {{0, 10e6}, {0, 12e6}, {2e6, 20e6}, {2e6, 22e6}};
  const auto f = fit_mohr_coulomb(pts);
  EXPECT_NEAR(f.slope, 5.0, 1e-12);
  EXPECT_NEAR(f.intercept_Pa, 11e6, 1e-6);
  EXPECT_NEAR(f.r_squared, 1 - 4.0 / 104.0, 1e-12);
  EXPECT_NEAR(f.friction_angle_deg, std::asin(4.0 / 6.0) * 180 / std::numbers::pi, 1e-12);
}

TEST(MohrCoulomb, OneConfiningPressureIsAnError) {
  const std::vector<StrengthPoint> pts = {{0, 10e6}, {0, 11e6}};
  try {
    fit_mohr_coulomb(pts);
    FAIL() << "expected InputError";
  } catch (const ff::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("confining pressure"), std::string::npos) << e.what();
  }
}

TEST(MohrCoulomb, StrengthFallingWithConfinementIsAnError) {
  const std::vector<StrengthPoint> pts = {{0, 10e6}, {5e6, 12e6}};  // b = 0.4 < 1
  EXPECT_THROW(fit_mohr_coulomb(pts), ff::InputError);
}

// A triaxial summary gives sigma_p = sigma3 + peak differential stress; a UCS summary sigma3 = 0.
TEST(MohrCoulomb, PeakStrengthFromSummaries) {
  const auto dir = std::filesystem::temp_directory_path() / "fracflow_test_batch_summary";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "summary.json") << R"({"driver":"triaxial","peak_differential_stress_Pa":20e6,
      "confining_pressure_Pa":5e6,"youngs_modulus_Pa":2e9,"poisson_ratio":0.3,"cracks":{"tensile":3,"shear":4,"total":7}})";
  auto s = read_run_summary(dir);
  auto p = peak_strength(s);
  ASSERT_TRUE(p);
  EXPECT_DOUBLE_EQ(p->sigma3, 5e6);
  EXPECT_DOUBLE_EQ(p->sigma_p, 25e6);
  EXPECT_DOUBLE_EQ(s.cracks_total, 7);
  EXPECT_TRUE(std::isnan(s.ucs_Pa));
  std::ofstream(dir / "summary.json") << R"({"driver":"ucs","ucs_Pa":14e6})";
  p = peak_strength(read_run_summary(dir));
  ASSERT_TRUE(p);
  EXPECT_DOUBLE_EQ(p->sigma3, 0);
  EXPECT_DOUBLE_EQ(p->sigma_p, 14e6);
  std::ofstream(dir / "summary.json") << R"({"driver":"flow/cavity"})";
  EXPECT_FALSE(peak_strength(read_run_summary(dir)));
  std::filesystem::remove_all(dir);
  EXPECT_THROW(read_run_summary(dir), ff::Error);
}
