// injection.fluid = "network" in 3D (coupling/hydrofrac/network_load.hpp): a block of bonded
// spheres fractured from a vertical borehole through the 3D pore network (regular triangulation,
// PFV throats), run through the fracflow program. The 2D tests: test_hydrofrac_network.cpp.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
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

struct Scratch : ff::test::TestScratch {
  Scratch() : TestScratch("hydrofrac_network") {}
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

// examples/hydrofrac_3d.toml's scenario written into the scratch folder, and the sets that make
// it a 12 x 12 x 4 mm block (~550 spheres) without VTK.
fs::path small_block(const Scratch& s) {
  return s.write("block3d.toml", ff::test::read_bytes(fs::path(FRACFLOW_SOURCE_DIR) / "examples" / "hydrofrac_3d.toml") + kOutput);
}
const std::string kSmallBlock = " --set hydrofrac.vtk_interval=0 --set sample.width=12e-3 --set sample.depth=12e-3 --set "
                                "sample.height=4e-3 --set measure.radii=[1.8] --set measure.circle_radius=0.3";

}  // namespace

#ifndef FRACFLOW_NETWORK3D_FAST  // test_hydrofrac_network3d (label long)
// examples/hydrofrac_3d.toml's rock in a 12 x 12 x 4 mm block (~550 spheres, sigma_H = 6, sigma_h = 3,
// sigma_v = 8 MPa) fractured through the 3D network: breakdown found, the first cracks at the
// wall; the breakdown pressure against the sleeve model's (no penetration) on the same block.
// A few minutes (one implicit flow step per DEM step on ~3000 pores): label long.
TEST(HydrofracNetwork, ThreeDimensionalBlockBreaksFromTheHole) {
  Scratch s;
  const fs::path file = small_block(s);
  const std::string& sets = kSmallBlock;
  const auto js = run_scenario(file, s / "sleeve", sets + " --set injection.penetration=false");
  const auto j = run_scenario(file, s / "network", sets + " --set injection.fluid=network");
  ASSERT_FALSE(j["breakdown"]["pressure_Pa"].is_null()) << j["breakdown"].dump();
  const double pn = j["breakdown"]["pressure_Pa"].get<double>();
  const double ps = js["breakdown"]["pressure_Pa"].is_null() ? NAN : js["breakdown"]["pressure_Pa"].get<double>();
  std::printf("3D breakdown: network %.2f MPa, sleeve (no penetration) %.2f MPa; network: %s\n", 1e-6 * pn, 1e-6 * ps,
              j["network"].dump().c_str());
  EXPECT_GT(j["fracture"]["connected_cracks"].get<long>(), 5);
  ASSERT_GE(ff::read_csv(s / "network" / "cracks.csv").rows(), 3u);
  const double a = j["borehole"]["effective_radius_m"].get<double>();
  const auto d = ff::test::first_crack_distances(s / "network" / "cracks.csv", 6e-3, 6e-3, 3);
  for (double x : d) EXPECT_LT(x, a + 4 * 0.6e-3) << "a first crack away from the hole";
}


#else  // test_hydrofrac_network3d_fast: the seconds-long ones, in make test

// The 3D drained faces (network.faces = auto; with network.walls = auto the pores between the grains and
// the six walls, held at p0) resume bit for bit: the same block to 3 MPa, stopped mid-injection and
// resumed, gives the whole run's series and cracks; and no grain near a face breaks before the hole
// does. With the pressure prediction (the default) the resume falls mid-cycle: the prediction's state is
// in the checkpoint. The same with closed faces: the wall pores' pressure pushes the servo walls (and is
// in the checkpoint).
TEST(HydrofracNetwork, ThreeDimensionalDrainedFacesResumeBitForBit) {
  Scratch s;
  const fs::path file = small_block(s);
  for (const std::string faces : {"drained", "closed"}) {
    const std::string sets =
        kSmallBlock + " --set injection.fluid=network --set injection.max_pressure=3e6 --set network.faces=" + faces;
    const auto j = run_scenario(file, s / ("whole_" + faces), sets);
    EXPECT_EQ(j["network"]["faces"].get<std::string>(), faces);
    EXPECT_TRUE(j["network"]["walls"].get<bool>());
    EXPECT_EQ(j["cracks"]["total"].get<long>(), 0);
    ff::test::expect_resume_identical(file, s / ("whole_" + faces), s / ("parts_" + faces), 707, sets);  // mid-cycle
  }
}

