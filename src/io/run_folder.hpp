// A results folder of ours and the rules that keep results from being lost (issue 12):
// - a run folder carries a marker (DIR/.fracflow/run.json); --overwrite only ever replaces a
//   folder with that marker, and only once the new run is known to start (NewRunFolder::begin,
//   called by the driver through RunOptions::begin_output);
// - the current directory, its ancestors, '/', the home folder and the folders that hold the
//   scenario file are never results folders;
// - one folder, one writer: run and resume hold an flock(2) on DIR/.fracflow/lock for the life
//   of the process, so a crashed or killed process never leaves the folder locked;
// - DIR/.fracflow/scenario.toml keeps the scenario as resolved at the start, so resume can tell
//   which keys of DIR/scenario.toml were edited since.
#pragma once
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "io/params.hpp"

namespace ff {

std::filesystem::path run_meta_dir(const std::filesystem::path& dir);           // DIR/.fracflow
std::filesystem::path run_marker_file(const std::filesystem::path& dir);        // DIR/.fracflow/run.json
std::filesystem::path original_scenario_file(const std::filesystem::path& dir); // DIR/.fracflow/scenario.toml
// True when `dir` holds our marker (a run made by fracflow).
bool is_fracflow_run(const std::filesystem::path& dir);

// Throws InputError when `dir` is the current directory or one of its ancestors, '/', $HOME, or
// a folder that contains `scenario_file` (empty: none). `flag` names the option in the message.
void refuse_protected_out_dir(const std::filesystem::path& dir, const std::filesystem::path& scenario_file,
                              const std::string& flag = "--out");
// Throws InputError when `dir` cannot be created or written (read-only mount, permissions, a
// file in the way): creates and removes a probe folder in `dir`, or in its nearest existing
// ancestor when `dir` does not exist yet.
void probe_writable(const std::filesystem::path& dir, const std::string& flag = "--out");

// An flock(2) on DIR/.fracflow/lock, released when this object (or the process) ends.
class FolderLock {
 public:
  FolderLock() = default;
  // Takes the lock, creating DIR/.fracflow/lock; throws InputError naming the folder and the
  // holder's pid when another process holds it.
  static FolderLock acquire(const std::filesystem::path& dir);
  FolderLock(FolderLock&& o) noexcept : fd_(std::exchange(o.fd_, -1)) {}
  FolderLock& operator=(FolderLock&& o) noexcept;
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;
  ~FolderLock() { release(); }
  void release();
  bool held() const { return fd_ >= 0; }

 private:
  int fd_ = -1;
};

// The folder of a new run (`fracflow run --out DIR`, the runs of the batch tools).
class NewRunFolder {
 public:
  // Every check that can be made before the run starts; creates and deletes nothing (apart from
  // the writability probe). `dir` must be missing or empty, or hold a run of ours when
  // `overwrite` (whose lock is then taken and held until begin() replaces it). Throws InputError.
  NewRunFolder(std::filesystem::path dir, bool overwrite, const std::filesystem::path& scenario_file);
  // The run is known to start: replaces the old run (moved to a sibling name, then deleted) or
  // creates the folder, takes its lock and writes the marker (version, time, `command`),
  // DIR/scenario.toml and DIR/.fracflow/scenario.toml (both `resolved_toml`). Throws InputError
  // when another process created the folder meanwhile, ff::Error when it cannot write.
  void begin(const std::string& resolved_toml, const std::string& command);
  bool begun() const { return begun_; }
  const std::filesystem::path& dir() const { return dir_; }
  // After an input error from the driver: removes the folder begin() made when it holds no
  // results yet (no series.csv, no checkpoint/), so a refused run leaves nothing behind.
  void discard_if_empty();

 private:
  std::filesystem::path dir_;
  bool replace_ = false, begun_ = false;
  FolderLock old_lock_, lock_;
};

// The folder of a batch tool (`sweep`, `calibrate`, `validate-triaxial`; `what` names it in
// messages, e.g. "sweep folder"): the same refusals as NewRunFolder, then, with `overwrite`, the
// old folder of ours is deleted (the tools call this once every input has been checked), DIR is
// created with its marker and the returned lock is held while the tool writes.
FolderLock prepare_batch_folder(const std::filesystem::path& dir, bool overwrite, const std::string& what);

// One key whose resolved value differs between the scenario at the start of a run and now.
struct ScenarioChange {
  std::string key, before, after;  // "(absent)" when the key exists on one side only
};
// Every key whose value differs, in table order.
std::vector<ScenarioChange> scenario_changes(const std::vector<std::pair<std::string, ParamValue>>& original,
                                             const std::vector<std::pair<std::string, ParamValue>>& current);
std::string to_string(const ScenarioChange& c);  // "key: before -> after"

}  // namespace ff
