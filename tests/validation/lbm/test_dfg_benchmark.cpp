// The DFG benchmark "laminar flow around a cylinder" (Schaefer & Turek 1996, Notes Numer. Fluid
// Mech. 52, 547-566), run through flow/cylinder exactly as examples/dfg_2d1.toml: channel
// 2.2 x 0.41 m, cylinder D = 0.1 m at (0.2, 0.2) (off the centre line), nu = 1e-3 m^2/s,
// rho = 1 kg/m^3, parabolic inflow with U_m = 0.3 m/s (Re = 20 on U = 2/3 U_m and D).
// Published intervals (their Table 4, case 2D-1): c_D 5.57-5.59, c_L 0.0104-0.0110,
// L_a 0.0842-0.0852 m, Delta p 0.1172-0.1176 Pa.
//
// The solver does not reach every interval yet (issue 14, accuracy control is separate work),
// so each quantity is held to the interval widened by a stated margin that shrinks with
// resolution; the figures are printed. Measured (Mach 0.087, TRT, Bouzidi; D = 20 and 40 with
// run.end_time = 22 s, residual acoustic ringing of c_D about +-0.1%):
//   D = 10: c_D 5.692 (+1.8%), c_L 0.00999 (-4.0%), L_a 0.0813 (-3.5%), Delta p 0.1131 (-3.5%)
//   D = 20: c_D 5.651 (+1.1%), c_L 0.00999 (-3.9%), L_a 0.0847 (in), Delta p 0.1181 (+0.4%)
//   D = 40: c_D 5.635 (+0.8%), c_L 0.01039 (-0.1%), L_a 0.0851 (in), Delta p 0.1187 (+0.9%)
// Margins: D = 10 (default suite): 3% (c_D), 8% (c_L), 5% (L_a, Delta p); D = 20 (label long):
// 1.5% (c_D), 6% (c_L), 1.5% (L_a), 1% (Delta p).
//
// Label long also runs 2D-2 (U_m = 1.5 m/s, Re = 100; intervals c_D,max 3.22-3.24, c_L,max
// 0.99-1.01, St 0.295-0.305, Delta p(t0 + 1/(2f)) 2.46-2.50 Pa) at D = 20, Mach 0.087, tau 0.52:
// measured c_D,max 3.381 (+4.3%), c_L,max 1.024 (+1.4%), St 0.2996 (in), Delta p 2.4925 (in) over
// 11 periods (543 s on 2 busy cores); margins 5%, 3%, 1%, 1%. And 3D-1Z (duct 2.5 x 0.41 x 0.41,
// U_m = 0.45 m/s, Re = 20; c_D 6.05-6.25, c_L 0.008-0.010, Delta p 0.165-0.175 Pa) at D = 10,
// Mach 0.087, tau 0.533: measured c_D 6.2265 (in), c_L 0.00940 (in), Delta p 0.1634 (-1.0%),
// L_a 0.0738 m (mid-plane), 354 s on 2 busy cores; margins 1%, 5%, 2%.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "flow_driver_runner.hpp"
#include "lbm/analysis.hpp"

namespace {

const char* kDfg2d1 = R"(
driver = "flow/cylinder"
[channel]
height = 0.41
length = 2.2
[cylinder]
diameter = 0.1
x = 0.2
y = 0.2
wall = "bouzidi"
initial_perturbation = 0.0
[inlet]
profile = "parabolic"
velocity = 0.3
[fluid]
density = 1.0
viscosity = 1.0e-3
[run]
end_time = 20.0
inflow_ramp_time = -1
[output]
samples = 400
vtk = false
plots = false
)";

struct Interval {
  const char* name;
  double lo, hi;
};

// |value| within [lo, hi] widened by `margin` (relative) on both sides.
void expect_in(const Interval& iv, double v, double margin) {
  const double lo = iv.lo * (1 - margin), hi = iv.hi * (1 + margin);
  const double off = v < iv.lo ? v / iv.lo - 1 : v > iv.hi ? v / iv.hi - 1 : 0.0;
  std::printf("  %-10s %.5g  interval %.5g-%.5g  %s\n", iv.name, v, iv.lo, iv.hi,
              off == 0 ? "inside" : fmt::format("{:+.2f}% outside", 100 * off).c_str());
  EXPECT_GE(v, lo) << iv.name;
  EXPECT_LE(v, hi) << iv.name;
}

// margins: c_D, c_L, L_a, Delta p.
void check_2d1(int cells, double m_cd, double m_cl, double m_la, double m_dp) {
  const double dt = 0.05 * (0.1 / cells) / 0.3;  // lattice U_m = 0.05: Mach 0.087
  const auto j = ff::testing::run_flow_driver(fmt::format("dfg_2d1_{}", cells), kDfg2d1,
                                              {"lbm.resolution=" + std::to_string(cells),
                                               "lbm.time_step=" + fmt::format("{}", dt)});
  const auto& r = j["results"];
  std::printf("DFG 2D-1, D = %d cells, Mach %.3f, tau %.4f, %.1f s wall (%s):\n", cells,
              double(j["units"]["mach_characteristic"]), double(j["units"]["tau"]), double(j["wall_time_s"]),
              std::string(j["stop_reason"]).c_str());
  EXPECT_NEAR(double(r["reynolds"]), 20.0, 1e-9);
  ASSERT_FALSE(bool(r["shedding"]));
  expect_in({"c_D", 5.57, 5.59}, r["cd_final"], m_cd);
  expect_in({"c_L", 0.0104, 0.0110}, r["cl_final"], m_cl);
  expect_in({"L_a [m]", 0.0842, 0.0852}, r["recirculation_length_m"], m_la);
  expect_in({"dp [Pa]", 0.1172, 0.1176}, r["dp_final_Pa"], m_dp);
}

}  // namespace

