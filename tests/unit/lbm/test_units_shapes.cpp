// Unit conversion ([S003] Table 1, METHODS §4.9) and its stability checks; the analytic
// shapes' link fractions; the post-processing helpers.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "lbm/analysis.hpp"
#include "lbm/shapes.hpp"
#include "lbm/units.hpp"

using namespace ff;
using namespace ff::lbm;

TEST(LbmUnits, ConversionFactors) {
  // Water, 0.1 mm cells, tau = 0.8: dt = (tau - 1/2) dx^2 / (3 nu).
  const Units u = Units::from_tau(1e-4, 0.8, 1e-6, 1000);
  EXPECT_NEAR(u.dt(), 0.3 * 1e-8 / 3e-6, 1e-18);
  EXPECT_NEAR(u.nu_lb(), 0.1, 1e-15);
  EXPECT_NEAR(u.to_si_velocity(u.to_lattice_velocity(0.37)), 0.37, 1e-15);
  EXPECT_NEAR(u.velocity_factor(), 1e-4 / u.dt(), 1e-12);
  EXPECT_NEAR(u.pressure_factor(), 1000 * 1e-8 / (u.dt() * u.dt()), 1e-9);
  // p = c_s^2 (rho - 1) P_r and back.
  EXPECT_NEAR(u.to_si_pressure(1 + u.to_si_density_offset(12.5)), 12.5, 1e-12);
  // A force density G [N/m^3] on V = N dx^3 is the force G V: per unit depth in 2D.
  const double G = 3.0, cells = 40;
  EXPECT_NEAR(u.to_si_force(u.to_lattice_force_density(G) * cells, 2), G * cells * 1e-8, 1e-20);
  EXPECT_NEAR(u.to_si_force(u.to_lattice_force_density(G) * cells, 3), G * cells * 1e-12, 1e-24);
  // That force on a lever arm of 7 cells (7e-4 m) is a torque of F * 7e-4.
  EXPECT_NEAR(u.to_si_torque(u.to_lattice_force_density(G) * cells * 7, 2), G * cells * 1e-8 * 7e-4, 1e-24);
  EXPECT_NEAR(u.to_si_torque(u.to_lattice_force_density(G) * cells * 7, 3), G * cells * 1e-12 * 7e-4, 1e-28);
  // The other way round: from the time step.
  const Units v = Units::from_time_step(1e-4, u.dt(), 1e-6, 1000);
  EXPECT_NEAR(v.tau(), 0.8, 1e-12);
  EXPECT_NE(u.describe(2).find("tau = 0.8"), std::string::npos);
}

TEST(LbmUnits, StabilityChecksNameTheFix) {
  const Units u = Units::from_tau(1e-3, 0.6, 1e-3, 1000);  // u_r = 30 m/s
  EXPECT_TRUE(u.check(0.3, 50, "lbm.resolution", UnitsMode::Tau, "trt", 1.0).warnings.empty());  // Ma 0.017
  // Ma = 0.17: a warning naming a resolution that brings it below 0.1.
  const auto w = u.check(3.0, 50, "lbm.resolution", UnitsMode::Tau, "trt", 1.0);
  ASSERT_EQ(w.warnings.size(), 1u);
  EXPECT_TRUE(w.error.empty());
  EXPECT_NE(w.warnings[0].find("lbm.resolution = 87 or more"), std::string::npos) << w.warnings[0];
  // Ma = 0.52: an error.
  const auto e = u.check(9.0, 50, "lbm.resolution", UnitsMode::Tau, "trt", 1.0);
  EXPECT_NE(e.error.find("Mach number"), std::string::npos);
  // A speed that no lattice resolves: the advice said "lbm.resolution = -2147483648 or more" (an int
  // overflow; fuzzed with a lid velocity of 1e300, session 49).
  const auto absurd = u.check(1e300, 50, "lbm.resolution", UnitsMode::Tau, "trt", 1.0);
  EXPECT_NE(absurd.error.find("beyond the 2^30 cells a side may have"), std::string::npos) << absurd.error;
  EXPECT_EQ(absurd.error.find("-2147483648"), std::string::npos) << absurd.error;
  // In time-step mode the fix is a smaller time step.
  const Units d = Units::from_time_step(1e-3, u.dt(), 1e-3, 1000);
  EXPECT_NE(d.check(3.0, 50, "lbm.resolution", UnitsMode::TimeStep, "trt", 1.0).warnings[0].find("set lbm.time_step = "), std::string::npos);
  // tau close to 1/2, or large: a warning.
  EXPECT_EQ(Units::from_tau(1e-3, 0.505, 1e-6, 1000).check(0.01, 50, "lbm.resolution", UnitsMode::Tau, "trt", 1.0).warnings.size(), 1u);
  const auto big = Units::from_tau(1e-3, 4.0, 1e-6, 1000).check(1e-6, 50, "lbm.resolution", UnitsMode::Tau, "trt", 1.0);
  ASSERT_EQ(big.warnings.size(), 1u);
  EXPECT_NE(big.warnings[0].find("set lbm.tau = 2"), std::string::npos) << big.warnings[0];
}

TEST(LbmUnits, TauAtOrBelowHalfIsAnError) {
  Units u = Units::from_tau(1e-3, 0.5, 1e-6, 1000);
  const auto c = u.check(1e-6, 20, "lbm.resolution", UnitsMode::Tau, "trt", 1.0);
  EXPECT_NE(c.error.find("above 1/2"), std::string::npos) << c.error;
  EXPECT_NE(c.error.find("set lbm.time_step = "), std::string::npos) << c.error;
}

