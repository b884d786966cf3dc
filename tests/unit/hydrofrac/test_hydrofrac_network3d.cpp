// injection.fluid = "network" in 3D (drivers/hydrofrac/network_load.hpp): a block of bonded
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


// The 3D drained faces (network.faces = auto: hull pores and the band of one radius along the faces
// held at p0; the band is fixed at the start) resume bit for bit: the same block to 3 MPa, stopped
// mid-injection and resumed, gives the whole run's series and cracks; and no grain near a face
// breaks before the hole does (with closed faces the flat pores between the grains on a wall broke
// bonds at 0.1-0.4 MPa on the 30,000-sphere example: docs/hydrofrac.md, "Faces").
TEST(HydrofracNetwork, ThreeDimensionalDrainedFacesResumeBitForBit) {
  Scratch s;
  const fs::path file = small_block(s);
  const std::string sets = kSmallBlock + " --set injection.fluid=network --set injection.max_pressure=3e6";
  const auto j = run_scenario(file, s / "whole", sets);
  EXPECT_EQ(j["network"]["faces"].get<std::string>(), "drained");
  EXPECT_EQ(j["cracks"]["total"].get<long>(), 0);
  ff::test::expect_resume_identical(file, s / "whole", s / "parts", 700, sets);
}
