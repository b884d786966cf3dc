#include "batch/run_case.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <omp.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cmath>
#include <deque>
#include <fstream>
#include <limits>

#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "core/log.hpp"
#include "io/run_folder.hpp"
#include "io/scenario.hpp"

extern char** environ;

namespace fs = std::filesystem;

namespace ff::batch {

std::unique_ptr<LoadedScenario> load_scenario_for_run(const std::string& path, const std::vector<std::string>& overrides,
                                                      bool resume) {
  const std::string text = path.empty() ? std::string(default_scenario_text()) : read_text_file(path);
  const std::string source = path.empty() ? "<built-in default scenario>" : path;
  const auto entries = parse_toml_flat(text, source);  // parsed once: a large file costs one pass
  std::string driver_name = peek_driver(entries, source);
  for (auto& o : overrides)
    if (o.rfind("driver=", 0) == 0) driver_name = o.substr(7);
  if (driver_name.empty()) {
    if (all_drivers().empty()) throw InputError("no driver is built into this fracflow");
    driver_name = std::string(all_drivers().front().name);
  }
  auto l = std::make_unique<LoadedScenario>();
  l->driver = &find_driver(driver_name);
  l->table = parameter_table(*l->driver);
  l->config = load_scenario(l->table, path, entries, overrides);
  if (!resume && l->driver->validate) l->driver->validate(l->config);
  return l;
}

namespace {
// The driver reads the thread count from the OpenMP runtime and quiet is a process-wide flag: both
// set for one in-process run and restored afterwards.
class ThreadsAndQuiet {
 public:
  ThreadsAndQuiet(int threads, bool quiet) : threads_(omp_get_max_threads()), quiet_(log::quiet()) {
    omp_set_num_threads(threads);
    log::quiet() = quiet || quiet_;
  }
  ~ThreadsAndQuiet() {
    omp_set_num_threads(threads_);
    log::quiet() = quiet_;
  }
  ThreadsAndQuiet(const ThreadsAndQuiet&) = delete;
  ThreadsAndQuiet& operator=(const ThreadsAndQuiet&) = delete;

