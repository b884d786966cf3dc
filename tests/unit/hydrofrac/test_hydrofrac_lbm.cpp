// The hydrofrac driver through the fracflow program, as a user runs it: the elastic state
// around a pressurised borehole against Kirsch's solution, the breakdown pressure against the
// minimum in-situ stress (with the rock's tensile strength measured by the direct-tension
// driver on the same material), the fracture's orientation against sigma_H, penetration,
// the constant-rate mode, natural fractures, input errors and resume bit for bit.
// Small 2D blocks (560-2900 disks) keep the binary under a minute on one core. The fracture's
// orientation needs a finer block: tests/validation/hydrofrac (label long).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "../program_runner.hpp"
#include "hydrofrac_scenario.hpp"
#include "io/csv.hpp"

namespace fs = std::filesystem;

namespace {

const std::string& kOutput = ff::test::kQuietOutput;
std::string material(double strength) { return ff::test::coal_matrix_2d(strength); }

// A 24 mm block, disks 0.4-0.6 mm (~560), a 2.5 mm borehole, sigma_H = 4 MPa along x.
const std::string kBlock = "driver = \"hydrofrac\"\n" + material(17.4e6) + R"(
[sample]
shape = "box"
width = 24e-3
height = 24e-3
radius_min = 0.4e-3
radius_max = 0.6e-3
porosity = 0.2
bond_gap = 0.2e-3
seed = 1
[borehole]
radius = 2.5e-3
[insitu]
sigma_H = 4e6
sigma_h = 2e6
[injection]
ramp_rate = 2e10
fluid = "lbm"
max_pressure = 25e6
[fluid]
density = 1000
viscosity = 1e-2
bulk_modulus = 3e8
)" + kOutput;

struct Scratch : ff::test::TestScratch {
  Scratch() : TestScratch("hydrofrac_lbm") {}
  fs::path write(const std::string& name, const std::string& text) const {
    const fs::path p = path / name;
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }
};

ff::test::ProgramResult fracflow(const std::string& args) { return ff::test::run_program(args); }

nlohmann::json run_scenario(const fs::path& file, const fs::path& out, const std::string& sets = "") {
  const auto r = fracflow("run " + file.string() + " --out " + out.string() + " -q -j1" + sets);
  EXPECT_EQ(r.code, 0) << r.output;
  return ff::test::read_json(out / "summary.json");
}

}  // namespace


// injection.fluid = "lbm" on the 24 mm block (92 x 92 cells, dx = 0.267 mm, quasi-static walls):
// a run stopped at step 9000 (mid-injection, after breakdown) and resumed reproduces the whole
// run's series and crack log bit for bit (populations, LBM step and last particle set are in the
// checkpoint), and two threads give the same files. The breakdown happens (cracks start at the
// wall, tensile first: seed 002 Fig. 9) and the fluid enters cracks connected to the hole (measured
// 9 wetted crack points of 35 connected at 25 MPa); the mass budget closes (summary.json lbm).
// test_hydrofrac_lbm_load.cpp checks the load and the crack invasion against exact values.
TEST(HydrofracLbm, ResumeAndTwoThreadsAreBitIdenticalAndTheRockBreaks) {
  Scratch s;
  const fs::path file = s.write("block.toml", kBlock);
  const fs::path whole = s / "whole", parts = s / "parts", two = s / "two";
  const auto j = run_scenario(file, whole);
  ASSERT_TRUE(j.contains("injection"));
  EXPECT_GT(j["cracks"]["tensile"].get<long>(), 0);
  EXPECT_TRUE(j["breakdown"]["pressure_Pa"].is_number());
  EXPECT_GT(j["injection"]["wetted_cracks"].get<long>(), 0);
  // Where the injected fluid went: lattice change = injected + covering/refill + residual, the
  // residual (bounce-back interpolation) below 2% of the injected (measured 0.2%).
  const auto& b = j["lbm"]["mass_budget_m3"];
  EXPECT_NEAR(b["lattice_change"].get<double>(),
              b["injected"].get<double>() + b["covering_refill"].get<double>() + b["residual"].get<double>(),
              1e-9 * b["lattice_change"].get<double>());
  EXPECT_LT(std::abs(b["residual"].get<double>()), 0.02 * b["injected"].get<double>());
  // The fluid's largest Mach number is measured (and in the resumed run's summary, compared below):
  // a slow ramp keeps it well under the lattice's 0.1 (seed 002's Fig. 9 example: 0.015).
  const double mach = j["lbm"]["max_mach"].get<double>();
  EXPECT_TRUE(mach > 0 && mach < 0.1) << mach;
  ff::test::expect_resume_identical(file, whole, parts, 9000);
  auto r = fracflow("run " + file.string() + " --out " + two.string() + " -q -j2 --set dem.parallel_min=200");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(ff::test::read_bytes(whole / "series.csv"), ff::test::read_bytes(two / "series.csv"));
  EXPECT_EQ(ff::test::read_bytes(whole / "cracks.csv"), ff::test::read_bytes(two / "cracks.csv"));
}

