// `fracflow calibrate`: adjust the parallel-bond micro-parameters of a UCS scenario until its
// E, nu and UCS match laboratory values (rules in src/batch/calibration.hpp).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <thread>

#include "batch/calibration.hpp"
#include "batch/run_case.hpp"
#include "batch/sweep.hpp"
#include "commands.hpp"
#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "core/log.hpp"
#include "io/json_out.hpp"
#include "io/run_folder.hpp"

namespace fs = std::filesystem;
using namespace ff;
using namespace ff::batch;

namespace {

struct CalibrateArgs {
  std::string scenario, out, pair = "matrix-matrix";
  std::string triaxial;                        // triaxial scenario that measures b (with --target-b)
  std::vector<double> b_confinement = {2.5e6, 7.5e6};
  std::vector<std::string> sets;
  CalibrationSettings settings;
  int threads = 1;
  int jobs = 2;                                // triaxial runs at a time (with --target-b)
  bool overwrite = false;
};

// The scenario keys of one group pair's calibrated parameters, with their values.
std::vector<std::pair<std::string, double>> parameter_keys(const std::string& pair, const MicroParameters& p) {
  return {{"dem.contact." + pair + ".emod", p.contact_emod_Pa},
          {"dem.contact." + pair + ".kratio", p.contact_kratio},
          {"dem.bond." + pair + ".emod", p.bond_emod_Pa},
          {"dem.bond." + pair + ".kratio", p.bond_kratio},
          {"dem.bond." + pair + ".tensile_strength", p.tensile_strength_Pa},
          {"dem.bond." + pair + ".cohesion", p.cohesion_Pa},
          {"dem.bond." + pair + ".friction_angle", p.friction_angle_deg}};
}

std::string step_line(const CalibrationStep& s, bool calibrates_slope) {
  const auto& p = s.params;
  const auto& m = s.measured;
  const bool with_b = s.slope_measured;
  return fmt::format("iter {:2d}: emod {:.4g} GPa, kratio {:.4g}, tensile {:.4g} MPa, cohesion {:.4g} MPa{} -> "
                     "E {:.4g} GPa ({:+.1f}%), nu {:.3f} ({:+.3f}), UCS {:.4g} MPa ({:+.1f}%){}{}",
                     s.iteration, 1e-9 * p.bond_emod_Pa, p.bond_kratio, 1e-6 * p.tensile_strength_Pa,
                     1e-6 * p.cohesion_Pa,
                     calibrates_slope ? fmt::format(", friction angle {:.4g} deg", p.friction_angle_deg) : "",
                     1e-9 * m.youngs_modulus_Pa, 100 * s.youngs_modulus_error, m.poisson_ratio, s.poisson_error,
                     1e-6 * m.ucs_Pa, 100 * s.ucs_error,
                     with_b ? fmt::format(", b {:.3f} ({:+.1f}%)", m.slope_b, 100 * s.slope_error) : "",
                     s.converged ? "  converged" : "");
}

void write_csv(const fs::path& file, const std::vector<CalibrationStep>& steps) {
  std::ofstream f(file);
  f << "iteration,bond_emod_Pa,contact_emod_Pa,bond_kratio,contact_kratio,tensile_strength_Pa,cohesion_Pa,"
       "bond_friction_angle_deg,youngs_modulus_Pa,poisson_ratio,ucs_Pa,slope_b,youngs_modulus_error,poisson_error,"
       "ucs_error,slope_measured,slope_error,converged\n";
  for (auto& s : steps)
    f << fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", s.iteration, s.params.bond_emod_Pa,
                     s.params.contact_emod_Pa, s.params.bond_kratio, s.params.contact_kratio, s.params.tensile_strength_Pa,
                     s.params.cohesion_Pa, s.params.friction_angle_deg, s.measured.youngs_modulus_Pa,
                     s.measured.poisson_ratio, s.measured.ucs_Pa, s.measured.slope_b, s.youngs_modulus_error,
                     s.poisson_error, s.ucs_error, s.slope_measured ? 1 : 0, s.slope_error, s.converged ? 1 : 0);
  if (!f) throw Error(fmt::format("cannot write '{}'", file.string()));
}

nlohmann::json params_json(const std::string& pair, const MicroParameters& p) {
  nlohmann::json j = nlohmann::json::object();
  for (auto& [k, v] : parameter_keys(pair, p)) j[k] = v;
  return j;
}

