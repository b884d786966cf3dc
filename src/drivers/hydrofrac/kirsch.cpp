#include "drivers/hydrofrac/kirsch.hpp"

#include <algorithm>
#include <cmath>

#include "dem/diagnostics.hpp"
#include "geometry/shapes.hpp"

namespace ff::drivers::hydrofrac {

PolarStress kirsch(Real sH, Real sh, Real p, Real a, Real r, Real t) {
  const Real m = 0.5 * (sH + sh), d = 0.5 * (sH - sh);
  const Real q2 = a * a / (r * r), q4 = q2 * q2;
  PolarStress s;
  s.rr = m * (1 - q2) + d * (1 - 4 * q2 + 3 * q4) * std::cos(2 * t) + p * q2;
  s.tt = m * (1 + q2) - d * (1 + 3 * q4) * std::cos(2 * t) - p * q2;
  s.rt = -d * (1 + 2 * q2 - 3 * q4) * std::sin(2 * t);
  return s;
}

Vec3 kirsch_average(Real sH, Real sh, Real p, Real a, Real x, Real y, Real rho, int dim) {
  // Midpoint rule on a 64 x 64 (x 64) grid over the region's bounding square (cube).
  constexpr int n = 64;
  Vec3 sum = Vec3::Zero();
  Real w_sum = 0;
  const int nz = dim == 3 ? n : 1;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const Real u = rho * (2.0 * (i + 0.5) / n - 1), v = rho * (2.0 * (j + 0.5) / n - 1);
        const Real w = dim == 3 ? rho * (2.0 * (k + 0.5) / n - 1) : 0.0;
        if (u * u + v * v + w * w > rho * rho) continue;
        const Real px = x + u, py = y + v, r = std::hypot(px, py);
        if (r < a) continue;
        const Real t = std::atan2(py, px), c = std::cos(t), s = std::sin(t);
        const PolarStress ps = kirsch(sH, sh, p, a, r, t);
        // Polar to Cartesian.
        sum += Vec3(ps.rr * c * c + ps.tt * s * s - 2 * ps.rt * s * c, ps.rr * s * s + ps.tt * c * c + 2 * ps.rt * s * c,
                    (ps.rr - ps.tt) * s * c + ps.rt * (c * c - s * s));
        w_sum += 1;
      }
  return w_sum > 0 ? Vec3(sum / w_sum) : Vec3::Zero();
}

Real circle_overlap_area(Real R, Real r, Real d) {
  if (d >= R + r) return 0;
  if (d <= std::abs(R - r)) return kPi * std::min(R, r) * std::min(R, r);
  const Real a1 = std::acos(std::clamp((d * d + r * r - R * R) / (2 * d * r), -1.0, 1.0));
  const Real a2 = std::acos(std::clamp((d * d + R * R - r * r) / (2 * d * R), -1.0, 1.0));
  return r * r * a1 + R * R * a2 - 0.5 * std::sqrt(std::max<Real>(0, (-d + r + R) * (d + r - R) * (d - r + R) * (d + r + R)));
}

CircleStress measure_circle(const dem::DemSystem& sys, const Vec3& centre, Real rho) {
  const auto& P = sys.particles;
  const int dim = sys.settings.dim;
  CircleStress m;
  m.centre = centre;
  m.radius = rho;
  auto inside = [&](Index i) { return (P.pos[i] - centre).squaredNorm() <= rho * rho; };
  Real vp = 0, solid = 0;
  for (std::size_t i = 0; i < P.size(); ++i) {
    const Real r = P.radius[i], d = (P.pos[i] - centre).norm();
    if (d > rho + r) continue;
    solid += dim == 3 ? geom::sphere_overlap_volume(rho, r, d) : circle_overlap_area(rho, r, d);
    if (!inside(static_cast<Index>(i))) continue;
    vp += dim == 3 ? 4.0 / 3.0 * kPi * r * r * r : kPi * r * r;
    ++m.particles;
  }
  const Real region = dim == 3 ? 4.0 / 3.0 * kPi * rho * rho * rho : kPi * rho * rho;
  m.porosity = 1 - solid / region;
  const Real volume = vp > 0 && solid > 0 ? vp * region / solid : 1;
  const Mat3 s = dem::average_stress_of(sys, inside, volume);
  m.xx = -s(0, 0);
  m.yy = -s(1, 1);
  m.zz = -s(2, 2);
  m.xy = -0.5 * (s(0, 1) + s(1, 0));
  return m;
}

}  // namespace ff::drivers::hydrofrac