// Constant-rate injection with the LBM fluid, the pumped fluid entering as a mass source over the
// hole's cells or through seed 003's velocity box (Sec. 4.1: a square of half the hole's radius whose
// cells carry the outward velocity). Both pump Q t (the series' injected volume against Q t since the
// first injection row within 1 %, after the box's first rows) and the hole's pressure rises alike
// (within 3 % row by row once above 1 MPa). Measured 2026-11-29: 0.14 % and 1.4 % (7.60 / 7.71 MPa at
// the end); without the box's correction of U (below) it pumped ~25 % more than Q.
TEST(HydrofracLbm, VelocityBoxPumpsTheRateAsTheMassSource) {
  Scratch s;
  const fs::path file = s.write("block.toml", kBlock);
  const double Q = 1.3e-3;  // m^3/s per m: ~2e10 Pa/s in the hole at K_eff 3e8
  const std::string sets = " --set injection.mode=\"rate\" --set injection.rate=1.3e-3 --set injection.max_time=3e-4";
  run_scenario(file, s / "mass", sets);
  run_scenario(file, s / "box", sets + " --set injection.lbm_source=\"velocity_box\"");
  const auto m = ff::read_csv(s / "mass" / "series.csv"), b = ff::read_csv(s / "box" / "series.csv");
  ASSERT_EQ(m.rows(), b.rows());
  std::size_t first = m.rows(), compared = 0;
  double worst_q = 0, worst_p = 0;
  for (std::size_t r = 0; r < m.rows(); ++r) {
    if (m.column("stage")[r] < 1) continue;
    if (first == m.rows()) first = r;
    const double t = b.column("time_s")[r] - b.column("time_s")[first];
    if (r < first + 3) continue;
    worst_q = std::max(worst_q, std::abs((b.column("injected_volume_m3")[r] - b.column("injected_volume_m3")[first]) / (Q * t) - 1));
    if (m.column("pressure_Pa")[r] > 1e6) {
      worst_p = std::max(worst_p, std::abs(b.column("pressure_Pa")[r] / m.column("pressure_Pa")[r] - 1));
      ++compared;
    }
  }
  std::printf("velocity box: pumped volume vs Q t worst %.3f %%, pressure vs the mass source worst %.3f %% over %zu rows "
              "(final %.3f / %.3f MPa)\n",
              100 * worst_q, 100 * worst_p, compared, 1e-6 * b.column("pressure_Pa")[b.rows() - 1],
              1e-6 * m.column("pressure_Pa")[m.rows() - 1]);
  EXPECT_GT(compared, 5u);
  EXPECT_LT(worst_q, 0.01);
  EXPECT_LT(worst_p, 0.03);
  // Refused where it has no meaning: the ramp mode and the other fluids.
  const auto r = fracflow("check " + file.string() + " --set injection.lbm_source=\"velocity_box\"");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("injection.lbm_source"), std::string::npos) << r.output;
}

