#include "coupling/fluid_spec.hpp"

#include <fmt/format.h>

#include <cmath>

#include "core/error.hpp"

namespace ff::coupling {

namespace {
const double kSqrt3 = std::sqrt(3.0);
}

FluidScales derive_scales(const FluidSpec& s) {
  auto key = [&](const char* k) { return s.prefix + "." + k; };
  auto fail = [&](const char* k, const std::string& what) {
    throw InputError(fmt::format("{}: {}", key(k), what));
  };
  if (!(s.density > 0)) fail("density", fmt::format("must be positive (got {})", s.density));
  if (s.dynamic_viscosity < 0) fail("dynamic_viscosity", fmt::format("must be positive (got {})", s.dynamic_viscosity));
  if (s.dynamic_viscosity == 0 && !(s.viscosity > 0))
    fail("viscosity", fmt::format("must be positive (got {})", s.viscosity));
  if (!(s.dx > 0)) fail("dx", fmt::format("the lattice spacing must be positive (got {})", s.dx));
  std::vector<const char*> set;
  if (s.tau != 0) set.push_back("tau");
  if (s.time_step != 0) set.push_back("time_step");
  if (s.sound_speed != 0) set.push_back("sound_speed");
  if (s.bulk_modulus != 0) set.push_back("bulk_modulus");
  if (set.size() != 1)
    fail(set.empty() ? "tau" : set[1],
         fmt::format("set exactly one of {0}.tau, {0}.time_step, {0}.sound_speed and {0}.bulk_modulus (each fixes the "
                     "LBM time step; {1} set)",
                     s.prefix, set.empty() ? std::string("none is") : fmt::format("{} and {} are both", set[0], set[1])));
  FluidScales r;
  r.fixed_by = key(set[0]);
  double dt = 0;
  const double nu = s.dynamic_viscosity > 0 ? s.dynamic_viscosity / s.density : s.viscosity, dx = s.dx;
  if (s.tau != 0) {
    if (!(s.tau > 0.5)) fail("tau", fmt::format("must exceed 1/2 (got {})", s.tau));
    dt = (s.tau - 0.5) * dx * dx / (3.0 * nu);
  } else if (s.time_step != 0) {
    if (!(s.time_step > 0)) fail("time_step", fmt::format("must be positive (got {})", s.time_step));
    dt = s.time_step;
  } else {
    double c = s.sound_speed;
    if (s.bulk_modulus != 0) {
      if (!(s.bulk_modulus > 0)) fail("bulk_modulus", fmt::format("must be positive (got {})", s.bulk_modulus));
      c = std::sqrt(s.bulk_modulus / s.density);
    } else if (!(c > 0)) {
      fail("sound_speed", fmt::format("must be positive (got {})", c));
    }
    dt = dx / (kSqrt3 * c);  // c_s,lb = 1/sqrt(3) = c dt / dx
  }
  r.units = lbm::Units::from_time_step(dx, dt, nu, s.density);
  r.sound_speed = dx / (kSqrt3 * dt);
  r.bulk_modulus = s.density * r.sound_speed * r.sound_speed;
  r.background_pressure = s.background_pressure;
  r.mach = s.reference_velocity / r.sound_speed;
  r.density_variation = s.pressure_range / r.bulk_modulus;
  const double tau = r.units.tau();
  // tau - 1/2 = 3 nu dt / dx^2, and with the step from the sound speed dt = dx / (sqrt(3) c_s): a finer
  // lattice raises tau either way, a longer step (lower sound speed or bulk modulus) too.
  const std::string dx_key = s.dx_key.empty() ? key("dx") : s.dx_key;
  // The viscosity as the scenario gives it, and the density where the bulk modulus sets the sound
  // speed (c = sqrt(K / rho): a density of 1e-12 gave tau - 1/2 = 2e-9 with advice that left it out).
  const std::string visc_key = s.dynamic_viscosity > 0 ? key("dynamic_viscosity") : key("viscosity");
  const bool by_modulus = std::string(set[0]) == "bulk_modulus";
  auto density_way = [&](const char* way) {
    return by_modulus ? fmt::format(", or a {} {}: c = sqrt({} / {})", way, key("density"), key("bulk_modulus"),
                                    key("density"))
                      : std::string();
  };
  if (tau - 0.5 < kMinTauMinusHalf && std::string(set[0]) == "tau")
    fail("tau", fmt::format("{} is too close to 1/2 (tau - 1/2 = {:.3g} < {}): the LBM is unstable there; raise it",
                            tau, tau - 0.5, kMinTauMinusHalf));
  if (tau - 0.5 < kMinTauMinusHalf)
    fail(set[0], fmt::format("gives tau = {:.6g}, too close to 1/2 (tau - 1/2 = {:.3g} < {}): the LBM is unstable there. "
                             "To fix it, raise the time step (a larger {}, or a lower {} or {}{}), raise {} (nu = {:.4g} m^2/s "
                             "now) or use a finer {} (tau - 1/2 = 3 nu dt / dx^2)",
                             tau, tau - 0.5, kMinTauMinusHalf, key("time_step"), key("sound_speed"), key("bulk_modulus"),
                             density_way("higher"), visc_key, nu, dx_key));
  if (tau > kMaxTau)
    fail(set[0], fmt::format("gives tau = {:.6g} > {}: the partially saturated cells' drag error grows with tau "
                             "(docs/lbm.md); use a shorter time step (a smaller {}, or a higher {} or {}{}), a less "
                             "viscous fluid ({}; nu = {:.4g} m^2/s now) or a coarser {}",
                             tau, kMaxTau, key("time_step"), key("sound_speed"), key("bulk_modulus"),
                             density_way("lower"), visc_key, nu, dx_key));
  if (tau - 0.5 < kWarnTauMinusHalf)
    r.warnings.push_back(fmt::format("tau = {:.5g} is close to 1/2: TRT stays stable there, but under-resolved flow may "
                                     "ring",
                                     tau));
  if (r.mach > kMaxMach)
    fail(set[0], fmt::format("gives the sound speed {:.4g} m/s, and {} = {:.4g} m/s is Mach {:.3g} > {}: the LBM is "
                             "then far from incompressible. Raise the sound speed: a higher {} or {}, or a shorter "
                             "step ({} or {} smaller)",
                             r.sound_speed, key("reference_velocity"), s.reference_velocity, r.mach, kMaxMach,
                             key("sound_speed"), key("bulk_modulus"), key("time_step"), key("tau")));
  if (r.mach > kWarnMach)
    r.warnings.push_back(fmt::format("Mach number {:.3g} > {}: compressibility error about Ma^2 = {:.2g}", r.mach,
                                     kWarnMach, r.mach * r.mach));
  if (r.density_variation > kMaxDensityVariation)
    fail(set[0], fmt::format("gives K_eff = {:.4g} Pa, and {} = {:.4g} Pa is a lattice density variation of {:.3g} > "
                             "{}: raise {} or {} (or shorten the step: a smaller {} or {})",
                             r.bulk_modulus, key("pressure_range"), s.pressure_range, r.density_variation,
                             kMaxDensityVariation, key("bulk_modulus"), key("sound_speed"), key("time_step"), key("tau")));
  if (r.density_variation > kWarnDensityVariation)
    r.warnings.push_back(fmt::format("pressure changes of {:.4g} Pa are lattice density changes of {:.3g}: the "
                                     "fluid is {:.3g} times as compressible as at K = 2.2 GPa (water)",
                                     s.pressure_range, r.density_variation, 2.2e9 / r.bulk_modulus));
  return r;
}

std::string FluidScales::describe() const {
  return fmt::format(
      "fluid: LBM step dt = {:.6g} s (from {}), tau = {:.5g}, dx = {:.6g} m; sound speed {:.5g} m/s, effective bulk "
      "modulus K_eff = rho c_s^2 = {:.5g} Pa; Mach number {:.3g}; background pressure p0 = {:.6g} Pa carried outside "
      "the populations (p = p0 + K_eff (rho_lb - 1))",
      units.dt(), fixed_by, units.tau(), units.dx(), sound_speed, bulk_modulus, mach, background_pressure);
}

long sub_steps(double dt_lbm, double dt_dem) {
  if (!(dt_dem > 0) || !(dt_lbm > 0)) throw InputError("coupling: the LBM and DEM time steps must be positive");
  const double q = dt_lbm / dt_dem;
  // Beyond this the count overflowed `long` (a contact modulus of 1e300: one sub-step, and the grains
  // flew off at their first contact); long before it a run would never end.
  constexpr double kMaxSubSteps = 1e8;
  if (!(q <= kMaxSubSteps))
    throw InputError(fmt::format("coupling: the DEM step {:.4g} s is {:.3g} times shorter than the LBM step {:.4g} s "
                                 "(at most {:g} DEM sub-steps per LBM step): the contact stiffness is far too high for "
                                 "the particles' mass (lower dem.contact_modulus in sedimentation, dem.contact.*.emod "
                                 "elsewhere) or the LBM step far too long",
                                 dt_dem, q, dt_lbm, kMaxSubSteps));
  long n = long(std::ceil(q));
  // dt_lbm an exact multiple of dt_dem up to round-off: no extra sub-step.
  if (n > 1 && double(n - 1) >= q * (1 - 1e-12)) --n;
  return std::max(1L, n);
}

}  // namespace ff::coupling