int run_calibrate_command(const CalibrateArgs& a) {
  // Calibration runs need no VTK or plots; the user's --set may turn them back on.
  std::vector<std::string> base = {"output.vtk=false", "output.plots=false"};
  base.insert(base.end(), a.sets.begin(), a.sets.end());
  auto l = load_scenario_for_run(a.scenario, base);  // validated before anything is written
  const Config& cfg = l->config;
  if (l->driver->name != "ucs")
    throw InputError(fmt::format("calibrate: the scenario's driver is '{}'; calibration runs UCS tests, so it needs "
                                 "driver = \"ucs\"", l->driver->name));
  if (cfg.string("dem.bond_law") != "parallel")
    throw InputError(fmt::format("calibrate: dem.bond_law = \"{}\"; the calibration rules are for parallel bonds "
                                 "(dem.bond_law = \"parallel\")", cfg.string("dem.bond_law")));
  const auto bond_pairs = cfg.names("dem.bond"), contact_pairs = cfg.names("dem.contact");
  auto has = [](const std::vector<std::string>& v, const std::string& x) { return std::find(v.begin(), v.end(), x) != v.end(); };
  if (!has(bond_pairs, a.pair) || !has(contact_pairs, a.pair)) {
    std::string known;
    for (auto& p : bond_pairs) known += " " + p;
    throw InputError(fmt::format("--group-pair {}: the scenario has no [dem.bond.{}] and [dem.contact.{}] tables; "
                                 "its bond group pairs are:{}", a.pair, a.pair, a.pair, known.empty() ? " (none)" : known));
  }
  const MicroParameters start{cfg.real("dem.bond." + a.pair + ".emod"),   cfg.real("dem.contact." + a.pair + ".emod"),
                              cfg.real("dem.bond." + a.pair + ".kratio"), cfg.real("dem.contact." + a.pair + ".kratio"),
                              cfg.real("dem.bond." + a.pair + ".tensile_strength"),
                              cfg.real("dem.bond." + a.pair + ".cohesion"),
                              cfg.real("dem.bond." + a.pair + ".friction_angle")};
  check_calibration_input(start, a.settings);
  const bool with_b = a.settings.calibrates_slope();
  if (with_b) {  // the triaxial scenario is checked before anything is written, too
    if (a.triaxial.empty())
      throw InputError("--target-b needs --triaxial FILE: a triaxial scenario of the same sample and group pairs, run "
                       "at the --b-confinement pressures to measure b");
    if (a.b_confinement.size() < 2)
      throw InputError(fmt::format("--b-confinement: {} pressure(s) given; b is a slope and needs at least two, e.g. "
                                   "2.5e6,7.5e6 (seed 000 Table 3)", a.b_confinement.size()));
    for (double p : a.b_confinement)
      if (!(p > 0)) throw InputError(fmt::format("--b-confinement: {} Pa: every pressure must be positive", p));
    auto t = load_scenario_for_run(a.triaxial, base);
    if (t->driver->name != "triaxial")
      throw InputError(fmt::format("--triaxial {}: its driver is '{}'; it must be a triaxial scenario (driver = "
                                   "\"triaxial\")", a.triaxial, t->driver->name));
    const auto tb = t->config.names("dem.bond"), tc = t->config.names("dem.contact");
    if (!has(tb, a.pair) || !has(tc, a.pair))
      throw InputError(fmt::format("--triaxial {}: it has no [dem.bond.{}] and [dem.contact.{}] tables", a.triaxial,
                                   a.pair, a.pair));
  }

  const fs::path out = a.out.empty() ? fs::path("runs") / ("calibrate_" + (a.scenario.empty() ? std::string("default")
                                                                                              : fs::path(a.scenario).stem().string()))
                                     : fs::path(a.out);
  // Replaces only a folder of ours; held locked while the calibration writes it.
  const FolderLock out_lock = prepare_batch_folder(out, a.overwrite, "calibration folder");
  const auto& t = a.settings.target;
  log::info("calibrating {} of {} to E = {:.4g} GPa, nu = {:.3f}, UCS = {:.4g} MPa (tolerances {:.0f}%, {:.3f}, {:.0f}%), "
            "at most {} UCS runs in {}",
            a.pair, a.scenario.empty() ? "the built-in default scenario" : a.scenario, 1e-9 * t.youngs_modulus_Pa,
            t.poisson_ratio, 1e-6 * t.ucs_Pa, 100 * a.settings.youngs_modulus_tolerance, a.settings.poisson_tolerance,
            100 * a.settings.ucs_tolerance, a.settings.max_iterations, out.string());
  if (with_b) {
    std::string ps;
    for (double p : a.b_confinement) ps += fmt::format(" {:.4g}", 1e-6 * p);
    log::info("and the triaxial slope to b = {:.3f} (tolerance {:.0f}%) by the bond friction angle, from runs of {} at "
              "sigma3 ={} MPa beside the UCS runs that come within {:g} tolerances of E, nu and UCS",
              a.settings.target.slope_b, 100 * a.settings.slope_tolerance, a.triaxial, ps,
              a.settings.slope_measure_window);
  }

  auto model = [&](const MicroParameters& p, int it, bool measure_slope) {
    std::vector<std::string> overrides = base;
    for (auto& [k, v] : parameter_keys(a.pair, p)) overrides.push_back(fmt::format("{}={}", k, v));
    InProcessRun run;
    run.out_dir = out / fmt::format("iter_{:02d}", it);
    run.threads = a.threads;
    // The triaxial runs that measure b go at the same time as the UCS run: a sweep of child
    // processes (in its own thread, which only waits for them) while this process runs the UCS test.
    std::optional<SweepResult> triaxial;
    std::string triaxial_error;
    std::thread sweep_thread;
    if (measure_slope) {
      SweepOptions so;
      so.scenario = a.triaxial;
      so.sets = overrides;
      SweepAxis axis{"triaxial.confining_pressure", {}};
      for (double q : a.b_confinement) axis.values.push_back(fmt::format("{}", q));
      so.axes = {axis};
      so.out_dir = out / fmt::format("iter_{:02d}_triaxial", it);
      so.executable = fs::read_symlink("/proc/self/exe");
      so.jobs = a.jobs;
      so.threads_per_job = a.threads;
      so.plots = false;
      so.quiet = true;
      sweep_thread = std::thread([&triaxial, &triaxial_error, so] {
        try {
          triaxial = run_sweep(so);
        } catch (const std::exception& e) {
          triaxial_error = e.what();
        }
      });
    }
    RunStatus status = RunStatus::Interrupted;
    try {
      status = run_in_process(a.scenario, overrides, run);
    } catch (...) {
      if (sweep_thread.joinable()) sweep_thread.join();
      throw;
    }
    if (sweep_thread.joinable()) sweep_thread.join();
    if (status != RunStatus::Finished)
      throw Error(fmt::format("calibration run {} was interrupted ({}); its folder is {}", it,
                              stop_cause_or("an ABORT file?"),
                              run.out_dir.string()));
    const RunSummary s = read_run_summary(run.out_dir);
    // A run without a peak or an elastic fit has nothing to update from (null in summary.json).
    if (!std::isfinite(s.youngs_modulus_Pa) || !std::isfinite(s.poisson_ratio) || !std::isfinite(s.ucs_Pa))
      throw Error(fmt::format("calibration run {} measured no {}: {}; see {}", it,
                              !std::isfinite(s.ucs_Pa) && !std::isfinite(s.youngs_modulus_Pa) ? "UCS, E or nu"
                              : std::isfinite(s.ucs_Pa)                                       ? "E or nu"
                                                                                              : "UCS",
                              s.missing.empty() ? "summary.json holds no value" : s.missing, run.out_dir.string()));
    MacroProperties m{s.youngs_modulus_Pa, s.poisson_ratio, s.ucs_Pa, 0.0};
    if (measure_slope) {
      const fs::path dir = out / fmt::format("iter_{:02d}_triaxial", it);
      if (!triaxial_error.empty()) throw Error(fmt::format("calibration run {}: triaxial runs: {}", it, triaxial_error));
      const auto& pts = triaxial->strength_points;
      if (triaxial->failed > 0 || pts.size() < 2)
        throw Error(fmt::format("calibration run {}: {} of the triaxial runs in {} failed; see their logs", it,
                                triaxial->failed, dir.string()));
      // Least-squares slope of the peak differential stress sigma1 - sigma3 on sigma3 (seed 000 Eq. 1).
      std::vector<double> s3, q;
      for (auto& pt : pts) s3.push_back(pt.sigma3), q.push_back(pt.sigma_p - pt.sigma3);
      m.slope_b = fit_line(s3, q).slope;
    }
    return m;
  };
  std::vector<CalibrationStep> steps;
  auto on_step = [&](const CalibrationStep& s) {
    steps.push_back(s);
    fmt::print("{}\n", step_line(s, with_b));  // the iteration lines are the result: printed even with -q
    std::fflush(stdout);
    write_csv(out / "calibration.csv", steps);
  };
  const CalibrationResult r = calibrate(start, a.settings, model, on_step);
  const CalibrationStep& chosen = r.steps[r.chosen];

  {
    std::ofstream f(out / "calibrated.toml");
    f << fmt::format("# fracflow calibrate: {} of {}\n# targets E = {} Pa, nu = {}, UCS = {} Pa; {} at iteration {}\n"
                     "# measured there: E = {:.6g} Pa, nu = {:.4f}, UCS = {:.6g} Pa\n"
                     "# Paste into the scenario (replacing these keys in its existing tables).\n",
                     a.pair, a.scenario.empty() ? "the built-in default scenario" : a.scenario, t.youngs_modulus_Pa,
                     t.poisson_ratio, t.ucs_Pa, r.converged ? "converged" : "NOT converged; closest run", chosen.iteration,
                     chosen.measured.youngs_modulus_Pa, chosen.measured.poisson_ratio, chosen.measured.ucs_Pa);
    if (with_b)
      f << fmt::format("# triaxial slope: target b = {}, measured b = {:.4f} ({} at sigma3 =", t.slope_b,
                       chosen.measured.slope_b, a.triaxial)
        << [&] { std::string ps; for (double q : a.b_confinement) ps += fmt::format(" {}", q); return ps; }() << " Pa)\n";
    const auto& p = r.final_params;
    f << fmt::format("\n[dem.contact.{}]\nemod = {}\nkratio = {}\n", a.pair, p.contact_emod_Pa, p.contact_kratio);
    f << fmt::format("\n[dem.bond.{}]\nemod = {}\nkratio = {}\ntensile_strength = {}\ncohesion = {}\n"
                     "friction_angle = {}\n",
                     a.pair, p.bond_emod_Pa, p.bond_kratio, p.tensile_strength_Pa, p.cohesion_Pa, p.friction_angle_deg);
  }
  nlohmann::json j;
  j["scenario"] = a.scenario.empty() ? "<built-in default scenario>" : a.scenario;
  j["sets"] = a.sets;
  j["group_pair"] = a.pair;
  j["targets"] = {{"youngs_modulus_Pa", t.youngs_modulus_Pa}, {"poisson_ratio", t.poisson_ratio}, {"ucs_Pa", t.ucs_Pa}};
  j["tolerances"] = {{"youngs_modulus_relative", a.settings.youngs_modulus_tolerance},
                     {"poisson_ratio_absolute", a.settings.poisson_tolerance},
                     {"ucs_relative", a.settings.ucs_tolerance}};
  if (with_b) {
    j["targets"]["slope_b"] = t.slope_b;
    j["tolerances"]["slope_b_relative"] = a.settings.slope_tolerance;
    j["triaxial_scenario"] = a.triaxial;
    j["b_confinement_Pa"] = a.b_confinement;
  }
  j["rules"] = "seed 000 Sec. 5.2: E linear in emod, nu linear in ln(kratio), UCS linear in the strengths at fixed "
               "tensile_strength/cohesion; b (with --target-b) linear in tan(bond friction_angle), moved only after "
               "a run with E, nu and UCS in tolerance (docs/batch.md)";
  j["converged"] = r.converged;
  j["stop_reason"] = r.stop_reason;
  j["chosen_iteration"] = chosen.iteration;
  j["initial_parameters"] = params_json(a.pair, start);
  j["final_parameters"] = params_json(a.pair, r.final_params);
  j["final_measured"] = {{"youngs_modulus_Pa", chosen.measured.youngs_modulus_Pa},
                         {"poisson_ratio", chosen.measured.poisson_ratio},
                         {"ucs_Pa", chosen.measured.ucs_Pa},
                         {"slope_b", chosen.measured.slope_b}};
  j["iterations"] = nlohmann::json::array();
  for (auto& s : r.steps)
    j["iterations"].push_back({{"iteration", s.iteration},
                               {"dir", (out / fmt::format("iter_{:02d}", s.iteration)).string()},
                               {"parameters", params_json(a.pair, s.params)},
                               {"youngs_modulus_Pa", s.measured.youngs_modulus_Pa},
                               {"poisson_ratio", s.measured.poisson_ratio},
                               {"ucs_Pa", s.measured.ucs_Pa},
                               {"slope_b", s.measured.slope_b},
                               {"slope_measured", s.slope_measured},
                               {"slope_error", s.slope_error},
                               {"youngs_modulus_error", s.youngs_modulus_error},
                               {"poisson_error", s.poisson_error},
                               {"ucs_error", s.ucs_error},
                               {"converged", s.converged}});
  write_json_atomic(out / "calibration.json", j);
  if (r.converged) {
    fmt::print("converged after {} UCS runs; parameters in {}\n", r.steps.size(), (out / "calibrated.toml").string());
    return 0;
  }
  log::error("not converged ({}); the closest run (iteration {}) is in {}", r.stop_reason, chosen.iteration,
             (out / "calibrated.toml").string());
  return 1;
}

