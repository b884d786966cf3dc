// Axis-aligned bounding box, the common bound of every region and mesh.
#pragma once
#include <limits>

#include "core/types.hpp"

namespace ff::geom {
struct Aabb {
  Vec3 lo{Vec3::Constant(std::numeric_limits<Real>::infinity())};
  Vec3 hi{Vec3::Constant(-std::numeric_limits<Real>::infinity())};

  bool empty() const { return (lo.array() > hi.array()).any(); }
  void expand(const Vec3& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  bool contains(const Vec3& p) const {
    return (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all();
  }
  Vec3 extent() const { return hi - lo; }
};
}  // namespace ff::geom

namespace ff {
using geom::Aabb;
}  // namespace ff
