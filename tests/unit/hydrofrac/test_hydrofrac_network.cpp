// injection.fluid = "network" (coupling/hydrofrac/network_load.hpp): hydraulic fracturing from a
// borehole through the pore network of issue 16, run through the fracflow program as a user does:
//  1. before breakdown the hole pressure loads the rock as the sleeve model does (Kirsch): the
//     stress increments on measurement circles around the hole, network against sleeve, on the
//     same block and packing;
//  2. a 2D block breaks, the first cracks at the hole, the breakdown pressure printed and
//     compared with the sleeve model's (3D: test_hydrofrac_network3d.cpp, label long);
//  3. mass budget in rate mode: the pumped mass equals the change of the pores' mass;
//  4. 1 and 2 threads identical, resume bit for bit.
// Small 2D blocks (~560-1300 disks): each test 10-35 s on a busy core.
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
std::string material(double strength) { return ff::test::coal_matrix_2d(strength); }

// test_hydrofrac.cpp's block: 24 mm, disks 0.4-0.6 mm (~560), a 2.5 mm hole, sigma_H = 4 MPa (x),
// sigma_h = 2 MPa; the fluid given by `fluid`.
std::string block(const std::string& fluid) {
  return "driver = \"hydrofrac\"\n" + material(17.4e6) + R"(
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
fluid = ")" + fluid + "\"\n" + kOutput;
}

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

}  // namespace

// 1. Kirsch through the network. A 30 mm block of unbreakable bonded disks (~1300), a = 4 mm,
// s0 = 3 MPa, the hole's pressure ramped to 6 MPa; eight circles of 2.4 mm at r = 2a. A viscous
// liquid (1 Pa s) and tight channels keep the rock's pores near p0 over the 0.3 ms ramp (the
// pore-pressure front stays within a grain or two of the wall), so the load is the hole pressure
// on the wall as in the sleeve model (Kirsch: +p a^2/r^2 radial, -p a^2/r^2 hoop; Jaeger, Cook &
// Zimmerman 2007, eqs. 8.4.11-13). The network's load acts on the grains' arcs inside the hole's
// triangles, the sleeve's on the flooded surface: the two increments are compared on the same
// packing. Measured: radial 1.35 (network) vs 1.25 MPa (sleeve), hoop -1.69 vs -1.43 MPa (Kirsch
// +-1.46): 7% and 17% of the Kirsch increment apart (the network's extra hoop change: the liquid
// that entered the first pores pushes too). Tolerance 20% of the Kirsch increment (one circle
// scatters by up to 40%, test_hydrofrac.cpp); a missing or doubled wall load fails by far more.
TEST(HydrofracNetwork, BeforeBreakdownTheRockIsLoadedAsByTheSleeve) {
  Scratch s;
  const std::string text = "driver = \"hydrofrac\"\n" + material(1e12) + R"(
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
radius = 4e-3
[insitu]
sigma_H = 3e6
sigma_h = 3e6
[injection]
ramp_rate = 2e10
max_pressure = 6.2e6
[network]
viscosity = 1.0
[measure]
radii = [2.0]
angles = [0, 45, 90, 135, 180, 225, 270, 315]
circle_radius = 0.6
pressure = 6e6
)" + kOutput;
  const fs::path file = s.write("kirsch.toml", text);
  double m_rr[2] = {0, 0}, m_tt[2] = {0, 0}, k_rr = 0, k_tt = 0;
  int n = 0;
  for (int f = 0; f < 2; ++f) {
    const auto j = run_scenario(file, s / fmt::format("f{}", f), f == 0 ? " --set injection.fluid=sleeve" : " --set injection.fluid=network");
    ASSERT_TRUE(j["elastic_state"].contains("pressurised")) << j.dump(1);
    const auto& a = j["elastic_state"]["insitu"];
    const auto& b = j["elastic_state"]["pressurised"];
    for (std::size_t c = 0; c < a.size(); ++c) {
      if (a[c]["kind"] == "interior") continue;
      m_rr[f] += b[c]["measured_Pa"]["rr"].get<double>() - a[c]["measured_Pa"]["rr"].get<double>();
      m_tt[f] += b[c]["measured_Pa"]["tt"].get<double>() - a[c]["measured_Pa"]["tt"].get<double>();
      if (f == 0) {
        k_rr += b[c]["kirsch_Pa"]["rr"].get<double>() - a[c]["kirsch_Pa"]["rr"].get<double>();
        k_tt += b[c]["kirsch_Pa"]["tt"].get<double>() - a[c]["kirsch_Pa"]["tt"].get<double>();
        ++n;
      }
    }
    if (f == 1) {
      ASSERT_TRUE(j.contains("network"));
      std::printf("network: %s\n", j["network"].dump().c_str());
    }
  }
  ASSERT_EQ(n, 8);
  for (double* v : {&m_rr[0], &m_rr[1], &m_tt[0], &m_tt[1]}) *v /= n;
  k_rr /= n, k_tt /= n;
  std::printf("r = 2a: radial increment sleeve %.3f, network %.3f MPa (Kirsch %.3f); hoop sleeve %.3f, network %.3f MPa "
              "(Kirsch %.3f)\n",
              1e-6 * m_rr[0], 1e-6 * m_rr[1], 1e-6 * k_rr, 1e-6 * m_tt[0], 1e-6 * m_tt[1], 1e-6 * k_tt);
  EXPECT_NEAR(m_rr[1], m_rr[0], 0.2 * std::abs(k_rr));
  EXPECT_NEAR(m_tt[1], m_tt[0], 0.2 * std::abs(k_tt));
}

