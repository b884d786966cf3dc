// A run that will take very long says so before it starts: the number of steps the scenario
// asks for (from its keys, before any step), then, once the first few hundred steps have
// given the speed, the wall time that makes, each with the keys that shorten it. Shorter runs
// print nothing.
#pragma once
#include <chrono>
#include <string>
#include <string_view>

namespace ff::drivers {

// Runs of more steps than this announce their length.
constexpr double kLongRunSteps = 1e6;
// Runs of more steps than this are refused: at a million steps a second (a small 2D sample on
// one core) they would take over 11 days, and step counters and times lose their meaning long
// before 1e15 (a step of 1e-154 s from a bulk modulus of 1e300 Pa, an end time of 1e300 s).
constexpr double kMaxRunSteps = 1e12;

// Throws InputError when `steps` (the run's planned steps, after set-up) exceeds kMaxRunSteps or
// is not a number, naming `shorten`; called before the run writes anything, so that `check`
// refuses it too.
// `dt` (> 0) is named in the message (a step far too short is the usual cause).
void refuse_endless_run(double steps, std::string_view shorten, double dt = 0);

// "about 3 h 10 min", "about 12 min", "about 40 s".
std::string duration_text(double seconds);

// The notice for a run of up to `steps` steps at `steps_per_s` (0: not measured yet), naming
// `shorten` (e.g. "ucs.platen_velocity or ucs.max_strain"); empty when steps <= kLongRunSteps.
std::string long_run_notice(double steps, double steps_per_s, std::string_view shorten);

// Prints the step count at construction (after set-up) and the time estimate once from the
// speed of the first steps; both only for long runs. Allocates nothing in update().
class LongRunNotice {
 public:
  // `steps`: the run's steps from `first_step` on (an upper bound: stop criteria may end it sooner).
  LongRunNotice(double steps, std::string shorten, long first_step);
  // Call once per output row with the current step count.
  void update(long step);

 private:
  double steps_;
  std::string shorten_;
  long first_step_;
  bool pending_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace ff::drivers
