#include "batch/calibration.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "batch/mohr_coulomb.hpp"
#include "core/error.hpp"
#include "core/types.hpp"

namespace ff::batch {

void check_calibration_input(const MicroParameters& p, const CalibrationSettings& s) {
  auto positive = [](double v, const char* name, const char* allowed) {
    if (!(v > 0) || !std::isfinite(v))
      throw InputError(fmt::format("{} = {}: must be {}", name, v, allowed));
  };
  positive(s.target.youngs_modulus_Pa, "--target-E", "a positive Young's modulus in Pa, e.g. 2.37e9");
  positive(s.target.ucs_Pa, "--target-ucs", "a positive strength in Pa, e.g. 14.97e6");
  if (!(s.target.poisson_ratio > -1 && s.target.poisson_ratio < 0.5))
    throw InputError(fmt::format("--target-nu = {}: must lie in (-1, 0.5), e.g. 0.35", s.target.poisson_ratio));
  positive(s.youngs_modulus_tolerance, "--tol-E", "a positive relative tolerance, e.g. 0.05");
  positive(s.ucs_tolerance, "--tol-ucs", "a positive relative tolerance, e.g. 0.05");
  positive(s.poisson_tolerance, "--tol-nu", "a positive absolute tolerance, e.g. 0.03");
  positive(s.poisson_slope_guess, "--nu-slope", "a positive d nu / d ln(kratio), e.g. 0.08");
  if (s.max_iterations < 1) throw InputError(fmt::format("--max-iter = {}: must be at least 1", s.max_iterations));
  if (!(s.max_factor > 1)) throw InputError(fmt::format("max_factor = {}: must be above 1", s.max_factor));
  positive(p.bond_emod_Pa, "bond emod", "positive");
  positive(p.contact_emod_Pa, "contact emod", "positive");
  positive(p.bond_kratio, "bond kratio", "positive");
  positive(p.contact_kratio, "contact kratio", "positive");
  positive(p.tensile_strength_Pa, "bond tensile_strength", "positive");
  positive(p.cohesion_Pa, "bond cohesion", "positive");
  if (s.target.slope_b != 0) {
    if (!(s.target.slope_b > 0) || !std::isfinite(s.target.slope_b))
      throw InputError(fmt::format("--target-b = {}: must be positive (the slope of the peak differential stress "
                                   "against sigma3; seed 000 Eq. 1: 3.54)", s.target.slope_b));
    positive(s.slope_tolerance, "--tol-b", "a positive relative tolerance, e.g. 0.1");
    positive(s.slope_gradient_guess, "--b-gradient", "a positive d b / d tan(phi_b), e.g. 4.6");
    if (!(p.friction_angle_deg >= 0 && p.friction_angle_deg < s.max_friction_angle_deg))
      throw InputError(fmt::format("bond friction_angle = {} deg: must lie in [0, {}) to be calibrated",
                                   p.friction_angle_deg, s.max_friction_angle_deg));
  }
}

void score_step(CalibrationStep& st, const CalibrationSettings& s) {
  st.youngs_modulus_error = (st.measured.youngs_modulus_Pa - s.target.youngs_modulus_Pa) / s.target.youngs_modulus_Pa;
  st.poisson_error = st.measured.poisson_ratio - s.target.poisson_ratio;
  st.ucs_error = (st.measured.ucs_Pa - s.target.ucs_Pa) / s.target.ucs_Pa;
  const bool with_b = s.calibrates_slope() && st.slope_measured;
  st.slope_error = with_b ? (st.measured.slope_b - s.target.slope_b) / s.target.slope_b : 0.0;
  st.converged = std::abs(st.youngs_modulus_error) < s.youngs_modulus_tolerance &&
                 std::abs(st.poisson_error) < s.poisson_tolerance && std::abs(st.ucs_error) < s.ucs_tolerance &&
                 (!s.calibrates_slope() || (st.slope_measured && std::abs(st.slope_error) < s.slope_tolerance));
}

double worst_scaled_error_without_slope(const CalibrationStep& st, const CalibrationSettings& s) {
  const double w = std::max({std::abs(st.youngs_modulus_error) / s.youngs_modulus_tolerance,
                             std::abs(st.poisson_error) / s.poisson_tolerance, std::abs(st.ucs_error) / s.ucs_tolerance});
  return std::isfinite(w) ? w : HUGE_VAL;
}

double worst_scaled_error(const CalibrationStep& st, const CalibrationSettings& s) {
  if (s.calibrates_slope() && !st.slope_measured) return HUGE_VAL;
  const double w = std::max(worst_scaled_error_without_slope(st, s), std::abs(st.slope_error) / s.slope_tolerance);
  return std::isfinite(w) ? w : HUGE_VAL;
}

namespace {

double tan_deg(double deg) { return std::tan(deg * kPi / 180); }

// Two parameter sets share a friction angle (they are rounded to 6 digits, so equal means equal).
bool same_angle(double a, double b) { return std::abs(a - b) <= 1e-9 * std::max(1.0, std::abs(a)); }

// The least-squares slope of y on x when it is usable: a spread of at least 2% in x (per point)
// and a slope no flatter than a tenth of the guess (otherwise the measurement scatter would send
// the parameter far away); else nothing.
std::optional<double> usable_slope(std::span<const double> x, std::span<const double> y, double guess) {
  if (x.size() < 2) return std::nullopt;
  const LineFit line = fit_line(x, y);
  if (line.sxx > 1e-4 * static_cast<double>(x.size()) && line.slope > 0.1 * guess) return line.slope;
  return std::nullopt;
}

// d nu / d ln(kratio): from the runs at one friction angle, the current one first, else the
// latest earlier angle with a usable fit, else the guess.
double poisson_slope(std::span<const CalibrationStep> history, const CalibrationSettings& s) {
  std::vector<double> angles;  // distinct angles, latest first
  for (auto it = history.rbegin(); it != history.rend(); ++it)
    if (std::none_of(angles.begin(), angles.end(), [&](double a) { return same_angle(a, it->params.friction_angle_deg); }))
      angles.push_back(it->params.friction_angle_deg);
  for (double angle : angles) {
    std::vector<double> x, y;
    for (auto& h : history)
      if (same_angle(h.params.friction_angle_deg, angle))
        x.push_back(std::log(h.params.bond_kratio)), y.push_back(h.measured.poisson_ratio);
    if (const auto slope = usable_slope(x, y, s.poisson_slope_guess)) return *slope;
  }
  return s.poisson_slope_guess;
}

// d b / d tan(phi_b): from the runs that measured b, else the guess.
double slope_gradient(std::span<const CalibrationStep> history, const CalibrationSettings& s) {
  std::vector<double> x, y;
  for (auto& h : history)
    if (h.slope_measured) x.push_back(tan_deg(h.params.friction_angle_deg)), y.push_back(h.measured.slope_b);
  return usable_slope(x, y, s.slope_gradient_guess).value_or(s.slope_gradient_guess);
}

bool within_tolerances_without_slope(const CalibrationStep& st, const CalibrationSettings& s) {
  return worst_scaled_error_without_slope(st, s) < 1;
}

}  // namespace

MicroParameters next_parameters(std::span<const CalibrationStep> history, const CalibrationSettings& s) {
  if (history.empty()) throw Error("next_parameters: no run to update from");
  const CalibrationStep& last = history.back();
  const MacroProperties& m = last.measured;
  if (!(m.youngs_modulus_Pa > 0) || !(m.ucs_Pa > 0) || !std::isfinite(m.youngs_modulus_Pa) || !std::isfinite(m.ucs_Pa) ||
      !std::isfinite(m.poisson_ratio))
    throw Error(fmt::format("calibration iteration {}: the run measured E = {}, nu = {}, UCS = {}; cannot update from "
                            "that (see the run's folder)",
                            last.iteration, m.youngs_modulus_Pa, m.poisson_ratio, m.ucs_Pa));
  if (s.calibrates_slope() && last.slope_measured && !(std::isfinite(m.slope_b) && m.slope_b > 0))
    throw Error(fmt::format("calibration iteration {}: the triaxial runs measured b = {}; cannot update from that (see "
                            "the run's folder)", last.iteration, m.slope_b));
  auto limit = [&](double f) { return std::clamp(f, 1 / s.max_factor, s.max_factor); };
  MicroParameters p = last.params;

  if (s.calibrates_slope() && within_tolerances_without_slope(last, s)) {
    // E, nu and UCS in tolerance but b not measured: the same parameters again, now with b (the
    // runs are deterministic). Moving on would trade a run in tolerance for one that may not be: on
    // validate-triaxial's sample a kratio step of 6% after such a run moved E from +0.2% to -5.5%.
    if (!last.slope_measured) return p;
    // b measured: move the friction angle only (see the header).
    const double t = tan_deg(p.friction_angle_deg) + (s.target.slope_b - m.slope_b) / slope_gradient(history, s);
    p.friction_angle_deg = std::clamp(std::atan(std::max(t, 0.0)) * 180 / kPi, 0.0, s.max_friction_angle_deg);
    return p;
  }

  // E linear in the moduli (through the origin).
  const double f_emod = limit(s.target.youngs_modulus_Pa / m.youngs_modulus_Pa);
  p.bond_emod_Pa *= f_emod;
  p.contact_emod_Pa *= f_emod;

  // nu linear in ln(kratio).
  const double f_kratio = limit(std::exp((s.target.poisson_ratio - m.poisson_ratio) / poisson_slope(history, s)));
  p.bond_kratio *= f_kratio;
  p.contact_kratio *= f_kratio;

  // UCS linear in the strengths at fixed tensile_strength / cohesion.
  const double f_strength = limit(s.target.ucs_Pa / m.ucs_Pa);
  p.tensile_strength_Pa *= f_strength;
  p.cohesion_Pa *= f_strength;
  return p;
}

bool next_run_measures_slope(std::span<const CalibrationStep> history, const CalibrationSettings& s) {
  return s.calibrates_slope() && !history.empty() &&
         worst_scaled_error_without_slope(history.back(), s) < s.slope_measure_window;
}

std::string slope_out_of_reach(std::span<const CalibrationStep> history, const CalibrationSettings& s) {
  if (history.empty() || !s.calibrates_slope()) return {};
  const CalibrationStep& last = history.back();
  if (!last.slope_measured || last.converged || !within_tolerances_without_slope(last, s)) return {};
  const double phi = last.params.friction_angle_deg, b = last.measured.slope_b;
  if (b < s.target.slope_b && phi >= s.max_friction_angle_deg)
    return fmt::format("b* = {:.3g} is out of reach: b = {:.3g} with E, nu and UCS in tolerance at the largest bond "
                       "friction angle allowed ({:g} deg)", s.target.slope_b, b, s.max_friction_angle_deg);
  if (b > s.target.slope_b && phi <= 0)
    return fmt::format("b* = {:.3g} is out of reach: b = {:.3g} with E, nu and UCS in tolerance at a bond friction "
                       "angle of 0", s.target.slope_b, b);
  return {};
}

MicroParameters rounded(const MicroParameters& p, int digits) {
  auto r = [digits](double v) { return std::stod(fmt::format("{:.{}g}", v, digits)); };
  return {r(p.bond_emod_Pa),         r(p.contact_emod_Pa), r(p.bond_kratio), r(p.contact_kratio),
          r(p.tensile_strength_Pa), r(p.cohesion_Pa),     r(p.friction_angle_deg)};
}

CalibrationResult calibrate(const MicroParameters& start, const CalibrationSettings& s, const UcsModel& model,
                            const std::function<void(const CalibrationStep&)>& on_step) {
  check_calibration_input(start, s);
  CalibrationResult r;
  MicroParameters p = start;
  bool measure_slope = false;
  for (int it = 1; it <= s.max_iterations; ++it) {
    CalibrationStep st;
    st.iteration = it;
    st.params = p;
    st.slope_measured = measure_slope;
    st.measured = model(p, it, measure_slope);
    if (!measure_slope) st.measured.slope_b = 0;
    score_step(st, s);
    r.steps.push_back(st);
    if (on_step) on_step(st);
    if (st.converged) {
      r.converged = true;
      r.stop_reason = fmt::format("converged after {} runs", it);
      break;
    }
    if (r.stop_reason = slope_out_of_reach(r.steps, s); !r.stop_reason.empty()) break;
    if (it < s.max_iterations) {
      p = rounded(next_parameters(r.steps, s));
      measure_slope = next_run_measures_slope(r.steps, s);
    }
  }
  if (r.stop_reason.empty()) r.stop_reason = fmt::format("not converged within {} runs", s.max_iterations);
  if (r.converged) {
    r.chosen = static_cast<int>(r.steps.size()) - 1;
  } else {
    // The closest run. With b calibrated, E, nu and UCS come first (b is the optional target): the
    // run with those in tolerance and the smallest b error when there is one; else the closest
    // among the runs that measured b (when any did).
    auto rank = [&](const CalibrationStep& x) -> std::pair<int, double> {
      if (!s.calibrates_slope()) return {0, worst_scaled_error_without_slope(x, s)};
      if (x.slope_measured && within_tolerances_without_slope(x, s)) return {0, std::abs(x.slope_error)};
      return {x.slope_measured ? 1 : 2, x.slope_measured ? worst_scaled_error(x, s) : worst_scaled_error_without_slope(x, s)};
    };
    r.chosen = 0;
    for (std::size_t i = 1; i < r.steps.size(); ++i)
      if (rank(r.steps[i]) < rank(r.steps[r.chosen])) r.chosen = static_cast<int>(i);
  }
  r.final_params = r.steps[r.chosen].params;
  return r;
}

}  // namespace ff::batch
