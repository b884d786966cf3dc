// Flow past a circular cylinder between two plates ([S003] Sec. 3.3), run through the
// flow/cylinder driver. References (tests/data/lbm/, from [S003] Tables 2-3):
//  * wall correction factor lambda(k) = F / (mu u_max) at Re = 2e-4 ([S003] Eq. 16) against
//    the analytical values of Faxen (1946); tolerance 3% (issue 3). At k = 0.5 Faxen's
//    truncated series is itself about 4% too high: converged LBM runs (D = 12, 20, 40 cells:
//    87.1, 87.9, 88.2) and the finite differences of Richou et al. (2004, 88.8) agree, so k = 0.5
//    is checked against Richou et al. with the same 3%.
//  * drag coefficient Cd(Re) for Re = 1..40, [S003] set-up (400 x 400 lu, D = 20 lu, uniform
//    inflow 0.1 lu/ts through the moving-wall bounce-back of [S003] Eq. 8, stair-wise cylinder,
//    BGK); tolerance 4% (issue 3) against the DLSM-LBM column of Table 3 and, at the published
//    resolution, also against its IBM column (Han & Cundall 2011).
//  * Re = 100 vortex street: mean Cd within 5% of the range 1.26 (Jiang & Zhao 2019) to 1.33
//    (Park, Kwon & Choi 1998, unbounded), Strouhal number reported and checked against 0.165
//    (Williamson 1996) within 5%.
// Reduced resolutions run in the default suite; the published resolutions under label long.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "flow_driver_runner.hpp"
#include "io/csv.hpp"

namespace {

std::string data(const std::string& f) { return std::string(FRACFLOW_TEST_DATA) + "/lbm/" + f; }
std::string num(double v) { return fmt::format("{}", v); }

// ---------------------------------------------------------------- Table 2
// Stokes flow (Re = 2e-4 on u_max and D) past a cylinder midway between plates, parabolic
// Zou-He inflow, channel 2.5 H long as in [S003]; TRT + Bouzidi walls (the steady result does
// not depend on tau, so tau = 1 lets the flow settle fast).
const char* kWallFactor = R"(
driver = "flow/cylinder"
[cylinder]
diameter = 1.0e-3
initial_perturbation = 0.0
wall = "bouzidi"
[inlet]
profile = "parabolic"
velocity = 2.0e-7
[fluid]
viscosity = 1.0e-6
[lbm]
tau = 1.0
[run]
steady_tolerance = 1.0e-5
[output]
samples = 2000
vtk = false
plots = false
)";

void check_table2(int cells_per_d) {
  const ff::CsvTable t = ff::read_csv(data("jiang_zhao_2019_table2_wall_correction.csv"));
  for (std::size_t i = 0; i < t.rows(); ++i) {
    const double k = t.column("k")[i], faxen = t.column("lambda_analytical_Faxen1946")[i];
    const double fdm = t.column("lambda_FDM_Richou2004")[i];
    const double H = 1e-3 / k, L = 2.5 * H;
    const auto j = ff::testing::run_flow_driver(
        fmt::format("cylinder_lambda_k{}_{}", k, cells_per_d), kWallFactor,
        {"channel.height=" + num(H), "channel.length=" + num(L), "cylinder.x=" + num(L / 2),
         "lbm.resolution=" + std::to_string(cells_per_d),
         // at most 400000 steps: dt = (tau - 1/2) dx^2 / (3 nu) = (1e-3 / cells)^2 / 6e-6 s
         "run.end_time=" + num(4e5 / 6e-6 * (1e-3 / cells_per_d) * (1e-3 / cells_per_d))});
    const double lambda = j["results"]["lambda_wall_factor"];
    std::printf("k = %.1f, D = %d cells: lambda = %.4f; Faxen %.4f (%+.2f%%), Richou FDM %.4f (%+.2f%%); %s\n", k,
                cells_per_d, lambda, faxen, 100 * (lambda / faxen - 1), fdm, 100 * (lambda / fdm - 1),
                std::string(j["stop_reason"]).c_str());
    if (k < 0.45) {
      EXPECT_NEAR(lambda, faxen, 0.03 * faxen) << "k = " << k;
    } else {
      EXPECT_NEAR(lambda, fdm, 0.03 * fdm) << "k = " << k;
    }
  }
}

// ---------------------------------------------------------------- Table 3
// [S003] 3.3.2 in lattice units: dx = 1 mm, dt = 0.01 s, inflow 0.01 m/s = 0.1 lu/ts,
// nu = U D / Re.
const char* kDrag = R"(
driver = "flow/cylinder"
[channel]
height = 0.4
length = 0.4
[cylinder]
diameter = 0.02
x = 0.2
initial_perturbation = 0.0
wall = "halfway"
[inlet]
condition = "bounce_back"
velocity = 0.01
[lbm]
collision = "bgk"
resolution = 20
time_step = 0.01
[run]
end_time = 1000
steady_tolerance = 1.0e-5
[output]
samples = 400
vtk = false
plots = false
)";

