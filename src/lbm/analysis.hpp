// Post-processing shared by the flow drivers and the validation tests: profiles on a
// cell-centred line, time averages and oscillation frequency (Strouhal number).
#pragma once
#include <span>

namespace ff::lbm {

// Value at `pos` of a cell-centred profile: v[j] sits at (j + 1/2) h on [0, n h], with wall
// values v_lo at 0 and v_hi at n h. Linear interpolation.
double interpolate_profile(std::span<const double> v, double h, double pos, double v_lo, double v_hi);

// Statistics of a signal v(t) over t >= t_from: mean, extremes, and the frequency from the
// upward crossings of the mean (linear interpolation between samples; 0 if fewer than two).
struct Oscillation {
  double mean = 0, min = 0, max = 0;
  double frequency = 0;               // 1 / mean period
  int cycles = 0;                     // full periods seen
  double first_up = 0, last_up = 0;   // times of the first and last upward crossing
};
Oscillation analyse_oscillation(std::span<const double> t, std::span<const double> v, double t_from);

// Time average of v(t) over [t0, t1] (trapezoidal rule, linear interpolation at the ends);
// with the crossings of an Oscillation it averages over whole periods.
double time_average(std::span<const double> t, std::span<const double> v, double t0, double t1);

// Smallest and largest sample of v(t) with t0 <= t <= t1, and the time of the largest (the
// last one on ties); NaN if no sample lies in the window.
struct Extremes {
  double min = 0, max = 0;
  double t_max = 0;
};
Extremes extremes(std::span<const double> t, std::span<const double> v, double t0, double t1);

// v at time s, linear interpolation between samples; NaN outside [t.front(), t.back()].
double interpolate_series(std::span<const double> t, std::span<const double> v, double s);

}  // namespace ff::lbm