// The hydrofrac driver with the other bond law, seed 002's 6-DOF rotational bond (its lattice solid;
// tensile strength c / tan(phi) = 17.3 MPa here), on the same block: a breakdown found and the first
// cracks at the hole's wall, with the sleeve and with the LBM fluid. Measured 2026-11-29: sleeve
// breakdown 25.4 MPa, LBM 14.1 MPa (initiation 13.2), the first cracks 3.1 mm from the axis (wall at
// 2.49 mm); the rotational bonds fail in shear here (cohesion 10 MPa below their tension).
TEST(HydrofracLbm, RotationalBondsBreakFromTheHole) {
  Scratch s;
  std::string text = kBlock;
  auto replace = [&](const std::string& a, const std::string& b) {
    const auto at = text.find(a);
    ASSERT_NE(at, std::string::npos) << a;
    text.replace(at, a.size(), b);
  };
  replace("bond_law = \"parallel\"", "bond_law = \"rotational\"");
  {  // the parallel bond's table -> the rotational bond's
    const auto from = text.find("[dem.bond.matrix-matrix]"), to = text.find("friction_angle = 4.0", from);
    ASSERT_TRUE(from != std::string::npos && to != std::string::npos);
    text.replace(from, to + std::string("friction_angle = 4.0").size() - from,
                 "[dem.bond.matrix-matrix]\nyoungs_modulus = 2.09e9\npoisson_ratio = 0.25\ncohesion = 10e6\nfriction_angle = 30.0");
  }
  const fs::path file = s.write("rotational.toml", text);
  for (const char* fluid : {"sleeve", "lbm"}) {
    // (the LBM block's 25 MPa cap is its fluid's density limit; the sleeve has none)
    const auto j = run_scenario(file, s / fluid, fmt::format(" --set injection.fluid=\"{}\"{}", fluid,
                                                              std::string(fluid) == "sleeve" ? " --set injection.max_pressure=40e6" : ""));
    ASSERT_TRUE(j["breakdown"]["pressure_Pa"].is_number()) << fluid << j["breakdown"].dump();
    const double a = j["borehole"]["effective_radius_m"].get<double>();
    const auto d = ff::test::first_crack_distances(s / fluid / "cracks.csv", 12e-3, 12e-3, 3);
    ASSERT_EQ(d.size(), 3u) << fluid;
    std::printf("rotational bonds, %s: breakdown %.2f MPa, first cracks at %.2f / %.2f / %.2f mm (wall %.2f mm)\n", fluid,
                1e-6 * j["breakdown"]["pressure_Pa"].get<double>(), 1e3 * d[0], 1e3 * d[1], 1e3 * d[2], 1e3 * a);
    for (double x : d) EXPECT_LT(x, a + 4 * 0.6e-3) << fluid << ": a first crack away from the hole";
  }
}

// The same block with the partially saturated cells (fluid.scheme = "psm"), stopped at step 3000 and
// resumed: the solid fractions of the last particle set handed to the solver come back with the
// checkpoint, so the resumed run's series and cracks are the whole run's, byte for byte.
TEST(HydrofracLbm, PsmResumeIsBitIdentical) {
  Scratch s;
  const fs::path file = s.write("block.toml", kBlock);
  const fs::path whole = s / "whole", parts = s / "parts";
  const std::string sets = " --set fluid.scheme=psm --set injection.max_pressure=8e6";
  const auto r = fracflow("run " + file.string() + " --out " + whole.string() + " -q -j1" + sets);
  ASSERT_EQ(r.code, 0) << r.output;
  ff::test::expect_resume_identical(file, whole, parts, 3000, sets);
}

// `fracflow check` on an LBM scenario prints what `run` logs at the start of injection: dt_lbm,
// dt_dem, the sub-cycle count n, tau, the Mach number and K_eff (the DEM step needs the sample,
// which check builds for this). The block's numbers: dt_dem 1.183e-07 s, n = 2, tau 0.5998.
TEST(HydrofracLbm, CheckPrintsTheStepsAndTheFluid) {
  Scratch s;
  const fs::path file = s.write("block.toml", kBlock);
  const auto r = fracflow("check " + file.string());
  ASSERT_EQ(r.code, 0) << r.output;
  for (const char* want : {"dt_lbm = 2.366e-07 s", "dt_dem = 1.183e-07 s", "n = 2 DEM sub-steps", "tau = 0.5998", "Mach 0",
                           "K_eff = 4.236e+08 Pa"})
    EXPECT_NE(r.output.find(want), std::string::npos) << want << " not in:\n" << r.output;
}