 private:
  int threads_;
  bool quiet_;
};
}  // namespace

RunStatus run_in_process(const std::string& scenario_path, const std::vector<std::string>& overrides,
                         const InProcessRun& run) {
  auto l = load_scenario_for_run(scenario_path, overrides);  // every key validated before anything is written
  if (stop_requested()) return RunStatus::Interrupted;      // a batch told to stop starts no new run
  // The same folder rules as `fracflow run` (never --overwrite here): created, with its marker,
  // lock and scenario.toml, only when the driver's set-up has passed (opt.begin_output).
  NewRunFolder folder(run.out_dir, false, scenario_path);
  std::string command = "run " + (scenario_path.empty() ? std::string("(built-in default)") : scenario_path);
  for (auto& o : overrides) command += " --set " + o;
  RunOptions opt;
  opt.out_dir = run.out_dir;
  opt.threads = std::max(1, run.threads);
  opt.max_steps = run.max_steps;
  opt.max_wall_s = run.max_wall_s;
  opt.abort_file = run.out_dir / "ABORT";
  opt.progress_interval_s = run.quiet ? 0 : l->config.real("output.progress_interval");
  opt.begin_output = [&folder, resolved = l->config.resolved_toml(), command] {
    // As `fracflow run`: from here on SIGINT/SIGTERM ask the driver for a checkpoint and a stop
    // (before, the process just ends: nothing is written yet). A second signal still kills.
    install_stop_signal_handlers();
    folder.begin(resolved, command);
  };
  const ThreadsAndQuiet scoped(opt.threads, run.quiet);
  try {
    return l->driver->run(l->config, opt);
  } catch (const InputError&) {
    folder.discard_if_empty();  // a refused run leaves nothing behind, as with `fracflow run`
    throw;
  }
}

RunStatus resume_in_process(const fs::path& dir, const InProcessRun& run) {
  if (!fs::exists(dir / "scenario.toml") || !fs::exists(dir / "checkpoint"))
    throw InputError(fmt::format("'{}' holds no run with a checkpoint to resume from", dir.string()));
  const FolderLock lock = FolderLock::acquire(dir);  // one writer per folder
  auto l = load_scenario_for_run((dir / "scenario.toml").string(), {}, /*resume=*/true);
  RunOptions opt;
  opt.out_dir = dir;
  opt.resume = true;
  opt.threads = std::max(1, run.threads);
  opt.max_steps = run.max_steps;
  opt.max_wall_s = run.max_wall_s;
  opt.abort_file = dir / "ABORT";
  opt.progress_interval_s = run.quiet ? 0 : l->config.real("output.progress_interval");
  std::error_code ec;
  fs::remove(opt.abort_file, ec);  // the request that stopped it, as `fracflow resume` does
  if (stop_requested()) return RunStatus::Interrupted;
  install_stop_signal_handlers();  // a signal now stops the run after a checkpoint, as above
  const ThreadsAndQuiet scoped(opt.threads, run.quiet);
  return l->driver->run(l->config, opt);
}

double json_number(const nlohmann::json& j, std::initializer_list<const char*> path) {
  const nlohmann::json* p = &j;
  for (const char* k : path) {
    if (!p->is_object() || !p->contains(k)) return std::numeric_limits<double>::quiet_NaN();
    p = &(*p)[k];
  }
  return p->is_number() ? p->get<double>() : std::numeric_limits<double>::quiet_NaN();
}

RunSummary read_run_summary(const fs::path& out_dir) {
  const fs::path file = out_dir / "summary.json";
  std::ifstream in(file);
  if (!in) throw Error(fmt::format("'{}' is missing: the run did not finish", file.string()));
  RunSummary s;
  try {
    s.raw = nlohmann::json::parse(in);
  } catch (const std::exception& e) {
    throw Error(fmt::format("'{}' is not valid JSON: {}", file.string(), e.what()));
  }
  s.driver = s.raw.value("driver", std::string());
  s.ucs_Pa = json_number(s.raw, {"ucs_Pa"});
  s.peak_differential_stress_Pa = json_number(s.raw, {"peak_differential_stress_Pa"});
  s.confining_pressure_Pa = json_number(s.raw, {"confining_pressure_Pa"});
  s.youngs_modulus_Pa = json_number(s.raw, {"youngs_modulus_Pa"});
  s.poisson_ratio = json_number(s.raw, {"poisson_ratio"});
  s.strain_at_peak = json_number(s.raw, {"strain_at_peak"});
  s.cracks_tensile = json_number(s.raw, {"cracks", "tensile"});
  s.cracks_shear = json_number(s.raw, {"cracks", "shear"});
  s.cracks_total = json_number(s.raw, {"cracks", "total"});
  s.wall_time_s = json_number(s.raw, {"wall_time_s"});
  for (const char* block : {"peak", "elastic_fit"}) {
    const auto it = s.raw.find(block);
    if (it == s.raw.end() || !it->is_object() || !it->contains("reason") || !(*it)["reason"].is_string()) continue;
    s.missing += fmt::format("{}{}: {}", s.missing.empty() ? "" : "; ",
                             std::string(block) == "peak" ? "no peak" : "no elastic constants",
                             (*it)["reason"].get<std::string>());
  }
  return s;
}

std::optional<StrengthPoint> peak_strength(const RunSummary& s) {
  StrengthPoint p;
  if (s.driver == "ucs") {
    p = {0.0, s.ucs_Pa};
  } else if (s.driver == "triaxial") {
    p = {s.confining_pressure_Pa, s.confining_pressure_Pa + s.peak_differential_stress_Pa};
  } else {
    return std::nullopt;
  }
  if (!std::isfinite(p.sigma3) || !std::isfinite(p.sigma_p)) return std::nullopt;
  return p;
}

int run_child_process(const fs::path& executable, const std::vector<std::string>& args, const fs::path& log,
                      const fs::path& run_dir) {
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  posix_spawn_file_actions_adddup2(&fa, STDOUT_FILENO, STDERR_FILENO);
  posix_spawn_file_actions_addclose(&fa, STDIN_FILENO);
  std::vector<std::string> argv_store;
  argv_store.reserve(args.size() + 1);
  argv_store.push_back(executable.string());
  argv_store.insert(argv_store.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : argv_store) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, executable.c_str(), &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) return -1;
  int status = 0;
  bool passed_on = false;
  // Polled, not a blocking waitpid: the stop handlers use SA_RESTART, so a blocked waitpid would
  // never see the request.
  for (;;) {
    const pid_t w = waitpid(pid, &status, WNOHANG);
    if (w == pid) break;
    if (w < 0 && errno != EINTR) return -1;
    if (!passed_on && stop_requested()) {
      passed_on = true;
      if (!run_dir.empty() && is_fracflow_run(run_dir))
        std::ofstream(run_dir / "ABORT") << "stop request passed on by the batch command (" << stop_signal_name() << ")\n";
      else
        ::kill(pid, SIGTERM);
    }
    ::usleep(20000);
  }
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return -1;
}

std::string tail_of_file(const fs::path& path, int lines) {
  std::ifstream in(path);
  std::deque<std::string> last;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    last.push_back(line);
    if (static_cast<int>(last.size()) > lines) last.pop_front();
  }
  std::string out;
  for (auto& l : last) out += (out.empty() ? "" : "\n") + l;
  return out;
}

}  // namespace ff::batch
