#include "dem/diagnostics.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>

#include "core/error.hpp"

namespace ff::dem {

namespace {
// Sums f(i) for i in [0, n) in fixed blocks, so the result does not depend on the thread count.
template <class F>
Real deterministic_sum(std::size_t n, std::size_t parallel_min, F f) {
  constexpr std::size_t kBlock = 4096;
  const std::size_t nb = (n + kBlock - 1) / kBlock;
  std::vector<Real> part(nb, 0.0);
#pragma omp parallel for schedule(static) if (n > parallel_min)
  for (std::size_t b = 0; b < nb; ++b) {
    Real s = 0;
    const std::size_t end = std::min(n, (b + 1) * kBlock);
    for (std::size_t i = b * kBlock; i < end; ++i) s += f(i);
    part[b] = s;
  }
  Real s = 0;
  for (Real v : part) s += v;
  return s;
}
}  // namespace

std::size_t intact_bonds(const DemSystem& s) { return s.bonds.intact(); }

long contacts_touching(const DemSystem& s) {
  long c = 0;
  for (auto& L : s.pair_loads()) c += L.f.squaredNorm() > 0;
  return c;
}

Real kinetic_energy(const DemSystem& s) {
  const auto& p = s.particles;
  return deterministic_sum(p.size(), s.settings.parallel_min, [&](std::size_t i) {
    return 0.5 * p.mass[i] * p.vel[i].squaredNorm() + 0.5 * p.inertia[i] * p.omega[i].squaredNorm();
  });
}

namespace {
// Normal springs of the touching contacts plus the intact bonds [J] (with_shear: also the shear
// springs' |Fs|^2/(2 k)).
Real contact_and_bond_energy(const DemSystem& s, bool with_shear) {
  const auto& x = s.particles.pos;
  const auto& r = s.particles.radius;
  const auto& materials = s.materials;
  const auto pi = s.neighbors().first(), pj = s.neighbors().second();
  const auto& cstate = s.contact_state();
  const int dim = s.settings.dim;
  Real e = 0;
  materials.with_contact_law([&]<class Law>(std::type_identity<Law>) {
    const auto& prm = materials.contact_params<Law>();
    for (std::size_t p = 0; p < pi.size(); ++p) {
      const Index a = pi[p], b = pj[p];
      const Real gap = (x[b] - x[a]).norm() - r[a] - r[b];
      if (gap >= 0) continue;
      const int pt = materials.pair(s.particles.group[a], s.particles.group[b]);
      e += with_shear ? Law::strain_energy(prm[pt], r[a], r[b], -gap, cstate[p], dim)
                      : Law::normal_energy(prm[pt], r[a], r[b], -gap, dim);
    }
  });
  const BondSet& bs = s.bonds;
  materials.with_bond_law([&]<class Law>(std::type_identity<Law>) {
    const auto& mats = materials.bond_params<Law>();
    const auto& st = bs.state<Law>();
    for (std::size_t b = 0; b < bs.size(); ++b)
      if (!bs.broken[b]) e += Law::energy(mats[bs.pair[b]], st[b], r[bs.i[b]], r[bs.j[b]], dim);
  });
  return e;
}

Real inertial_kinetic_energy(const DemSystem& s) {
  const auto& p = s.particles;
  return deterministic_sum(p.size(), s.settings.parallel_min, [&](std::size_t i) {
    // Particles held at a prescribed velocity (zero inverse mass) belong to the boundary.
    return (p.inv_mass[i] != 0 ? 0.5 * p.vel[i].squaredNorm() / p.inv_mass[i] : 0.0) +
           (p.inv_inertia[i] != 0 ? 0.5 * p.omega[i].squaredNorm() / p.inv_inertia[i] : 0.0);
  });
}
}  // namespace

Real strain_energy(const DemSystem& s) { return contact_and_bond_energy(s, true); }

void start_energy_tracking(DemSystem& s) {
  EnergyBook b;
  const Real normal = contact_and_bond_energy(s, false);
  b.shear0 = contact_and_bond_energy(s, true) - normal;
  b.strain0 = normal + b.shear0;
  b.kinetic0 = inertial_kinetic_energy(s);
  s.energy = b;
}

EnergyReport energy_report(const DemSystem& s) {
  const EnergyBook& b = s.energy;
  EnergyReport e;
  e.kinetic = inertial_kinetic_energy(s);
  // The shear springs hold what they held at the start plus the work of their force increments.
  e.strain = contact_and_bond_energy(s, false) + b.shear0 + b.shear_work;
  e.boundary_work = b.boundary_work;
  e.damping = b.damping;
  e.friction = b.friction;
  e.dashpot = b.dashpot;
  e.bond_break = b.bond_break;
  const Real accounted = (e.kinetic - b.kinetic0) + (e.strain - b.strain0) + e.damping + e.friction + e.dashpot + e.bond_break;
  e.balance_error = b.boundary_work != 0 ? (b.boundary_work - accounted) / std::abs(b.boundary_work) : 0.0;
  return e;
}

Real max_unbalanced_force_ratio(const DemSystem& s, std::size_t first) {
  const std::size_t n = std::min(first, s.particles.size());
  const Real unbalanced =
      deterministic_sum(n, s.settings.parallel_min, [&](std::size_t i) { return s.particles.force[i].norm(); });
  // Mean over the interactions that carry load (PFC's "average ratio").
  Real contact = 0;
  std::size_t loaded = 0;
  auto add = [&](const PairLoad& L) {
    const Real f = L.f.norm();
    if (f > 0) { contact += f; ++loaded; }
  };
  for (auto& L : s.pair_loads()) add(L);
  for (auto& L : s.bonds.loads()) add(L);
  for (auto& wc : s.wall_contacts())
    for (auto& L : wc.load) add(L);
  if (loaded == 0 || n == 0) return 0;
  return (unbalanced / static_cast<Real>(n)) / (contact / static_cast<Real>(loaded));
}

Real pair_stiffness(const DemSystem& s, int pt, Real rA, Real rB, Real overlap) {
  Real k = 0;
  s.materials.with_contact_law([&]<class Law>(std::type_identity<Law>) {
    k = Law::time_step_stiffness(s.materials.contact_params<Law>()[pt], rA, rB, overlap, s.settings.dim);
  });
  return k;
}

Real critical_time_step(const DemSystem& s, std::span<const Real> extra_stiffness) {
  const auto& particles = s.particles;
  const auto& materials = s.materials;
  const std::size_t n = particles.size();
  std::vector<Real> kt(n, 0.0), kr(n, 0.0);
  const auto& x = particles.pos;
  const auto& r = particles.radius;
  const auto& grp = particles.group;
  const auto pi = s.neighbors().first(), pj = s.neighbors().second();
  for (std::size_t p = 0; p < pi.size(); ++p) {
    const Index a = pi[p], b = pj[p];
    const Real gap = (x[b] - x[a]).norm() - r[a] - r[b];
    if (gap >= 0) continue;
    const int pt = materials.pair(grp[a], grp[b]);
    const Real k = pair_stiffness(s, pt, r[a], r[b], -gap);
    kt[a] += k; kt[b] += k;
    kr[a] += k * r[a] * r[a]; kr[b] += k * r[b] * r[b];  // shear springs' lever arms (k >= ks)
  }
  const BondSet& bs = s.bonds;
  materials.with_bond_law([&]<class Law>(std::type_identity<Law>) {
    const auto& mats = materials.bond_params<Law>();
    const auto& st = bs.state<Law>();
    for (std::size_t b = 0; b < bs.size(); ++b) {
      if (bs.broken[b]) continue;
      const Index i = bs.i[b], j = bs.j[b];
      Real k = 0, krot = 0;
      Law::time_step_stiffness(mats[bs.pair[b]], st[b], r[i], r[j], s.settings.dim, k, krot);
      kt[i] += k; kt[j] += k;
      kr[i] += krot + k * r[i] * r[i];
      kr[j] += krot + k * r[j] * r[j];
    }
  });
  for (std::size_t w = 0; w < s.walls.size(); ++w) {
    const auto& wc = s.wall_contacts()[w];
    for (std::size_t k = 0; k < wc.particle.size(); ++k) {
      const Index i = wc.particle[k];
      ContactGeom g;
      if (!s.walls[w].geometry(g, x[i], r[i]) || g.gap >= 0) continue;
      const Real kw = pair_stiffness(s, materials.pair(grp[i], grp[i]), r[i], 0, -g.gap);
      kt[i] += kw;
      kr[i] += kw * r[i] * r[i];
    }
  }
  for (const auto& bnd : s.boundaries()) {
    const auto cp = bnd->contact_particles();
    const auto ck = bnd->contact_stiffness();
    for (std::size_t c = 0; c < cp.size(); ++c) {
      kt[cp[c]] += ck[c];
      kr[cp[c]] += ck[c] * r[cp[c]] * r[cp[c]];
    }
  }
  if (!extra_stiffness.empty() && extra_stiffness.size() != n)
    throw Error(fmt::format("critical_time_step: {} extra stiffnesses for {} particles", extra_stiffness.size(), n));
  Real dt = std::numeric_limits<Real>::infinity();
  for (std::size_t i = 0; i < n; ++i) {
    // A particle with no contact yet still meets one like itself (free particles otherwise
    // give no bound at all); a coupled module's stiffness adds to that, never replaces it (until
    // session 49 a floater's pore-fluid stiffness did, and the "critical step with the fluid" came
    // out 100 x longer than the solid's own for a sample with tiny grains).
    // A stiffness that overflowed (a modulus or bond radius multiplier of 1e300: inf, or NaN from
    // 0 x inf) allows no step; the fallback below and std::min would skip the NaN.
    if (!std::isfinite(kt[i]) || !std::isfinite(kr[i])) return 0;
    const Real k_solid = kt[i] > 0 ? kt[i] : pair_stiffness(s, materials.pair(grp[i], grp[i]), r[i], r[i], 0.01 * r[i]);
    const Real k = k_solid + (extra_stiffness.empty() ? 0 : extra_stiffness[i]);
    const Real kk = kr[i] > 0 ? kr[i] : k_solid * r[i] * r[i];
    if (!std::isfinite(k) || !std::isfinite(kk)) return 0;
    dt = std::min({dt, std::sqrt(1.0 / (particles.inv_mass[i] * k)), std::sqrt(1.0 / (particles.inv_inertia[i] * kk))});
  }
  return dt;
}

void scale_masses_for(DemSystem& s, Real dt, Real safety, std::span<const Real> extra_stiffness) {
  // m~ = max(m, (dt/s)^2 k_tran) (METHODS.md 1.6): done by scaling until the estimate allows dt.
  const Real dt_now = critical_time_step(s, extra_stiffness) * safety;
  if (dt_now >= dt) return;
  const Real f = (dt / dt_now) * (dt / dt_now);
  for (std::size_t i = 0; i < s.particles.size(); ++i) {
    s.particles.inv_mass[i] /= f;
    s.particles.inv_inertia[i] /= f;
  }
}

}  // namespace ff::dem
