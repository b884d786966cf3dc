// What a finished run reports, through the fracflow program on tiny samples (a few seconds in
// all): null with a reason instead of an untrustworthy number, typed parameters in every
// driver's summary.json, units in the CSV column names, the notice of a very long run, and the
// default scenario as the README describes it.
#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>

#include "../program_runner.hpp"
#include "batch/run_case.hpp"
#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "dem/presets.hpp"
namespace fs = std::filesystem;

namespace {

// ~150 spheres (as the sweep tests): about a second per run on one thread.
const std::string kTiny =
    " --set sample.diameter=5e-3 --set sample.height=8e-3 --set sample.porosity=0.45 --set output.vtk=false"
    " --set output.plots=false --set output.progress_interval=0 --threads 1";

fs::path scratch(const std::string& name) { return ff::test::fresh_out_dir("test_results", name); }

// The resumed run's series.csv equals the whole run's, byte for byte (and is not empty).
void expect_same_series(const fs::path& whole, const fs::path& resumed) {
  std::ifstream a(whole / "series.csv"), b(resumed / "series.csv");
  std::stringstream sa, sb;
  sa << a.rdbuf();
  sb << b.rdbuf();
  EXPECT_GT(sa.str().size(), 100u);
  EXPECT_EQ(sa.str(), sb.str());
}

using Result = ff::test::ProgramResult;
Result run_cli(const std::string& args) { return ff::test::run_program(args); }

using ff::test::read_json;

std::string first_line(const fs::path& p) {
  std::ifstream f(p);
  std::string line;
  std::getline(f, line);
  return line;
}

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// Warning lines other than those that say a value is null (expected where a test stops a run early).
std::string other_warnings(const std::string& output) {
  std::istringstream in(output);
  std::string line, out;
  while (std::getline(in, line))
    if (line.rfind("warning:", 0) == 0 && !has(line, "(null in summary.json)")) out += line + "\n";
  return out;
}

}  // namespace

// Stopped at ucs.max_strain = 0.1% (3 rows, stress still rising): no row lies in the 20-50%
// window of a peak that was never reached. E, nu and the UCS are null with their reasons, and
// the screen says so; never 0.
TEST(RunResults, UcsWithoutFitWindowOrPeakReportsNullWithReason) {
  const auto out = scratch("nofit");
  const auto r = run_cli("run --out " + out.string() + kTiny + " --set ucs.max_strain=1e-3");
  ASSERT_EQ(r.code, 0) << r.output;
  const auto j = read_json(out / "summary.json");
  EXPECT_TRUE(j["youngs_modulus_Pa"].is_null()) << j.dump(2);
  EXPECT_TRUE(j["poisson_ratio"].is_null());
  EXPECT_LT(j["elastic_fit"]["points"].get<int>(), 2);
  EXPECT_TRUE(j["elastic_fit"]["reason"].is_string()) << j.dump(2);
  EXPECT_TRUE(j["ucs_Pa"].is_null());
  EXPECT_TRUE(j["strain_at_peak"].is_null());
  EXPECT_FALSE(j["peak"]["reached"].get<bool>());
  EXPECT_TRUE(has(j["peak"]["reason"].get<std::string>(), "ucs.max_strain")) << j.dump(2);
  EXPECT_TRUE(j["peak"]["quasi_static"].is_null()) << j.dump(2);
  EXPECT_TRUE(has(r.output, "warning: no Young's modulus")) << r.output;
  EXPECT_TRUE(has(r.output, "warning: no UCS")) << r.output;
  EXPECT_TRUE(has(r.output, "no UCS, no E or nu")) << r.output;
  fs::remove_all(out);
}

