#include "batch/mohr_coulomb.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "core/error.hpp"

namespace ff::batch {

namespace {
constexpr double kDeg = std::numbers::pi / 180.0;
}

double mohr_coulomb_peak(double sigma3, double friction_angle_deg, double cohesion_Pa) {
  const double s = std::sin(friction_angle_deg * kDeg), co = std::cos(friction_angle_deg * kDeg);
  return 2 * cohesion_Pa * co / (1 - s) + sigma3 * (1 + s) / (1 - s);
}

LineFit fit_line(std::span<const double> x, std::span<const double> y) {
  const auto n = static_cast<double>(x.size());
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    mx += x[i];
    my += y[i];
  }
  if (!x.empty()) {
    mx /= n;
    my /= n;
  }
  double sxx = 0, sxy = 0, syy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxx += (x[i] - mx) * (x[i] - mx);
    sxy += (x[i] - mx) * (y[i] - my);
    syy += (y[i] - my) * (y[i] - my);
  }
  LineFit f;
  f.sxx = sxx;
  f.slope = sxy / sxx;
  f.intercept = my - f.slope * mx;
  double ss_res = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double r = y[i] - (f.intercept + f.slope * x[i]);
    ss_res += r * r;
  }
  f.r_squared = syy > 0 ? 1 - ss_res / syy : 1.0;
  return f;
}

MohrCoulombFit fit_mohr_coulomb(std::span<const StrengthPoint> points) {
  std::vector<double> s3, sp;
  for (auto& p : points) s3.push_back(p.sigma3), sp.push_back(p.sigma_p);
  const LineFit line = fit_line(s3, sp);
  if (points.size() < 2 || !(line.sxx > 0))
    throw InputError(fmt::format("Mohr-Coulomb fit: needs peak strengths at two or more different confining pressures, "
                                 "got {} point(s){}; vary triaxial.confining_pressure",
                                 points.size(), points.size() >= 2 ? ", all at one confining pressure" : ""));
  MohrCoulombFit f;
  f.points = static_cast<int>(points.size());
  f.slope = line.slope;
  f.intercept_Pa = line.intercept;
  f.r_squared = line.r_squared;
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