// check_ibm: also hold the IBM column to 4% (at the published resolution).
void check_table3(int cells_per_d, const std::vector<double>& reynolds, bool check_ibm) {
  const ff::CsvTable t = ff::read_csv(data("jiang_zhao_2019_table3_drag.csv"));
  const double scale = cells_per_d / 20.0;  // coarser lattices: the same problem in fewer cells
  // dx = D / cells; dt keeps the lattice inflow speed at 0.1; at most 100000 steps.
  for (std::size_t i = 0; i < t.rows(); ++i) {
    const double re = t.column("Re")[i];
    if (std::find(reynolds.begin(), reynolds.end(), re) == reynolds.end()) continue;
    const double dlsm = t.column("Cd_DLSM_LBM")[i], ibm = t.column("Cd_IBM_HanCundall2011")[i];
    const double D = 0.02, U = 0.01, nu = U * D / re;
    const auto j = ff::testing::run_flow_driver(
        fmt::format("cylinder_drag_re{}_{}", re, cells_per_d), kDrag,
        {"fluid.viscosity=" + num(nu), "lbm.resolution=" + std::to_string(cells_per_d),
         "lbm.time_step=" + num(0.01 / scale), "run.end_time=" + num(1000 / scale)});
    const double cd = j["results"]["cd_final"];
    std::printf("Re = %g, D = %d cells: Cd = %.4f; DLSM-LBM %.4f (%+.2f%%), IBM %.4f (%+.2f%%); %s\n", re, cells_per_d,
                cd, dlsm, 100 * (cd / dlsm - 1), ibm, 100 * (cd / ibm - 1), std::string(j["stop_reason"]).c_str());
    EXPECT_NEAR(cd, dlsm, 0.04 * dlsm) << "Re = " << re;
    if (check_ibm) {
      EXPECT_NEAR(cd, ibm, 0.04 * ibm) << "Re = " << re;
    }
  }
}

// ---------------------------------------------------------------- Re = 100
// A cylinder 15 D behind a uniform Zou-He inflow, 30 D before the outlet; periodic sides
// 32 D apart (a row of cylinders far apart: the unbounded-flow reference values apply; see
// docs/lbm.md for the same case between no-slip plates, where the plates' boundary layers
// raise Cd). TRT + Bouzidi; lattice inflow speed 0.05.
const char* kShedding = R"(
driver = "flow/cylinder"
[channel]
height = 0.32
length = 0.45
sides = "periodic"
[cylinder]
diameter = 0.01
x = 0.15
[inlet]
velocity = 0.01
[fluid]
viscosity = 1.0e-6
[run]
end_time = 250
[output]
samples = 5000
vtk = false
plots = false
)";

// cd_high: upper acceptance bound of the mean Cd.
void check_shedding(int cells_per_d, double cd_high) {
  const double dt = 0.05 * (0.01 / cells_per_d) / 0.01;  // lattice inflow speed 0.05
  const auto j = ff::testing::run_flow_driver(fmt::format("cylinder_re100_{}", cells_per_d), kShedding,
                                              {"lbm.resolution=" + std::to_string(cells_per_d), "lbm.time_step=" + num(dt)});
  const auto& r = j["results"];
  const double cd = r["cd_mean"], st = r["strouhal"];
  std::printf("Re = 100, D = %d cells: mean Cd = %.4f (target 1.26-1.33 +-5%%), St = %.4f, Cl amplitude %.3f over %d "
              "periods\n",
              cells_per_d, cd, st, double(r["cl_amplitude"]), int(r["shedding_periods_averaged"]));
  EXPECT_NEAR(double(r["reynolds"]), 100.0, 1e-9);
  ASSERT_TRUE(bool(r["shedding"]));
  EXPECT_GE(int(r["shedding_periods_averaged"]), 8);
  EXPECT_GE(cd, 0.95 * 1.26);
  EXPECT_LE(cd, cd_high);
  EXPECT_NEAR(st, 0.165, 0.05 * 0.165);
}

}  // namespace

#ifdef FRACFLOW_LONG_TESTS
TEST(LbmCylinderLong, WallCorrectionFactorTable2) { check_table2(20); }
TEST(LbmCylinderLong, DragCoefficientTable3) { check_table3(20, {1, 10, 20, 30, 40}, true); }
TEST(LbmCylinderLong, VortexSheddingRe100) { check_shedding(20, 1.05 * 1.33); }
#else
// Reduced checks: 12 cells across D for lambda (10 cells put only 7.5 cells into the gaps at
// k = 0.4 and under-predict lambda by 5%); half the published resolution for Cd, at the Reynolds
// numbers where that lattice is stable (Re 30-40 need D = 20 with the bounce-back inflow).
TEST(LbmCylinder, WallCorrectionFactorTable2) { check_table2(12); }
TEST(LbmCylinder, DragCoefficientTable3) { check_table3(10, {1, 10, 20}, false); }
// Reduced check: 10 cells across D over-predict the drag by about 2% (mean Cd 1.405 against
// 1.377 with 20 cells), so the bound is 8% above 1.33 here; St is held to the same 5%.
TEST(LbmCylinder, VortexSheddingRe100) { check_shedding(10, 1.08 * 1.33); }
#endif
