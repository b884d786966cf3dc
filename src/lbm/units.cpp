#include "lbm/units.hpp"

#include <fmt/format.h>

#include <cmath>

#include "core/error.hpp"
#include "lbm/lattice_budget.hpp"

namespace ff::lbm {

namespace {
constexpr double kMachWarn = 0.1, kMachError = 0.3, kTauWarn = 0.01, kTauLarge = 3.0;
// Beyond this the collision hardly relaxes (omega = 1/tau) and the walls slip by ~tau^2: not a flow
// solution. Reached by a speed of nothing in particular (1e-300 m/s at a fixed Mach number: dt and tau
// of 1e298, and a drag coefficient of 0/0 in series.csv).
constexpr double kTauMax = 1e4;
const double kCs = 1.0 / std::sqrt(3.0);
}  // namespace

const char* units_mode_key(UnitsMode m) {
  switch (m) {
    case UnitsMode::Tau: return "lbm.tau";
    case UnitsMode::TimeStep: return "lbm.time_step";
    case UnitsMode::Mach: return "lbm.mach";
    case UnitsMode::TargetError: return "lbm.target_error";
  }
  return "lbm.tau";
}

double compressibility_coefficient(bool incompressible, bool unsteady) {
  if (unsteady) return 2.2;
  return incompressible ? 0.1 : 1.0;
}
double expected_compressibility_error(double mach, double coefficient) { return coefficient * mach * mach; }
double mach_for_error(double error, double coefficient) { return std::sqrt(error / coefficient); }

Units Units::from_tau(double dx, double tau, double nu, double rho) {
  if (!(dx > 0) || !(nu > 0) || !(rho > 0)) throw InputError("LBM units need a positive cell size, viscosity and density");
  Units u;
  u.dx_ = dx;
  u.tau_ = tau;
  u.nu_ = nu;
  u.rho_ = rho;
  u.dt_ = (tau - 0.5) * dx * dx / (3.0 * nu);
  return u;
}

Units Units::from_time_step(double dx, double dt, double nu, double rho) {
  if (!(dx > 0) || !(dt > 0) || !(nu > 0) || !(rho > 0))
    throw InputError("LBM units need a positive cell size, time step, viscosity and density");
  Units u;
  u.dx_ = dx;
  u.dt_ = dt;
  u.nu_ = nu;
  u.rho_ = rho;
  u.tau_ = 0.5 + 3.0 * nu * dt / (dx * dx);
  return u;
}

Units Units::from_mach(double dx, double mach, double u, double nu, double rho) {
  if (!(mach > 0) || !(u > 0)) throw InputError("LBM units from a Mach number need a positive Mach number and speed");
  return from_time_step(dx, mach * kCs * dx / u, nu, rho);
}

StabilityCheck Units::check(double u, int resolution, const std::string& resolution_key, UnitsMode mode,
                            const std::string& collision, double error_coefficient) const {
  StabilityCheck r;
  const bool bgk = collision == "bgk";
  const std::string model = bgk ? "BGK (lbm.collision = \"bgk\")" : "TRT (lbm.collision = \"trt\")";
  const double ulb = to_lattice_velocity(std::abs(u));
  const double ma = ulb / kCs;
  // The fix that scales tau - 1/2 by f (f < 1 lowers the Mach number by f too at a fixed
  // resolution, whatever the key: tau - 1/2 = 3 nu dt / dx^2 and u_lb = u dt / dx), in the
  // key of the mode in use.
  auto time_fix = [&](double f) {
    const double tau_new = 0.5 + (tau_ - 0.5) * f, ma_new = ma * f;
    switch (mode) {
      case UnitsMode::Tau: return fmt::format("lbm.tau = {:.4g}", tau_new);
      case UnitsMode::TimeStep: return fmt::format("lbm.time_step = {:.4g} s (tau becomes {:.4g})", dt_ * f, tau_new);
      case UnitsMode::Mach:
        return fmt::format("lbm.mach = {:.3g} (tau becomes {:.4g}, expected compressibility error {:.2g})", ma_new,
                           tau_new, expected_compressibility_error(ma_new, error_coefficient));
      case UnitsMode::TargetError:
        return fmt::format("lbm.target_error = {:.3g} (Mach {:.3g}, tau becomes {:.4g})",
                           expected_compressibility_error(ma_new, error_coefficient), ma_new, tau_new);
    }
    return std::string();
  };
  // Fixes for the Mach number: with tau fixed u_lb scales as 1/N; with dt fixed as dt; with
  // the Mach number fixed only its own key changes it.
  auto mach_fix = [&](double target) {
    const double f = ma / target;
    // A speed far off can need more cells than a side may have (it overflowed an int: "set
    // lbm.resolution = -2147483648 or more", fuzzed with a lid velocity of 1e300).
    const double n_needed = std::ceil(resolution * f);
    const std::string finer = n_needed <= kMaxLatticeSide
                                  ? fmt::format("{} = {:.0f} or more", resolution_key, n_needed)
                                  : fmt::format("{} = {:.3g} (beyond the 2^30 cells a side may have: check the speed)",
                                                resolution_key, n_needed);
    switch (mode) {
      case UnitsMode::Tau:
        return fmt::format("set {} (same lbm.tau), or {}", finer, time_fix(1 / f));
      case UnitsMode::TimeStep:
        return fmt::format("set {} or less, or {} with lbm.time_step scaled by (old/new resolution)^2",
                           time_fix(1 / f), finer);
      default: return fmt::format("set {} or less", time_fix(1 / f));
    }
  };
  if (!(tau_ > 0.5)) {
    const double dt_needed = (0.55 - 0.5) * dx_ * dx_ / (3 * nu_);
    r.error = fmt::format("relaxation time tau = {:.6g} must be above 1/2 (nu_lb = {:.3g} <= 0): set lbm.time_step = "
                          "{:.4g} s or more (tau = 0.55), or raise {} (finer cells: tau - 1/2 = 3 nu dt / dx^2)",
                          tau_, nu_lb(), dt_needed, resolution_key);
    return r;
  }
  // A large tau's fix: the step that makes tau 2 (the Mach number only drops).
  const auto time_fix_to_tau_2 = [&] { return time_fix((2.0 - 0.5) / (tau_ - 0.5)); };
  if (tau_ > kTauMax) {
    r.error = fmt::format("relaxation time tau = {:.4g} is above {:g}: the collision hardly relaxes and the walls slip; "
                          "set {}, or check the flow's speed and viscosity",
                          tau_, kTauMax, time_fix_to_tau_2());
    return r;
  }
  if (ma > kMachError) {
    r.error = fmt::format("Mach number {:.3g} (lattice speed {:.3g}) is above {}: the flow is far from incompressible; {}",
                          ma, ulb, kMachError, mach_fix(kMachWarn));
    return r;
  }
  if (ma > kMachWarn)
    r.warnings.push_back(fmt::format("Mach number {:.3g} (lattice speed {:.3g}) is above {}: expected compressibility "
                                     "error {:.2g} ({:.2g} Ma^2); {}",
                                     ma, ulb, kMachWarn, expected_compressibility_error(ma, error_coefficient), error_coefficient,
                                     mach_fix(kMachWarn)));
  if (tau_ - 0.5 < kTauWarn) {
    // Larger tau at fixed Mach needs more cells: u_lb = Re_cell (tau - 1/2)/3 with Re_cell ~ 1/N.
    const double tau_target = 0.5 + kTauWarn * 5;
    const double f = (tau_target - 0.5) / (tau_ - 0.5);
    const std::string risk = bgk ? "BGK is at its stability limit there and its walls are inaccurate (TRT, "
                                   "lbm.collision = \"trt\", tolerates it better)"
                                 : "TRT stays stable only while the flow is well resolved, and the viscosity it carries "
                                   "is close to zero";
    const int n_needed = int(std::ceil(resolution * f));
    const bool mach_modes = mode == UnitsMode::Mach || mode == UnitsMode::TargetError;
    const std::string fix = mach_modes ? fmt::format("set {} = {} or more (same Mach number: tau - 1/2 grows with the "
                                                     "resolution), or {} (less accurate)",
                                                     resolution_key, n_needed, time_fix(f))
                                       : fmt::format("set {} (allowed: above 0.5) and {} = {} or more to keep the Mach "
                                                     "number",
                                                     time_fix(f), resolution_key, n_needed);
    r.warnings.push_back(fmt::format("relaxation time tau = {:.5g} is within {} of 1/2 with the {} collision: {}; {}",
                                     tau_, kTauWarn, model, risk, fix));
  }
  if (tau_ > kTauLarge) {
    const std::string risk = bgk ? "BGK walls slip (an error growing as tau^2)"
                                 : "open-face corners can become unstable with TRT";
    r.warnings.push_back(fmt::format("relaxation time tau = {:.4g} is large with the {} collision: {}; set {} (the Mach "
                                     "number only drops)",
                                     tau_, model, risk, time_fix_to_tau_2()));
  }
  return r;
}

std::string Units::describe(int dim) const {
  std::string s;
  s += "LBM units ([S003] Table 1):\n";
  s += fmt::format("  cell size      dx  = L_r = {:.6g} m\n", dx_);
  s += fmt::format("  time step      dt  = t_r = {:.6g} s\n", dt_);
  s += fmt::format("  density        rho_r     = {:.6g} kg/m^3 (rho_lb = 1)\n", rho_);
  s += fmt::format("  viscosity      nu  = {:.6g} m^2/s  ->  nu_lb = {:.6g}, tau = {:.6g}\n", nu_, nu_lb(), tau_);
  s += fmt::format("  velocity       u_r = {:.6g} m/s\n", velocity_factor());
  s += fmt::format("  pressure       P_r = {:.6g} Pa   (p - p0 = (rho_lb - 1) P_r / 3)\n", pressure_factor());
  s += fmt::format("  force          F_r = {:.6g} N/m per unit depth{}", force_factor(),
                   dim == 3 ? fmt::format(" (3D: F_r L_r = {:.6g} N)", force_factor() * dx_) : std::string());
  return s;
}

}  // namespace ff::lbm
