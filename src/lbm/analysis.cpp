#include "lbm/analysis.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace ff::lbm {

double interpolate_profile(std::span<const double> v, double h, double pos, double v_lo, double v_hi) {
  const std::size_t n = v.size();
  const double s = pos / h - 0.5;  // in units of cells from the first centre
  if (n == 0) return 0.0;
  if (s <= 0) {  // between the lower wall (at s = -1/2) and the first centre
    const double a = (s + 0.5) / 0.5;
    return v_lo + std::clamp(a, 0.0, 1.0) * (v[0] - v_lo);
  }
  if (s >= double(n - 1)) {
    const double a = (s - double(n - 1)) / 0.5;
    return v[n - 1] + std::clamp(a, 0.0, 1.0) * (v_hi - v[n - 1]);
  }
  const std::size_t j = std::size_t(s);
  const double a = s - double(j);
  return v[j] + a * (v[j + 1] - v[j]);
}

namespace {
// Times of upward crossings of `level` (t >= t_from).
std::vector<double> up_crossings(std::span<const double> t, std::span<const double> v, double level, double t_from) {
  std::vector<double> c;
  for (std::size_t i = 1; i < t.size(); ++i) {
    if (t[i - 1] < t_from) continue;
    const double a = v[i - 1] - level, b = v[i] - level;
    if (a < 0 && b >= 0) c.push_back(t[i - 1] + (t[i] - t[i - 1]) * (-a) / (b - a));
  }
  return c;
}
}  // namespace

Oscillation analyse_oscillation(std::span<const double> t, std::span<const double> v, double t_from) {
  Oscillation o;
  double sum = 0;
  std::size_t n = 0;
  o.min = INFINITY;
  o.max = -INFINITY;
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (t[i] < t_from) continue;
    sum += v[i];
    ++n;
    o.min = std::min(o.min, v[i]);
    o.max = std::max(o.max, v[i]);
  }
  if (n == 0) return Oscillation{};
  o.mean = sum / double(n);
  const auto c = up_crossings(t, v, o.mean, t_from);
  if (c.size() >= 2) {
    o.cycles = int(c.size()) - 1;
    o.frequency = double(o.cycles) / (c.back() - c.front());
    o.first_up = c.front();
    o.last_up = c.back();
  }
  return o;
}

double time_average(std::span<const double> t, std::span<const double> v, double t0, double t1) {
  double area = 0, span = 0;
  for (std::size_t i = 1; i < t.size(); ++i) {
    const double a = std::max(t[i - 1], t0), b = std::min(t[i], t1);
    if (b <= a || t[i] <= t[i - 1]) continue;
    auto at = [&](double s) { return v[i - 1] + (v[i] - v[i - 1]) * (s - t[i - 1]) / (t[i] - t[i - 1]); };
    area += 0.5 * (at(a) + at(b)) * (b - a);
    span += b - a;
  }
  return span > 0 ? area / span : 0.0;
}

Extremes extremes(std::span<const double> t, std::span<const double> v, double t0, double t1) {
  Extremes e{INFINITY, -INFINITY, NAN};
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (t[i] < t0 || t[i] > t1) continue;
    e.min = std::min(e.min, v[i]);
    if (v[i] >= e.max) {
      e.max = v[i];
      e.t_max = t[i];
    }
  }
  if (!(e.t_max == e.t_max)) return Extremes{NAN, NAN, NAN};
  return e;
}

double interpolate_series(std::span<const double> t, std::span<const double> v, double s) {
  if (t.empty() || s < t.front() || s > t.back()) return NAN;
  for (std::size_t i = 1; i < t.size(); ++i)
    if (s <= t[i]) return t[i] > t[i - 1] ? v[i - 1] + (v[i] - v[i - 1]) * (s - t[i - 1]) / (t[i] - t[i - 1]) : v[i];
  return v.back();
}

}  // namespace ff::lbm