// The warning names the collision model of the run (it used to blame BGK in TRT runs) and a
// value of the real key that the scenario accepts.
TEST(LbmUnits, TauNearHalfWarningNamesTheCollisionModelAndAnAllowedTau) {
  const Units u = Units::from_tau(1e-3, 0.505, 1e-6, 1000);
  for (const std::string model : {"trt", "bgk"}) {
    const auto c = u.check(0.001, 50, "lbm.resolution", UnitsMode::Tau, model, 1.0);
    ASSERT_EQ(c.warnings.size(), 1u) << model;
    const std::string& w = c.warnings[0];
    const std::string in_use = model == "trt" ? "with the TRT (lbm.collision = \"trt\") collision"
                                              : "with the BGK (lbm.collision = \"bgk\") collision";
    EXPECT_NE(w.find(in_use), std::string::npos) << w;
    if (model == "trt") {
      EXPECT_EQ(w.find("BGK"), std::string::npos) << w;
    }
    const auto at = w.find("set lbm.tau = ");
    ASSERT_NE(at, std::string::npos) << w;
    const double tau = std::stod(w.substr(at + 14));
    EXPECT_GT(tau, 0.5 + 0.01) << w;  // allowed (> 1/2) and out of the warning's range
    EXPECT_TRUE(Units::from_tau(1e-3, tau, 1e-6, 1000).check(0.001, 50, "lbm.resolution", UnitsMode::Tau, model, 1.0).warnings.empty());
  }
  // In time-step mode the fix is a time step, for the model in use.
  const Units d = Units::from_time_step(1e-3, u.dt(), 1e-6, 1000);
  const auto w = d.check(0.001, 50, "lbm.resolution", UnitsMode::TimeStep, "bgk", 1.0).warnings.at(0);
  EXPECT_NE(w.find("BGK (lbm.collision = \"bgk\")"), std::string::npos) << w;
  EXPECT_NE(w.find("set lbm.time_step = "), std::string::npos) << w;
}

TEST(LbmShapes, InsideAndLinkFractions) {
  const Shape circle = Circle{Vec3(1.5, 0, 0), 0.8};
  EXPECT_TRUE(inside(circle, Vec3(1.5, 0.7, 5)));  // a cylinder: z does not matter
  EXPECT_FALSE(inside(circle, Vec3(0.6, 0, 0)));
  EXPECT_NEAR(entry_fraction(circle, Vec3(0, 0, 0), Vec3(1, 0, 0)), 0.7, 1e-14);
  // Diagonal link into a circle: |(s, s) - (2, 2)| = 1 at s = 2 - 1/sqrt(2).
  EXPECT_NEAR(entry_fraction(Circle{Vec3(2, 2, 0), 1.0}, Vec3(1, 1, 0), Vec3(2, 2, 0)), 1 - 1 / std::sqrt(2.0), 1e-14);
  const Shape sphere = Sphere{Vec3(0, 0, 2), 1.25};
  EXPECT_NEAR(entry_fraction(sphere, Vec3(0, 0, 0), Vec3(0, 0, 1)), 0.75, 1e-14);
  const Shape box = Box{Vec3(0.25, 0.5, -1), Vec3(3, 3, 1)};
  EXPECT_NEAR(entry_fraction(box, Vec3(0, 0, 0), Vec3(1, 1, 0)), 0.5, 1e-14);
  EXPECT_TRUE(inside(box, Vec3(1, 1, 0)));
  EXPECT_EQ(reference_point(box), Vec3(1.625, 1.75, 0));
}

TEST(LbmAnalysis, OscillationFrequencyAndMean) {
  std::vector<double> t, v;
  for (int i = 0; i <= 4000; ++i) {
    t.push_back(0.05 * i);
    v.push_back(1.3 + 0.2 * std::sin(2 * M_PI * 0.173 * t.back() + 0.4));
  }
  const Oscillation o = analyse_oscillation(t, v, 20.0);
  EXPECT_NEAR(o.frequency, 0.173, 1e-4);
  EXPECT_NEAR(o.max, 1.5, 1e-3);
  EXPECT_NEAR(o.min, 1.1, 1e-3);
  EXPECT_NEAR(time_average(t, v, o.first_up, o.last_up), 1.3, 1e-5);
  // A steady signal has no frequency.
  std::vector<double> flat(t.size(), 2.0);
  EXPECT_EQ(analyse_oscillation(t, flat, 0).cycles, 0);
}

TEST(LbmAnalysis, CellCentredProfile) {
  const std::vector<double> v = {1, 3, 5};  // at 0.5, 1.5, 2.5 (h = 1), walls at 0 and 3
  EXPECT_DOUBLE_EQ(interpolate_profile(v, 1.0, 1.0, 0.0, 9.0), 2.0);
  EXPECT_DOUBLE_EQ(interpolate_profile(v, 1.0, 0.25, 0.0, 9.0), 0.5);
  EXPECT_DOUBLE_EQ(interpolate_profile(v, 1.0, 3.0, 0.0, 9.0), 9.0);
  EXPECT_DOUBLE_EQ(interpolate_profile(v, 0.5, 0.75, 0.0, 9.0), 3.0);
}
