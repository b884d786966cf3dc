// The Brazilian and direct-tension drivers, through the fracflow program as a user runs them:
// the stress at the centre of an elastic disc against the closed form, the tensile strength's
// repeatability over packings, and the driver plumbing (check, outputs, resume bit for bit).
// 2D samples of 300-700 disks keep the whole binary at about 15 s on one core. The loading
// speeds are quasi-static: halving them changes the strengths by 1-3% and the centre stresses
// by less than their scatter.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "io/csv.hpp"
#include "../program_runner.hpp"

namespace fs = std::filesystem;

namespace {

constexpr double kPi = 3.14159265358979323846;

// Coal-matrix micro-parameters of examples/ucs_2d.toml with equal bond tensile and shear
// strengths; 2D disks of unit thickness. The samples take a bond gap of 0.2 mm (~4.9 bonds per
// disk against 3.6 with the default 0.05 mm): a network well above rigidity behaves like the
// continuum of the closed form and splits from the centre more often (see the tests below).
const std::string kMaterial = R"(
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
)";

const std::string kBrazilian = "driver = \"brazilian\"\n" + kMaterial + R"(
[sample]
shape = "disc"
diameter = 20e-3
radius_min = 0.4e-3
radius_max = 0.6e-3
porosity = 0.2
bond_gap = 0.2e-3
seed = 1
[brazilian]
platen_velocity = 0.2
[output]
vtk = false
plots = false
progress_interval = 0
)";

const std::string kTension = "driver = \"direct_tension\"\n" + kMaterial + R"(
[sample]
shape = "box"
width = 14e-3
height = 28e-3
radius_min = 0.4e-3
radius_max = 0.6e-3
porosity = 0.2
bond_gap = 0.2e-3
seed = 1
[direct_tension]
grip_velocity = 0.1
[output]
vtk = false
plots = false
progress_interval = 0
)";

struct Scratch : ff::test::TestScratch {
  Scratch() : TestScratch("brazilian") {}
  fs::path write(const std::string& name, const std::string& text) const {
    const fs::path p = path / name;
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }
};

ff::test::ProgramResult fracflow(const std::string& args) { return ff::test::run_program(args); }

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Runs a scenario into `out` and returns its summary.json.
nlohmann::json run_scenario(const fs::path& file, const fs::path& out, const std::string& sets = "") {
  const auto r = fracflow("run " + file.string() + " --out " + out.string() + " -q -j1" + sets);
  EXPECT_EQ(r.code, 0) << r.output;
  return ff::test::read_json(out / "summary.json");
}

double mean(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size()); }
double coefficient_of_variation(const std::vector<double>& v) {
  const double m = mean(v);
  double s = 0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / static_cast<double>(v.size() - 1)) / m;
}

}  // namespace

