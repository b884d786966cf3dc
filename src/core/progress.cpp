#include "core/progress.hpp"

#include <fmt/core.h>

#include <cstdio>

#include "core/log.hpp"

namespace ff {
Progress::Progress(std::string label, double interval_s)
    : label_(std::move(label)), interval_s_(interval_s),
      start_(std::chrono::steady_clock::now()), last_(start_) {}

double Progress::elapsed_s() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

std::string format_duration(double s) {
  if (s < 0 || s != s) return "?";
  const long t = static_cast<long>(s + 0.5);
  if (t >= 3600) return fmt::format("{}h{:02}m", t / 3600, (t % 3600) / 60);
  if (t >= 60) return fmt::format("{}m{:02}s", t / 60, t % 60);
  return fmt::format("{}s", t);
}

void Progress::update(long step, double sim_time, double fraction_done, const std::string& extra) {
  if (interval_s_ <= 0 || log::quiet()) return;
  const auto now = std::chrono::steady_clock::now();
  const double since = std::chrono::duration<double>(now - last_).count();
  if (since < interval_s_) return;
  const double rate = (step - last_step_) / since;
  const double total = elapsed_s();
  std::string eta = "?";
  if (fraction_done > 1e-6 && fraction_done <= 1.0) eta = format_duration(total * (1.0 - fraction_done) / fraction_done);
  fmt::print(stdout, "[{}] step {}  t = {:.4g} s  {:.0f} steps/s  elapsed {}  ETA {}{}{}\n", label_, step,
             sim_time, rate, format_duration(total), eta, extra.empty() ? "" : "  ", extra);
  std::fflush(stdout);
  last_ = now;
  last_step_ = step;
}
}  // namespace ff
