#include "geometry/shapes.hpp"

#include <algorithm>
#include <cmath>

namespace ff::geom {

bool Box::contains(const Vec3& p) const {
  return (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all();
}

bool Cylinder::contains(const Vec3& p) const {
  const Vec3 d = p - base;
  const Real s = d.dot(axis);
  if (s < 0 || s > length) return false;
  return (d - s * axis).squaredNorm() <= radius * radius;
}

// Bounding box of a cylinder: each end disc extends radius*sqrt(1 - a_k^2) along axis k.
Aabb Cylinder::bounds() const {
  const Vec3 e = (Vec3::Ones() - axis.cwiseProduct(axis)).cwiseMax(0.0).cwiseSqrt() * radius;
  const Vec3 top = base + length * axis;
  return Aabb{base.cwiseMin(top) - e, base.cwiseMax(top) + e};
}

bool Ellipsoid::contains(const Vec3& p) const {
  const Vec3 q = orientation.conjugate() * (p - c);  // world -> body frame
  return q.cwiseQuotient(semi_axes).squaredNorm() <= 1.0;
}

// Half extent along world axis k is |R_k. * semi_axes| (row k of R scaled by the semi-axes).
Aabb Ellipsoid::bounds() const {
  const Mat3 m = orientation.toRotationMatrix() * semi_axes.asDiagonal();
  const Vec3 e = m.rowwise().norm();
  return Aabb{c - e, c + e};
}

bool region_contains(const Region& region, const Vec3& p) {
  return std::visit([&](const auto& r) { return r.contains(p); }, region);
}

Aabb region_bounds(const Region& region) {
  return std::visit([](const auto& r) { return r.bounds(); }, region);
}

Real sphere_overlap_volume(Real R, Real r, Real d) {
  if (d >= R + r) return 0;
  const Real small = std::min(R, r), large = std::max(R, r);
  if (d <= large - small) return 4.0 / 3.0 * kPi * small * small * small;
  const Real t = R + r - d;
  return kPi * t * t * (d * d + 2 * d * r - 3 * r * r + 2 * d * R + 6 * r * R - 3 * R * R) / (12 * d);
}

}  // namespace ff::geom
