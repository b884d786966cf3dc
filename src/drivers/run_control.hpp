// When a driver's time loop writes a checkpoint and when it stops early: one rule for every
// driver. Checkpoints come by wall clock (output.checkpoint_wall_interval), so a run killed at
// any moment (kill -9, power loss) loses at most that much work whatever its step count; a run
// stops with a checkpoint on SIGINT/SIGTERM, the ABORT file, --max-wall or --max-steps.
#pragma once
#include <chrono>
#include <string>

#include "drivers/driver.hpp"
#include "io/checkpoint.hpp"
#include "io/params.hpp"

namespace ff::drivers {

class RunControl {
 public:
  // Reads output.checkpoint_wall_interval; the wall clock starts now.
  RunControl(const Config& cfg, const RunOptions& opt);

  // Why the run must checkpoint and stop now at `step` (empty: go on). A stop signal is
  // named (SIGINT, SIGTERM); the reason is logged by the caller's status line.
  std::string stop_reason(long step) const;
  // True (and logged) when a resumed run's checkpoint is already at or past --max-steps: the run
  // must stop before stepping and write nothing (it ran on to its next row and saved a checkpoint
  // past the asked step; session 50).
  bool resumed_at_max_steps(long step) const;
  // True when output.checkpoint_wall_interval seconds have passed since the last checkpoint.
  bool checkpoint_due() const;
  // Restarts the wall-clock interval (call after every checkpoint written).
  void checkpoint_written();
  double elapsed_s() const;  // wall-clock seconds since construction (this session; --max-wall)
  // The whole run's wall time: the earlier sessions' (as their last checkpoint recorded it: work
  // done after it was redone, and is counted once) plus this one's. record() stores it in a
  // checkpoint (kWallTag), restore() reads it back on resume (absent in older checkpoints: 0).
  double run_wall_s() const { return earlier_s_ + elapsed_s(); }
  void record(CheckpointWriter& w) const;
  void restore(CheckpointReader& r);
  static constexpr const char* kWallTag = "run.wall_s";

 private:
  using Clock = std::chrono::steady_clock;
  const RunOptions& opt_;
  double wall_interval_s_ = 0, earlier_s_ = 0;
  Clock::time_point start_, last_checkpoint_;
};

// The message of an interruption, e.g. "stopping at step 1200 (SIGINT): checkpoint written".
void log_interruption(const std::string& reason, long step);

}  // namespace ff::drivers
