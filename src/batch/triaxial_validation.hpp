// The triaxial validation of seed 000 (Zhao, Konietzky & Herbst 2021) as one reproducible job:
// the scenarios it runs, the laboratory numbers it compares with, the checks it applies and the
// report it writes (docs/validation/triaxial.md). `fracflow validate-triaxial` runs it.
#pragma once
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace ff::batch {

// Seed 000 Table 3: laboratory triaxial tests on coal (peak differential stress sigma1 - sigma3).
// The same rows are in tests/data/dem/zhao2021_table3_triaxial_lab.csv (a test checks they agree).
struct LabTriaxialTest {
  const char* sample;
  double sigma3_MPa, peak_differential_MPa;
};
const std::vector<LabTriaxialTest>& lab_table3();
// Mean laboratory peak differential stress at a confining pressure [MPa]; nullopt when Table 3
// has no test at that pressure (within 1 kPa).
std::optional<double> lab_mean_peak_MPa(double sigma3_MPa);
// Seed 000 Eq. 1 as printed: peak differential stress = 18.3432 + 3.5415 sigma3 [MPa].
inline constexpr double kLabSlope = 3.5415, kLabIntercept_MPa = 18.3432;
// Seed 000 Table 5 averages (coal matrix, UCS tests): the calibration targets.
inline constexpr double kMatrixE_Pa = 2.37e9, kMatrixNu = 0.35, kMatrixUcs_Pa = 14.97e6;

// Geometry and loading of the validation samples.
struct ValidationSample {
  double diameter_m = 25e-3, height_m = 50e-3;          // Table 3's samples: ~25 x 50 mm
  double radius_min_m = 0.75e-3, radius_max_m = 1.125e-3;
  double strain_rate = 10;                               // [1/s]: platens each move at rate * H / 2
  double voxel_size_m = 0.5e-3;
  unsigned seed = 2;                                     // synthetic-sample seed and first packing seed
  // Packings per sample and pressure (seeds seed, seed + 1, ...): the peak of one ~4,000-sphere
  // packing scatters by ~1 MPa, as much as the C1-C4 difference the report looks for.
  int packings = 3;
  // Particles of the isotropic-stage check at seed 000's resolution (r_p = 0.5 mm, ~35,000
  // spheres): a measurement sphere then holds ~2,000 particles instead of ~300.
  double fine_radius_min_m = 0.4e-3, fine_radius_max_m = 0.6e-3;
};

// Scenario text of the validation runs, seed 000 Table 7 micro-parameters (the matrix values are
// the starting point; the calibrated ones are passed as overrides). `voxels` empty: a matrix-only
// sample; else the folder of a segmented voxel stack (relative to the scenario file), made by
// `fracflow make-sample` for the same geometry and voxel size.
std::string validation_scenario(const ValidationSample& s, const std::string& driver, const std::string& voxels);

// The numbers of one finished run that the report needs.
struct TriaxialRunResult {
  std::string label;               // e.g. "C1", "C4"
  std::string lateral;             // membrane, rigid_cylinder, particle_membrane
  double boundary_friction = 0;    // membrane.friction of the run (-1: each particle's own contact friction)
  double sigma3_Pa = 0;
  unsigned packing_seed = 0;       // sample.seed of the run
  double peak_differential_Pa = 0, strain_at_peak = 0, confinement_at_peak_Pa = 0;
  double youngs_modulus_Pa = 0, poisson_ratio = 0;
  double cracks_total = 0, cracks_tensile = 0, cracks_shear = 0;
  double largest_sphere_deviation = 0;  // isotropic stage: measurement spheres vs boundary
  int particles = 0;
  double wall_time_s = 0;
  std::vector<double> ring_radius_m, ring_z_m;  // final membrane profile (flexible membrane)
  std::filesystem::path dir;
};
// The lateral boundary of a run as the report names it, with its friction when it has one.
std::string lateral_label(const TriaxialRunResult& r);
// Reads a triaxial run's summary.json; throws ff::Error when something needed is missing.
TriaxialRunResult read_triaxial_result(const std::filesystem::path& run_dir, const std::string& label);

// The isotropic stage of a triaxial run: boundary stresses and the three measurement spheres.
struct IsotropicStageResult {
  double sigma3_Pa = 0, platen_Pa = 0, confinement_Pa = 0, largest_deviation = 0;
  struct Sphere {
    double axial_Pa = 0, lateral_Pa = 0, porosity = 0;
    int particles = 0;
  };
  std::vector<Sphere> spheres;
  int particles = 0;
  double wall_time_s = 0;
  std::filesystem::path dir;
};
// Reads the isotropic stage out of a triaxial run's summary.json; throws ff::Error when
// something needed is missing.
IsotropicStageResult read_isotropic_stage(const std::filesystem::path& run_dir);

// How uneven the final bulge is: radial expansion of each membrane ring between the platens
// relative to the sample radius R0 (rings outside [z_bottom, z_top] are left out).
struct BulgeProfile {
  double max_expansion = 0, min_expansion = 0, mean_expansion = 0;  // (r - R0) / R0
  double z_of_max_fraction = 0;  // height of the largest expansion as a fraction of the band
};
BulgeProfile bulge_profile(const TriaxialRunResult& r, double sample_radius_m);

// Peak differential stress over the packings at each confining pressure, in rising sigma3.
struct PeakStats {
  double sigma3_Pa = 0, mean_Pa = 0, sd_Pa = 0;  // sd: sample standard deviation (0 for one run)
  int runs = 0;
};
std::vector<PeakStats> peaks_by_pressure(const std::vector<TriaxialRunResult>& runs);
// The frictional-boundary runs (ValidationReport::friction) summed up: mean peaks of the flexible
// and the particle membrane and the largest isotropic-stage sphere deviation; nullopt unless both
// boundaries were run at one pressure.
struct FrictionComparison {
  PeakStats flexible, particle;
  double largest_sphere_deviation = 0;
};
std::optional<FrictionComparison> compare_friction_runs(const std::vector<TriaxialRunResult>& runs);
// The runs of one packing seed, in their order.
std::vector<const TriaxialRunResult*> runs_of_packing(const std::vector<TriaxialRunResult>& runs, unsigned seed);

// Least-squares line of the peak differential stress on sigma3 (seed 000 Eq. 1's form), through
// every run (with as many packings at each pressure, the slope of the line through the means).
struct DifferentialFit {
  double intercept_Pa = 0, slope = 0, r_squared = 0;
};
DifferentialFit fit_differential(const std::vector<TriaxialRunResult>& runs);

// The calibration's final figures out of `fracflow calibrate`'s calibration.json.
struct CalibrationNumbers {
  bool present = false, converged = false;
  double E = 0, nu = 0, ucs = 0, b = 0;
  int runs = 0;
};
CalibrationNumbers calibration_numbers(const nlohmann::json& calibration);
// A stress in MPa with two decimals, as the report prints it.
std::string mpa(double pa);

struct ValidationCheck {
  std::string what, measured, required;
  bool passed = false;
};

// Everything the report says.
struct ValidationReport {
  ValidationSample sample;
  nlohmann::json calibration;                 // calibration.json of `fracflow calibrate`
  std::vector<TriaxialRunResult> c1, c4;      // flexible membrane, one per confining pressure
  std::vector<TriaxialRunResult> laterals;    // C1 at the first pressure with other boundaries
  // C1 at the first pressure, flexible and particle membrane, with frictional boundary contacts
  // (membrane.friction = -1): what seed 000's Fig. 15 difference takes in this model.
  std::vector<TriaxialRunResult> friction;
  std::vector<IsotropicStageResult> isotropic_fine;  // C1 isotropic stages at seed resolution
  std::string inclusions = "scaled";        // rule for inclusion/interface parameters (see the command)
  std::vector<std::string> inclusion_sets;    // the overrides it gave
  std::string command, date, machine;
  double wall_time_s = 0;
};

// The checks of issue 4 / seed 000 Sec. 6, in report order.
std::vector<ValidationCheck> validation_checks(const ValidationReport& r);

// Writes the markdown report to `doc` (triaxial_validation_report.cpp), with its figures (PNG + the CSV they are drawn from) in
// `doc`'s folder / images. Plotting problems only warn (src/io/plot.hpp).
void write_validation_report(const ValidationReport& r, const std::filesystem::path& doc);

}  // namespace ff::batch
