// The `fracflow` program: parse the command line, load and validate the scenario, pick the
// driver, run it. Everything physical lives in the library.
#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <omp.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include <unistd.h>

#include "batch/run_case.hpp"
#include "commands.hpp"
#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "core/log.hpp"
#include "drivers/driver.hpp"
#include "drivers/flow/flow_runner.hpp"
#include "fracflow/version.hpp"
#include "io/run_folder.hpp"
#include "io/scenario.hpp"

namespace fs = std::filesystem;
using namespace ff;

namespace {

void apply_threads(int threads) {
  if (threads > 0) omp_set_num_threads(threads);
}

constexpr int kMaxThreads = 1024;

// --threads: a whole number from 0 (all cores) to kMaxThreads, said in words when it is not.
CLI::Validator threads_range() {
  return CLI::Validator(
      [](std::string& s) -> std::string {
        long v = -1;
        const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
        if (ec == std::errc() && end == s.data() + s.size() && v >= 0 && v <= kMaxThreads) return {};
        return fmt::format("must be a whole number from 1 to {} (0 or absent: all cores), not '{}'", kMaxThreads, s);
      },
      "0..1024");
}

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

// "unknown command 'runn', did you mean 'run'?" for a first argument that names no subcommand
// (CLI11 would only say that it did not expect it); empty when argv[1] is fine.
std::string unknown_command(CLI::App& app, int argc, char** argv) {
  if (argc < 2 || argv[1][0] == '-') return {};
  const std::string word = argv[1];
  std::vector<std::string> names;
  for (auto* sub : app.get_subcommands([](CLI::App*) { return true; })) names.push_back(sub->get_name());
  if (std::find(names.begin(), names.end(), word) != names.end()) return {};
  if (fs::path(word).extension() == ".toml")
    return fmt::format("unknown command '{}'; to run this scenario: fracflow run {}", word, word);
  std::string best;
  std::size_t best_d = 3;  // suggest only names within two edits
  for (auto& n : names)
    if (const auto d = edit_distance(word, n); d < best_d && d < n.size()) best = n, best_d = d;
  std::string all;
  for (auto& n : names) all += (all.empty() ? "" : ", ") + n;
  if (!best.empty()) return fmt::format("unknown command '{}', did you mean '{}'? (commands: {})", word, best, all);
  return fmt::format("unknown command '{}'; the commands are: {} (fracflow --help says what each does)", word, all);
}

// The command as typed, for the results folder's marker.
std::string command_line(int argc, char** argv) {
  std::string s;
  for (int i = 0; i < argc; ++i) {
    const std::string a = argv[i];
    const bool quote = a.empty() || a.find_first_of(" \t'\"$") != std::string::npos;
    s += (i ? " " : "") + (quote ? "'" + a + "'" : a);
  }
  return s;
}

// Keys the user set that the set-up never read: valid keys of another shape, dimension, fluid or
// mode, which would otherwise be ignored without a word (check and run warn alike).
void warn_unread_keys(const Config& cfg) {
  for (const auto& k : cfg.unread_keys())
    log::warn("{}: key '{}' is set but this scenario does not use it (it belongs to another shape, dimension, "
              "fluid or mode of driver '{}'): it has no effect",
              cfg.origin(k), k, cfg.string("driver"));
  cfg.mark_set_up_done();
}

// Keys first read after the set-up (that warn_unread_keys() would have named wrongly, being
// missing from read_by_every_run()): with FRACFLOW_CHECK_LATE_READS set, as the tests run the
// command line, each is an error and the command fails.
bool late_reads_refused(const Config& cfg) {
  const char* on = std::getenv("FRACFLOW_CHECK_LATE_READS");
  if (!on || !*on) return false;
  const auto late = cfg.late_reads();
  for (const auto& k : late)
    log::error("internal: key '{}' was first read after the set-up: read it in the set-up, or add it to "
               "read_by_every_run() (io/params.cpp) if every run of driver '{}' reads it",
               k, cfg.string("driver"));
  return !late.empty();
}

// Why a driver returned RunStatus::Interrupted.
std::string stop_reason(const RunOptions& opt, double elapsed_s) {
  if (stop_requested()) return stop_signal_name();
  if (!opt.abort_file.empty() && fs::exists(opt.abort_file)) return fmt::format("the file {}", opt.abort_file.string());
  if (opt.max_wall_s > 0 && elapsed_s >= 0.99 * opt.max_wall_s) return fmt::format("--max-wall {:g}", opt.max_wall_s);
  if (opt.max_steps > 0) return fmt::format("--max-steps {}", opt.max_steps);
  return "a stop request";
}

// Runs the driver in `out`. `folder` (fresh runs) is created by the driver through
// opt.begin_output; on an input error it is removed again when it holds no results.
int execute(const batch::LoadedScenario& l, RunOptions opt, NewRunFolder* folder) {
  const auto start = std::chrono::steady_clock::now();
  try {
    const RunStatus st = l.driver->run(l.config, opt);
    if (late_reads_refused(l.config)) return 70;
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const std::string dir = opt.out_dir.string();
    // How to continue is printed even with --quiet: a stopped run must never look finished.
    if (st == RunStatus::Interrupted && folder && !folder->begun())
      fmt::print("run stopped by {} before it started; nothing was written\n", stop_reason(opt, elapsed));
    else if (st == RunStatus::Interrupted)
      fmt::print("run stopped by {}; a checkpoint is in {}/checkpoint. Continue with: fracflow resume {}\n",
                 stop_reason(opt, elapsed), dir, dir);
    else
      log::info("results in {}", dir);
    std::fflush(stdout);
    return 0;
  } catch (const InputError& e) {
    log::error("{}", e.what());
    if (folder) folder->discard_if_empty();
    return 2;
  } catch (const NumericalError& e) {
    log::error("{}", e.what());
    return 3;
  }
}

// `fracflow check` after the scenario's own checks: the driver's set-up as `run` does it (the
// sample, walls, membrane, network or lattice, the time steps), stopped where the run would
// begin writing, so that what `run` refuses only once the sample exists (a DEM step above the
// critical one, a lattice too small...) `check` refuses too. The run's folder is a path that is
// never created: a driver writes nothing before begin_output.
struct SetUpPassed {};

void check_set_up(const batch::LoadedScenario& l) {
  RunOptions opt;
  opt.threads = omp_get_max_threads();
  opt.out_dir = fs::temp_directory_path() / fmt::format("fracflow_check_{}_not_created", static_cast<long>(::getpid()));
  opt.progress_interval_s = 0;
  opt.begin_output = [] { throw SetUpPassed{}; };
  try {
    (void)l.driver->run(l.config, opt);
  } catch (const SetUpPassed&) {
    warn_unread_keys(l.config);
    return;
  }
  throw Error(fmt::format("check: driver '{}' finished its set-up without reaching its output stage", l.driver->name));
}

// The keys of DIR/scenario.toml edited since the run started (from DIR/.fracflow/scenario.toml,
// the scenario as resolved then). Refused unless `accept`; accepted ones go to summary.json.
std::vector<std::string> edited_scenario(const fs::path& dir, const batch::LoadedScenario& now, bool accept) {
  const fs::path original = original_scenario_file(dir);
  if (!fs::exists(original)) return {};  // a run made before the marker existed: nothing to compare with
  if (read_text_file(original.string()) == read_text_file((dir / "scenario.toml").string())) return {};
  const auto before = batch::load_scenario_for_run(original.string(), {}, /*resume=*/true);
  std::vector<std::string> changes;
  for (auto& c : scenario_changes(before->config.resolved_values(), now.config.resolved_values()))
    changes.push_back(to_string(c));
  if (changes.empty()) return {};  // comments or layout only
  std::string list;
  for (auto& c : changes) list += (list.empty() ? "" : "; ") + c;
  if (!accept)
    throw InputError(fmt::format("{} was edited after the run started ({} key(s) changed: {}); a resumed run continues "
                                 "the run as it started: restore the file (the original is {}), or pass "
                                 "--accept-edited-scenario to continue with the edits (recorded in summary.json)",
                                 (dir / "scenario.toml").string(), changes.size(), list, original.string()));
  log::warn("continuing with an edited scenario (recorded in summary.json): {}", list);
  return changes;
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
  bool overwrite = false, quiet = false, accept_edited = false;

  auto* run = app.add_subcommand("run", "run a scenario (the built-in default when no file is given)");
  run->add_option("scenario", scenario, "scenario file (TOML)");
  run->add_option("--out,-o", out_dir, "results folder (default: runs/<scenario name>)");
  run->add_option("--threads,-j", threads, "OpenMP threads (default: all cores)")->check(threads_range());
  run->add_option("--set,-s", sets, "override a parameter: --set key=value (repeatable)");
  run->add_option("--max-wall", max_wall, "stop with a checkpoint after this many wall-clock seconds")
      ->check(CLI::NonNegativeNumber);
  run->add_option("--max-steps", max_steps, "stop with a checkpoint once this time step is reached")
      ->check(CLI::NonNegativeNumber);
  run->add_flag("--overwrite", overwrite,
                "replace an existing run in --out (only a folder holding a fracflow run, and only once the new run "
                "has started)");
  run->add_flag("--quiet,-q", quiet, "no status lines");

  auto* check = app.add_subcommand("check", "validate a scenario and print every resolved parameter");
  check->add_option("scenario", scenario, "scenario file (TOML); none: the built-in default");
  check->add_option("--set,-s", sets, "override a parameter: --set key=value (repeatable)");
  bool skip_set_up = false;
  check->add_flag("--skip-set-up", skip_set_up,
                  "only the checks that need no sample or lattice (quicker for large samples; what run refuses once "
                  "the sample is built, such as a DEM time step above the critical one, is then not checked)");

  auto* resume = app.add_subcommand("resume", "continue a run from its last checkpoint");
  resume->add_option("dir", resume_dir, "results folder of the run")->required();
  resume->add_option("--threads,-j", threads, "OpenMP threads")->check(threads_range());
  resume->add_option("--max-wall", max_wall, "stop with a checkpoint after this many wall-clock seconds")
      ->check(CLI::NonNegativeNumber);
  resume->add_option("--max-steps", max_steps, "stop with a checkpoint once this time step is reached")
      ->check(CLI::NonNegativeNumber);
  resume->add_flag("--accept-edited-scenario", accept_edited,
                   "continue even though DIR/scenario.toml was edited since the run started (the changed keys are "
                   "recorded in summary.json)");
  resume->add_flag("--quiet,-q", quiet, "no status lines");

  auto* params = app.add_subcommand("params", "print the parameter reference of every driver (Markdown)");
  auto* drivers = app.add_subcommand("drivers", "list the drivers (loading protocols)");
  std::vector<std::pair<CLI::App*, cli::Command::Run>> extra;
  for (auto& c : cli::registered_commands()) {
    auto r = c.setup(app);
    extra.emplace_back(app.get_subcommand(c.name), std::move(r));
  }

  if (const std::string unknown = unknown_command(app, argc, argv); !unknown.empty()) {
    log::error("{}", unknown);
    return 2;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);  // prints help, the version, or the error and a hint
    return code == 0 ? 0 : 2;      // a bad command line is an input error like any other
  }
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
      const drivers::FlowCheckReport derived;  // what a flow driver's validate() derives (dt, tau, Mach...)
      auto l = batch::load_scenario_for_run(scenario, sets);
      if (!skip_set_up) {
        try {
          check_set_up(*l);
        } catch (const NumericalError& e) {
          log::error("{}", e.what());
          return 3;  // as run
        }
      }
      fmt::print("{}: valid{}; driver '{}' ({})\n\n{}", scenario.empty() ? "built-in default scenario" : scenario,
                 skip_set_up ? " (set-up not built: --skip-set-up)" : " (set-up built as run builds it; nothing written)",
                 l->driver->name, l->driver->summary, l->config.describe());
      if (!derived.text().empty()) fmt::print("\n{}", derived.text());
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
      // Refuses protected, foreign, busy and unwritable folders now; creates (or replaces) the
      // folder only when the driver calls opt.begin_output, after its set-up has passed.
      NewRunFolder folder(out_dir, overwrite, scenario);
      opt.out_dir = out_dir;
      opt.progress_interval_s = quiet ? 0 : l->config.real("output.progress_interval");
      opt.begin_output = [&folder, &cfg = l->config, resolved = l->config.resolved_toml(), cmd = command_line(argc, argv)] {
        warn_unread_keys(cfg);
        // Until now a signal ends the process at once (nothing is written yet, an old run is
        // untouched); from here on it asks the driver for a checkpoint.
        install_stop_signal_handlers();
        folder.begin(resolved, cmd);
      };
      opt.abort_file = opt.out_dir / "ABORT";
      return execute(*l, opt, &folder);
    }
    if (*resume) {
      const fs::path dir(resume_dir);
      if (!fs::exists(dir))
        throw InputError(fmt::format("'{}' does not exist: no run wrote it (a run creates its folder once its sample or "
                                     "lattice is built; one stopped before that left nothing); start it with fracflow "
                                     "run SCENARIO --out {}",
                                     resume_dir, resume_dir));
      if (!fs::exists(dir / "scenario.toml"))
        throw InputError(fmt::format("'{}' is not a fracflow results folder (no scenario.toml)", resume_dir));
      if (!fs::exists(dir / "checkpoint"))
        throw InputError(fmt::format("'{}' has no checkpoint/ to resume from (the run stopped before writing one); "
                                     "run it again with fracflow run SCENARIO --out {} --overwrite ({}/scenario.toml "
                                     "holds its parameters: copy it out of the folder to use it as SCENARIO)",
                                     resume_dir, resume_dir, resume_dir));
      const FolderLock lock = FolderLock::acquire(dir);  // one writer per folder, until this process ends
      auto l = batch::load_scenario_for_run((dir / "scenario.toml").string(), {}, /*resume=*/true);
      opt.accepted_scenario_changes = edited_scenario(dir, *l, accept_edited);
      opt.out_dir = dir;
      opt.resume = true;
      opt.abort_file = dir / "ABORT";
      opt.progress_interval_s = quiet ? 0 : l->config.real("output.progress_interval");
      std::error_code ec;
      fs::remove(opt.abort_file, ec);
      install_stop_signal_handlers();
      return execute(*l, opt, nullptr);
    }
  } catch (const InputError& e) {
    log::error("{}", e.what());
    return 2;
  } catch (const fs::filesystem_error& e) {  // a folder or file that cannot be made or read
    log::error("{}", e.what());
    return 2;
  } catch (const Error& e) {
    log::error("{}", e.what());
    return 1;
  } catch (const std::exception& e) {
    log::error("{}", e.what());
    return 1;
  }
  return 0;
}