// An elastic disc under diametral point loads P (thickness t, diameter D) has, at its centre,
// sigma_xx = +2P/(pi D t) across the loaded diameter and sigma_yy = -6P/(pi D t) along it
// (Timoshenko & Goodier 1970, Theory of Elasticity, s. 41; Hondros 1959). Averaged over a
// central circle of radius rho R, the same field gives (1 - rho^2) and -(3 - rho^2) times
// 2P/(pi D t) (integrated numerically, 1e6 points, to 1e-7). In 2D the field does not depend on
// the elastic constants (Michell), so a granular disc must reproduce it on average.
// Set-up: bonds that cannot break, a disc 30 particles across, rho = 0.4 (~120 disks in the
// circle), rows after the first 0.2% of diametral strain (seating on the platens), the mean
// over 4 packings. Tolerance 15% on that mean: one packing scatters by ~10% (force chains);
// the flat platens spread P over an arc 2 alpha ~ 0.1 rad, which lowers the centre values by
// ~1% (Hondros); the mean of 4 packings came within 6% (across) and 2% (along). The bond gap is
// 0.2 mm (4.9 bonds per disk): with the default 0.05 mm (3.6 bonds per disk, a network barely
// above rigidity) the across stress reads ~24% low at this size, and ~10% low at twice the
// diameter. A factor 2 in either formula, or the two components swapped, is off by 50% or more.
TEST(Brazilian, ElasticDiscCentreStressMatchesTheClosedForm) {
  Scratch s;
  const double rho = 0.4, D = 30e-3, t = 1.0;
  const fs::path file = s.write("elastic.toml", kBrazilian);
  std::vector<double> across_mean, along_mean;
  for (int seed = 1; seed <= 4; ++seed) {
    const fs::path out = s / fmt::format("elastic{}", seed);
    // Bonds that cannot break; stop at the strain cap, long before anything would.
    run_scenario(file, out,
                 fmt::format(" --set sample.diameter=30e-3 --set brazilian.platen_velocity=0.2"
                             " --set brazilian.max_strain=0.006 --set brazilian.centre_gauge_radius={} --set sample.seed={}"
                             " --set dem.bond.matrix-matrix.tensile_strength=1e15 --set dem.bond.matrix-matrix.cohesion=1e15",
                             rho, seed));
    const ff::CsvTable csv = ff::read_csv(out / "series.csv");
    const auto strain = csv.column("diametral_strain"), load = csv.column("load_N");
    const auto nominal = csv.column("tensile_stress_Pa"), across = csv.column("centre_stress_across_Pa"),
               along = csv.column("centre_stress_along_Pa"), cracks = csv.column("cracks_total");
    std::vector<double> ra, rl;
    for (std::size_t k = 0; k < strain.size(); ++k) {
      EXPECT_EQ(cracks[k], 0);
      // ISRM (1978): the nominal tensile stress is 2 P / (pi D t) of the platen load.
      EXPECT_NEAR(nominal[k], 2 * load[k] / (kPi * D * t), 1e-12 * std::abs(nominal[k]));
      if (strain[k] < 0.002) continue;
      ASSERT_GT(load[k], 0);
      ra.push_back(across[k] / nominal[k]);
      rl.push_back(along[k] / nominal[k]);
    }
    ASSERT_GE(ra.size(), 10u);
    across_mean.push_back(mean(ra));
    along_mean.push_back(mean(rl));
    std::printf("seed %d: centre stress / (2P/(pi D t)): across %.3f, along %.3f\n", seed, ra.empty() ? 0 : mean(ra),
                rl.empty() ? 0 : mean(rl));
  }
  const double expect_across = 1 - rho * rho, expect_along = -(3 - rho * rho);
  std::printf("mean of 4 packings: across %.3f (closed form %.3f), along %.3f (closed form %.3f)\n", mean(across_mean),
              expect_across, mean(along_mean), expect_along);
  EXPECT_NEAR(mean(across_mean), expect_across, 0.15 * expect_across);
  EXPECT_NEAR(mean(along_mean), expect_along, 0.15 * std::abs(expect_along));
}

