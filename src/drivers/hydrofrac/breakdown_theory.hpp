// Classical borehole breakdown pressures and the comparison of a sweep over sigma_h with them
// (`fracflow validate-hydrofrac` writes docs/validation/hydrofrac.md from these).
#pragma once
#include <cmath>
#include <string>
#include <vector>

#include "core/types.hpp"

namespace ff::drivers::hydrofrac {

// Hubbert & Willis (1957), non-penetrating fluid, elastic impermeable rock, pore pressure p0:
// the wall's hoop stress 3 sh - sH - P (Kirsch) reaches -T: P_b = 3 sh - sH + T - p0.
Real hubbert_willis(Real sigma_H, Real sigma_h, Real T, Real p0 = 0);
// Haimson & Fairhurst (1967), penetrating fluid in a poroelastic rock:
// P_b = (3 sh - sH + T - 2 eta p0) / (2 - 2 eta), eta = alpha (1 - 2 nu) / (2 (1 - nu)) in
// [0, 0.5]; eta = 0.5 gives Hubbert-Willis, eta = 0 halves it (fluid pressure acting fully on the
// fracture faces without a poroelastic stress change, H&W's penetrating case).
Real haimson_fairhurst(Real sigma_H, Real sigma_h, Real T, Real eta, Real p0 = 0);

struct LineFit {
  Real slope = 0, offset = 0, r2 = 0;
  int points = 0;
};
// Least squares y = slope x + offset (needs two distinct x; else points = 0).
LineFit fit_line(const std::vector<Real>& x, const std::vector<Real>& y);

// One point of the sweep (pressures in Pa; NaN where a run found no breakdown).
struct BreakdownPoint {
  Real sigma_H = 0, sigma_h = 0;
  Real sleeve_breakdown = 0, sleeve_initiation = 0, penetrating_breakdown = 0;
  Real sleeve_azimuth_deg = 0;
  long particles = 0;
  Real wall_time_s = 0;
  // Over the packings of the point (the pressures above are their means): max - min [Pa].
  int packings = 1;
  Real initiation_range = 0, breakdown_range = 0, penetrating_range = 0;
  // The same blocks with the lattice Boltzmann fluid (injection.fluid = "lbm"; NaN: not run).
  Real lbm_breakdown = NAN, lbm_initiation = NAN, lbm_range = NAN;
};
struct SweepContext {
  Real tensile_strength = 0;      // measured by the direct-tension driver [Pa]
  std::string tension_run, block, command, date, machine;
  std::string lbm_fluid;          // the LBM runs' fluid in words (empty: none run)
  Real ramp_rate = 0, hole_radius = 0, grain_radius = 0;
};
// The report (markdown): the table, the fits against both theories, the differences explained.
std::string breakdown_report(const std::vector<BreakdownPoint>& points, const SweepContext& ctx);

}  // namespace ff::drivers::hydrofrac
