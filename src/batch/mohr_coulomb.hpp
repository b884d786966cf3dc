// Mohr-Coulomb envelope fitted to peak strengths from UCS and triaxial runs.
//
// With compression positive, the Coulomb criterion tau = c + sigma tan(phi) written in principal
// stresses at failure is the straight line
//     sigma_p = a + b sigma3,   b = (1 + sin phi) / (1 - sin phi),   a = 2 c cos phi / (1 - sin phi)
// (a is the uniaxial compressive strength C0 of the envelope). Sources: Jaeger, Cook & Zimmerman,
// Fundamentals of Rock Mechanics, 4th ed. (2007), Sec. 4.5 (sigma1 = C0 + q sigma3; the equation
// number was not checked against the book), and Labuz & Zang (2012), ISRM suggested method
// "Mohr-Coulomb failure criterion", Rock Mech. Rock Eng. 45:975. Inverted:
//     sin phi = (b - 1) / (b + 1),   c = a (1 - sin phi) / (2 cos phi).
#pragma once
#include <span>
#include <string>

namespace ff::batch {

// One peak strength: confining pressure sigma3 and axial stress at peak sigma_p [Pa],
// compression positive (a UCS run is sigma3 = 0, sigma_p = UCS).
struct StrengthPoint {
  double sigma3 = 0;
  double sigma_p = 0;
};

struct MohrCoulombFit {
  double intercept_Pa = 0;      // a: fitted uniaxial compressive strength C0
  double slope = 0;             // b = (1 + sin phi) / (1 - sin phi)
  double friction_angle_deg = 0;
  double cohesion_Pa = 0;
  double r_squared = 0;         // coefficient of determination of the line (1 for an exact line)
  int points = 0;
};

// Least-squares line y = intercept + slope x, from centred sums (no cancellation for MPa-sized
// values). sxx = sum (x - mean x)^2 tells whether the x values spread at all (slope is NaN when
// they do not); r_squared = 1 - SS_res / SS_tot (1 when every y is equal).
struct LineFit {
  double intercept = 0, slope = 0, r_squared = 0, sxx = 0;
};
LineFit fit_line(std::span<const double> x, std::span<const double> y);

// Least-squares line sigma_p = a + b sigma3 and the phi, c it implies. Throws ff::InputError
// when fewer than two distinct confining pressures are given, or when b < 1 (peak strength
// falling faster than the confinement rises has no Coulomb friction angle).
MohrCoulombFit fit_mohr_coulomb(std::span<const StrengthPoint> points);

// The point sigma_p = a + b sigma3 of given phi [deg] and c [Pa] (for tests and plots).
double mohr_coulomb_peak(double sigma3, double friction_angle_deg, double cohesion_Pa);

}  // namespace ff::batch