// Walls in the network (network.walls, PFV's boundary spheres) against the network that ends at the hull
// of the grain centres, on the same block with closed faces: without walls the flat tetrahedra between
// the grains pressed on a wall build pressures of their own as the grains move, and the block breaks at
// its faces (measured 2026-11-30: breakdown 0.66 MPa, the first cracks 4.9-5.7 mm from the axis, 712
// cracks; on the 30,000-sphere example 0.1-1.7 GPa in such pores, docs/hydrofrac.md); with the walls the
// pores along the faces are the gaps between the grains and the walls, and the block holds until the
// hole breaks (without crack channels 17.26 MPa, first cracks at 2.73-2.78 mm, the hole's effective radius
// 2.72 mm; the fracture at 0.0 deg from sigma_H; with network.crack_channels = true, the default since
// 2026-11-30: 16.37 MPa, first cracks at 2.73-3.30 mm, -0.8 deg). With drained faces the walls change little: 19.47 MPa (19.69 without; the
// breakdown of closed faces is lower: the pore pressure the injection raises in the block stays).
TEST(HydrofracNetwork, WallsLetClosedFacesHoldUntilTheHoleBreaks) {
  Scratch s;
  const fs::path file = small_block(s);
  const std::string sets = kSmallBlock + " --set injection.fluid=network --set network.faces=closed";
  const auto hull = run_scenario(file, s / "hull", sets + " --set network.walls=off");
  const auto walls = run_scenario(file, s / "walls", sets);
  ASSERT_FALSE(walls["breakdown"]["pressure_Pa"].is_null());
  const double a = walls["borehole"]["effective_radius_m"].get<double>();
  const double pw = walls["breakdown"]["pressure_Pa"].get<double>();
  const double ph = hull["breakdown"]["pressure_Pa"].is_null() ? NAN : hull["breakdown"]["pressure_Pa"].get<double>();
  std::printf("3D closed faces: breakdown with walls %.2f MPa (%ld cracks), without %.2f MPa (%ld cracks)\n", 1e-6 * pw,
              walls["cracks"]["total"].get<long>(), 1e-6 * ph, hull["cracks"]["total"].get<long>());
  EXPECT_FALSE(hull["network"]["walls"].get<bool>());
  EXPECT_TRUE(walls["network"]["walls"].get<bool>());
  EXPECT_GT(pw, 10e6);
  for (double x : ff::test::first_crack_distances(s / "walls" / "cracks.csv", 6e-3, 6e-3, 3))
    EXPECT_LT(x, a + 4 * 0.6e-3) << "with walls: a first crack away from the hole";
  EXPECT_LT(ph, 0.2 * pw) << "without walls the closed block no longer breaks at its faces: update the comment";
}

// The held steps' pressure prediction (network.predict_pressures, on by default): the same block
// fractured with a flow step every DEM step (the stiffness of the water allows no more without it)
// and with one every 20, the pressures predicted in between. Measured 2026-11-29 (one thread, no walls
// in the network): breakdown 19.69 MPa and initiation 18.14 MPa in both, 49 and 48 cracks, fracture
// 10.1 and 9.6 mm at 0.3 and 1.2 deg from sigma_H; 11.5 s and 4.7 s (network update 5.6 -> 0.3 s, flow
// 3.3 -> 0.3 s, forces and prediction 0.3 -> 1.9 s). With the walls (2026-11-30): breakdown 19.47 MPa in
// both, initiation 17.48 / 17.70 MPa, 61 / 64 cracks; with network.crack_channels = true (the default
// since 2026-11-30, AMG) 18.80 MPa in both, initiation 17.48 / 17.70 MPa, 45 / 47 cracks. Asserted: the pressures within 2 %, the cracks within 20 %.
TEST(HydrofracNetwork, PressurePredictionKeepsTheBreakdownPressure) {
  Scratch s;
  const fs::path file = small_block(s);
  const auto one = run_scenario(file, s / "every_step", kSmallBlock + " --set injection.fluid=network --set "
                                                         "network.predict_pressures=false");
  const auto pred = run_scenario(file, s / "predicted", kSmallBlock + " --set injection.fluid=network");
  ASSERT_FALSE(one["breakdown"]["pressure_Pa"].is_null());
  ASSERT_FALSE(pred["breakdown"]["pressure_Pa"].is_null());
  EXPECT_EQ(one["network"]["flow_every"].get<long>(), 1);
  EXPECT_FALSE(one["network"]["predict_pressures"].get<bool>());
  EXPECT_EQ(pred["network"]["flow_every"].get<long>(), 20);
  EXPECT_TRUE(pred["network"]["predict_pressures"].get<bool>());
  const double b1 = one["breakdown"]["pressure_Pa"].get<double>(), b2 = pred["breakdown"]["pressure_Pa"].get<double>();
  const double i1 = one["breakdown"]["initiation_pressure_Pa"].get<double>(),
               i2 = pred["breakdown"]["initiation_pressure_Pa"].get<double>();
  const double c1 = one["cracks"]["total"].get<double>(), c2 = pred["cracks"]["total"].get<double>();
  std::printf("3D network, flow step every DEM step / every 20 with the prediction: breakdown %.4f / %.4f MPa, "
              "initiation %.4f / %.4f MPa, cracks %.0f / %.0f, flow steps %ld / %ld\n", 1e-6 * b1, 1e-6 * b2, 1e-6 * i1,
              1e-6 * i2, c1, c2, one["network"]["flow_steps"].get<long>(), pred["network"]["flow_steps"].get<long>());
  EXPECT_NEAR(b2, b1, 0.02 * b1);
  EXPECT_NEAR(i2, i1, 0.02 * i1);
  EXPECT_NEAR(c2, c1, 0.2 * c1);
}