// The tensile strength from five packings (seeds) of the same disc (~300 disks) and bar (~400
// disks). Bound on the coefficient of variation: 20% for both (measured over 6 packings: 11%
// for the disc, 8% for the bar; with the default bond gap of 0.05 mm, 12-26% and 12-18%: the
// sparser network fails more often at a platen, or at its weakest section, and scatters more).
// The ratio of the Brazilian to the direct tensile strength (BTS/DTS) is reported. Laboratory
// data: BTS/DTS ~ 1.1-1.4 (DTS = f BTS, f ~ 0.7 sedimentary, 0.8 igneous, 0.9 metamorphic:
// Perras & Diederichs 2014, Geotech. Geol. Eng. 32:525); Griffith's criterion gives exactly 1
// (the centre's state, compression 3x the tension, fails at the uniaxial tensile strength).
// This bonded-disk model gives ~0.5-0.65: the compression along the loaded diameter wedges the
// bonded network open at the particle scale, and flat platens start cracks at their contacts.
// The ratio is a calibration property of the micro-parameters, not a constant, so the check
// (0.4-2) only catches a gross error (a lost factor 2, the wrong area or thickness).
TEST(Brazilian, TensileStrengthIsRepeatableOverPackings) {
  Scratch s;
  const fs::path braz = s.write("braz.toml", kBrazilian), tens = s.write("tension.toml", kTension);
  std::vector<double> bts, dts;
  for (int seed = 1; seed <= 5; ++seed) {
    const std::string set = fmt::format(" --set sample.seed={}", seed);
    const auto jb = run_scenario(braz, s / fmt::format("b{}", seed), set);
    const auto jt = run_scenario(tens, s / fmt::format("t{}", seed), set);
    ASSERT_TRUE(jb["tensile_strength_Pa"].is_number()) << jb.dump(1);
    ASSERT_TRUE(jt["tensile_strength_Pa"].is_number()) << jt.dump(1);
    bts.push_back(jb["tensile_strength_Pa"].get<double>());
    dts.push_back(jt["tensile_strength_Pa"].get<double>());
    // The strength is the peak of the curve: 2P/(pi D t) of the peak load, and force / area.
    EXPECT_NEAR(bts.back(), 2 * jb["peak_load_N"].get<double>() / (kPi * 20e-3 * 1.0), 1e-9 * bts.back());
    EXPECT_NEAR(dts.back(), jt["peak_load_N"].get<double>() / (14e-3 * 1.0), 1e-9 * dts.back());
    // The peak among rows near equilibrium (drivers/curve_peak.hpp): at most the strength, and for
    // these dry quasi-static tests within 10 % of it.
    for (const auto* j : {&jb, &jt}) {
      const auto& q = (*j)["peak"]["quasi_static"];
      ASSERT_TRUE(q.is_object()) << j->dump(1);
      EXPECT_LE(q["stress_Pa"].get<double>(), (*j)["tensile_strength_Pa"].get<double>());
      EXPECT_GT(q["stress_Pa"].get<double>(), 0.9 * (*j)["tensile_strength_Pa"].get<double>());
    }
    EXPECT_GT(jb["peak"]["quasi_static"]["diametral_strain"].get<double>(), 0);
    EXPECT_GT(jt["peak"]["quasi_static"]["axial_strain"].get<double>(), 0);
  }
  const double cb = coefficient_of_variation(bts), ct = coefficient_of_variation(dts);
  std::printf("Brazilian: mean %.3f MPa, CoV %.1f%%; direct tension: mean %.3f MPa, CoV %.1f%%; BTS/DTS %.2f\n",
              1e-6 * mean(bts), 100 * cb, 1e-6 * mean(dts), 100 * ct, mean(bts) / mean(dts));
  EXPECT_LT(cb, 0.20);
  EXPECT_LT(ct, 0.20);
  EXPECT_GT(mean(bts) / mean(dts), 0.4);
  EXPECT_LT(mean(bts) / mean(dts), 2.0);
}

// `check` refuses bad keys of both drivers, naming the key, with exit code 2.
TEST(Brazilian, CheckRefusesBadKeysNamingThem) {
  Scratch s;
  const fs::path braz = s.write("braz.toml", kBrazilian), tens = s.write("tension.toml", kTension);
  struct Case {
    fs::path file;
    std::string set, key;
  };
  const std::vector<Case> cases = {
      {braz, "brazilian.platen_velocity=-1", "brazilian.platen_velocity"},
      {braz, "brazilian.stop_fraction=1.5", "brazilian.stop_fraction"},
      {braz, "brazilian.centre_gauge_radius=0", "brazilian.centre_gauge_radius"},
      {braz, "sample.shape=box", "sample.shape"},  // a Brazilian sample is a disc or a cylinder
      {tens, "direct_tension.grip_velocity=0", "direct_tension.grip_velocity"},
      {tens, "direct_tension.grip_thickness=40", "direct_tension.grip_thickness"},  // no free length left
      {tens, "sample.shape=disc", "sample.shape"},
  };
  for (const Case& c : cases) {
    const auto r = fracflow("check " + c.file.string() + " --set " + c.set);
    EXPECT_EQ(r.code, 2) << c.set << "\n" << r.output;
    EXPECT_NE(r.output.find(c.key), std::string::npos) << c.set << "\n" << r.output;
  }
  EXPECT_EQ(fracflow("check " + braz.string()).code, 0);
  EXPECT_EQ(fracflow("check " + tens.string()).code, 0);
}

