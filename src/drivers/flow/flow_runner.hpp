// The time loop shared by the flow benchmarks: builds the solver for the lattice and precision
// chosen in the scenario, converts units, writes series.csv, vtk/ (.vti + .pvd), checkpoints,
// summary.json and plots, checks stability, stops at steady state, end time, wall-clock limit
// or ABORT file, and resumes bit for bit.
#pragma once
#include <string>
#include <string_view>

#include "drivers/driver.hpp"
#include "drivers/flow/flow_case.hpp"

namespace ff::drivers {

// Defaults a case gives to the shared keys.
struct LbmDefaults {
  int resolution = 20;       // cells across the characteristic length
  double tau = 0.8;
  double end_time = 1.0;     // s
  double density = 1000;     // kg/m^3 (water)
  double viscosity = 1e-6;   // m^2/s (water at 20 C)
  double steady_tolerance = 1e-7;
  double inflow_ramp_time = 0;  // s
};

// Declares lbm.*, fluid.*, run.*, probes.* and output.* keys of the flow drivers.
void declare_lbm_params(ParamTable& t, const LbmDefaults& d);

// The units of a flow run and the key that chose the time step: lbm.tau, lbm.time_step,
// lbm.mach or lbm.target_error (at most one set; none: lbm.tau's default).
struct FlowUnits {
  lbm::Units units;
  lbm::UnitsMode mode = lbm::UnitsMode::Tau;
  double mach = 0;            // Ma = u_lb / c_s of the case's characteristic speed
  double coefficient = 1;     // C of the expected error C Ma^2 (lbm::compressibility_coefficient)
  double expected_error = 0;  // C Ma^2
  std::string error_model;    // why this C: equilibrium and regime
  bool by_default = false;    // none of the four keys set: lbm.tau's default
  const char* key() const { return lbm::units_mode_key(mode); }
};
// Units for a cell size dx [m] and the characteristic speed u [m/s] of the case; `unsteady`:
// the case expects a time-periodic flow (FlowCase::unsteady), which sets the error model.
FlowUnits make_units(const Config& cfg, double dx, double u, bool unsteady);
// One paragraph: dt, tau, Mach number, expected compressibility error and the key in use.
std::string describe_flow_units(const FlowUnits& fu, const FlowCase& fc);

// `fracflow check` prints what a flow scenario derives (dt, tau, Mach number, expected error,
// warnings): while one of these lives, validate_flow() appends its report to it. One at a
// time, for the CLI's check (a process-wide hook, so that no driver file has to pass it on).
class FlowCheckReport {
 public:
  FlowCheckReport();
  ~FlowCheckReport();
  FlowCheckReport(const FlowCheckReport&) = delete;
  FlowCheckReport& operator=(const FlowCheckReport&) = delete;
  const std::string& text() const { return text_; }
  static void append(const std::string& s);  // no-op when none lives
  static bool active();                       // one lives (`fracflow check`): worth deriving a report

 private:
  std::string text_;
};

RunStatus run_flow(const Config& cfg, const RunOptions& opt, FlowCase& fc, std::string_view driver_name);

}  // namespace ff::drivers
