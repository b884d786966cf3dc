// The DEM particles (SI) as the LBM's particle set (lattice units), and the LBM's loads back in
// SI: the one conversion every DEM-LBM coupling uses (DemLbmCoupler, the hydrofrac LBM fluid).
//   position (x - origin) / dx (origin: SI centre of cell (0, 0, 0)), radius r / dx,
//   velocity v dt / dx, omega omega dt (Units: lbm/units.hpp), ids carried along;
//   2D (D2Q9): z of the position and velocity and the in-plane components of omega are zeroed.
// `motion` scales the velocities (1: moving walls; 0: the particles are quasi-static walls for the
// fluid, which the hydrofrac LBM uses by default: docs/hydrofrac.md).
#pragma once
#include "dem/particle_store.hpp"
#include "lbm/psm.hpp"
#include "lbm/units.hpp"

namespace ff::coupling {

// Fills `set` (resized to the particles' count; no allocation once it has that size).
void fill_particle_set(const dem::ParticleStore& p, const Vec3& origin, const lbm::Units& u, int dim, lbm::ParticleSet& set,
                       double motion = 1.0);

// A particle's force and torque of the LBM (lattice units) in SI: [N], [N m]; 2D per metre of
// depth (the force on the DEM's unit-thickness disk), the out-of-plane force and the in-plane
// torque zeroed.
struct SiLoad {
  Vec3 force, torque;
};
SiLoad to_si_load(const lbm::Units& u, int dim, const Vec3& force, const Vec3& torque);

}  // namespace ff::coupling
