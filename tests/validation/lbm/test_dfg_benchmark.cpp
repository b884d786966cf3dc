// The DFG benchmark "laminar flow around a cylinder" (Schaefer & Turek 1996, Notes Numer. Fluid
// Mech. 52, 547-566), run through flow/cylinder exactly as examples/dfg_2d1.toml: channel
// 2.2 x 0.41 m, cylinder D = 0.1 m at (0.2, 0.2) (off the centre line), nu = 1e-3 m^2/s,
// rho = 1 kg/m^3, parabolic inflow with U_m = 0.3 m/s (Re = 20 on U = 2/3 U_m and D).
// Published intervals (their Table 4, case 2D-1): c_D 5.57-5.59, c_L 0.0104-0.0110,
// L_a 0.0842-0.0852 m, Delta p 0.1172-0.1176 Pa.
//
// Runs as the examples do: TRT (Lambda 3/16), Bouzidi cylinder, incompressible equilibrium
// (He & Luo 1997), the Mach number set by lbm.mach, convective outlet and the steady stop at
// 1e-5 for the steady cases. Long label (`make test-long`): each case at a resolution where
// every quantity lies inside the published interval; the default suite runs 2D-1 at D = 20
// cells, where the intervals are widened by stated margins. Figures: see each test and
// docs/lbm.md "Accuracy on the DFG benchmark".
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

// Relative widening of each interval on both sides (0: the published interval itself).
struct Margins {
  double cd, cl, la, dp;
};