// A run writes its outputs; a run stopped by --max-steps and resumed gives the same files, bit
// for bit, as one run through (the grips, gauges and peak bookkeeping survive the checkpoint).
TEST(Brazilian, ResumeAfterMaxStepsIsBitIdentical) {
  Scratch s;
  for (const auto& [name, text, columns] :
       {std::tuple{"brazilian", kBrazilian, std::vector<std::string>{"load_N", "platen_displacement_m", "tensile_stress_Pa", "diametral_strain", "cracks_total"}},
        std::tuple{"direct_tension", kTension, std::vector<std::string>{"load_N", "grip_displacement_m", "tensile_stress_Pa", "axial_strain", "lateral_strain", "cracks_total"}}}) {
    const fs::path file = s.write(std::string(name) + ".toml", text);
    const fs::path whole = s / (std::string(name) + "_whole"), parts = s / (std::string(name) + "_parts");
    const auto j = run_scenario(file, whole);
    for (const char* f : {"series.csv", "summary.json", "cracks.csv", "scenario.toml"})
      EXPECT_TRUE(fs::exists(whole / f)) << name << ": " << f;
    const ff::CsvTable csv = ff::read_csv(whole / "series.csv");
    for (const auto& c : columns) EXPECT_FALSE(csv.column(c).empty()) << name << ": " << c;
    EXPECT_TRUE(j["tensile_strength_Pa"].is_number()) << j.dump(1);
    EXPECT_EQ(j["driver"], name);
    auto r = fracflow("run " + file.string() + " --out " + parts.string() + " -q -j1 --max-steps 3000");
    ASSERT_EQ(r.code, 0) << r.output;
    ASSERT_FALSE(fs::exists(parts / "summary.json")) << name;
    r = fracflow("resume " + parts.string() + " -q -j1");
    ASSERT_EQ(r.code, 0) << r.output;
    EXPECT_EQ(slurp(whole / "series.csv"), slurp(parts / "series.csv")) << name;
    EXPECT_EQ(slurp(whole / "cracks.csv"), slurp(parts / "cracks.csv")) << name;
    const auto jp = ff::test::read_json(parts / "summary.json");
    EXPECT_EQ(j["tensile_strength_Pa"], jp["tensile_strength_Pa"]) << name;
    EXPECT_EQ(j["peak_load_N"], jp["peak_load_N"]) << name;
    EXPECT_EQ(j["cracks_up_to_peak"], jp["cracks_up_to_peak"]) << name;
    EXPECT_EQ(j["peak"]["quasi_static"], jp["peak"]["quasi_static"]) << name;
    EXPECT_EQ(j["steps"], jp["steps"]) << name;
  }
}

// No peak before the strain cap: the strength is null with the reason, never a number.
TEST(Brazilian, NoPeakGivesNullStrengthWithTheReason) {
  Scratch s;
  const fs::path file = s.write("braz.toml", kBrazilian);
  const auto j = run_scenario(file, s / "cap", " --set brazilian.max_strain=0.004");
  EXPECT_TRUE(j["tensile_strength_Pa"].is_null()) << j.dump(1);
  EXPECT_TRUE(j["peak_load_N"].is_null()) << j.dump(1);
  EXPECT_EQ(j["peak"]["reached"], false);
  EXPECT_NE(j["peak"]["reason"].get<std::string>().find("brazilian.max_strain"), std::string::npos) << j.dump(1);
}
