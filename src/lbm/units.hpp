// Conversion between SI units and lattice units (dx = dt = rho_0 = 1), [S003] Table 1 and
// METHODS §4.9: primary factors L_r = dx, t_r = dt, rho_r = rho_phys; the viscosity ties them,
// nu_lb = (tau - 1/2)/3 = nu dt / dx^2. Derived: u_r = L_r/t_r, P_r = rho_r L_r^2/t_r^2 and
// F_r = rho_r L_r^3/t_r^2. With rho in kg/m^3, F_r is a force per unit depth (N/m): the 2D
// force of [S003]; a 3D lattice force takes one more L_r (N). Pressures are reported relative
// to the reference state (p - p_0 = c_s^2 (rho_lb - 1) P_r).
#pragma once
#include <cmath>
#include <string>
#include <vector>

namespace ff::lbm {

// The scenario key that fixed the time step (check()'s advice names the keys of this mode).
enum class UnitsMode { Tau, TimeStep, Mach, TargetError };
const char* units_mode_key(UnitsMode m);  // "lbm.tau", "lbm.time_step", "lbm.mach", "lbm.target_error"

// Expected relative error of forces and pressures from the compressibility of the LBM at the
// Mach number Ma = u_lb / c_s of the characteristic speed: the weakly compressible scheme
// recovers Navier-Stokes up to O(Ma^2) terms (Krueger et al., The Lattice Boltzmann Method,
// 2017, Sec. 4.5), so the error is C Ma^2. C depends on the equilibrium and on whether the flow
// settles; measured on the DFG cylinder (docs/lbm.md, "Accuracy on the DFG benchmark"):
//  - compressible equilibrium, steady flow: 2D-1 drag moves by 1.04 Ma^2 (D = 20, 40 cells,
//    Ma 0.026-0.052): the pressure drop raises rho and the dynamic viscosity rho nu -> C = 1;
//  - incompressible equilibrium (He & Luo 1997), steady flow: drag 0.03 Ma^2, Delta p 0.08 Ma^2
//    (D = 40, Ma 0.025 -> 0.05) -> C = 0.1;
//  - vortex shedding, either equilibrium: at a fixed resolution dt scales with Ma, and the
//    amplitudes carry the time-step error: 2D-2 at D = 40, Ma 0.05 -> 0.1, c_D,max 0.58 Ma^2,
//    St 0.3 Ma^2, c_L,max 2.2 Ma^2 -> C = 2.2.
double compressibility_coefficient(bool incompressible, bool unsteady);
double expected_compressibility_error(double mach, double coefficient);
// The Mach number whose expected compressibility error is `error` (inverse of the above).
double mach_for_error(double error, double coefficient);

// Outcome of a stability check: warnings (the run goes on) or an error (it must not start).
struct StabilityCheck {
  std::vector<std::string> warnings;
  std::string error;  // empty: fine
};

class Units {
 public:
  // From the cell size [m], the relaxation time, the kinematic viscosity [m^2/s] and the
  // density [kg/m^3]: dt = (tau - 1/2) dx^2 / (3 nu).
  static Units from_tau(double dx, double tau, double nu, double rho);
  // From the cell size [m] and a time step [s]: tau = 1/2 + 3 nu dt / dx^2.
  static Units from_time_step(double dx, double dt, double nu, double rho);
  // From the cell size [m] and the Mach number of a speed u [m/s]: dt = Ma c_s dx / u.
  static Units from_mach(double dx, double mach, double u, double nu, double rho);

  double dx() const { return dx_; }
  double dt() const { return dt_; }
  double tau() const { return tau_; }
  double nu() const { return nu_; }        // m^2/s
  double nu_lb() const { return (tau_ - 0.5) / 3.0; }
  double rho() const { return rho_; }      // kg/m^3 (= rho_r, rho_lb = 1)

  // Conversion factors of [S003] Table 1.
  double velocity_factor() const { return dx_ / dt_; }                   // u_r  [m/s]
  double pressure_factor() const { return rho_ * dx_ * dx_ / (dt_ * dt_); }  // P_r [Pa]
  double force_factor() const { return rho_ * dx_ * dx_ * dx_ / (dt_ * dt_); }  // F_r [N/m]

  double mach(double u) const { return to_lattice_velocity(std::abs(u)) * std::sqrt(3.0); }  // u_lb / c_s

  double to_lattice_length(double m) const { return m / dx_; }
  double to_lattice_time(double s) const { return s / dt_; }
  double to_lattice_velocity(double v) const { return v * dt_ / dx_; }
  // Body-force density [N/m^3] -> lattice force density.
  double to_lattice_force_density(double f) const { return f * dt_ * dt_ / (rho_ * dx_); }
  double to_si_velocity(double u) const { return u * dx_ / dt_; }
  // Gauge pressure [Pa] of a lattice density.
  double to_si_pressure(double rho_lb) const { return (rho_lb - 1.0) / 3.0 * pressure_factor(); }
  double to_si_density_offset(double p) const { return 3.0 * p / pressure_factor(); }  // Pa -> rho_lb - 1
  // Force on a solid: N on a 3D lattice; on a 2D lattice N per metre of depth.
  double to_si_force(double f, int dim) const { return dim == 3 ? f * force_factor() * dx_ : f * force_factor(); }
  // Torque (force times a lattice lever arm): N m on a 3D lattice; N m per metre of depth (N) in 2D.
  double to_si_torque(double t, int dim) const { return to_si_force(t, dim) * dx_; }

  // Mach number and relaxation-time checks for a characteristic speed u [m/s] (METHODS §4.2:
  // tau > 1/2 needed, tau - 1/2 >= 0.01 advisable; Ma = u_lb / c_s below 0.1 advisable, above
  // 0.3 the compressibility error is unacceptable). `resolution` is the number of cells across
  // the characteristic length, named `resolution_key` in the scenario; `mode` says which key
  // fixed the time step (the fixes change that key or the resolution); `collision` is lbm.collision ("trt" or "bgk"),
  // named in the messages, whose limits differ. Each message names a key and a value that fixes it.
  // `error_coefficient` is C of the expected error C Ma^2 the advice quotes.
  StabilityCheck check(double u, int resolution, const std::string& resolution_key, UnitsMode mode,
                       const std::string& collision, double error_coefficient) const;

  // The table printed at the start of a run.
  std::string describe(int dim) const;

 private:
  double dx_ = 1, dt_ = 1, tau_ = 1, nu_ = 1, rho_ = 1;
};

}  // namespace ff::lbm
