// Status line for long runs: step, simulated time, steps/s and ETA, printed every few seconds.
#pragma once
#include <chrono>
#include <string>

namespace ff {
class Progress {
 public:
  // `label`: what is running; `interval_s`: seconds between lines (0 disables).
  explicit Progress(std::string label, double interval_s = 5.0);
  // Call often; prints only when `interval_s` has passed. `fraction_done` in [0,1] drives the ETA
  // (pass a negative value when unknown).
  void update(long step, double sim_time, double fraction_done, const std::string& extra = {});
  double elapsed_s() const;

 private:
  std::string label_;
  double interval_s_;
  std::chrono::steady_clock::time_point start_, last_;
  long last_step_ = 0;
};
std::string format_duration(double seconds);
}  // namespace ff
