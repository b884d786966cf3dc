// The triaxial validation's pieces that need no DEM run: the laboratory table against the
// reference data, the generated scenarios (they must validate), the slope fit, the bulge measure
// and the checks, on hand-made run results.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "batch/run_case.hpp"
#include "batch/triaxial_validation.hpp"

using namespace ff::batch;

namespace {

TriaxialRunResult run(double sigma3_MPa, double q_MPa, const char* lateral = "membrane") {
  TriaxialRunResult r;
  r.label = "C1";
  r.lateral = lateral;
  r.sigma3_Pa = 1e6 * sigma3_MPa;
  r.peak_differential_Pa = 1e6 * q_MPa;
  r.confinement_at_peak_Pa = r.sigma3_Pa;
  r.largest_sphere_deviation = 0.03;
  return r;
}

const ValidationCheck* find(const std::vector<ValidationCheck>& checks, const std::string& part) {
  for (auto& c : checks)
    if (c.what.find(part) != std::string::npos) return &c;
  return nullptr;
}

}  // namespace

// Seed 000 Table 3 (Zhao, Konietzky & Herbst 2021): the table compiled into the report equals the
// reference file tests/data/dem/zhao2021_table3_triaxial_lab.csv row by row.
TEST(TriaxialValidation, LabTableMatchesTheReferenceFile) {
  std::ifstream f(FRACFLOW_TEST_DATA "/dem/zhao2021_table3_triaxial_lab.csv");
  ASSERT_TRUE(f) << "reference file missing";
  std::string line;
  std::size_t row = 0;
  while (std::getline(f, line)) {
    if (line.empty() || line[0] == '#' || line.rfind("sample", 0) == 0) continue;
    std::stringstream ss(line);
    std::string name, s3, d, h, peak;
    std::getline(ss, name, ',');
    std::getline(ss, s3, ',');
    std::getline(ss, d, ',');
    std::getline(ss, h, ',');
    std::getline(ss, peak, ',');
    ASSERT_LT(row, lab_table3().size());
    EXPECT_EQ(name, lab_table3()[row].sample);
    EXPECT_DOUBLE_EQ(std::stod(s3), lab_table3()[row].sigma3_MPa);
    EXPECT_DOUBLE_EQ(std::stod(peak), lab_table3()[row].peak_differential_MPa);
    ++row;
  }
  EXPECT_EQ(row, lab_table3().size());
  EXPECT_NEAR(*lab_mean_peak_MPa(2.5), 27.43, 1e-9);
  EXPECT_NEAR(*lab_mean_peak_MPa(7.5), (44.45 + 42.24 + 46.83) / 3, 1e-9);
  EXPECT_FALSE(lab_mean_peak_MPa(10).has_value());
}

// An ordinary least-squares fit to the 7 Table 3 rows gives b = 3.4172 (reference file
// zhao2021_eq1_peak_vs_confinement.csv): the same fit of fit_differential, to 1e-4.
TEST(TriaxialValidation, DifferentialFitReproducesTheTable3Regression) {
  std::vector<TriaxialRunResult> rows;
  for (auto& t : lab_table3()) rows.push_back(run(t.sigma3_MPa, t.peak_differential_MPa));
  const auto f = fit_differential(rows);
  EXPECT_NEAR(f.slope, 3.4172, 1e-4);
  EXPECT_NEAR(1e-6 * f.intercept_Pa, 18.8594, 1e-4);
  EXPECT_NEAR(f.r_squared, 0.8223, 1e-4);
}

