// The elastic state around a pressurised borehole and the measurement circles (2D) / spheres
// (3D) that read it from the particles. Rock-mechanics signs: compression positive.
#pragma once
#include <vector>

#include "dem/dem_system.hpp"

namespace ff::drivers::hydrofrac {

// Kirsch's solution for a circular hole of radius a in an infinite plate under far-field
// principal stresses sH (along x) and sh (along y) with pressure p in the hole, plane strain
// (independent of the elastic constants). Jaeger, Cook & Zimmerman (2007), Fundamentals of Rock
// Mechanics, 4th ed., eqs. 8.4.11-8.4.13 with the pressure term of eq. 8.3.13:
//   s_rr = (sH+sh)/2 (1 - a^2/r^2) + (sH-sh)/2 (1 - 4a^2/r^2 + 3a^4/r^4) cos 2t + p a^2/r^2
//   s_tt = (sH+sh)/2 (1 + a^2/r^2) - (sH-sh)/2 (1 + 3a^4/r^4) cos 2t - p a^2/r^2
//   s_rt = -(sH-sh)/2 (1 + 2a^2/r^2 - 3a^4/r^4) sin 2t
// t measured from x. At the wall (r = a, t = 0): s_tt = 3 sh - sH - p, whence Hubbert & Willis
// (1957): P_b = 3 sh - sH + T.
struct PolarStress {
  Real rr = 0, tt = 0, rt = 0;
};
PolarStress kirsch(Real sH, Real sh, Real p, Real a, Real r, Real theta);
// Cartesian (xx, yy, xy) of Kirsch's field averaged over a disc (dim 2) or ball (dim 3; the
// field does not vary along z) of radius rho centred at (x, y) relative to the hole's axis;
// points inside the hole are left out.
Vec3 kirsch_average(Real sH, Real sh, Real p, Real a, Real x, Real y, Real rho, int dim);

// Average stress of the particles whose centres lie in a circle (sphere) of radius rho, with
// PFC's porosity correction (as the triaxial driver's measurement spheres, METHODS.md 1.7):
// sigma = -(1 - n)/sum(V_p) sum_p sum_c (x_c - x_p) f_c, n the porosity inside the region from
// each particle's exact share of it. Compression positive.
struct CircleStress {
  Vec3 centre = Vec3::Zero();
  Real radius = 0;
  int particles = 0;
  Real porosity = 0;
  Real xx = 0, yy = 0, zz = 0, xy = 0;
};
CircleStress measure_circle(const dem::DemSystem& sys, const Vec3& centre, Real rho);

// Area of the intersection of two circles of radii R and r with centres d apart.
Real circle_overlap_area(Real R, Real r, Real d);

}  // namespace ff::drivers::hydrofrac