// 3D (D3Q19): examples/hydrofrac_3d_lbm.toml's rock (bonded spheres 0.4-0.6 mm, porosity 0.4) in
// an 11 x 11 x 4 mm block (~500 spheres) with a vertical 1.8 mm borehole, sigma_H / sigma_h /
// sigma_v = 6 / 3 / 8 MPa, the hole's pressure ramped at 1e11 Pa/s. Bonded spheres leave their
// pores connected, so the fluid fills the whole pore space (docs/hydrofrac.md, "3D").
//  - Closed faces: the box fills to a nearly uniform pressure, which loads no grain; the fluid on
//    the faces takes the walls' load (the servos hold the total stress: fluid share + contacts),
//    and once it passes sigma_h the grains lose the walls. No crack by 12 MPa (nor by 30: measured).
//  - Drained faces (the far field held at p0): the seepage from the hole to the faces loads the
//    skeleton and the rock breaks, tensile, along sigma_H (within 15 degrees: the issue's criterion
//    for sigma_H / sigma_h >= 1.5; measured 3.1 deg, breakdown 24.6 MPa); the fluid that left
//    through the faces is most of the injected; the faces carry nothing. Stopped mid-injection and
//    resumed: bit for bit.
TEST(HydrofracLbm, ThreeDBreaksWithDrainedFacesAlongSigmaHNotInAClosedBox) {
  Scratch s;
  const fs::path file = s.write("block3d.toml", ff::test::read_bytes(fs::path(FRACFLOW_SOURCE_DIR) / "examples" / "hydrofrac_3d_lbm.toml") + kOutput);
  const std::string block = " --set sample.width=11e-3 --set sample.depth=11e-3 --set sample.height=4e-3 --set "
                            "borehole.radius=1.8e-3 --set measure.radii=[1.8,2.3] --set measure.circle_radius=0.35 --set "
                            "injection.ramp_rate=1e11 --set injection.max_pressure=30e6";
  const fs::path closed = s / "closed", drained = s / "drained", parts = s / "parts";
  const auto c = run_scenario(file, closed, block + " --set fluid.faces=closed --set injection.max_pressure=12e6");
  EXPECT_EQ(c["cracks"]["total"].get<long>(), 0);
  EXPECT_TRUE(c["breakdown"]["pressure_Pa"].is_null());
  const auto series = ff::read_csv(closed / "series.csv");
  const auto& total = series.column("sigma_yy_wall_Pa");
  const auto& fluid = series.column("sigma_yy_fluid_Pa");
  const auto& p = series.column("pressure_Pa");
  const std::size_t last = series.rows() - 1;
  EXPECT_GT(fluid[last], 3e6);                     // the pore fluid on the faces passed sigma_h ...
  // ... and carries the walls alone: the grains lose the walls, a few touching again now and then
  // (contacts 0-14 kPa over the last five rows, against 216 kPa just before the fluid passed
  // sigma_h = 3 MPa): within 1 % of sigma_h.
  EXPECT_NEAR(total[last], fluid[last], 0.01 * 3e6);
  EXPECT_LT(fluid[last], p[last]);                 // lagging the hole's pressure
  const std::string faces = block + " --set fluid.faces=drained";
  const auto d = run_scenario(file, drained, faces);
  ASSERT_TRUE(d["breakdown"]["pressure_Pa"].is_number());
  EXPECT_GT(d["cracks"]["tensile"].get<long>(), 10 * d["cracks"]["shear"].get<long>());
  EXPECT_LT(std::abs(d["fracture"]["azimuth_deg"].get<double>()), 15.0);
  const auto& b = d["lbm"]["mass_budget_m3"];
  EXPECT_LT(b["drained"].get<double>(), -0.5 * b["injected"].get<double>());
  EXPECT_EQ(ff::read_csv(drained / "series.csv").column("sigma_yy_fluid_Pa").back(), 0.0);
  ff::test::expect_resume_identical(file, drained, parts, 2000, faces);
}
