// The 3D Brazilian test against the closed form (label "long": 45-100 s on 2 busy cores): the
// scenario of examples/brazilian_3d.toml, a cylinder of 20 mm diameter and 10 mm thickness
// lying on its side (~3,500 spheres), with bonds that cannot break.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "io/csv.hpp"
#include "../program_runner.hpp"

namespace fs = std::filesystem;

// Closed form as in test_brazilian.cpp (Timoshenko & Goodier 1970 s. 41; Hondros 1959): over a
// central circle of rho R, (1 - rho^2) and -(3 - rho^2) times 2P/(pi D t) across and along the
// loaded diameter. A disc of thickness t = D/2 with free faces is in generalized plane stress:
// its thickness-averaged stresses obey the 2D equations, and the gauge (a cylinder through the
// thickness) averages through it. Tolerance 10% for one packing: the gauge holds ~600 spheres
// (measured: +1% across, +1.5% along); a factor 2 or swapped components fail.
TEST(Brazilian3D, ElasticCylinderOnItsSideMatchesTheClosedForm) {
  const ff::test::TestScratch s("brazilian3d");
  const fs::path out = s / "run";
  const double rho = 0.4, D = 20e-3, t = 10e-3, pi = 3.14159265358979323846;
  const auto r = ff::test::run_program(fmt::format(
      "run {}/examples/brazilian_3d.toml --out {} -q -j2 --set output.vtk=false --set output.plots=false"
      " --set sample.diameter={} --set sample.height={} --set brazilian.max_strain=0.006"
      " --set brazilian.centre_gauge_radius={} --set dem.bond.matrix-matrix.tensile_strength=1e15"
      " --set dem.bond.matrix-matrix.cohesion=1e15",
      FRACFLOW_SOURCE_DIR, out.string(), D, t, rho));
  ASSERT_EQ(r.code, 0) << r.output;
  const ff::CsvTable csv = ff::read_csv(out / "series.csv");
  const auto strain = csv.column("diametral_strain"), load = csv.column("load_N");
  const auto nominal = csv.column("tensile_stress_Pa"), across = csv.column("centre_stress_across_Pa"),
             along = csv.column("centre_stress_along_Pa");
  double ra = 0, rl = 0;
  int n = 0;
  for (std::size_t k = 0; k < strain.size(); ++k) {
    EXPECT_NEAR(nominal[k], 2 * load[k] / (pi * D * t), 1e-12 * std::abs(nominal[k]));
    if (strain[k] < 0.002) continue;  // seating on the platens
    ra += across[k] / nominal[k];
    rl += along[k] / nominal[k];
    ++n;
  }
  ASSERT_GE(n, 10);
  ra /= n;
  rl /= n;
  std::printf("3D: centre stress / (2P/(pi D t)): across %.3f (closed form %.3f), along %.3f (%.3f)\n", ra,
              1 - rho * rho, rl, -(3 - rho * rho));
  EXPECT_NEAR(ra, 1 - rho * rho, 0.10 * (1 - rho * rho));
  EXPECT_NEAR(rl, -(3 - rho * rho), 0.10 * (3 - rho * rho));
}
