// Calibration of parallel-bond micro-parameters against laboratory E, nu and UCS by repeated
// UCS runs, with the relations seed 000 (Zhao, Konietzky & Herbst 2021, Sec. 5.2; METHODS.md 1.7)
// reports for PFC's parallel-bond model:
//   - E is linear in the bond (and contact) modulus:        emod   <- emod * E* / E
//   - nu is linear in the logarithm of the stiffness ratio: ln k   <- ln k + (nu* - nu) / s,
//     s = d nu / d ln k fitted by least squares to the runs so far (a guess for the first step)
//   - UCS is linear in the bond strengths at a fixed tensile/cohesion ratio:
//                                                           strengths <- strengths * UCS* / UCS
// and, when a triaxial slope b* is asked for (peak differential stress sigma_p = a + b sigma3,
// the form of seed 000 Eq. 1, b = 3.54; the slope of sigma1 = sigma3 + sigma_p is b + 1), the
// pressure sensitivity of the bonds' shear strength (tau = c + sigma tan(phi_b), PFC 5's
// pb_fa; METHODS.md 1.5):
//   - b is taken as linear in tan(phi_b):                  tan(phi_b) <- tan(phi_b) + (b* - b) / s_b,
//     s_b = d b / d tan(phi_b) by least squares over the runs that measured b (a guess first).
//     Measured on the C1-like example: phi_b = 4 deg -> b = 0.73, 30 deg -> b = 3.05 (s_b ~ 4.6).
//
// Order of the updates. E, nu and UCS are updated together after every run (stiffness hardly
// depends on the strengths, and the multiplicative updates absorb the weaker cross effects). The
// friction angle is NOT: it moves only after a run that has E, nu and UCS within their tolerances
// and measured b, and is held while the other three are brought back (block Gauss-Seidel). Moving
// all four at once failed on the 25 x 50 mm coal matrix sample (2026-11-22, 6 runs, not converged):
// at kratio 30, raising phi_b from 40 to 60 deg raised the measured nu from 0.35 to 0.67-0.73 and
// lowered E (damage inside the 20-50% fit window), so the nu-ln(kratio) fit over all runs mixed
// samples of different friction and sent kratio 30 -> 7.5 (E +203%). Hence also:
//   - the nu slope is fitted over the runs at the current phi_b only (the latest angle with two
//     usable runs when the current one has fewer; the guess when none has),
//   - b is measured (the triaxial runs) only when the previous run was within twice the E, nu and
//     UCS tolerances, i.e. close to where phi_b may move next; a run with the three in tolerance
//     that did not measure b is repeated with b (same parameters),
//   - at phi_b = 0 or at its cap with b still off in the direction the angle cannot go, the
//     calibration stops: b* is out of reach of the bond friction angle (stop_reason says so).
#pragma once
#include <functional>
#include <span>
#include <string>
#include <vector>

