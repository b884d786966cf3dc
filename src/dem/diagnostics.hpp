// Diagnostics of a DemSystem, read-only (free functions over a const DemSystem&): energies,
// Love-Weber average stress, critical time step, unbalanced force, contact and bond counts.
#pragma once
#include <limits>
#include <span>

#include "dem/dem_system.hpp"

namespace ff::dem {

std::size_t intact_bonds(const DemSystem& s);
long contacts_touching(const DemSystem& s);
Real kinetic_energy(const DemSystem& s);  // translational + rotational [J] (half-step velocities)
Real strain_energy(const DemSystem& s);   // springs of contacts and intact bonds [J]
// Mean |F_unbalanced| over the first `particles` particles (all by default) / mean |F_contact|
// over the loaded interactions.
Real max_unbalanced_force_ratio(const DemSystem& s, std::size_t particles = std::numeric_limits<std::size_t>::max());
// Normal stiffness of a contact of pair type `pair_type` (rB = 0: a wall) [N/m]; Hertz at
// `overlap`, at least 1% of the smaller radius (time-step estimates).
Real pair_stiffness(const DemSystem& s, int pair_type, Real rA, Real rB, Real overlap);
// Critical time step sqrt(m/k_tran), sqrt(I/k_rot) over all particles (METHODS.md 1.6), from the
// current contacts, bonds, wall and boundary contacts. `extra_stiffness` (empty, or one entry per
// particle [N/m]) adds what another physics module pushes on each particle with, e.g. the pore fluid
// (coupling::DemPorenetCoupling::fluid_stiffness): central forces, so translational only.
Real critical_time_step(const DemSystem& s, std::span<const Real> extra_stiffness = {});
// Density scaling: inertial masses so that `dt` is `safety` times the critical step.
void scale_masses_for(DemSystem& s, Real dt, Real safety, std::span<const Real> extra_stiffness = {});

// Energy bookkeeping (energy.hpp; settings.track_energy). start_energy_tracking() zeroes the
// book and takes the present kinetic and strain energies as the reference.
struct EnergyReport {
  Real kinetic = 0;        // E_kin with the inertial masses, half-step velocities [J]
  Real strain = 0;         // E_strain of contacts (normal + shear) and intact bonds [J]
  Real boundary_work = 0, damping = 0, friction = 0, dashpot = 0, bond_break = 0;  // since the start [J]
  // (W - dE_kin - dE_strain - D) / W: the part of the boundary work not accounted for [-]
  Real balance_error = 0;
};
void start_energy_tracking(DemSystem& s);
EnergyReport energy_report(const DemSystem& s);

// Love-Weber average stress of the particles i with selected(i) (tension +), divided by `volume`
// [Pa] (METHODS.md 1.7).
template <class Pred> Mat3 average_stress_of(const DemSystem& s, Pred selected, Real volume);
// The same over the particles whose centres lie in `inside` (a predicate of the position).
template <class Pred> Mat3 average_stress(const DemSystem& s, Pred inside, Real volume) {
  return average_stress_of(s, [&](Index i) { return inside(s.particles.pos[i]); }, volume);
}

template <class Pred>
Mat3 average_stress_of(const DemSystem& sys, Pred inside, Real volume) {
  // sigma_ij = 1/V sum_p sum_c (x^c_i - x^p_i) F^{c,p}_j with F^{c,p} the force on p at c.
  Mat3 s = Mat3::Zero();
  const auto& x = sys.particles.pos;
  const auto& rad = sys.particles.radius;
  auto add_pair = [&](Index a, Index b, const Vec3& xc, const Vec3& f_on_b) {
    if (inside(b)) s += (xc - x[b]) * f_on_b.transpose();
    if (inside(a)) s -= (xc - x[a]) * f_on_b.transpose();
  };
  const auto pi = sys.neighbors().first(), pj = sys.neighbors().second();
  const auto& pload = sys.pair_loads();
  for (std::size_t p = 0; p < pi.size(); ++p) {
    const Vec3& f = pload[p].f;
    if (f.squaredNorm() == 0) continue;
    const Real ra = rad[pi[p]];
    const Vec3 n = (x[pj[p]] - x[pi[p]]).normalized();
    add_pair(pi[p], pj[p], x[pi[p]] + ra * n, f);
  }
  const BondSet& bs = sys.bonds;
  const auto& bload = bs.loads();
  for (std::size_t b = 0; b < bs.size(); ++b) {
    if (bs.broken[b]) continue;
    const Index a = bs.i[b], c = bs.j[b];
    const Vec3 n = (x[c] - x[a]).normalized();
    add_pair(a, c, x[a] + rad[a] * n, bload[b].f);
  }
  for (std::size_t w = 0; w < sys.walls.size(); ++w) {
    const auto& wc = sys.wall_contacts()[w];
    for (std::size_t k = 0; k < wc.particle.size(); ++k) {
      const Index p = wc.particle[k];
      const Vec3& f_wall = wc.load[k].f;
      if (f_wall.squaredNorm() == 0 || !inside(p)) continue;
      ContactGeom g;
      if (!sys.walls[w].geometry(g, x[p], rad[p])) continue;
      s += (g.xc - x[p]) * (-f_wall).transpose();
    }
  }
  for (const auto& bnd : sys.boundaries()) {  // the boundary pushes the particle with -f at xc
    const auto cp = bnd->contact_particles();
    const auto cl = bnd->contact_loads();
    for (std::size_t c = 0; c < cp.size(); ++c)
      if (cl[c].f.squaredNorm() > 0 && inside(cp[c])) s += (cl[c].xc - x[cp[c]]) * (-cl[c].f).transpose();
  }
  return s / volume;
}

}  // namespace ff::dem