const bool registered = ff::cli::register_command({"calibrate", [](CLI::App& app) {
  auto a = std::make_shared<CalibrateArgs>();
  auto* sub = app.add_subcommand("calibrate",
                                 "adjust the parallel-bond micro-parameters of a UCS scenario (emod, kratio, strengths; bond friction "
                                 "angle for b) by repeated UCS (and triaxial) runs until E, nu, UCS (and b) match targets");
  sub->add_option("scenario", a->scenario, "UCS scenario file (TOML); none: the built-in default");
  sub->add_option("--target-E", a->settings.target.youngs_modulus_Pa, "target Young's modulus [Pa], e.g. 2.37e9")->required();
  sub->add_option("--target-nu", a->settings.target.poisson_ratio, "target Poisson's ratio, e.g. 0.35")->required();
  sub->add_option("--target-ucs", a->settings.target.ucs_Pa, "target uniaxial compressive strength [Pa], e.g. 14.97e6")
      ->required();
  sub->add_option("--group-pair", a->pair, "group pair whose bond and contact parameters are calibrated")
      ->capture_default_str();
  sub->add_option("--max-iter", a->settings.max_iterations, "UCS runs at most")->capture_default_str();
  sub->add_option("--tol-E", a->settings.youngs_modulus_tolerance, "relative tolerance on E")->capture_default_str();
  sub->add_option("--tol-nu", a->settings.poisson_tolerance, "absolute tolerance on nu")->capture_default_str();
  sub->add_option("--tol-ucs", a->settings.ucs_tolerance, "relative tolerance on UCS")->capture_default_str();
  sub->add_option("--nu-slope", a->settings.poisson_slope_guess,
                  "first guess of d nu / d ln(kratio), used until two runs give a slope")
      ->capture_default_str();
  sub->add_option("--target-b", a->settings.target.slope_b,
                  "also calibrate b, the slope of the peak differential stress against sigma3 (seed 000 Eq. 1: "
                  "3.54; the sigma1 slope is b + 1), by the bond friction angle; needs --triaxial");
  sub->add_option("--triaxial", a->triaxial, "triaxial scenario of the same sample, run at the --b-confinement pressures")
      ->check(CLI::ExistingFile);
  sub->add_option("--b-confinement", a->b_confinement, "confining pressures [Pa] of the runs that measure b")
      ->delimiter(',')
      ->capture_default_str();
  sub->add_option("--tol-b", a->settings.slope_tolerance, "relative tolerance on b")->capture_default_str();
  sub->add_option("--b-gradient", a->settings.slope_gradient_guess,
                  "first guess of d b / d tan(bond friction angle), used until two runs give one")
      ->capture_default_str();
  sub->add_option("--jobs", a->jobs, "triaxial runs at a time (beside the UCS run)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  sub->add_option("--out,-o", a->out, "calibration folder (default: runs/calibrate_<scenario name>)");
  sub->add_option("--set,-s", a->sets, "override a parameter in every run: --set key=value (repeatable)");
  sub->add_option("--threads-per-run,-j", a->threads, "OpenMP threads of each UCS run")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  sub->add_flag("--overwrite", a->overwrite, "replace an existing calibration folder");
  return ff::cli::Command::Run([a] { return run_calibrate_command(*a); });
}});

}  // namespace