// The same in the triaxial driver (rigid cylinder, ~150 spheres, under a second): stopped at
// triaxial.max_strain = 0.03% of the deviatoric stage, the peak and E, nu are null with reasons.
TEST(RunResults, TriaxialWithoutPeakReportsNullWithReasonAndUnitColumns) {
  const auto out = scratch("triaxial");
  const fs::path scenario = fs::temp_directory_path() / "fracflow_test_results_triaxial.toml";
  std::ofstream(scenario) << "driver = \"triaxial\"\n[dem]\ndim = 3\n" << ff::dem::kCoalMatrixTable7Toml << R"(
[sample]
shape = "cylinder"
diameter = 5e-3
height = 8e-3
radius_min = 0.4e-3
radius_max = 0.6e-3
porosity = 0.45
bond_gap = 0.05e-3
[triaxial]
confining_pressure = 1e6
lateral = "rigid_cylinder"
max_strain = 3e-4
[output]
vtk = false
plots = false
progress_interval = 0
)";
  const auto r = run_cli("run " + scenario.string() + " --out " + out.string() + " --threads 1");
  ASSERT_EQ(r.code, 0) << r.output;
  const auto j = read_json(out / "summary.json");
  for (const char* key : {"peak_differential_stress_Pa", "peak_axial_stress_Pa", "confinement_at_peak_Pa", "strain_at_peak",
                          "youngs_modulus_Pa", "poisson_ratio"})
    EXPECT_TRUE(j[key].is_null()) << key << ": " << j.dump(2);
  EXPECT_TRUE(has(j["peak"]["reason"].get<std::string>(), "triaxial.max_strain")) << j.dump(2);
  EXPECT_TRUE(j["peak"]["quasi_static"].is_null()) << j.dump(2);  // no peak: not even a quasi-static one
  EXPECT_TRUE(j["elastic_fit"]["reason"].is_string()) << j.dump(2);
  EXPECT_TRUE(has(r.output, "warning: no peak differential stress")) << r.output;
  EXPECT_TRUE(j["parameters"]["triaxial.confining_pressure"].is_number_float());
  EXPECT_TRUE(j["parameters"]["triaxial.isotropic_max_steps"].is_number_integer());
  EXPECT_EQ(first_line(out / "isotropic.csv"), "step,time_s,axial_stress_Pa,confinement_Pa,unbalanced_force_ratio");
  EXPECT_EQ(first_line(out / "series.csv").rfind("step,time_s,axial_strain,axial_stress_Pa,differential_stress_Pa,"
                                                 "confinement_Pa,",
                                                 0),
            0u);
  fs::remove_all(out);
  fs::remove(scenario);
}

// A full tiny run: numbers where they exist, parameters with their types, units in the columns.
TEST(RunResults, UcsSummaryIsTypedAndColumnsCarryUnits) {
  const auto out = scratch("ucs");
  const auto r = run_cli("run --out " + out.string() + kTiny + " --set ucs.max_strain=0.03");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(other_warnings(r.output) + "", "") << r.output;
  const auto j = read_json(out / "summary.json");
  EXPECT_GT(j["ucs_Pa"].get<double>(), 0) << j.dump(2);
  EXPECT_GT(j["youngs_modulus_Pa"].get<double>(), 0);
  EXPECT_TRUE(j["peak"]["reached"].get<bool>());
  // The peak among rows near equilibrium (drivers/curve_peak.hpp): at most the largest stress, and
  // a dry sample's peak is quasi-static (within 5 % of it).
  const auto& q = j["peak"]["quasi_static"];
  ASSERT_TRUE(q.is_object()) << j.dump(2);
  EXPECT_LE(q["stress_Pa"].get<double>(), j["ucs_Pa"].get<double>());
  EXPECT_GT(q["stress_Pa"].get<double>(), 0.95 * j["ucs_Pa"].get<double>());
  EXPECT_GT(q["axial_strain"].get<double>(), 0);
  const auto& p = j["parameters"];
  EXPECT_TRUE(p["sample.porosity"].is_number_float());
  EXPECT_TRUE(p["ucs.series_interval"].is_number_integer());
  EXPECT_TRUE(p["output.vtk"].is_boolean());
  EXPECT_TRUE(p["driver"].is_string());
  EXPECT_EQ(first_line(out / "series.csv"),
            "step,time_s,axial_strain,axial_stress_Pa,lateral_strain,volumetric_strain,cracks_tensile,cracks_shear,"
            "cracks_total,intact_bonds,kinetic_energy_J,unbalanced_force_ratio,"
            // energy bookkeeping (issue 13 item 6)
            "energy_kinetic_J,strain_energy_J,boundary_work_J,damping_dissipation_J,friction_dissipation_J,"
            "dashpot_dissipation_J,bond_break_energy_J,energy_balance_error");
  EXPECT_EQ(first_line(out / "cracks.csv"), "time_s,x_m,y_m,z_m,nx,ny,nz,size_m,mode,group_a,group_b,id_a,id_b");
  fs::remove_all(out);
}

