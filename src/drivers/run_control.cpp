#include "drivers/run_control.hpp"

#include <fmt/format.h>

#include <filesystem>

#include "core/interrupt.hpp"
#include "core/log.hpp"

namespace ff::drivers {

RunControl::RunControl(const Config& cfg, const RunOptions& opt)
    : opt_(opt), wall_interval_s_(cfg.real("output.checkpoint_wall_interval")), start_(Clock::now()),
      last_checkpoint_(start_) {}

double RunControl::elapsed_s() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }

bool RunControl::checkpoint_due() const {
  return wall_interval_s_ > 0 && std::chrono::duration<double>(Clock::now() - last_checkpoint_).count() >= wall_interval_s_;
}

void RunControl::checkpoint_written() { last_checkpoint_ = Clock::now(); }

void RunControl::record(CheckpointWriter& w) const { w.put_value(kWallTag, run_wall_s()); }

void RunControl::restore(CheckpointReader& r) {
  if (r.has(kWallTag)) earlier_s_ = r.get_value<double>(kWallTag);
}

std::string RunControl::stop_reason(long step) const {
  if (stop_requested()) return fmt::format("{} received", stop_signal_name());
  if (!opt_.abort_file.empty() && std::filesystem::exists(opt_.abort_file))
    return fmt::format("the file {} appeared", opt_.abort_file.string());
  if (opt_.max_steps > 0 && step >= opt_.max_steps) return fmt::format("step {} reached (--max-steps)", opt_.max_steps);
  if (opt_.max_wall_s > 0 && elapsed_s() >= opt_.max_wall_s)
    return fmt::format("{} s of wall-clock time reached (--max-wall)", opt_.max_wall_s);
  return {};
}

bool RunControl::resumed_at_max_steps(long step) const {
  if (!opt_.resume || opt_.max_steps <= 0 || step < opt_.max_steps) return false;
  log::info("the checkpoint is at step {}, at or past --max-steps {}: nothing to do (the folder is unchanged)", step,
            opt_.max_steps);
  return true;
}

void log_interruption(const std::string& reason, long step) {
  log::info("{}: checkpoint written at step {}; the run stops here", reason, step);
}

}  // namespace ff::drivers
