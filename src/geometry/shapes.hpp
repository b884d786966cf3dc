// Region primitives used to carve samples and to assign particles to material groups.
// Each shape answers `contains(point)` (boundary points count as inside) and `bounds()`.
#pragma once
#include <variant>

#include "core/types.hpp"
#include "geometry/aabb.hpp"
#include "geometry/point_in_mesh.hpp"

namespace ff::geom {

// Axis-aligned box [lo, hi].
struct Box {
  Vec3 lo{Vec3::Zero()}, hi{Vec3::Zero()};
  bool contains(const Vec3& p) const;
  Aabb bounds() const { return Aabb{lo, hi}; }
};

struct Sphere {
  Vec3 c{Vec3::Zero()};
  Real r = 0;
  bool contains(const Vec3& p) const { return (p - c).squaredNorm() <= r * r; }
  Aabb bounds() const { return Aabb{(c.array() - r).matrix(), (c.array() + r).matrix()}; }
};

// Finite circular cylinder from `base` along the unit vector `axis` for `length`.
struct Cylinder {
  Vec3 base{Vec3::Zero()};
  Vec3 axis{Vec3::UnitZ()};  // unit length
  Real radius = 0, length = 0;
  bool contains(const Vec3& p) const;
  Aabb bounds() const;
};

// Ellipsoid with semi-axes along the body axes, rotated by `orientation` (body -> world).
struct Ellipsoid {
  Vec3 c{Vec3::Zero()};
  Vec3 semi_axes{Vec3::Ones()};
  Quat orientation{Quat::Identity()};
  bool contains(const Vec3& p) const;
  Aabb bounds() const;
};

using Region = std::variant<Box, Sphere, Cylinder, Ellipsoid, MeshRegion>;

bool region_contains(const Region& region, const Vec3& p);
Aabb region_bounds(const Region& region);

// Volume of the intersection of two spheres of radii R and r whose centres are d apart (a lens,
// the sum of two spherical caps; the smaller sphere when one holds the other) [m^3].
Real sphere_overlap_volume(Real R, Real r, Real d);

}  // namespace ff::geom

namespace ff {
using geom::Box;
using geom::Cylinder;
using geom::Ellipsoid;
using geom::Region;
using geom::region_bounds;
using geom::region_contains;
using geom::Sphere;
}  // namespace ff