// 2. The 2D block breaks from the hole: breakdown found, the first cracks within two grain
// diameters of the wall, the fracture connected to the hole; the breakdown pressure against the
// sleeve model's (no penetration) on the same block. The fluid in the network enters the first
// cracks and the pores next to the wall, so it needs less pressure (Haimson & Fairhurst 1967:
// penetration lowers breakdown); measured: see the printout (docs/hydrofrac.md).
TEST(HydrofracNetwork, TwoDimensionalBlockBreaksFromTheHole) {
  Scratch s;
  const fs::path file = s.write("block.toml", block("network"));
  const auto js = run_scenario(file, s / "sleeve", " --set injection.fluid=sleeve");
  const auto j = run_scenario(file, s / "network");
  ASSERT_FALSE(j["breakdown"]["pressure_Pa"].is_null()) << j["breakdown"].dump();
  ASSERT_FALSE(js["breakdown"]["pressure_Pa"].is_null()) << js["breakdown"].dump();
  const double pn = j["breakdown"]["pressure_Pa"].get<double>(), ps = js["breakdown"]["pressure_Pa"].get<double>();
  std::printf("2D breakdown: network %.2f MPa, sleeve %.2f MPa (%+.1f%%); initiation network %s, sleeve %s; network: %s\n",
              1e-6 * pn, 1e-6 * ps, 100 * (pn / ps - 1), j["breakdown"]["initiation_pressure_Pa"].dump().c_str(),
              js["breakdown"]["initiation_pressure_Pa"].dump().c_str(), j["network"].dump().c_str());
  EXPECT_GT(j["fracture"]["connected_cracks"].get<long>(), 5);
  // Same rock, same in-situ stresses: breakdown within a factor of two of the sleeve's, not above it by more than 10%.
  EXPECT_LT(pn, 1.1 * ps);
  EXPECT_GT(pn, 0.5 * ps);
  const auto d = ff::test::first_crack_distances(s / "network" / "cracks.csv", 12e-3, 12e-3, 3);
  ASSERT_EQ(d.size(), 3u);
  const double a = j["borehole"]["effective_radius_m"].get<double>();
  for (double x : d) EXPECT_LT(x, a + 4 * 0.6e-3) << "a first crack away from the hole";
  // network.remap = pressure: the retriangulations carry the pores' pressures (no jump of K x the
  // total void's change in every pore) and report the mass that adds. Measured 2026-11-28: the same
  // breakdown (23.18 MPa: it comes before the first retriangulation), 9 retriangulations against 11,
  // +1.5e-5 kg/m added against 9.1e-3 kg/m injected (0.16 %).
  const auto jp = run_scenario(file, s / "network_pressure_remap", " --set network.remap=pressure");
  ASSERT_FALSE(jp["breakdown"]["pressure_Pa"].is_null());
  EXPECT_NEAR(jp["breakdown"]["pressure_Pa"].get<double>(), pn, 0.02 * pn);
  const auto& bp = jp["network"]["mass_budget_kg"];
  const double added = bp["remap_change"].get<double>(), injected = bp["injected"].get<double>();
  std::printf("pressure remap: breakdown %.2f MPa, %ld retriangulations, remap added %.3g kg/m, injected %.3g kg/m\n",
              1e-6 * jp["breakdown"]["pressure_Pa"].get<double>(), jp["network"]["retriangulations"].get<long>(), added,
              injected);
  EXPECT_GT(jp["network"]["retriangulations"].get<long>(), 0);
  EXPECT_NE(added, 0.0);
  EXPECT_LT(std::abs(added), 0.05 * injected);
  EXPECT_LT(std::abs(j["network"]["mass_budget_kg"]["remap_change"].get<double>()), 1e-12) << "mass remap: no mass added";
}

