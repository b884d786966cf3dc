#include "io/plot.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/log.hpp"
#include "io/json_out.hpp"

extern char** environ;

namespace ff {

namespace {

constexpr const char* kPython = "/usr/bin/python3";
constexpr int kMissingModules = 3;  // plot_series.py's exit code when matplotlib/numpy are absent

// "python3/matplotlib is missing" is said once per process, not once per figure.
std::atomic<bool> g_unavailable_warned{false};

nlohmann::json to_json(const PlotJob& j) {
  const PlotSpec& s = j.spec;
  return {{"csv", j.csv.string()},       {"png", j.png.string()},     {"title", s.title},
          {"xlabel", s.xlabel},          {"ylabel", s.ylabel},        {"y2label", s.y2label},
          {"x", s.x},                    {"y", s.y},                  {"y2", s.y2},
          {"x_scale", s.x_scale},        {"y_scale", s.y_scale},      {"y2_scale", s.y2_scale},
          {"reference_csv", s.reference_csv.string()}, {"ref_x", s.ref_x}, {"ref_y", s.ref_y},
          {"ref_label", s.ref_label},    {"logx", s.logx},            {"logy", s.logy},
          {"equal_aspect", s.equal_aspect}, {"y_labels", s.y_labels}};
}

std::string last_line(const std::filesystem::path& log) {
  std::ifstream in(log);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  return last;
}

// Runs python3 script spec_json with stdout/stderr to `log`; returns the exit status or -1.
int run_python(const std::filesystem::path& script, const std::filesystem::path& spec_json, const std::filesystem::path& log) {
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, STDOUT_FILENO, STDERR_FILENO);
  std::string a0 = kPython, a1 = script.string(), a2 = spec_json.string();
  char* argv[] = {a0.data(), a1.data(), a2.data(), nullptr};
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, kPython, &fa, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) return -1;
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

void warn_unavailable(const std::string& why) {
  if (!g_unavailable_warned.exchange(true)) log::warn("plots are skipped: {}", why);
}

}  // namespace

std::filesystem::path scripts_dir() {
  if (const char* env = std::getenv("FRACFLOW_SCRIPTS"); env && *env) return env;
  return std::filesystem::path(FRACFLOW_SOURCE_DIR) / "scripts";
}

int plot_series(std::span<const PlotJob> jobs) {
  if (jobs.empty()) return 0;
  try {
    const auto script = scripts_dir() / "plot_series.py";
    if (::access(kPython, X_OK) != 0) {
      warn_unavailable(fmt::format("{} not found", kPython));
      return 0;
    }
    if (!std::filesystem::exists(script)) {
      warn_unavailable(fmt::format("'{}' not found (set FRACFLOW_SCRIPTS to the scripts folder)", script.string()));
      return 0;
    }
    static std::atomic<int> counter{0};
    const auto tmp = std::filesystem::temp_directory_path() /
                     fmt::format("fracflow-plot-{}-{}", static_cast<long>(::getpid()), counter++);
    auto spec_file = tmp, log_file = tmp;
    spec_file += ".json";
    log_file += ".log";
    nlohmann::json all = nlohmann::json::array();
    for (auto& j : jobs) {
      all.push_back(to_json(j));
      std::error_code ec;
      std::filesystem::remove(j.png, ec);  // a stale PNG must not pass for a fresh one
    }
    write_json_atomic(spec_file, all);
    const int rc = run_python(script, spec_file, log_file);
    const std::string why = last_line(log_file);
    std::error_code ec;
    std::filesystem::remove(spec_file, ec);
    std::filesystem::remove(log_file, ec);
    if (rc == kMissingModules) {
      warn_unavailable(why.empty() ? "matplotlib or numpy is missing" : why);
      return 0;
    }
    int written = 0;
    for (auto& j : jobs) written += std::filesystem::exists(j.png) ? 1 : 0;
    if (rc != 0 || written != static_cast<int>(jobs.size()))
      log::warn("plotting failed ({} of {} figures written; {} exited with {}): {}", written, jobs.size(), script.string(),
                rc, why.empty() ? "no message" : why);
    return written;
  } catch (const std::exception& e) {  // plotting never stops a run
    log::warn("plotting failed: {}", e.what());
    return 0;
  }
}

bool plot_series(const std::filesystem::path& csv, const std::filesystem::path& png, const PlotSpec& spec) {
  const PlotJob job{csv, png, spec};
  return plot_series(std::span<const PlotJob>(&job, 1)) == 1;
}

}  // namespace ff
