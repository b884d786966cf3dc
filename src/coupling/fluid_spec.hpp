// The fluid of a coupled DEM-LBM run in SI units, and what follows from it: the LBM step, the
// relaxation time, the lattice sound speed, the effective bulk modulus and the Mach number
// (docs/coupling.md, "Fluid scales and pressure").
//
// Pressure treatment (issue 15 item 1): the LBM's equation of state is p = c_s^2 rho, so a
// pressure of tens of MPa cannot be a density variation of real water. The run carries a
// background pressure p0 outside the populations and a reduced sound speed c_s,phys = dx /
// (sqrt(3) dt):
//   p = p0 + rho_f c_s,phys^2 (rho_lb - 1),     K_eff = rho_f c_s,phys^2,
// so the lattice holds only the pressure differences, with the compressibility 1 / K_eff of
// the reduced sound speed (K_eff far below water's 2.2 GPa); the Mach number U / c_s,phys and
// the density variation (p - p0) / K_eff must stay small (Krueger et al. 2017, Sec. 4.5 and 7.2).
#pragma once
#include <string>
#include <vector>

#include "lbm/units.hpp"

namespace ff::coupling {

struct FluidSpec {
  double density = 1000;        // rho_f [kg/m^3]
  double viscosity = 1e-6;      // kinematic nu [m^2/s]
  double dynamic_viscosity = 0; // mu [Pa s]; when > 0 it replaces viscosity: nu = mu / rho_f
  double dx = 0;                // lattice spacing [m]
  // Exactly one of these fixes the LBM step (the others stay 0):
  double tau = 0;               // relaxation time: dt = (tau - 1/2) dx^2 / (3 nu)
  double time_step = 0;         // dt [s]
  double sound_speed = 0;       // c_s,phys [m/s]: dt = dx / (sqrt(3) c_s,phys)
  double bulk_modulus = 0;      // K_eff [Pa]: c_s,phys = sqrt(K_eff / rho_f)
  double background_pressure = 0;  // p0 [Pa], carried outside the populations
  double reference_velocity = 0;   // U [m/s] of the Mach number (0: no Mach check)
  double pressure_range = 0;       // largest |p - p0| expected [Pa] (0: no density-variation check)
  std::string prefix = "fluid";    // scenario table the keys live in (error messages name prefix.key)
  std::string dx_key;              // the key(s) that set dx, for the advice (empty: prefix.dx)
};

// Limits of the checks (errors; warnings at the lower values).
inline constexpr double kMinTauMinusHalf = 0.005, kWarnTauMinusHalf = 0.02, kMaxTau = 2.0;
inline constexpr double kWarnMach = 0.1, kMaxMach = 0.3;
inline constexpr double kWarnDensityVariation = 0.01, kMaxDensityVariation = 0.1;

struct FluidScales {
  lbm::Units units;          // dx, dt, tau, nu, rho (lbm/units.hpp)
  double sound_speed = 0;    // c_s,phys = dx / (sqrt(3) dt) [m/s]
  double bulk_modulus = 0;   // K_eff = rho_f c_s,phys^2 [Pa]
  double mach = 0;           // U / c_s,phys
  double density_variation = 0;  // pressure_range / K_eff (= max |rho_lb - 1|)
  double background_pressure = 0;
  std::string fixed_by;      // the key that fixed dt
  std::vector<std::string> warnings;

  double dt() const { return units.dt(); }
  // Physical pressure of a lattice density and back: p = p0 + K_eff (rho_lb - 1).
  double pressure(double rho_lb) const { return background_pressure + bulk_modulus * (rho_lb - 1.0); }
  double lattice_density(double p) const { return 1.0 + (p - background_pressure) / bulk_modulus; }
  std::string describe() const;  // one paragraph for the log
};

// Derives the scales; throws InputError naming prefix.key for every unusable choice (none or two
// of tau/time_step/sound_speed/bulk_modulus, tau - 1/2 < 0.005 or tau > 2, Mach > 0.3, density
// variation > 0.1).
FluidScales derive_scales(const FluidSpec& s);

// DEM sub-steps per LBM step: n = ceil(dt_lbm / dt_dem); the DEM then steps dt_lbm / n.
long sub_steps(double dt_lbm, double dt_dem);

struct CouplerTimes {  // wall-clock seconds spent in each part of DemLbmCoupler::step()
  double coupling = 0, lbm = 0, dem = 0;
};

}  // namespace ff::coupling
