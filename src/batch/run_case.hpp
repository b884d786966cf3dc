// One run of a scenario, the way `fracflow run` does it (validate everything, then write the
// folder, then call the driver), plus what the batch tools need around it: reading a run's
// summary.json back and starting `fracflow run` as a child process.
#pragma once
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "batch/mohr_coulomb.hpp"
#include "drivers/driver.hpp"
#include "io/params.hpp"

namespace ff::batch {

// A validated scenario. Config points into `table`, so the three live together (heap-held).
struct LoadedScenario {
  const Driver* driver = nullptr;
  ParamTable table;
  Config config;
};

// Reads the scenario file (or the built-in default when `path` is empty), applies the
// "key=value" overrides (later ones win), validates every key and runs the driver's validate()
// (every check run() makes before building its sample or lattice); throws ff::InputError.
// `resume`: the scenario.toml of a results folder, whose sample or lattice is in its checkpoint;
// validate() is left out (the files it names are relative to the original scenario's folder,
// and the run checked them when it started).
std::unique_ptr<LoadedScenario> load_scenario_for_run(const std::string& path, const std::vector<std::string>& overrides,
                                                      bool resume = false);

struct InProcessRun {
  std::filesystem::path out_dir;  // must be absent or empty
  int threads = 1;                // OpenMP threads for the driver
  bool quiet = true;              // no info/status lines while the driver runs
  long max_steps = 0;             // as RunOptions
  double max_wall_s = 0;
};

// Runs a scenario in this process: validate, check out_dir as `fracflow run` does
// (io/run_folder.hpp), call the driver, which creates out_dir with its marker, lock and
// scenario.toml once its set-up has passed. Input errors leave no out_dir behind; driver errors
// (ff::InputError from cross-parameter checks, ff::NumericalError) propagate. From then on SIGINT
// and SIGTERM stop the run after a checkpoint (RunStatus::Interrupted); once a stop has been
// requested (core/interrupt.hpp), it returns Interrupted at once and makes no folder.
RunStatus run_in_process(const std::string& scenario_path, const std::vector<std::string>& overrides,
                         const InProcessRun& run);

// Continues an interrupted run in `dir` from its checkpoint in this process, as `fracflow resume`
// does (its lock held for the run; the scenario as the folder's scenario.toml has it; out_dir of
// `run` is ignored). Throws ff::InputError when dir holds no run or no checkpoint.
RunStatus resume_in_process(const std::filesystem::path& dir, const InProcessRun& run);

// The headline numbers of a finished run's summary.json; absent and null numbers are NaN
// (a run writes null where it has no trustworthy value, e.g. an elastic fit without points).
struct RunSummary {
  std::string driver;
  double ucs_Pa = 0, peak_differential_stress_Pa = 0, confining_pressure_Pa = 0;
  double youngs_modulus_Pa = 0, poisson_ratio = 0, strain_at_peak = 0;
  double cracks_tensile = 0, cracks_shear = 0, cracks_total = 0;
  double wall_time_s = 0;
  // Why the peak or the elastic constants are null ("" when both are there), from the reasons
  // summary.json gives beside them.
  std::string missing;
  nlohmann::json raw;  // the whole file
};

// The number at `path` in `j` (nested keys); NaN when a key is absent or the value is not a number
// (null included).
double json_number(const nlohmann::json& j, std::initializer_list<const char*> path);

// Reads out_dir/summary.json; throws ff::Error naming the file when it is missing or unreadable.
RunSummary read_run_summary(const std::filesystem::path& out_dir);

// The peak strength of a UCS (sigma3 = 0) or triaxial run, compression positive; nullopt for
// other drivers or when the numbers are missing.
std::optional<StrengthPoint> peak_strength(const RunSummary& s);

// Starts `executable args...` with stdout and stderr appended to `log` and waits for it.
// Returns its exit status, 128 + signal when it was killed, or -1 when it could not start.
// A stop request to this process while the child runs (stop_requested(): SIGINT/SIGTERM once
// install_stop_signal_handlers() is in place) is passed on once: as the file run_dir/ABORT when
// the child's run folder has begun (its marker), so that it checkpoints and stops; before that as
// SIGTERM (the child has written nothing yet). Not a signal: Ctrl-C already reaches the child (same
// process group), and a second signal would kill it without its checkpoint.
int run_child_process(const std::filesystem::path& executable, const std::vector<std::string>& args,
                      const std::filesystem::path& log, const std::filesystem::path& run_dir = {});

// The last `lines` non-empty lines of a text file ("" when unreadable): a failed run's reason.
std::string tail_of_file(const std::filesystem::path& path, int lines);

}  // namespace ff::batch
