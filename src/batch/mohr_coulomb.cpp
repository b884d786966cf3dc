#include "batch/mohr_coulomb.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>

#include "core/error.hpp"

namespace ff::batch {

namespace {
constexpr double kDeg = std::numbers::pi / 180.0;
}

double mohr_coulomb_peak(double sigma3, double friction_angle_deg, double cohesion_Pa) {
  const double s = std::sin(friction_angle_deg * kDeg), co = std::cos(friction_angle_deg * kDeg);
  return 2 * cohesion_Pa * co / (1 - s) + sigma3 * (1 + s) / (1 - s);
}

MohrCoulombFit fit_mohr_coulomb(std::span<const StrengthPoint> points) {
  const auto n = static_cast<double>(points.size());
  double mx = 0, my = 0;
  for (auto& p : points) {
    mx += p.sigma3;
    my += p.sigma_p;
  }
  if (points.size() >= 1) {
    mx /= n;
    my /= n;
  }
  double sxx = 0, sxy = 0, syy = 0;  // centred sums: no cancellation for MPa-sized values
  for (auto& p : points) {
    sxx += (p.sigma3 - mx) * (p.sigma3 - mx);
    sxy += (p.sigma3 - mx) * (p.sigma_p - my);
    syy += (p.sigma_p - my) * (p.sigma_p - my);
  }
  if (points.size() < 2 || !(sxx > 0))
    throw InputError(fmt::format("Mohr-Coulomb fit: needs peak strengths at two or more different confining pressures, "
                                 "got {} point(s){}; vary triaxial.confining_pressure",
                                 points.size(), points.size() >= 2 ? ", all at one confining pressure" : ""));
  MohrCoulombFit f;
  f.points = static_cast<int>(points.size());
  f.slope = sxy / sxx;
  f.intercept_Pa = my - f.slope * mx;
  double ss_res = 0;
  for (auto& p : points) {
    const double r = p.sigma_p - (f.intercept_Pa + f.slope * p.sigma3);
    ss_res += r * r;
  }
  f.r_squared = syy > 0 ? 1 - ss_res / syy : 1.0;
  if (f.slope < 1)
    throw InputError(fmt::format("Mohr-Coulomb fit: the peak strength rises by only {:.3g} Pa per Pa of confinement "
                                 "(a Coulomb material needs >= 1, i.e. friction angle >= 0); check the runs",
                                 f.slope));
  const double sin_phi = (f.slope - 1) / (f.slope + 1);
  const double phi = std::asin(sin_phi);
  f.friction_angle_deg = phi / kDeg;
  f.cohesion_Pa = f.intercept_Pa * (1 - sin_phi) / (2 * std::cos(phi));
  return f;
}

}  // namespace ff::batch