// Natural fractures in 3D (vertical discs, seed 003 Sec. 4.3's joints as zero-strength bonds): from the
// generator and from a file they cut bonds, a disc cuts more the larger it is, and one outside the
// block cuts none. The sleeve to 5 MPa (no breakdown needed). Measured 2026-11-29: 35 bonds by 4
// generated discs; a disc at y = 8.5 mm: 68 bonds (10 mm), 5 (3 mm), 0 (outside).
TEST(HydrofracNetwork, NaturalFractureDiscsCutBonds3D) {
  Scratch s;
  const fs::path file = small_block(s);
  const std::string sets = kSmallBlock + " --set injection.max_pressure=5e6";
  auto cut = [&](const std::string& name, const std::string& more) {
    const auto j = run_scenario(file, s / name, sets + more);
    return j["borehole"]["natural_fracture_bonds"].get<long>();
  };
  const long generated = cut("gen", " --set dfn.count=4 --set dfn.buffer=1e-3");
  s.write("big.csv", "x_m,y_m,z_m,angle_deg,length_m\n0.006,0.0085,0.002,0,0.010\n");
  s.write("small.csv", "x_m,y_m,z_m,angle_deg,length_m\n0.006,0.0085,0.002,0,0.003\n");
  s.write("outside.csv", "x_m,y_m,z_m,angle_deg,length_m\n0.006,0.0085,0.020,0,0.003\n");
  const long big = cut("big", " --set dfn.file=\"big.csv\""), small = cut("small", " --set dfn.file=\"small.csv\"");
  std::printf("3D natural fractures: %ld bonds cut by 4 generated discs; one disc at y = 8.5 mm: %ld (10 mm), %ld (3 mm)\n",
              generated, big, small);
  EXPECT_GT(generated, 0);
  EXPECT_GT(small, 0);
  EXPECT_GT(big, 2 * small);
  // A file whose every disc lies outside the block (another unit or origin) is refused, naming the key;
  // with one inside too, the run goes on and the outside disc cuts nothing.
  const auto refused = fracflow("check " + file.string() + sets + " --set dfn.file=\"outside.csv\"");
  EXPECT_EQ(refused.code, 2) << refused.output;
  EXPECT_NE(refused.output.find("every fracture's centre lies outside the block"), std::string::npos) << refused.output;
  s.write("both.csv", "x_m,y_m,z_m,angle_deg,length_m\n0.006,0.0085,0.002,0,0.003\n0.006,0.0085,0.020,0,0.003\n");
  EXPECT_EQ(cut("both", " --set dfn.file=\"both.csv\""), small);
}

// One and two threads give the same files, bit for bit, through the breakdown: a 16 x 16 x 4 mm block
// (~1,040 spheres, 6,145 pores: above porenet::kParallelMin, so the network's loops, the multigrid
// smoother's blocks and the prediction run on both threads; every DEM loop over 200 items too), with
// retriangulations every 0.02 mean radii of motion so that the remap runs as well. Measured
// 2026-11-29: breakdown 25.5 MPa, 106 cracks, 6 retriangulations (3 % of the wall time); ~10 s per run.
TEST(HydrofracNetwork, ThreeDimensionalOneAndTwoThreadsAreBitIdentical) {
  Scratch s;
  const fs::path file = small_block(s);
  const std::string sets = " --set hydrofrac.vtk_interval=0 --set sample.width=16e-3 --set sample.depth=16e-3 --set "
                           "sample.height=4e-3 --set measure.radii=[1.8] --set measure.circle_radius=0.3 --set "
                           "injection.fluid=network --set network.retriangulation_tolerance=0.02 --set dem.parallel_min=200";
  const auto one = run_scenario(file, s / "one", sets);
  const auto r = fracflow("run " + file.string() + " --out " + (s / "two").string() + " -q -j2" + sets);
  ASSERT_EQ(r.code, 0) << r.output;
  ASSERT_FALSE(one["breakdown"]["pressure_Pa"].is_null()) << one["breakdown"].dump();
  EXPECT_GT(one["network"]["pores"].get<long>(), 4096) << "the network's loops would not run in parallel";
  EXPECT_GT(one["network"]["retriangulations"].get<long>(), 0);
  EXPECT_GT(one["cracks"]["total"].get<long>(), 10);
  EXPECT_EQ(ff::test::read_bytes(s / "one" / "series.csv"), ff::test::read_bytes(s / "two" / "series.csv"));
  EXPECT_EQ(ff::test::read_bytes(s / "one" / "cracks.csv"), ff::test::read_bytes(s / "two" / "cracks.csv"));
}

#endif
