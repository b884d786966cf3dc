#include "drivers/run_estimate.hpp"

#include <fmt/format.h>

#include <cmath>

#include "core/error.hpp"
#include "core/log.hpp"

namespace ff::drivers {

namespace {
// The speed is measured over at least this many steps and this much wall time (start-up
// effects, e.g. the first neighbour search, would otherwise dominate it).
constexpr long kTimedSteps = 200;
constexpr double kTimedSeconds = 1.0;

std::string steps_text(double steps) {
  if (steps >= 1e12) return fmt::format("{:.3g}", steps);
  if (steps >= 1e9) return fmt::format("{:.1f} billion", steps / 1e9);
  return fmt::format("{:.1f} million", steps / 1e6);
}
}  // namespace

std::string duration_text(double s) {
  if (!(s >= 0) || !std::isfinite(s)) return "an unknown time";
  const long t = std::lround(s);
  if (t >= 86400) return fmt::format("about {} d {} h", t / 86400, (t % 86400) / 3600);
  if (t >= 3600) return fmt::format("about {} h {} min", t / 3600, (t % 3600) / 60);
  if (t >= 60) return fmt::format("about {} min", std::lround(s / 60));
  return fmt::format("about {} s", t);
}

void refuse_endless_run(double steps, std::string_view shorten, double dt) {
  if (steps <= kMaxRunSteps) return;
  throw InputError(fmt::format("this run would need {:.3g} time steps{}, more than the {:.0e} a run may take (at a million "
                               "steps a second that is over 11 days): {} shorten it{}",
                               steps, dt > 0 ? fmt::format(" of {:.3g} s", dt) : std::string(), kMaxRunSteps, shorten,
                               dt > 0 ? ", and so does a longer time step (the log above says what set it: a stiffness, "
                                        "modulus or density far off makes it tiny)"
                                      : ""));
}

std::string long_run_notice(double steps, double steps_per_s, std::string_view shorten) {
  if (!(steps > kLongRunSteps)) return {};
  const std::string time = steps_per_s > 0 ? fmt::format("at the measured ~{:.0f} steps/s that is {}", steps_per_s,
                                                          duration_text(steps / steps_per_s))
                                           : std::string("the time it takes follows from the first steps");
  return fmt::format("this run needs up to {} steps; {}; {} shorten it", steps_text(steps), time, shorten);
}

LongRunNotice::LongRunNotice(double steps, std::string shorten, long first_step)
    : steps_(steps), shorten_(std::move(shorten)), first_step_(first_step), pending_(steps > kLongRunSteps),
      start_(std::chrono::steady_clock::now()) {
  if (pending_) log::info("{}", long_run_notice(steps_, 0, shorten_));
}

void LongRunNotice::update(long step) {
  if (!pending_) return;
  const long done = step - first_step_;
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  if (done < kTimedSteps || s < kTimedSeconds) return;
  pending_ = false;
  log::info("{}", long_run_notice(steps_ - static_cast<double>(done), static_cast<double>(done) / s, shorten_));
}

}  // namespace ff::drivers
