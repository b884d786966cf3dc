// Friction of the contacts between particles and the boundaries of a test (walls, flexible
// membrane elements, particle-membrane spheres).
#pragma once
#include "core/types.hpp"

namespace ff::dem {

// Friction of a boundary contact (wall, membrane element, membrane sphere) given as this value:
// the particle's own contact friction, dem.contact.<g>-<g>.friction of its group g, so that the
// boundary touches every particle "with the same contact law and friction as everything else"
// (issue 4; seed 000's PFC walls take the contact model of Table 7, mu_c = 0.4).
inline constexpr Real kGroupFriction = -1;
// What a boundary friction may be: a coefficient >= 0 or kGroupFriction.
inline bool valid_boundary_friction(Real mu) { return mu >= 0 || mu == kGroupFriction; }
// The friction a boundary contact of `particle_friction`'s particle uses.
inline Real boundary_friction(Real boundary, Real particle_friction) {
  return boundary == kGroupFriction ? particle_friction : boundary;
}

}  // namespace ff::dem
