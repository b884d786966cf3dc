// A driver is one loading protocol (UCS test, triaxial test, flow benchmark...): it declares
// its scenario keys and runs. Drivers are listed once, in registry.cpp.
#pragma once
#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "io/params.hpp"

namespace ff {

struct RunOptions {
  std::filesystem::path out_dir;     // results folder (exists when run() is called)
  int threads = 1;                   // OpenMP threads (already applied with omp_set_num_threads)
  double max_wall_s = 0;             // > 0: write a checkpoint and stop after this wall time
  long max_steps = 0;                // > 0: write a checkpoint and stop once this step is reached
  bool resume = false;               // continue from out_dir/checkpoint/
  std::filesystem::path abort_file;  // when this file appears: checkpoint and stop
  double progress_interval_s = 5;    // status line period (0: silent)
  // Called by the driver once its set-up has passed every check and the sample/lattice is
  // built, before it writes any file into out_dir (not called on resume). The CLI uses it to
  // replace an old run only when the new one is known to start (--overwrite). May be empty.
  std::function<void()> begin_output;
  // Keys of scenario.toml edited since the run started that the user accepted at resume
  // (fracflow resume --accept-edited-scenario); recorded in summary.json by every driver.
  std::vector<std::string> accepted_scenario_changes;
};

// Calls opt.begin_output when set (every driver calls this once, after set-up, on a fresh run).
inline void begin_output(const RunOptions& opt) {
  if (opt.begin_output && !opt.resume) opt.begin_output();
}

// What run() reports back to the CLI.
enum class RunStatus { Finished, Interrupted };

struct Driver {
  std::string_view name;
  std::string_view summary;
  void (*declare)(ParamTable&);
  RunStatus (*run)(const Config&, const RunOptions&);
  // Every cross-parameter check that needs no sample or lattice (pairs of keys, groups named
  // but not declared, files the scenario names, LBM stability limits...), throwing InputError
  // as run() would. Called for `check`, `run`, sweeps and calibration before anything is
  // written, so that `check` refuses what `run` refuses; run() calls the same functions.
  void (*validate)(const Config&) = nullptr;
};

std::span<const Driver> all_drivers();
const Driver& find_driver(const std::string& name);  // throws InputError listing the drivers
// The full table of a driver: the common keys (driver, output.*) plus its own.
ParamTable parameter_table(const Driver& d);
// The built-in default scenario (`fracflow run` with no file).
std::string_view default_scenario_text();

}  // namespace ff
