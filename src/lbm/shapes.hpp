// Minimal analytic solids for the LBM (lattice units, cell centres at integer coordinates):
// enough to mark solid cells and to compute the wall distance q on each cut link for
// interpolated bounce-back (METHODS §4.6). The general geometry module will supply more
// shapes later; these stay small on purpose.
#pragma once
#include <variant>

#include "core/types.hpp"

namespace ff::lbm {

// Circular cylinder with its axis along z (a disk on a 2D lattice).
struct Circle {
  Vec3 center = Vec3::Zero();
  double radius = 1;
};
struct Sphere {
  Vec3 center = Vec3::Zero();
  double radius = 1;
};
// Axis-aligned box [lo, hi].
struct Box {
  Vec3 lo = Vec3::Zero();
  Vec3 hi = Vec3::Zero();
};
using Shape = std::variant<Circle, Sphere, Box>;

bool inside(const Shape& s, const Vec3& p);

// For a segment a -> b with a outside and b inside the shape, the fraction s in [0, 1] of the
// way from a where the segment first meets the surface (the link fraction q of Bouzidi et al.).
double entry_fraction(const Shape& s, const Vec3& a, const Vec3& b);

// A reference point of the shape (torques are taken about it).
Vec3 reference_point(const Shape& s);

}  // namespace ff::lbm