namespace ff::batch {

// The micro-parameters being calibrated, of one group pair. Bond and contact moduli are scaled
// together (their ratio stays as given), and so are the two stiffness ratios.
struct MicroParameters {
  double bond_emod_Pa = 0, contact_emod_Pa = 0;
  double bond_kratio = 0, contact_kratio = 0;
  double tensile_strength_Pa = 0, cohesion_Pa = 0;
  double friction_angle_deg = 0;  // bond friction angle phi_b (changed only when b is calibrated)
};

// What one UCS run measures.
struct MacroProperties {
  double youngs_modulus_Pa = 0, poisson_ratio = 0, ucs_Pa = 0;
  double slope_b = 0;  // d(peak differential stress)/d sigma3 (0 when not measured; as a target: not calibrated)
};

struct CalibrationSettings {
  MacroProperties target;
  double youngs_modulus_tolerance = 0.05;  // relative
  double ucs_tolerance = 0.05;             // relative
  double poisson_tolerance = 0.03;         // absolute
  int max_iterations = 12;                 // UCS runs at most
  double poisson_slope_guess = 0.08;       // d nu / d ln(kratio) for the first step (seed 000 default sample:
                                           // nu ~ 0.30 at kratio 14.65, ~0.1 near kratio 1)
  double max_factor = 4;                   // no parameter changes by more than this factor per iteration
  double slope_tolerance = 0.10;           // relative, on b (when target.slope_b > 0)
  double slope_gradient_guess = 4.6;       // d b / d tan(phi_b) for the first step (see above)
  double max_friction_angle_deg = 60;      // phi_b stays in [0, this]
  double slope_measure_window = 2;         // measure b after a run within this many tolerances of E, nu, UCS
  bool calibrates_slope() const { return target.slope_b > 0; }
};

struct CalibrationStep {
  int iteration = 0;  // 1-based
  MicroParameters params;
  MacroProperties measured;
  double youngs_modulus_error = 0;  // (E - E*) / E*
  double poisson_error = 0;         // nu - nu*
  double ucs_error = 0;             // (UCS - UCS*) / UCS*
  double slope_error = 0;           // (b - b*) / b* (0 when b is not calibrated or not measured)
  bool slope_measured = false;      // this run measured b (triaxial runs beside the UCS run)
  bool converged = false;           // all within their tolerances (b measured when calibrated)
};

struct CalibrationResult {
  std::vector<CalibrationStep> steps;
  bool converged = false;
  int chosen = -1;          // index into steps: the converged step, else the closest (see calibrate())
  MicroParameters final_params;
  std::string stop_reason;  // why it stopped: converged, out of runs, or b* out of reach
};

// Stands in for one UCS run with the given parameters (iteration is 1-based) and, when
// measure_slope, the triaxial runs that measure b (else slope_b is left 0).
using UcsModel = std::function<MacroProperties(const MicroParameters&, int iteration, bool measure_slope)>;

// Throws ff::InputError for non-positive targets, tolerances or parameters.
void check_calibration_input(const MicroParameters& start, const CalibrationSettings& s);

// Fills the error fields and `converged` of a step from its measurement.
void score_step(CalibrationStep& step, const CalibrationSettings& s);

// The parameters for the next run from the runs so far (the update rules above).
// Throws ff::Error when the last measurement is not a positive finite number.
MicroParameters next_parameters(std::span<const CalibrationStep> history, const CalibrationSettings& s);

// Whether the next run measures b: b is calibrated and the last run was within
// slope_measure_window tolerances of E, nu and UCS.
bool next_run_measures_slope(std::span<const CalibrationStep> history, const CalibrationSettings& s);

// Non-empty when the last run shows b* out of reach: E, nu, UCS within tolerance, b measured
// and off, and phi_b already at the end of its range the update would push it past.
std::string slope_out_of_reach(std::span<const CalibrationStep> history, const CalibrationSettings& s);

// Each parameter rounded to `digits` significant digits: the calibrated values are written as
// short numbers, and the runs use exactly those numbers so the snippet reproduces them.
MicroParameters rounded(const MicroParameters& p, int digits = 6);

// Runs the loop: measure, stop when within tolerance (or b* is out of reach), else update.
// `on_step` is called after each measurement (for reporting as it goes). Not converged, the
// result's run is the one with the smallest worst scaled error; with b calibrated, a run that
// measured b with E, nu and UCS in tolerance comes first (the smallest b error among those).
CalibrationResult calibrate(const MicroParameters& start, const CalibrationSettings& s, const UcsModel& model,
                            const std::function<void(const CalibrationStep&)>& on_step = {});

// How far a step is from the targets, in units of the tolerances (< 1: converged). A run that
// did not measure b counts as infinitely far when b is calibrated.
double worst_scaled_error(const CalibrationStep& step, const CalibrationSettings& s);
// The same over E, nu and UCS only.
double worst_scaled_error_without_slope(const CalibrationStep& step, const CalibrationSettings& s);

}  // namespace ff::batch
