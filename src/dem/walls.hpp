// Rigid walls: planes (platens, box sides) and the inside of cylinders (sample vessel,
// rigid confining sleeve). A wall is body B of a contact with rB = 0, so walls go through the
// same contact laws as particles (STYLE.md B). Each wall has a prescribed velocity (planes:
// translation; cylinders: radial speed) and accumulates the force the particles exert on it.
#pragma once
#include <string>
#include <vector>

#include "dem/contact/boundary_friction.hpp"
#include "dem/contact/contact_geometry.hpp"

namespace ff::dem {

struct Wall {
  enum class Kind : std::uint8_t { Plane, CylinderInside } kind = Kind::Plane;
  std::string name;
  Vec3 point = Vec3::Zero();   // plane: a point on it; cylinder: a point on the axis
  Vec3 normal = Vec3::UnitZ(); // plane: unit normal pointing to the particles; cylinder: unit axis
  Real radius = 0;             // cylinder radius [m]
  Vec3 velocity = Vec3::Zero();  // plane translation velocity [m/s]
  Real radial_velocity = 0;    // cylinder: dR/dt [m/s]
  Real friction = 0.5;         // Coulomb friction of wall contacts [-]; kGroupFriction: the particle's own
                               // group contact friction, as between two of its particles
  bool active = true;
  // Output of the last step: total force exerted BY the particles ON the wall [N],
  // and the summed normal stiffness of its contacts (for servos) [N/m].
  Vec3 force = Vec3::Zero();
  Real contact_stiffness = 0;
  int contacts = 0;
  Vec3 displacement = Vec3::Zero();  // accumulated translation [m]

  // Fills the contact geometry of particle (x, r) against this wall; false if no geometry
  // (particle on the wrong side or on the cylinder axis). A = particle, B = wall.
  bool geometry(ContactGeom& g, const Vec3& x, Real r) const {
    Vec3 n;
    Real dist;
    if (kind == Kind::Plane) {
      dist = (x - point).dot(normal);
      if (dist <= 0) return false;
      n = -normal;
    } else {
      const Vec3 d = x - point;
      const Vec3 radial = d - d.dot(normal) * normal;
      const Real rho = radial.norm();
      if (rho <= 0 || rho >= radius) return false;
      dist = radius - rho;
      n = radial / rho;
    }
    g.n = n;
    g.gap = dist - r;
    g.xc = x + (r + 0.5 * g.gap) * n;
    g.rA = r;
    g.rB = 0;
    return true;
  }
  // Wall velocity at a point of its surface.
  Vec3 velocity_at(const ContactGeom& g) const { return kind == Kind::Plane ? velocity : radial_velocity * g.n; }
  // Distance the surface moved in one step (neighbour-list skin check).
  Real step_motion(Real dt) const { return kind == Kind::Plane ? std::abs(velocity.dot(normal)) * dt : std::abs(radial_velocity) * dt; }
  void move(Real dt) {
    if (kind == Kind::Plane) {
      point += velocity * dt;
      displacement += velocity * dt;
    } else {
      radius += radial_velocity * dt;
    }
  }
};

}  // namespace ff::dem