// The flow drivers wrote every parameter as a string; now as the DEM drivers do.
TEST(RunResults, FlowSummaryParametersKeepTheirTypes) {
  const auto out = scratch("flow");
  const auto r = run_cli("run " + std::string(FRACFLOW_SOURCE_DIR) + "/examples/poiseuille.toml --out " + out.string() +
                         " --set run.end_time=0.02 --set output.vtk=false --set output.plots=false --quiet --threads 1");
  ASSERT_EQ(r.code, 0) << r.output;
  const auto j = read_json(out / "summary.json");
  const auto& p = j["parameters"];
  EXPECT_TRUE(p["lbm.resolution"].is_number_integer()) << p.dump(2);
  EXPECT_TRUE(p["fluid.density"].is_number_float());
  EXPECT_TRUE(p["run.end_time"].is_number_float());
  EXPECT_TRUE(p["output.vtk"].is_boolean());
  EXPECT_TRUE(p["lbm.lattice"].is_string());
  EXPECT_EQ(first_line(out / "series.csv"),
            "step,time_s,u_max_m_per_s,u_max_analytic_m_per_s,flow_rate_m2_per_s,wall_shear_stress_Pa");
  EXPECT_EQ(first_line(out / "profile.csv"), "y_m,u_lbm_m_per_s,u_analytic_m_per_s");
  fs::remove_all(out);
}

// A cylinder run too short to shed vortices has no Strouhal number: null with the reason, not 0.
TEST(RunResults, CylinderWithoutSheddingHasNullStrouhalWithReason) {
  const auto out = scratch("cylinder");
  const auto r = run_cli("run " + std::string(FRACFLOW_SOURCE_DIR) + "/examples/cylinder_channel.toml --out " +
                         out.string() +
                         " --set run.end_time=1 --set lbm.resolution=6 --set output.vtk=false --set output.plots=false "
                         "--quiet --threads 1");
  ASSERT_EQ(r.code, 0) << r.output;
  const auto j = read_json(out / "summary.json");
  const auto& res = j["results"];
  EXPECT_FALSE(res["shedding"].get<bool>());
  EXPECT_TRUE(res["strouhal"].is_null()) << res.dump(2);
  EXPECT_TRUE(has(res["strouhal_reason"].get<std::string>(), "no vortex shedding")) << res.dump(2);
  EXPECT_EQ(first_line(out / "series.csv"), "step,time_s,Fx_N_per_m,Fy_N_per_m,Cd,Cl,dp_front_back_Pa");
  fs::remove_all(out);
}

// Platens at 10 um/s: ~2.7e8 steps to ucs.max_strain. The run says so, naming the keys, before
// its first step; --max-steps stops it right after.
TEST(RunResults, VeryLongRunPrintsItsEstimateFirst) {
  const auto out = scratch("long");
  const auto r = run_cli("run --out " + out.string() + kTiny + " --set ucs.platen_velocity=1e-5 --max-steps 300");
  const auto at = r.output.find("this run needs up to");
  ASSERT_NE(at, std::string::npos) << r.output;
  EXPECT_TRUE(has(r.output, "million steps")) << r.output;
  EXPECT_TRUE(has(r.output, "ucs.platen_velocity or ucs.max_strain shorten it")) << r.output;
  const auto step = r.output.find("step 300");  // the interruption message comes after the estimate
  if (step != std::string::npos) {
    EXPECT_LT(at, step);
  }
  fs::remove_all(out);
}

// README walk-through: "about 1,700 bonded spheres", "porosity 0.40", and a run without
// warnings. The sample alone (stopped at 0.01% strain: only the null-value warnings that cap
// causes) matches within 3% of the count and 0.005 of the porosity.
TEST(RunResults, DefaultScenarioBuildsTheSampleTheReadmeDescribes) {
  const auto out = scratch("default");
  const auto r = run_cli("run --out " + out.string() +
                         " --set ucs.max_strain=1e-4 --set output.vtk=false --set output.plots=false --quiet --threads 1");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(other_warnings(r.output), "") << r.output;
  const auto s = read_json(out / "summary.json")["sample"];
  EXPECT_NEAR(s["particles"].get<double>(), 1700, 0.03 * 1700) << s.dump(2);
  EXPECT_NEAR(s["porosity"].get<double>(), 0.40, 0.005) << s.dump(2);
  fs::remove_all(out);
}

// A calibration run whose E, nu and UCS are null stops the calibration with their reasons; it
// never enters the update as 0.
TEST(RunResults, CalibrationRefusesARunWithoutPeakOrFit) {
  const auto out = scratch("calibrate");
  std::string sets;
  for (const char* s : {"sample.diameter=5e-3", "sample.height=8e-3", "sample.porosity=0.45", "output.vtk=false",
                        "output.plots=false", "ucs.max_strain=1e-3"})
    sets += std::string(" --set ") + s;
  const auto r = run_cli("calibrate --target-E 2.37e9 --target-nu 0.35 --target-ucs 14.97e6 --max-iter 3 --out " +
                         out.string() + sets);
  EXPECT_NE(r.code, 0) << r.output;
  EXPECT_TRUE(has(r.output, "calibration run 1 measured no UCS, E or nu")) << r.output;
  EXPECT_TRUE(has(r.output, "raise ucs.max_strain")) << r.output;
  EXPECT_FALSE(fs::exists(out / "iter_02")) << "a second run was started from a run without results";
  fs::remove_all(out);
}