// 2b. The void-gradient pressure force (network.pressure_forces, conservative) breaks the same block
// from the hole once the faces are drained (the hull and a band of one largest radius held at p0).
// With closed faces its first cracks were 11-15 mm from the axis, at the faces (measured 2026-11-28:
// the liquid-full pores flattened against the servo walls push far more through their void's
// gradient than through their arcs); drained: the first cracks at the wall, breakdown 23.18 MPa,
// 17 retriangulations (3,789 closed).
TEST(HydrofracNetwork, VoidGradientForceWithDrainedFacesBreaksFromTheHole) {
  Scratch s;
  const fs::path file = s.write("block.toml", block("network"));
  const auto j = run_scenario(file, s / "vg", " --set network.pressure_forces=void_gradient --set network.faces=drained");
  ASSERT_FALSE(j["breakdown"]["pressure_Pa"].is_null()) << j["breakdown"].dump();
  std::printf("void gradient, drained faces: breakdown %.2f MPa, %ld retriangulations\n",
              1e-6 * j["breakdown"]["pressure_Pa"].get<double>(), j["network"]["retriangulations"].get<long>());
  EXPECT_GT(j["breakdown"]["pressure_Pa"].get<double>(), 10e6);  // the sleeve's 33 MPa, the surface force's 21-26
  const auto d = ff::test::first_crack_distances(s / "vg" / "cracks.csv", 12e-3, 12e-3, 3);
  ASSERT_EQ(d.size(), 3u);
  const double a = j["borehole"]["effective_radius_m"].get<double>();
  for (double x : d) EXPECT_LT(x, a + 4 * 0.6e-3) << "a first crack away from the hole";
  EXPECT_LT(j["network"]["retriangulations"].get<long>(), 200);
  const double share = j["network"]["retriangulation_wall_share"].get<double>();  // timed and reported
  EXPECT_TRUE(share > 0 && share < 1) << share;
}

// 3. Mass budget (rate mode, the block closed): what was pumped (rho Q t) equals what the pores
// gained, through the fracturing and the retriangulations (porenet's remap conserves mass, the
// implicit step's fluxes are applied once to both pores). Tolerance 1e-9 of the injected mass
// (round-off over ~10^3 flow steps).
TEST(HydrofracNetwork, PumpedMassEqualsThePoresGain) {
  Scratch s;
  const fs::path file = s.write("block.toml", block("network"));
  const auto j = run_scenario(file, s / "rate",
                              " --set injection.mode=rate --set injection.rate=2e-3 --set injection.max_time=4e-4");
  const auto& b = j["network"]["mass_budget_kg"];
  const double inj = b["injected"].get<double>(), gain = b["pore_mass_end"].get<double>() - b["pore_mass_start"].get<double>();
  std::printf("rate mode: injected %.9g kg/m, pores gained %.9g kg/m (residual %.3g); %ld retriangulations; peak %.2f MPa\n",
              inj, gain, b["residual"].get<double>(), j["network"]["retriangulations"].get<long>(),
              1e-6 * j["injection"]["peak_pressure_Pa"].get<double>());
  EXPECT_NEAR(inj, 1000 * 2e-3 * (j["steps"].get<double>() * j["time_step_s"].get<double>() - j["injection"]["start_time_s"].get<double>()),
              0.01 * inj);
  EXPECT_NEAR(gain, inj, 1e-9 * inj);
  EXPECT_GT(j["injection"]["peak_pressure_Pa"].get<double>(), 1e6);
}

// 4. Resume and threads: a run stopped during the injection and resumed gives the same files as one
// run through; two threads (every loop parallel) give the same series and cracks.
TEST(HydrofracNetwork, ResumeAndTwoThreadsAreBitIdentical) {
  Scratch s;
  const fs::path file = s.write("block.toml", block("network"));
  const fs::path whole = s / "whole", parts = s / "parts", two = s / "two";
  const auto j = run_scenario(file, whole);
  ff::test::expect_resume_identical(file, whole, parts, 9000);
  const auto jp = ff::test::read_json(parts / "summary.json");
  EXPECT_EQ(j["breakdown"], jp["breakdown"]);
  EXPECT_EQ(j["network"]["mass_budget_kg"], jp["network"]["mass_budget_kg"]);
  const auto r = fracflow("run " + file.string() + " --out " + two.string() +
                          " -q -j2 --max-steps 12000 --set dem.parallel_min=200");
  ASSERT_EQ(r.code, 0) << r.output;
  const std::string s1 = ff::test::read_bytes(whole / "series.csv"), s2 = ff::test::read_bytes(two / "series.csv");
  const std::string c1 = ff::test::read_bytes(whole / "cracks.csv"), c2 = ff::test::read_bytes(two / "cracks.csv");
  ASSERT_GT(s2.size(), 1000u);
  ASSERT_GT(c2.size(), 100u) << "no crack by step 12000: the comparison would not cover the fracturing";
  EXPECT_EQ(s1.substr(0, s2.size()), s2);
  EXPECT_EQ(c1.substr(0, c2.size()), c2);
}
