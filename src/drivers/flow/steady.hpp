// The steady-state stop of the flow drivers (run.steady_tolerance; issue 14).
//
// A velocity inlet and a pressure outlet (or two walls) leave the domain ringing with its
// longitudinal acoustic modes for a long time (DFG 2D-1: Cd +-2% at 10 s, +-0.2% at 40 s), so
// sample-to-sample changes never fall below a small tolerance. The monitored value is therefore
// averaged over a window of one period of the slowest acoustic mode, 4 L / c_s (L: the largest
// non-periodic extent of the domain): a whole number of periods of every longitudinal mode with
// a velocity-pressure pair of ends (quarter-wave: 4 L / ((2k + 1) c_s)) or two closed ends
// (half-wave: 2 L / (k c_s)), so the window mean removes them. The drift compares that mean
// with the one kSteadyLag windows earlier and takes the largest relative difference over every
// window alignment within the last window (a slow beat between the window and an oscillation
// of another period, as in vortex shedding, shows up at some alignment). A value approaching
// its limit exponentially with a time constant tau_r up to ~kSteadyLag windows stays within
// the drift of that limit (the change over kSteadyLag windows is >= (e - 1) times what
// remains).
#pragma once
#include <algorithm>
#include <cmath>
#include <limits>

namespace ff::drivers {

inline constexpr long kSteadyMinSamples = 10;  // samples per window, at least
inline constexpr long kSteadyLag = 3;          // windows between the two means compared

// Relative drift of the window mean of the monitored series v(0..n-1) (v(i): the i-th value
// after the inflow ramp), window w samples; infinity until (kSteadyLag + 1) w values exist.
template <class V>
double steady_drift(const V& v, long n, long w) {
  const long lag = kSteadyLag * w;
  if (w < 1 || n < lag + w + w - 1) return std::numeric_limits<double>::infinity();
  // Sliding sums of the window ending at e and of the one ending at e - lag, for the last w ends.
  double now = 0, before = 0;
  const long e0 = n - w;  // first end considered
  for (long i = e0 - w + 1; i <= e0; ++i) {
    now += v(i);
    before += v(i - lag);
  }
  double drift = 0;
  for (long e = e0;; ++e) {
    const double a = now / double(w), b = before / double(w);
    const double d = std::abs(a - b) / std::max(std::abs(a), 1e-300);
    if (!(d == d)) return std::numeric_limits<double>::infinity();
    drift = std::max(drift, d);
    if (e + 1 >= n) break;
    now += v(e + 1) - v(e + 1 - w);
    before += v(e + 1 - lag) - v(e + 1 - lag - w);
  }
  return drift;
}

}  // namespace ff::drivers