TEST(TriaxialValidation, GeneratedScenariosValidate) {
  ValidationSample s;
  for (const char* d : {"ucs", "triaxial"}) {
    const auto file = std::filesystem::temp_directory_path() / (std::string("ff_validation_") + d + ".toml");
    std::ofstream(file) << validation_scenario(s, d, "");
    EXPECT_NO_THROW(load_scenario_for_run(file.string(), {})) << d;
  }
  const std::string coal = validation_scenario(s, "triaxial", "../samples/c1/voxels");
  EXPECT_NE(coal.find("[dem.bond.matrix-inclusion]"), std::string::npos);
  EXPECT_NE(coal.find("origin = [-0.01225, -0.01225, 0.00025]"), std::string::npos);  // as make-sample writes it
  EXPECT_NE(coal.find("platen_velocity = 0.25"), std::string::npos);                    // 10/s on 50 mm
}

TEST(TriaxialValidation, BulgeProfileKeepsTheLoadedBand) {
  TriaxialRunResult r = run(5, 30);
  // Sleeve 1.2 x 50 mm = 60 mm from z = -5 to 55 mm, 7 rings; the outer rings stay at R0.
  const double R0 = 12.5e-3;
  r.ring_z_m = {-5e-3, 5e-3, 15e-3, 25e-3, 35e-3, 45e-3, 55e-3};
  r.ring_radius_m = {R0, 1.01 * R0, 1.02 * R0, 1.05 * R0, 1.02 * R0, 1.01 * R0, R0};
  const auto b = bulge_profile(r, R0);
  EXPECT_NEAR(b.max_expansion, 0.05, 1e-12);
  EXPECT_NEAR(b.min_expansion, 0.01, 1e-12);
  EXPECT_NEAR(b.z_of_max_fraction, 0.5, 1e-12);
}

TEST(TriaxialValidation, ChecksFollowTheIssueCriteria) {
  ValidationReport rep;
  rep.c1 = {run(2.5, 26), run(5, 36), run(7.5, 44)};
  rep.c4 = {run(2.5, 24), run(5, 33), run(7.5, 42)};
  rep.laterals = {run(2.5, 20, "particle_membrane")};
  auto checks = validation_checks(rep);
  ASSERT_NE(find(checks, "rises"), nullptr);
  EXPECT_TRUE(find(checks, "rises")->passed);
  EXPECT_TRUE(find(checks, "slope b")->passed);  // 3.6
  EXPECT_TRUE(find(checks, "particle membrane")->passed);
  EXPECT_TRUE(find(checks, "stronger than C4")->passed);
  EXPECT_TRUE(find(checks, "sigma3 = 2.5 MPa: peak vs")->passed);
  // A flat envelope fails the slope and the 7.5 MPa peak; a weaker flexible membrane fails Fig. 15.
  rep.c1 = {run(2.5, 26), run(5, 28), run(7.5, 30)};
  rep.laterals = {run(2.5, 27, "particle_membrane")};
  checks = validation_checks(rep);
  EXPECT_FALSE(find(checks, "slope b")->passed);
  EXPECT_FALSE(find(checks, "sigma3 = 7.5 MPa: peak vs")->passed);
  EXPECT_FALSE(find(checks, "particle membrane")->passed);
  EXPECT_FALSE(find(checks, "stronger than C4")->passed);  // 84 vs 99 MPa summed
}

// The runs with frictional boundary contacts are quoted beside the Fig. 15 check but do not
// decide it: the frictionless flexible and particle membranes do.
TEST(TriaxialValidation, FrictionRunsAreQuotedNotJudged) {
  ValidationReport rep;
  rep.c1 = {run(2.5, 26), run(5, 36), run(7.5, 44)};
  rep.laterals = {run(2.5, 26, "particle_membrane")};
  TriaxialRunResult fw = run(2.5, 29), pm = run(2.5, 26.5, "particle_membrane");
  fw.boundary_friction = pm.boundary_friction = -1;
  fw.largest_sphere_deviation = 0.36;
  rep.friction = {fw, pm};
  const auto* c = find(validation_checks(rep), "particle membrane");
  ASSERT_NE(c, nullptr);
  EXPECT_FALSE(c->passed);  // 26 vs 26 MPa without friction
  EXPECT_NE(c->measured.find("29.00 vs 26.50 MPa (+9.4%)"), std::string::npos) << c->measured;
  EXPECT_NE(c->measured.find("up to 36% off"), std::string::npos) << c->measured;
  EXPECT_EQ(lateral_label(fw), "membrane, friction of the particles");
  fw.boundary_friction = 0.3;
  EXPECT_EQ(lateral_label(fw), "membrane, friction 0.3");
  EXPECT_EQ(lateral_label(rep.laterals[0]), "particle_membrane");
}

