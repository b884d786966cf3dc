// The hydraulic fracture grows along sigma_H once sigma_H/sigma_h >= 1.5 (issue 15; seed 003
// s. 4.1: "the cracks ... propagate in the direction of least resistance, which is perpendicular
// to the minimum horizontal stress"; Kirsch: the hoop stress at the wall is least where sigma_H
// is tangent to it). A 30 mm block of ~1500 bonded disks (0.3-0.45 mm), a 3.5 mm borehole,
// sigma_H/sigma_h = 2 with sigma_H along x, then swapped (along y: a check that the measured
// azimuth is not x whatever happens). The azimuth is that of the cracks connected to the hole
// when the fracture first reaches one borehole radius beyond the wall (summary.json
// breakdown.fracture). Measured (seeds 1, 2): 7.4 and 9.3 deg along x; -85.8 and 84.4 deg
// along y. Tolerance 15 deg (the issue's). On the 560-disk block of the unit tests (a hole five
// grains across) the azimuth scattered by up to 29 deg over three packings: too coarse.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "../../unit/program_runner.hpp"

namespace fs = std::filesystem;

namespace {
const std::string kBlock = R"(driver = "hydrofrac"
[dem]
dim = 2
bond_law = "parallel"
[dem.group.matrix]
density = 1390
[dem.contact.matrix-matrix]
emod = 2.09e9
kratio = 14.65
friction = 0.4
[dem.bond.matrix-matrix]
emod = 2.09e9
kratio = 14.65
tensile_strength = 17.4e6
cohesion = 17.4e6
friction_angle = 4.0
[sample]
shape = "box"
width = 30e-3
height = 30e-3
radius_min = 0.3e-3
radius_max = 0.45e-3
porosity = 0.2
bond_gap = 0.15e-3
seed = 1
[borehole]
radius = 3.5e-3
[insitu]
sigma_H = 4e6
sigma_h = 2e6
[injection]
ramp_rate = 2e10
[output]
vtk = false
plots = false
progress_interval = 0
)";
}  // namespace

TEST(HydrofracOrientation, FractureWithin15DegreesOfSigmaH) {
  ff::test::TestScratch s("hydrofrac-orientation");
  const fs::path file = s / "block.toml";
  std::ofstream(file) << kBlock;
  for (int seed = 1; seed <= 2; ++seed)
    for (bool swapped : {false, true}) {
      const fs::path out = s / fmt::format("s{}{}", seed, swapped ? "y" : "x");
      const std::string sets = fmt::format(" --set sample.seed={}{}", seed,
                                           swapped ? " --set insitu.sigma_H=2e6 --set insitu.sigma_h=4e6" : "");
      const auto r = ff::test::run_program("run " + file.string() + " --out " + out.string() + " -q -j1" + sets);
      ASSERT_EQ(r.code, 0) << r.output;
      const auto j = ff::test::read_json(out / "summary.json");
      ASSERT_TRUE(j["breakdown"]["pressure_Pa"].is_number()) << j.dump(1);
      const double az = j["breakdown"]["fracture"]["azimuth_deg"];
      std::printf("seed %d, sigma_H along %s: fracture azimuth %.1f deg, breakdown %.2f MPa\n", seed, swapped ? "y" : "x", az,
                  1e-6 * j["breakdown"]["pressure_Pa"].get<double>());
      // Deviation from the sigma_H direction, folded into [0, 90].
      const double dev = swapped ? 90 - std::abs(az) : std::abs(az);
      EXPECT_LT(dev, 15.0) << j["breakdown"].dump(1);
    }
}