// The time-series tools behind the 2D-2 quantities, on a sampled sine v = sin(2 pi f t) + 0.3:
// its extremes over whole periods (1.3 and -0.7 within the sampling error 1 - cos(pi f dt)),
// the time of the last maximum (t = (k + 1/4) / f) and, half a period later, the minimum read
// off by linear interpolation.
TEST(DfgBenchmark, SeriesToolsOnASine) {
  const double f = 3.0, dt = 1e-3;
  std::vector<double> t, v;
  for (int i = 0; i <= 3000; ++i) {
    t.push_back(i * dt);
    v.push_back(std::sin(2 * M_PI * f * t.back()) + 0.3);
  }
  const auto o = ff::lbm::analyse_oscillation(t, v, 0.5);
  EXPECT_NEAR(o.frequency, f, 1e-6);
  const auto e = ff::lbm::extremes(t, v, o.first_up, o.last_up);
  const double tol = 1 - std::cos(M_PI * f * dt);
  EXPECT_NEAR(e.max, 1.3, tol);
  EXPECT_NEAR(e.min, -0.7, tol);
  const double k = std::round(e.t_max * f - 0.25);
  EXPECT_NEAR(e.t_max, (k + 0.25) / f, dt);
  EXPECT_NEAR(ff::lbm::interpolate_series(t, v, e.t_max + 0.5 / o.frequency), -0.7, 2 * tol + 2 * M_PI * f * dt * 1e-3);
  EXPECT_TRUE(std::isnan(ff::lbm::interpolate_series(t, v, 3.5)));
  // Linear data are interpolated exactly.
  const std::vector<double> lt = {0, 1, 3}, lv = {1, 3, 7};
  EXPECT_DOUBLE_EQ(ff::lbm::interpolate_series(lt, lv, 2.0), 5.0);
}

#ifdef FRACFLOW_LONG_TESTS
TEST(DfgBenchmarkLong, Case2d1) { check_2d1(20, 0.015, 0.06, 0.015, 0.01); }

TEST(DfgBenchmarkLong, Case2d2) {
  const auto j = ff::testing::run_flow_driver(
      "dfg_2d2_20", kDfg2d1,
      {"inlet.velocity=1.5", "cylinder.initial_perturbation=0.05", "lbm.resolution=20", "lbm.time_step=1.6666666667e-4",
       "run.end_time=10", "output.samples=4000"});
  const auto& r = j["results"];
  std::printf("DFG 2D-2, D = 20 cells, Mach %.3f, tau %.4f, %.1f s wall, %d periods:\n",
              double(j["units"]["mach_characteristic"]), double(j["units"]["tau"]), double(j["wall_time_s"]),
              int(r["shedding_periods_averaged"]));
  EXPECT_NEAR(double(r["reynolds"]), 100.0, 1e-9);
  ASSERT_TRUE(bool(r["shedding"]));
  EXPECT_GE(int(r["shedding_periods_averaged"]), 8);
  expect_in({"c_D,max", 3.22, 3.24}, r["cd_max_periods"], 0.05);
  expect_in({"c_L,max", 0.99, 1.01}, r["cl_max_periods"], 0.03);
  expect_in({"St", 0.295, 0.305}, r["strouhal"], 0.01);
  ASSERT_FALSE(r["dp_half_period_after_cl_max_Pa"].is_null());
  expect_in({"dp [Pa]", 2.46, 2.50}, r["dp_half_period_after_cl_max_Pa"], 0.01);
}

// As examples/dfg_3d1z.toml.
TEST(DfgBenchmarkLong, Case3d1z) {
  const auto j = ff::testing::run_flow_driver(
      "dfg_3d1z_10", kDfg2d1,
      {"channel.length=2.5", "channel.depth=0.41", "cylinder.x=0.5", "inlet.velocity=0.45", "lbm.lattice=\"D3Q19\"",
       "lbm.resolution=10", "lbm.time_step=1.1111111111e-3", "run.end_time=16", "output.samples=320"});
  const auto& r = j["results"];
  std::printf("DFG 3D-1Z, D = 10 cells, Mach %.3f, tau %.4f, %.1f s wall:\n", double(j["units"]["mach_characteristic"]),
              double(j["units"]["tau"]), double(j["wall_time_s"]));
  EXPECT_NEAR(double(r["reynolds"]), 20.0, 1e-9);
  ASSERT_FALSE(bool(r["shedding"]));
  expect_in({"c_D", 6.05, 6.25}, r["cd_final"], 0.01);
  expect_in({"c_L", 0.008, 0.010}, r["cl_final"], 0.05);
  expect_in({"dp [Pa]", 0.165, 0.175}, r["dp_final_Pa"], 0.02);
}
#else
TEST(DfgBenchmark, Case2d1Coarse) { check_2d1(10, 0.03, 0.08, 0.05, 0.05); }
#endif
