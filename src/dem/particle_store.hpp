// Particles as structure of arrays: one contiguous array per property (STYLE.md C).
// 2D runs use the same arrays: disks of unit thickness in the x-y plane (z, vz, wx, wy stay 0).
#pragma once
#include <vector>

#include "core/types.hpp"

namespace ff::dem {

struct ParticleStore {
  // State (checkpointed).
  std::vector<Vec3> pos, vel, omega;      // [m], [m/s], [rad/s]
  std::vector<Quat> orient;               // body orientation (needed by rotational bonds)
  std::vector<Vec3> disp;                 // displacement since the sample was built [m] (output)
  std::vector<Real> radius;               // [m]
  std::vector<Real> mass, inertia;        // physical mass [kg], moment of inertia [kg m^2]
  std::vector<Real> inv_mass, inv_inertia;  // inertial (possibly density-scaled) inverses
  std::vector<std::int32_t> group;        // material group index
  // Load of constant magnitude towards the z axis: horizontal, along -(x, y, 0)/|(x, y)| from the
  // current position every step, so it exerts no moment about the axis (the confining loads of a
  // particle membrane); zero for most particles [N].
  std::vector<Real> inward_force;
  // Per-step accumulators (not checkpointed: recomputed every step).
  std::vector<Vec3> force, moment;

  std::size_t size() const { return pos.size(); }
  void resize(std::size_t n) {
    pos.resize(n, Vec3::Zero()); vel.resize(n, Vec3::Zero()); omega.resize(n, Vec3::Zero());
    orient.resize(n, Quat::Identity()); disp.resize(n, Vec3::Zero()); radius.resize(n, 0);
    mass.resize(n, 0); inertia.resize(n, 0); inv_mass.resize(n, 0); inv_inertia.resize(n, 0);
    group.resize(n, 0); inward_force.resize(n, 0);
    force.resize(n, Vec3::Zero()); moment.resize(n, Vec3::Zero());
  }
  // Sets mass and inertia from density: spheres in 3D, disks of thickness 1 m in 2D.
  void set_mass_from_density(std::size_t i, Real density, int dim) {
    const Real r = radius[i];
    if (dim == 3) {
      mass[i] = density * 4.0 / 3.0 * kPi * r * r * r;
      inertia[i] = 0.4 * mass[i] * r * r;
    } else {
      mass[i] = density * kPi * r * r;  // unit thickness
      inertia[i] = 0.5 * mass[i] * r * r;
    }
    inv_mass[i] = 1.0 / mass[i];
    inv_inertia[i] = 1.0 / inertia[i];
  }
};

}  // namespace ff::dem