// With several packings per pressure the checks use the means: peaks_by_pressure() averages per
// sigma3 (sample standard deviation), and C1 - C4 is the mean of the differences of runs with
// the same packing seed.
TEST(TriaxialValidation, ChecksAverageOverPackings) {
  auto packed = [](double s3, double q, unsigned seed, const char* label = "C1") {
    TriaxialRunResult r = run(s3, q);
    r.label = label;
    r.packing_seed = seed;
    return r;
  };
  ValidationReport rep;
  rep.sample.seed = 2;
  rep.c1 = {packed(2.5, 25, 2), packed(2.5, 27, 3), packed(5, 34, 2), packed(5, 36, 3)};
  rep.c4 = {packed(2.5, 26, 2, "C4"), packed(2.5, 25, 3, "C4"), packed(5, 33, 2, "C4"), packed(5, 34, 3, "C4")};
  const auto p = peaks_by_pressure(rep.c1);
  ASSERT_EQ(p.size(), 2u);
  EXPECT_DOUBLE_EQ(p[0].sigma3_Pa, 2.5e6);
  EXPECT_NEAR(p[0].mean_Pa, 26e6, 1e-6);
  EXPECT_NEAR(p[0].sd_Pa, std::sqrt(2.0) * 1e6, 1e-6);  // values 25, 27
  EXPECT_EQ(p[0].runs, 2);
  EXPECT_EQ(runs_of_packing(rep.c1, 3).size(), 2u);
  auto checks = validation_checks(rep);
  const auto* c = find(checks, "stronger than C4");
  ASSERT_NE(c, nullptr);
  // Paired differences -1, +2, +1, +2: mean +1.00 MPa, standard error sqrt(2)/2 = 0.71 MPa.
  EXPECT_NE(c->measured.find("+1.00 +- 0.71"), std::string::npos) << c->measured;
  EXPECT_TRUE(c->passed);
  EXPECT_NE(find(checks, "rises")->what.find("mean of 2 packings"), std::string::npos);
  // One weak C1 packing at 2.5 MPa turns the mean difference negative.
  rep.c1[1].peak_differential_Pa = 20e6;
  EXPECT_FALSE(find(validation_checks(rep), "stronger than C4")->passed);
}

// The isotropic-stage check uses the runs at seed resolution when there are any.
TEST(TriaxialValidation, IsotropicCheckPrefersTheSeedResolutionRuns) {
  ValidationReport rep;
  rep.c1 = {run(2.5, 26), run(5, 36)};
  rep.c1[0].largest_sphere_deviation = 0.08;  // a coarse sample's sphere of ~300 particles
  EXPECT_FALSE(find(validation_checks(rep), "measurement spheres")->passed);
  IsotropicStageResult fine;
  fine.sigma3_Pa = 2.5e6;
  fine.largest_deviation = 0.024;
  fine.particles = 28000;
  fine.spheres = {{2.5e6, 2.5e6, 0.37, 2000}, {2.5e6, 2.5e6, 0.37, 2040}, {2.5e6, 2.5e6, 0.37, 1990}};
  rep.isotropic_fine = {fine};
  const auto* c = find(validation_checks(rep), "measurement spheres");
  ASSERT_NE(c, nullptr);
  EXPECT_TRUE(c->passed);
  EXPECT_NE(c->measured.find(">= 1990 particles"), std::string::npos) << c->measured;
  rep.isotropic_fine[0].largest_deviation = 0.06;
  EXPECT_FALSE(find(validation_checks(rep), "measurement spheres")->passed);
}
