// The `fracflow` program: parse the command line, load and validate the scenario, pick the
// driver, run it. Everything physical lives in the library.
#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <omp.h>

#include <chrono>
#include <filesystem>
#include <fstream>

#include "batch/run_case.hpp"
#include "commands.hpp"
#include "core/error.hpp"
#include "core/log.hpp"
#include "drivers/driver.hpp"
#include "fracflow/version.hpp"

namespace fs = std::filesystem;
using namespace ff;

namespace {

void apply_threads(int threads) {
  if (threads > 0) omp_set_num_threads(threads);
}

// Runs the driver in `out`. On an input error raised while setting up (before results exist),
// a folder this call created is removed again so no half-written results remain.
int execute(const batch::LoadedScenario& l, RunOptions opt, bool created_dir) {
  try {
    const RunStatus st = l.driver->run(l.config, opt);
    if (st == RunStatus::Interrupted)
      log::info("run interrupted; a checkpoint is in {}/checkpoint. Continue with: fracflow resume {}", opt.out_dir.string(),
                opt.out_dir.string());
    else
      log::info("results in {}", opt.out_dir.string());
    return 0;
  } catch (const InputError& e) {
    log::error("{}", e.what());
    const bool has_results = fs::exists(opt.out_dir / "series.csv") || fs::exists(opt.out_dir / "checkpoint");
    if (created_dir && !has_results) fs::remove_all(opt.out_dir);
    return 2;
  } catch (const NumericalError& e) {
    log::error("{}", e.what());
    return 3;
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"fracflow: bonded-particle DEM and lattice Boltzmann simulation of rock, coal and concrete fracture"};
  app.set_version_flag("--version", std::string("fracflow ") + kVersion);
  app.require_subcommand(1);

  std::string scenario, out_dir, resume_dir;
  std::vector<std::string> sets;
  int threads = 0;
  double max_wall = 0;
  long max_steps = 0;
  bool overwrite = false, quiet = false;

  auto* run = app.add_subcommand("run", "run a scenario (the built-in default when no file is given)");
  run->add_option("scenario", scenario, "scenario file (TOML)");
  run->add_option("--out,-o", out_dir, "results folder (default: runs/<scenario name>)");
  run->add_option("--threads,-j", threads, "OpenMP threads (default: all cores)")->check(CLI::NonNegativeNumber);
  run->add_option("--set,-s", sets, "override a parameter: --set key=value (repeatable)");
  run->add_option("--max-wall", max_wall, "stop with a checkpoint after this many wall-clock seconds")
      ->check(CLI::NonNegativeNumber);
  run->add_option("--max-steps", max_steps, "stop with a checkpoint once this time step is reached")
      ->check(CLI::NonNegativeNumber);
  run->add_flag("--overwrite", overwrite, "replace an existing results folder");
  run->add_flag("--quiet,-q", quiet, "no status lines");

  auto* check = app.add_subcommand("check", "validate a scenario and print every resolved parameter");
  check->add_option("scenario", scenario, "scenario file (TOML); none: the built-in default");
  check->add_option("--set,-s", sets, "override a parameter: --set key=value (repeatable)");

  auto* resume = app.add_subcommand("resume", "continue a run from its last checkpoint");
  resume->add_option("dir", resume_dir, "results folder of the run")->required();
  resume->add_option("--threads,-j", threads, "OpenMP threads")->check(CLI::NonNegativeNumber);
  resume->add_option("--max-wall", max_wall, "stop with a checkpoint after this many wall-clock seconds")
      ->check(CLI::NonNegativeNumber);
  resume->add_option("--max-steps", max_steps, "stop with a checkpoint once this time step is reached")
      ->check(CLI::NonNegativeNumber);
  resume->add_flag("--quiet,-q", quiet, "no status lines");

  auto* params = app.add_subcommand("params", "print the parameter reference of every driver (Markdown)");
  auto* drivers = app.add_subcommand("drivers", "list the drivers (loading protocols)");
  std::vector<std::pair<CLI::App*, cli::Command::Run>> extra;
  for (auto& c : cli::registered_commands()) {
    auto r = c.setup(app);
    extra.emplace_back(app.get_subcommand(c.name), std::move(r));
  }

  CLI11_PARSE(app, argc, argv);
  log::quiet() = quiet;

  try {
    for (auto& [sub, fn] : extra)
      if (*sub) return fn();
    if (*drivers) {
      for (auto& d : all_drivers()) fmt::print("{:<22} {}\n", d.name, d.summary);
      return 0;
    }
    if (*params) {
      for (auto& d : all_drivers()) {
        fmt::print("### driver `{}`\n\n{}\n\n{}\n", d.name, d.summary, parameter_table(d).markdown());
      }
      return 0;
    }
    if (*check) {
      auto l = batch::load_scenario_for_run(scenario, sets);
      fmt::print("{}: valid; driver '{}' ({})\n\n{}", scenario.empty() ? "built-in default scenario" : scenario,
                 l->driver->name, l->driver->summary, l->config.describe());
      return 0;
    }
    apply_threads(threads);
    RunOptions opt;
    opt.threads = threads > 0 ? threads : omp_get_max_threads();
    opt.max_wall_s = max_wall;
    opt.max_steps = max_steps;
    if (*run) {
      auto l = batch::load_scenario_for_run(scenario, sets);  // every key validated before anything is written
      if (out_dir.empty())
        out_dir = "runs/" + (scenario.empty() ? std::string("default") : fs::path(scenario).stem().string());
      opt.out_dir = out_dir;
      opt.progress_interval_s = quiet ? 0 : l->config.real("output.progress_interval");
      bool created = false;
      if (fs::exists(opt.out_dir) && !fs::is_empty(opt.out_dir)) {
        if (!overwrite)
          throw InputError(fmt::format("results folder '{}' already holds a run; pass --overwrite to replace it, "
                                       "--out to choose another folder, or `fracflow resume {}` to continue it",
                                       out_dir, out_dir));
        fs::remove_all(opt.out_dir);
      }
      created = !fs::exists(opt.out_dir);
      fs::create_directories(opt.out_dir);
      {
        std::ofstream f(opt.out_dir / "scenario.toml");
        f << l->config.resolved_toml();
      }
      opt.abort_file = opt.out_dir / "ABORT";
      return execute(*l, opt, created);
    }
    if (*resume) {
      const fs::path dir(resume_dir);
      if (!fs::exists(dir / "scenario.toml"))
        throw InputError(fmt::format("'{}' is not a fracflow results folder (no scenario.toml)", resume_dir));
      if (!fs::exists(dir / "checkpoint"))
        throw InputError(fmt::format("'{}' has no checkpoint/ to resume from", resume_dir));
      auto l = batch::load_scenario_for_run((dir / "scenario.toml").string(), {});
      opt.out_dir = dir;
      opt.resume = true;
      opt.abort_file = dir / "ABORT";
      opt.progress_interval_s = quiet ? 0 : l->config.real("output.progress_interval");
      std::error_code ec;
      fs::remove(opt.abort_file, ec);
      return execute(*l, opt, false);
    }
  } catch (const InputError& e) {
    log::error("{}", e.what());
    return 2;
  } catch (const Error& e) {
    log::error("{}", e.what());
    return 1;
  }
  return 0;
}
