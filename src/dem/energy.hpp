// Energy bookkeeping of a DemSystem (issue 13 item 6), on when DemSettings::track_energy is set.
// The system is the particles with their contacts and bonds; walls, boundaries (membrane),
// external loads and gravity act on it from outside. Over any interval
//   W_boundaries = dE_kin + dE_strain + D_damping + D_friction + D_dashpot + D_breakage
// (PFC's energy tracking: Itasca PFC 5/6 documentation, "Energy tracking": boundary work,
// kinetic, strain, local-damping, slip and dashpot energies; bond strain energy of Potyondy &
// Cundall 2004). How each term is computed, and why it closes with the leapfrog integrator:
//  * E_kin = sum 1/2 m~ v^2 + 1/2 I~ w^2 with the half-step velocities and the inertial (possibly
//    density-scaled) masses; leapfrog gives dE_kin = sum F.(v- + v+)/2 dt exactly for the net
//    force F, so every work below is taken with the mean velocity (v- + v+)/2 of the step.
//  * W_boundaries: the walls', boundaries', external loads' and gravity's forces and moments on
//    each particle times its mean velocity and spin (summed per particle, in a fixed order).
//  * D_damping: minus the work of Cundall's local damping force, the same way.
//  * D_friction: slip energy of each particle-particle contact, D = -(F0 + F1)/2 . (ds + dFs/k)
//    (contact_geometry.hpp, shear_work()); D_dashpot: c (d delta_n)^2 / dt per contact.
//  * E_strain: normal springs of the contacts (1/2 kn delta^2, or 8/15 E* sqrt(R*) delta^(5/2) for
//    Hertz), the intact bonds (each law's energy()), and the shear springs as the sum of the work
//    of their force increments (exactly |Fs|^2/(2 ks) for the linear law; for Hertz-Mindlin, whose
//    kt depends on the overlap, |Fs|^2/(2 kt) with the current kt is not a state function, so the
//    increments are summed instead).
//  * D_breakage: a bond's energy() when it breaks (its springs stop acting at once).
#pragma once
#include <vector>

#include "core/types.hpp"

namespace ff::dem {

// Cumulative since tracking started [J].
struct EnergyBook {
  Real boundary_work = 0;  // work of walls, boundaries, external loads and gravity on the particles
  Real damping = 0;        // dissipated by local damping
  Real friction = 0;       // dissipated by contact slip
  Real dashpot = 0;        // dissipated by the viscous normal dashpot
  Real bond_break = 0;     // strain energy of the bonds when they broke
  Real shear_work = 0;     // elastic work stored in the contacts' shear springs
  Real kinetic0 = 0, strain0 = 0;  // E_kin and E_strain when tracking started
  Real shear0 = 0;                 // the shear springs' |Fs|^2/(2 k) when tracking started
};

// Sum of f(i), i in [0, n), as T (+=), in fixed blocks: the same on any thread count. `part`
// holds the block sums (reserved beforehand: no allocation once it is large enough).
template <class T, class F>
T blocked_sum(std::size_t n, std::size_t parallel_min, std::vector<T>& part, F f) {
  constexpr std::size_t kBlock = 4096;
  const std::size_t nb = (n + kBlock - 1) / kBlock;
  part.resize(nb);
#pragma omp parallel for schedule(static) if (n > parallel_min)
  for (std::size_t b = 0; b < nb; ++b) {
    T s = T::Zero();
    const std::size_t end = std::min(n, (b + 1) * kBlock);
    for (std::size_t i = b * kBlock; i < end; ++i) s += f(i);
    part[b] = s;
  }
  T s = T::Zero();
  for (const T& v : part) s += v;
  return s;
}

}  // namespace ff::dem