// batch::run_in_process stopped by max_steps leaves a checkpoint; batch::resume_in_process continues
// it (as `fracflow resume`, an old ABORT request removed) to the same series.csv as an uninterrupted run, byte for byte
// (validate-saturated --resume continues interrupted runs this way).
TEST(RunResults, InProcessRunStoppedAndResumedEqualsTheWholeRun) {
  const std::vector<std::string> tiny = {"sample.diameter=5e-3", "sample.height=8e-3", "sample.porosity=0.45",
                                         "output.vtk=false",     "output.plots=false", "output.progress_interval=0",
                                         "ucs.max_strain=0.01"};
  const auto whole = scratch("inproc_whole"), parts = scratch("inproc_parts");
  fs::remove_all(whole);
  fs::remove_all(parts);
  ff::batch::InProcessRun r;
  r.out_dir = whole;
  ASSERT_EQ(ff::batch::run_in_process("", tiny, r), ff::RunStatus::Finished);
  long steps = 0;  // the whole run's last step; stop the other half-way
  {
    std::ifstream f(whole / "series.csv");
    std::string line, last;
    while (std::getline(f, line)) last = line;
    steps = std::stol(last.substr(0, last.find(',')));
  }
  ASSERT_GT(steps, 100);
  r.out_dir = parts;
  r.max_steps = steps / 2;
  ASSERT_EQ(ff::batch::run_in_process("", tiny, r), ff::RunStatus::Interrupted);
  ASSERT_TRUE(fs::exists(parts / "checkpoint"));
  EXPECT_FALSE(fs::exists(parts / "summary.json"));
  r.max_steps = 0;
  std::ofstream(parts / "ABORT") << "stop\n";  // a stop request of the earlier run is not repeated
  ASSERT_EQ(ff::batch::resume_in_process(parts, r), ff::RunStatus::Finished);
  expect_same_series(whole, parts);
  EXPECT_THROW(ff::batch::resume_in_process(scratch("inproc_none"), r), ff::InputError);
  fs::remove_all(whole);
  fs::remove_all(parts);
}

// A SIGTERM during an in-process run (validate-saturated, validate-hydrofrac, calibrate) asks for a
// checkpoint and a stop, as with `fracflow run`, instead of ending the process at once (it did: the
// study lost everything since its runs' last 60-s checkpoints). Without the handler this test dies of
// the signal. The stopped run resumes to the uninterrupted run's series.csv, byte for byte; once a
// stop is requested, no further run starts (no folder).
TEST(RunResults, InProcessRunStopsOnSigtermWithACheckpoint) {
  const std::vector<std::string> tiny = {"sample.diameter=5e-3", "sample.height=8e-3", "sample.porosity=0.45",
                                         "output.vtk=false",     "output.plots=false", "output.progress_interval=0",
                                         "ucs.max_strain=0.01"};
  const auto whole = scratch("sig_whole"), parts = scratch("sig_parts"), after = scratch("sig_after");
  for (const auto& d : {whole, parts, after}) fs::remove_all(d);
  ff::batch::InProcessRun r;
  r.out_dir = whole;
  ASSERT_EQ(ff::batch::run_in_process("", tiny, r), ff::RunStatus::Finished);
  // The signal as soon as the run has begun its output (its scenario.toml is written then).
  std::thread killer([&] {
    for (int k = 0; k < 200000 && !fs::exists(parts / "scenario.toml"); ++k)
      std::this_thread::sleep_for(std::chrono::microseconds(50));
    std::raise(SIGTERM);
  });
  r.out_dir = parts;
  const auto st = ff::batch::run_in_process("", tiny, r);
  killer.join();
  ASSERT_EQ(st, ff::RunStatus::Interrupted) << "the run ended before the signal arrived";
  EXPECT_TRUE(ff::stop_requested());
  EXPECT_TRUE(fs::exists(parts / "checkpoint"));
  EXPECT_FALSE(fs::exists(parts / "summary.json"));
  r.out_dir = after;
  EXPECT_EQ(ff::batch::run_in_process("", tiny, r), ff::RunStatus::Interrupted);
  EXPECT_FALSE(fs::exists(after)) << "a run started after the stop request";
  EXPECT_EQ(ff::batch::resume_in_process(parts, r), ff::RunStatus::Interrupted);
  ff::clear_stop_request();
  ASSERT_EQ(ff::batch::resume_in_process(parts, r), ff::RunStatus::Finished);
  expect_same_series(whole, parts);
  fs::remove_all(whole);
  fs::remove_all(parts);
}
