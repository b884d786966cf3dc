// The time loop shared by the flow benchmarks: builds the solver for the lattice and precision
// chosen in the scenario, converts units, writes series.csv, vtk/ (.vti + .pvd), checkpoints,
// summary.json and plots, checks stability, stops at steady state, end time, wall-clock limit
// or ABORT file, and resumes bit for bit.
#pragma once
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

// Declares lbm.*, fluid.*, run.* and output.* keys of the flow drivers.
void declare_lbm_params(ParamTable& t, const LbmDefaults& d);
// Units for a cell size [m] from lbm.tau or lbm.time_step, fluid.viscosity and fluid.density.
lbm::Units make_units(const Config& cfg, double dx);

RunStatus run_flow(const Config& cfg, const RunOptions& opt, FlowCase& fc, std::string_view driver_name);

}  // namespace ff::drivers
