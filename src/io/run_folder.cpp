#include "io/run_folder.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "core/log.hpp"
#include "fracflow/version.hpp"
#include "io/atomic_file.hpp"

namespace fs = std::filesystem;

namespace ff {

fs::path run_meta_dir(const fs::path& dir) { return dir / ".fracflow"; }
fs::path run_marker_file(const fs::path& dir) { return run_meta_dir(dir) / "run.json"; }
fs::path original_scenario_file(const fs::path& dir) { return run_meta_dir(dir) / "scenario.toml"; }
bool is_fracflow_run(const fs::path& dir) {
  std::error_code ec;
  return fs::is_regular_file(run_marker_file(dir), ec);
}

namespace {

// Absolute, symlinks resolved where the path exists, no trailing separator: two spellings of
// one folder compare equal.
fs::path normal(const fs::path& p) {
  std::error_code ec;
  fs::path a = fs::absolute(p, ec);
  if (ec) a = p;
  fs::path c = fs::weakly_canonical(a, ec);
  if (ec) c = a.lexically_normal();
  if (!c.has_filename() && c.has_relative_path()) c = c.parent_path();
  return c;
}

[[noreturn]] void refuse(const fs::path& dir, const std::string& flag, const std::string& what) {
  throw InputError(fmt::format("{} '{}' is {}: fracflow never writes a run into, or replaces, the current directory "
                               "or a folder above it, '/', the home folder or a folder that holds the scenario "
                               "file; choose a new folder, e.g. {} runs/NAME",
                               flag, dir.string(), what, flag));
}

fs::path lock_file(const fs::path& dir) { return run_meta_dir(dir) / "lock"; }

long read_pid(const fs::path& file) {
  std::ifstream in(file);
  long pid = 0;
  in >> pid;
  return in ? pid : 0;
}

std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

// This process's arguments, space-separated (for the marker of a batch folder).
std::string process_command_line() {
  std::ifstream in("/proc/self/cmdline", std::ios::binary);
  std::string s((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  while (!s.empty() && s.back() == '\0') s.pop_back();
  std::replace(s.begin(), s.end(), '\0', ' ');
  return s;
}

bool is_empty_dir(const fs::path& dir) {
  std::error_code ec;
  return fs::is_empty(dir, ec) && !ec;
}

// What an --out folder holds, once it has passed the refusals every new folder meets (protected
// folders, a file in the way). The callers word the refusals of the other cases.
enum class Existing { Nothing, OurRun, Foreign };
Existing existing_folder(const fs::path& dir, const fs::path& scenario_file) {
  refuse_protected_out_dir(dir, scenario_file);
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    throw InputError(fmt::format("--out '{}' is a file, not a folder; choose another folder with --out", dir.string()));
  if (!fs::exists(dir, ec) || is_empty_dir(dir)) return Existing::Nothing;
  return is_fracflow_run(dir) ? Existing::OurRun : Existing::Foreign;
}

// The lock of an old folder of ours that is to be replaced (refused while another process writes
// it), after checking that its parent, where the replacement happens, can be written.
FolderLock lock_for_replacement(const fs::path& dir) {
  probe_writable(dir.parent_path().empty() ? fs::path(".") : dir.parent_path());
  return FolderLock::acquire(dir);
}

// DIR/.fracflow/run.json: `fields` plus what every marker says.
void write_marker(const fs::path& dir, nlohmann::json fields) {
  fields["fracflow_run"] = 1;
  fields["version"] = kVersion;
  fields["created_utc"] = utc_now();
  fields["pid"] = static_cast<long>(::getpid());
  write_file_atomic(run_marker_file(dir), fields.dump(2) + "\n");
}

}  // namespace

void refuse_protected_out_dir(const fs::path& dir, const fs::path& scenario_file, const std::string& flag) {
  const fs::path target = normal(dir);
  if (target == target.root_path()) refuse(dir, flag, "the root folder");
  std::error_code ec;
  const fs::path cwd = normal(fs::current_path(ec));
  if (!ec)
    for (fs::path p = cwd;; p = p.parent_path()) {
      if (target == p) refuse(dir, flag, p == cwd ? "the current directory" : "a folder above the current directory");
      if (p == p.parent_path()) break;
    }
  if (const char* home = std::getenv("HOME"); home && *home && target == normal(home))
    refuse(dir, flag, "the home folder");
  if (!scenario_file.empty())
    for (fs::path p = normal(scenario_file).parent_path();; p = p.parent_path()) {
      if (target == p) refuse(dir, flag, fmt::format("a folder that holds the scenario file '{}'", scenario_file.string()));
      if (p == p.parent_path()) break;
    }
}

void probe_writable(const fs::path& dir, const std::string& flag) {
  fs::path at = normal(dir);
  std::error_code ec;
  while (!fs::exists(at, ec) && at != at.parent_path()) at = at.parent_path();
  if (!fs::is_directory(at, ec))
    throw InputError(fmt::format("{} '{}': '{}' is a file, not a folder; choose another folder with {}", flag,
                                 dir.string(), at.string(), flag));
  // access(2) is not enough: root passes it on folders it may not write (e.g. under /proc).
  // One name per call: threads of one process (calibrate's UCS run beside its triaxial sweep)
  // probe the same parent at once.
  static std::atomic<unsigned long> probes{0};
  const fs::path probe = at / fmt::format(".fracflow-probe-{}-{}", static_cast<long>(::getpid()), probes++);
  if (::mkdir(probe.c_str(), 0700) != 0) {
    const int err = errno;
    throw InputError(fmt::format("{} '{}' cannot be written: cannot create anything in '{}' ({}); choose a folder you "
                                 "can write with {}",
                                 flag, dir.string(), at.string(), std::strerror(err), flag));
  }
  ::rmdir(probe.c_str());
}

FolderLock& FolderLock::operator=(FolderLock&& o) noexcept {
  if (this != &o) {
    release();
    fd_ = std::exchange(o.fd_, -1);
  }
  return *this;
}

void FolderLock::release() {
  if (fd_ >= 0) ::close(fd_);  // closing the last descriptor drops the flock
  fd_ = -1;
}

FolderLock FolderLock::acquire(const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(run_meta_dir(dir), ec);
  const fs::path file = lock_file(dir);
  // O_CLOEXEC: child processes (plotting) must not keep the folder locked after we end.
  const int fd = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) {
    const int err = errno;
    throw InputError(fmt::format("cannot lock results folder '{}': cannot open '{}' ({})", dir.string(),
                                 file.string(), std::strerror(err)));
  }
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    ::close(fd);
    if (err != EWOULDBLOCK)
      throw InputError(fmt::format("cannot lock results folder '{}': {}", dir.string(), std::strerror(err)));
    const long pid = read_pid(file);
    throw InputError(fmt::format("results folder '{}' is in use by {} (a run or resume writing into it); wait until "
                                 "it ends or stop it (Ctrl-C, or create the file {}), or choose another folder with --out",
                                 dir.string(), pid > 0 ? fmt::format("process {}", pid) : std::string("another process"),
                                 (dir / "ABORT").string()));
  }
  // The pid is only for the message above; the flock itself is what guards the folder.
  const std::string pid = std::to_string(static_cast<long>(::getpid())) + "\n";
  if (::ftruncate(fd, 0) == 0 && ::pwrite(fd, pid.data(), pid.size(), 0) < 0) {
    // not fatal: the message then says "another process"
  }
  FolderLock l;
  l.fd_ = fd;
  return l;
}

NewRunFolder::NewRunFolder(fs::path dir, bool overwrite, const fs::path& scenario_file) : dir_(std::move(dir)) {
  const Existing existing = existing_folder(dir_, scenario_file);
  if (existing != Existing::Nothing) {
    if (existing == Existing::Foreign)
      throw InputError(fmt::format(
          "results folder '{}' is not empty and holds no fracflow run (no {}), so fracflow neither writes into it nor "
          "deletes it, with or without --overwrite; choose a new or empty folder with --out (a run made by an older "
          "fracflow has no marker: continue it with `fracflow resume {}`, or delete it yourself)",
          dir_.string(), run_marker_file(dir_).string(), dir_.string()));
    if (!overwrite)
      throw InputError(fmt::format("results folder '{}' already holds a run; pass --overwrite to replace it, --out to "
                                   "choose another folder, or `fracflow resume {}` to continue it",
                                   dir_.string(), dir_.string()));
    old_lock_ = lock_for_replacement(dir_);  // the swap renames in the parent
    replace_ = true;
  }
  probe_writable(dir_);
}

void NewRunFolder::begin(const std::string& resolved_toml, const std::string& command) {
  if (begun_) return;
  fs::path aside;
  if (replace_) {
    // Same parent, so rename(2) is atomic: the old run stays whole until the new folder exists.
    aside = dir_.parent_path() / fmt::format(".{}.fracflow-old-{}", normal(dir_).filename().string(),
                                             static_cast<long>(::getpid()));
    std::error_code ec;
    fs::rename(dir_, aside, ec);
    if (ec)
      throw Error(fmt::format("cannot move the old run '{}' aside to replace it: {}", dir_.string(), ec.message()));
  } else if (fs::exists(dir_) && !is_empty_dir(dir_)) {
    throw InputError(fmt::format("results folder '{}' was created by another process while this run was being set "
                                 "up; choose another folder with --out",
                                 dir_.string()));
  }
  try {
    fs::create_directories(dir_);
    lock_ = FolderLock::acquire(dir_);
    write_marker(dir_, {{"command", command}});
    write_file_atomic(original_scenario_file(dir_), resolved_toml);
    write_file_atomic(dir_ / "scenario.toml", resolved_toml);
  } catch (...) {
    if (replace_) {  // put the old run back
      std::error_code ec;
      lock_.release();
      fs::remove_all(dir_, ec);
      fs::rename(aside, dir_, ec);
    }
    throw;
  }
  begun_ = true;
  if (replace_) {
    std::error_code ec;
    fs::remove_all(aside, ec);
    old_lock_.release();
    if (ec) log::warn("the old run was moved to '{}' but could not be deleted: {}", aside.string(), ec.message());
  }
}

void NewRunFolder::discard_if_empty() {
  if (!begun_) return;
  if (fs::exists(dir_ / "series.csv") || fs::exists(dir_ / "checkpoint")) return;
  lock_.release();
  std::error_code ec;
  fs::remove_all(dir_, ec);
  begun_ = false;
}

FolderLock prepare_batch_folder(const fs::path& dir, bool overwrite, const std::string& what) {
  const Existing existing = existing_folder(dir, {});
  if (existing != Existing::Nothing) {
    if (existing == Existing::Foreign)
      throw InputError(fmt::format("{} '{}' is not empty and holds no fracflow results (no {}), so fracflow neither "
                                   "writes into it nor deletes it, with or without --overwrite; choose a new or empty "
                                   "folder with --out",
                                   what, dir.string(), run_marker_file(dir).string()));
    if (!overwrite)
      throw InputError(fmt::format("{} '{}' already holds results; pass --overwrite to replace it or --out to choose "
                                   "another folder",
                                   what, dir.string()));
    FolderLock old = lock_for_replacement(dir);
    fs::remove_all(dir);
  }
  probe_writable(dir);
  fs::create_directories(dir);
  FolderLock lock = FolderLock::acquire(dir);
  write_marker(dir, {{"kind", what}, {"command", process_command_line()}});
  return lock;
}

std::vector<ScenarioChange> scenario_changes(const std::vector<std::pair<std::string, ParamValue>>& original,
                                             const std::vector<std::pair<std::string, ParamValue>>& current) {
  std::map<std::string, const ParamValue*> before;
  for (auto& [k, v] : original) before[k] = &v;
  std::vector<ScenarioChange> out;
  for (auto& [k, v] : current) {
    auto it = before.find(k);
    if (it == before.end()) {
      out.push_back({k, "(absent)", format_value(v)});
      continue;
    }
    if (!(*it->second == v)) out.push_back({k, format_value(*it->second), format_value(v)});
    before.erase(it);
  }
  for (auto& [k, v] : original)
    if (before.count(k)) out.push_back({k, format_value(v), "(absent)"});
  return out;
}

std::string to_string(const ScenarioChange& c) { return fmt::format("{}: {} -> {}", c.key, c.before, c.after); }

}  // namespace ff
