// Parameter sweeps: the Cartesian product of --vary values, each case a `fracflow run` child
// process in its own folder, the headline numbers gathered into sweep.csv / sweep.json, and a
// Mohr-Coulomb envelope when the cases are UCS/triaxial runs at several confining pressures.
// Child processes rather than threads: drivers set OpenMP state and process-wide flags, and a
// crash or a NumericalError in one case must not take the others down.
#pragma once
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "batch/mohr_coulomb.hpp"
#include "batch/run_case.hpp"

namespace ff::batch {

// One --vary option: a key and the values it takes (as written, each read like --set).
struct SweepAxis {
  std::string key;
  std::vector<std::string> values;
};

// Parses "key=v1,v2,v3". Commas inside [...] belong to a list value ("dem.gravity=[0,0,-9.81],[0,0,0]").
// Throws ff::InputError naming the option for a missing '=', an empty key or an empty value.
SweepAxis parse_vary(const std::string& option);

// Every combination of the axes' values, first axis varying slowest; each case as its
// (key, value) pairs in axis order. Throws ff::InputError when a key is varied twice.
std::vector<std::vector<std::pair<std::string, std::string>>> cartesian_product(std::span<const SweepAxis> axes);

// Folder name of case `index` out of `count`: case_000 ... (more digits for 1000+ cases).
std::string case_name(std::size_t index, std::size_t count);

struct SweepOptions {
  std::string scenario;                 // scenario file; "" = the built-in default
  std::vector<std::string> sets;        // --set overrides applied to every case
  std::vector<SweepAxis> axes;          // --vary
  std::filesystem::path out_dir;        // DIR: case_XXX/, logs/, sweep.csv, sweep.json, plots/
  std::filesystem::path executable;     // the fracflow program run for each case
  int jobs = 0;                         // cases at a time; 0 = cores / threads_per_job
  int threads_per_job = 1;              // OpenMP threads of each case
  bool overwrite = false;               // replace an existing non-empty out_dir
  bool resume = false;                  // continue the sweep in out_dir (same scenario, --set and --vary)
  bool plots = true;                    // draw plots/peak_vs_confinement.png when there is a fit
  bool quiet = false;                   // no line per finished case
};

struct SweepCase {
  std::string name;                                        // case_XXX
  std::vector<std::pair<std::string, std::string>> values; // the varied keys of this case
  std::vector<std::string> overrides;                      // --set list given to the run
  std::filesystem::path dir, log;
  int exit_code = -1;
  std::string status;                  // "ok", "failed", "no summary", "interrupted" (a checkpoint:
                                       // --resume continues it), "not started" (stopped before it)
  std::string error;                   // last lines of the log when not ok
  std::optional<RunSummary> summary;
  bool stopped() const { return status == "interrupted" || status == "not started"; }  // by a stop request
};

struct SweepResult {
  std::vector<SweepCase> cases;
  int failed = 0;
  int interrupted = 0, not_started = 0;  // after a stop request (SIGINT/SIGTERM): continue with --resume
  int read_before = 0, continued = 0;    // --resume: cases finished before, cases continued from a checkpoint
  std::optional<MohrCoulombFit> fit;
  std::string fit_note;                // why there is no fit, when there is none
  std::vector<StrengthPoint> strength_points;
};

// Draws out_dir/plots/peak_vs_confinement.png (peak sigma_p of each run as markers, the fitted
// envelope as a line; the data beside it as peak_vs_confinement.csv). True when the PNG was
// written; plotting problems are warnings, never errors (src/io/plot.hpp).
bool plot_peak_vs_confinement(const std::filesystem::path& out_dir, std::span<const StrengthPoint> points,
                              const MohrCoulombFit& fit);

// Validates every case (scenario + overrides) before anything is written, then runs them,
// `jobs` at a time, and writes sweep.csv, sweep.json and the plot. A failing case is recorded
// with its exit code and log; the others go on. Throws ff::InputError for bad options.
// SIGINT/SIGTERM (handlers installed here) stop the sweep: each running case is asked to
// checkpoint and stop (run_child_process), no new case starts, sweep.json records which cases
// are interrupted or not started, and `resume` continues: finished cases are read, interrupted
// ones resumed from their checkpoints, the others run (a sweep.json is written before the first
// case, so that --resume can check the options even after a kill -9).
SweepResult run_sweep(const SweepOptions& opt);

}  // namespace ff::batch