void check_2d1(int cells, double mach, Margins m) {
  const auto j = ff::testing::run_flow_driver(
      fmt::format("dfg_2d1_{}", cells), kDfg2d1,
      {"lbm.resolution=" + std::to_string(cells), fmt::format("lbm.mach={}", mach), "outlet.condition=\"convective\"",
       "run.steady_tolerance=1e-5", "run.end_time=40", "output.samples=800"});
  const auto& r = j["results"];
  std::printf("DFG 2D-1, D = %d cells, Mach %.3f, tau %.4f, %.1f s wall (%s):\n", cells,
              double(j["units"]["mach_characteristic"]), double(j["units"]["tau"]), double(j["wall_time_s"]),
              std::string(j["stop_reason"]).c_str());
  EXPECT_NEAR(double(r["reynolds"]), 20.0, 1e-9);
  ASSERT_FALSE(bool(r["shedding"]));
  EXPECT_EQ(std::string(j["stop_reason"]).rfind("steady state", 0), 0u) << "the steady stop must fire before 40 s";
  expect_in({"c_D", 5.57, 5.59}, r["cd_final"], m.cd);
  expect_in({"c_L", 0.0104, 0.0110}, r["cl_final"], m.cl);
  expect_in({"L_a [m]", 0.0842, 0.0852}, r["recirculation_length_m"], m.la);
  expect_in({"dp [Pa]", 0.1172, 0.1176}, r["dp_final_Pa"], m.dp);
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
// 2D-1 at D = 160 cells (Mach 0.1, tau 1.42; the expected error 0.1 Ma^2 = 0.1% is below the
// intervals' half-widths): FIGURES_2D1_160
TEST(DfgBenchmarkLong, Case2d1) { check_2d1(160, 0.1, {0, 0, 0, 0}); }

// 2D-2 (U_m = 1.5 m/s, Re = 100; intervals c_D,max 3.22-3.24, c_L,max 0.99-1.01,
// St 0.295-0.305, Delta p(t0 + 1/(2f)) 2.46-2.50 Pa, t0 the time of a c_L maximum) at D = 80
// cells, Mach 0.05; the street starts from a small kick and is periodic after ~4 s; extremes
// over the whole periods after that. Measured: c_D,max 3.2361, c_L,max 0.99678, St 0.3017,
// Delta p 2.4879 Pa, all inside, over 10 periods; 1137 s on 1 of 2 busy cores.
TEST(DfgBenchmarkLong, Case2d2) {
  const auto j = ff::testing::run_flow_driver(
      "dfg_2d2_80", kDfg2d1,
      {"inlet.velocity=1.5", "cylinder.initial_perturbation=0.05", "lbm.resolution=80", "lbm.mach=0.05",
       "run.inflow_ramp_time=0.5", "run.end_time=8", "output.samples=8000"});
  const auto& r = j["results"];
  std::printf("DFG 2D-2, D = 80 cells, Mach %.3f, tau %.4f, %.1f s wall, %d periods:\n",
              double(j["units"]["mach_characteristic"]), double(j["units"]["tau"]), double(j["wall_time_s"]),
              int(r["shedding_periods_averaged"]));
  EXPECT_NEAR(double(r["reynolds"]), 100.0, 1e-9);
  ASSERT_TRUE(bool(r["shedding"]));
  EXPECT_GE(int(r["shedding_periods_averaged"]), 8);
  expect_in({"c_D,max", 3.22, 3.24}, r["cd_max_periods"], 0);
  expect_in({"c_L,max", 0.99, 1.01}, r["cl_max_periods"], 0);
  expect_in({"St", 0.295, 0.305}, r["strouhal"], 0);
  ASSERT_FALSE(r["dp_half_period_after_cl_max_Pa"].is_null());
  expect_in({"dp [Pa]", 2.46, 2.50}, r["dp_half_period_after_cl_max_Pa"], 0);
}

// As examples/dfg_3d1z.toml: 3D-1Z (duct 2.5 x 0.41 x 0.41 m, cylinder axis along z at
// (0.5, 0.2), U(0, y, z) = 16 U_m y z (H - y)(H - z) / H^4 with U_m = 0.45 m/s, Re = 20 on
// U = 4/9 U_m; intervals c_D 6.05-6.25, c_L 0.008-0.010, Delta p 0.165-0.175 Pa between
// (0.45, 0.2, 0.205) and (0.55, 0.2, 0.205)) at D = 10 cells (0.41 m is a whole number of
// cells at multiples of 10), D3Q19, Mach 0.1 (expected error 0.1 Ma^2 = 0.1% for a steady flow
// with the incompressible equilibrium). Measured: c_D 6.1853 (in), c_L 0.00951 (in), Delta p
// 0.16118 Pa (-2.3%), 460 s on 1 of 2 busy cores, steady stop. The issue asks c_D and c_L inside
// their intervals; Delta p is held to its interval widened by 3%: at D = 10 the surface
// extrapolation of the stagnation pressure is still coarse (2D-1 at D = 10: Delta p -4.4%,
// at D = 20: -0.3%).
TEST(DfgBenchmarkLong, Case3d1z) {
  const auto j = ff::testing::run_flow_driver(
      "dfg_3d1z_10", kDfg2d1,
      {"channel.length=2.5", "channel.depth=0.41", "cylinder.x=0.5", "inlet.velocity=0.45", "lbm.lattice=\"D3Q19\"",
       "lbm.resolution=10", "lbm.mach=0.1", "outlet.condition=\"convective\"", "run.steady_tolerance=1e-5",
       "run.end_time=40", "output.samples=800"});
  const auto& r = j["results"];
  std::printf("DFG 3D-1Z, D = 10 cells, Mach %.3f, tau %.4f, %.1f s wall (%s):\n",
              double(j["units"]["mach_characteristic"]), double(j["units"]["tau"]), double(j["wall_time_s"]),
              std::string(j["stop_reason"]).c_str());
  EXPECT_NEAR(double(r["reynolds"]), 20.0, 1e-9);
  ASSERT_FALSE(bool(r["shedding"]));
  expect_in({"c_D", 6.05, 6.25}, r["cd_final"], 0);
  expect_in({"c_L", 0.008, 0.010}, r["cl_final"], 0);
  expect_in({"dp [Pa]", 0.165, 0.175}, r["dp_final_Pa"], 0.03);
}
#else
// 2D-1 at D = 20 cells (Mach 0.05, tau 0.558; 11.5 s on 1 of 2 busy cores). Measured: c_D 5.6059
// (+0.28%), c_L 0.010002 (-3.8%), L_a 0.084174 m (-0.03%), Delta p 0.11683 Pa (-0.31%); margins
// 0.6%, 6%, 0.5%, 0.5%: they catch a drag error of the size the compressible equilibrium made
// (+1%) and a lost recirculation or pressure recovery.
TEST(DfgBenchmark, Case2d1) { check_2d1(20, 0.05, {0.006, 0.06, 0.005, 0.005}); }
#endif
