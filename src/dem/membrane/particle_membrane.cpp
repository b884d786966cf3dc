#include "dem/membrane/particle_membrane.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.hpp"
#include "dem/diagnostics.hpp"

namespace ff::dem {

namespace {
// Latex-like Poisson ratio of the membrane's own contacts and rotational bonds [-].
constexpr Real kMembranePoisson = 0.45;

Index sphere_index(const ParticleMembraneLayout& l, std::int64_t i, std::int64_t j) {
  i %= l.n_theta;
  if (i < 0) i += l.n_theta;
  return static_cast<Index>(l.first + j * l.n_theta + i);
}

// Grows an n x n pair table to (n+1) x (n+1): old pairs keep their values, (a, new) and
// (new, a) get cross(a), (new, new) gets own. Tables of another size (unused laws) stay as they are.
template <class T, class Cross>
void grow_table(std::vector<T>& table, int n, const T& own, Cross cross) {
  if (table.size() != static_cast<std::size_t>(n) * n) return;
  const int n1 = n + 1;
  std::vector<T> t(static_cast<std::size_t>(n1) * n1);
  for (int a = 0; a < n; ++a) {
    for (int b = 0; b < n; ++b) t[a * n1 + b] = table[a * n + b];
    t[a * n1 + n] = t[n * n1 + a] = cross(table[a * n + a]);
  }
  t[n * n1 + n] = own;
  table.swap(t);
}
}  // namespace

ParticleMembraneLayout particle_membrane_layout(const ParticleMembraneSpec& s) {
  auto bad = [](const std::string& what) { throw InputError("particle membrane: " + what); };
  const Real H = s.z_top - s.z_bottom;
  if (!(s.sample_radius > 0)) bad("the sample radius must be > 0");
  if (!(H > 0)) bad("the top platen must lie above the bottom one");
  if (!(s.particle_radius > 0)) bad("the membrane particle radius must be > 0");
  if (!(s.clearance >= 0)) bad("the clearance must be >= 0");
  if (!(s.pressure >= 0)) bad("the confining pressure must be >= 0");
  ParticleMembraneLayout l;
  // For n_z rows, r = H / (2 n_z); the ring is the smallest whose touching spheres clear the
  // sample: n_theta = the least n with R_c = r / sin(pi/n) >= R + clearance + r. Of the row counts
  // whose radius is within kRadiusTolerance of the requested one, the one whose inner surface
  // lies closest to R + clearance is taken (the ring's step in R_c is about r/pi otherwise).
  const Real want = s.sample_radius + s.clearance;
  const Real n_mid = H / (2 * s.particle_radius);
  const auto n_lo = std::max<std::int64_t>(1, static_cast<std::int64_t>(std::ceil(n_mid / (1 + kRadiusTolerance))));
  const auto n_hi = std::max(n_lo, static_cast<std::int64_t>(std::floor(n_mid / (1 - kRadiusTolerance))));
  Real best_gap = std::numeric_limits<Real>::infinity();
  for (std::int64_t nz = n_lo; nz <= n_hi; ++nz) {
    const Real r = H / (2.0 * static_cast<Real>(nz));  // rows touch, end rows touch the platens
    auto n_theta = std::max<std::int64_t>(3, static_cast<std::int64_t>(std::ceil(kPi / std::asin(r / (want + r)))));
    Real rc = r / std::sin(kPi / static_cast<Real>(n_theta));
    if (rc - r < want * (1 - 1e-12)) rc = r / std::sin(kPi / static_cast<Real>(++n_theta));
    const Real gap = rc - r - want;
    if (gap < best_gap) {
      best_gap = gap;
      l.n_z = nz;
      l.n_theta = n_theta;
      l.particle_radius = r;
      l.centre_radius = rc;
    }
  }
  l.z_bottom = s.z_bottom;
  l.z_top = s.z_top;
  l.pressure = s.pressure;
  l.force = s.pressure * 2 * kPi * l.inner_radius() * H / static_cast<Real>(l.count());
  return l;
}

Vec3 particle_membrane_position(const ParticleMembraneLayout& l, int i, int j) {
  const Real t = 2 * kPi * static_cast<Real>(i) / static_cast<Real>(l.n_theta);
  return Vec3(l.centre_radius * std::cos(t), l.centre_radius * std::sin(t),
              l.z_bottom + static_cast<Real>(2 * j + 1) * l.particle_radius);
}

int add_particle_membrane_group(Materials& m, const ParticleMembraneMaterial& pm) {
  if (m.group_index(kParticleMembraneGroup) >= 0)
    throw InputError(fmt::format("a particle group named '{}' is declared, but that name is reserved for the particle "
                                 "membrane (triaxial.lateral = \"particle_membrane\"); rename the group",
                                 kParticleMembraneGroup));
  const int n = m.groups();
  const Real E = pm.emod, nu = kMembranePoisson;
  // Every registered law's table grows (a table not filled for this scenario stays empty).
  for_each_law(ContactLaws{}, [&]<class Law>(std::type_identity<Law>) {
    grow_table(m.contact_params<Law>(), n, Law::elastic(E, nu), [&](typename Law::Params p) {
      p.fric = boundary_friction(pm.friction, p.fric);
      return p;
    });
  });
  // Soft, unbreakable bonds; (sample, membrane) pairs are never bonded.
  for_each_law(BondLaws{}, [&]<class Law>(std::type_identity<Law>) {
    grow_table(m.bond_params<Law>(), n, Law::elastic(E, nu, kUnbreakable), [](const typename Law::Material& p) { return p; });
  });
  m.group_names.emplace_back(kParticleMembraneGroup);
  m.density.push_back(pm.density);
  return n;
}

void remap_pair_indices(std::span<std::int32_t> pair, int n_old, int n_new) {
  for (auto& p : pair) p = (p / n_old) * n_new + p % n_old;
}

void InwardLoads::add_external_loads(ParticleStore& p) const {
  if (force_ == 0) return;
  for (const Index i : particle_) {  // constant magnitude, towards the z axis from where it is now
    const Vec3& x = p.pos[i];
    const Real rho = std::hypot(x.x(), x.y());
    if (rho > 0) p.ext_force[i] += Vec3(x.x(), x.y(), 0) * (-force_ / rho);
  }
}

void InwardLoads::reorder(std::span<const Index> new_of_old) {
  for (auto& i : particle_) i = new_of_old[i];
}

InwardLoads& attach_particle_membrane_loads(DemSystem& sys, const ParticleMembraneLayout& l) {
  std::vector<Index> idx(static_cast<std::size_t>(l.count()));
  for (std::int64_t k = 0; k < l.count(); ++k) idx[static_cast<std::size_t>(k)] = static_cast<Index>(l.first + k);
  return static_cast<InwardLoads&>(sys.add_boundary(std::make_unique<InwardLoads>(std::move(idx), l.force)));
}

ParticleMembraneLayout add_particle_membrane(DemSystem& sys, const ParticleMembraneSpec& spec,
                                             const ParticleMembraneMaterial& pm) {
  if (sys.settings.dim != 3) throw InputError("particle membrane: 3D samples only (dem.dim = 3)");
  if (pm.bonded && !sys.materials.has_bonds())
    throw InputError("particle membrane: its particles are bonded, so it needs dem.bond_law = \"parallel\" or \"rotational\"");
  ParticleMembraneLayout l = particle_membrane_layout(spec);
  const int n_old = sys.materials.groups();
  l.group = add_particle_membrane_group(sys.materials, pm);
  remap_pair_indices(sys.bonds.pair, n_old, sys.materials.groups());
  auto& P = sys.particles;
  l.first = static_cast<std::int64_t>(P.size());
  P.resize(P.size() + static_cast<std::size_t>(l.count()));
  for (std::int64_t j = 0; j < l.n_z; ++j)
    for (std::int64_t i = 0; i < l.n_theta; ++i) {
      const Index k = sphere_index(l, i, j);
      P.pos[k] = particle_membrane_position(l, static_cast<int>(i), static_cast<int>(j));
      P.radius[k] = l.particle_radius;
      P.group[k] = l.group;
      P.set_mass_from_density(k, pm.density, 3);
    }
  attach_particle_membrane_loads(sys, l);
  // Ring neighbours, then row neighbours, sphere by sphere (a fixed order).
  if (pm.bonded)
    for (std::int64_t j = 0; j < l.n_z; ++j)
      for (std::int64_t i = 0; i < l.n_theta; ++i) {
        sys.add_bond(sphere_index(l, i, j), sphere_index(l, i + 1, j));
        if (j + 1 < l.n_z) sys.add_bond(sphere_index(l, i, j), sphere_index(l, i, j + 1));
      }
  sys.initialise();
  return l;
}

Real stabilise_particle_membrane(DemSystem& sys, ParticleMembraneLayout& l, Real dt, Real safety,
                                 int assumed_contacts) {
  auto& P = sys.particles;
  const auto& mat = sys.materials;
  const Real r = l.particle_radius;
  // Stiffest contact with a sample sphere: the linear kn = pi min(r, rs)^2 E / (r + rs) peaks at
  // rs = r, so the sample radius closest to r is taken for every sample group.
  Real rs_lo = std::numeric_limits<Real>::infinity(), rs_hi = 0;
  for (std::int64_t i = 0; i < l.first; ++i) {
    rs_lo = std::min(rs_lo, P.radius[i]);
    rs_hi = std::max(rs_hi, P.radius[i]);
  }
  if (l.first == 0) rs_lo = rs_hi = r;
  const Real rs = std::clamp(r, rs_lo, rs_hi);
  Real kc = 0;
  for (int g = 0; g < mat.groups(); ++g)
    if (g != l.group) kc = std::max(kc, pair_stiffness(sys, mat.pair(l.group, g), r, rs, 0.01 * std::min(r, rs)));
  // Four bonds and four soft contacts with its ring and row neighbours.
  const int pm = mat.pair(l.group, l.group);
  Real kb = 0, kb_rot = 0;
  mat.with_bond_law([&]<class Law>(std::type_identity<Law>) {
    const auto& bm = mat.bond_params<Law>();
    if (bm.empty()) return;
    const auto st = Law::install(bm[pm], BondEnds{Vec3::Zero(), Vec3(2 * r, 0, 0), Quat::Identity(), Quat::Identity(), r, r});
    Law::time_step_stiffness(bm[pm], st, r, r, 3, kb, kb_rot);
  });
  const Real kmm = pair_stiffness(sys, pm, r, r, 0.01 * r);
  const Real kt = assumed_contacts * kc + 4 * (kb + kmm);
  const Real kr = assumed_contacts * kc * r * r + 4 * (kb_rot + (kb + kmm) * r * r);
  if (l.count() == 0) return 1;
  const auto k0 = static_cast<std::size_t>(l.first);
  const Real crit = std::min(std::sqrt(1 / (P.inv_mass[k0] * kt)), std::sqrt(1 / (P.inv_inertia[k0] * kr)));
  const Real need = dt / safety;
  if (crit >= need) return 1;
  const Real f = (need / crit) * (need / crit);
  for (std::int64_t k = 0; k < l.count(); ++k) {
    P.inv_mass[k0 + k] /= f;
    P.inv_inertia[k0 + k] /= f;
  }
  l.mass_factor *= f;
  return f;
}

void limit_particle_membrane_speed(ParticleStore& p, const ParticleMembraneLayout& l, Real v_max) {
  for (std::int64_t k = 0; k < l.count(); ++k) {
    Vec3& v = p.vel[static_cast<std::size_t>(l.first + k)];
    const Real s2 = v.squaredNorm();
    if (s2 > v_max * v_max) v *= v_max / std::sqrt(s2);
  }
}

Real particle_membrane_mean_radius(const ParticleStore& p, const ParticleMembraneLayout& l) {
  Real s = 0;
  for (std::int64_t k = 0; k < l.count(); ++k) {
    const Vec3& x = p.pos[static_cast<std::size_t>(l.first + k)];
    s += std::hypot(x.x(), x.y());
  }
  return l.count() ? s / static_cast<Real>(l.count()) : 0;
}

Real particle_membrane_confinement(const ParticleStore& p, const ParticleMembraneLayout& l, Real z_lo, Real z_hi) {
  const Real r_in = particle_membrane_mean_radius(p, l) - l.particle_radius;
  return l.total_force() / (2 * kPi * r_in * (z_hi - z_lo));
}

Real particle_membrane_volume(const ParticleStore& p, const ParticleMembraneLayout& l, Real z_lo, Real z_hi) {
  const Real r_in = particle_membrane_mean_radius(p, l) - l.particle_radius;
  return kPi * r_in * r_in * (z_hi - z_lo);
}

void particle_membrane_profile(const ParticleStore& p, const ParticleMembraneLayout& l, std::span<Real> radius,
                               std::span<Real> z) {
  for (std::int64_t j = 0; j < l.n_z; ++j) {
    Real sr = 0, sz = 0;
    for (std::int64_t i = 0; i < l.n_theta; ++i) {
      const Vec3& x = p.pos[sphere_index(l, i, j)];
      sr += std::hypot(x.x(), x.y());
      sz += x.z();
    }
    radius[j] = sr / static_cast<Real>(l.n_theta);
    z[j] = sz / static_cast<Real>(l.n_theta);
  }
}

std::size_t particle_membrane_bonds(const DemSystem& sys, const ParticleMembraneLayout& l) {
  const int pm = sys.materials.pair(l.group, l.group);
  std::size_t n = 0;
  for (std::size_t b = 0; b < sys.bonds.i.size(); ++b) n += sys.bonds.pair[b] == pm && !sys.bonds.broken[b];
  return n;
}

}  // namespace ff::dem
