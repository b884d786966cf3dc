#include "dem/dem_system.hpp"

#include <fmt/format.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>

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

std::size_t DemSystem::install_bonds(Real max_gap) {
  // Candidates come from a fresh neighbour list whose skin exceeds the bonding gap slightly: the
  // list keeps pairs closer than (not at) its cut-off, and a pair with gap == max_gap (touching
  // spheres with max_gap = 0) must be bonded. The exact test is the `gap > max_gap` below.
  const Real r_max = particles.size() ? *std::max_element(particles.radius.begin(), particles.radius.end()) : 0;
  NeighborList tmp;
  tmp.build(particles.pos, particles.radius, std::max(max_gap, Real(0)) + 1e-9 * r_max);
  const auto pi = tmp.first(), pj = tmp.second();
  std::size_t added = 0;
  for (std::size_t p = 0; p < pi.size(); ++p) {
    const Index a = pi[p], b = pj[p];
    const Real gap = (particles.pos[b] - particles.pos[a]).norm() - particles.radius[a] - particles.radius[b];
    if (gap > max_gap) continue;
    add_bond(a, b);
    ++added;
  }
  build_bond_adjacency();
  return added;
}

void DemSystem::add_bond(Index a, Index b) {
  if (materials.bond_law == BondLaw::None) throw Error("internal: add_bond() with dem.bond_law = none");
  if (a > b) std::swap(a, b);
  const int pt = materials.pair(particles.group[a], particles.group[b]);
  bond_i.push_back(a);
  bond_j.push_back(b);
  bond_pair.push_back(pt);
  bond_broken.push_back(0);
  if (materials.bond_law == BondLaw::Parallel) {
    pbond.push_back(ParallelBond::install());
  } else {
    const BondEnds e{particles.pos[a], particles.pos[b], particles.orient[a], particles.orient[b], particles.radius[a],
                     particles.radius[b]};
    rbond.push_back(RotationalBond::install(materials.rotational[pt], e));
  }
}

void DemSystem::build_bond_adjacency() {
  const std::size_t n = particles.size(), nb = bond_i.size();
  bond_adj_offset_.assign(n + 1, 0);
  for (std::size_t b = 0; b < nb; ++b) {
    ++bond_adj_offset_[bond_i[b] + 1];
    ++bond_adj_offset_[bond_j[b] + 1];
  }
  for (std::size_t i = 0; i < n; ++i) bond_adj_offset_[i + 1] += bond_adj_offset_[i];
  bond_adj_.resize(bond_adj_offset_[n]);
  bond_fill_.assign(bond_adj_offset_.begin(), bond_adj_offset_.end() - 1);
  for (std::size_t b = 0; b < nb; ++b) {
    bond_adj_[bond_fill_[bond_i[b]]++] = static_cast<std::int64_t>(b) << 1;
    bond_adj_[bond_fill_[bond_j[b]]++] = (static_cast<std::int64_t>(b) << 1) | 1;
  }
  bload_.assign(nb, PairLoad{});
  bond_fail_flag_.assign(nb, 0);
}

void DemSystem::compact_bonds() {
  std::size_t k = 0;
  const bool par = materials.bond_law == BondLaw::Parallel, rot = materials.bond_law == BondLaw::Rotational;
  for (std::size_t b = 0; b < bond_i.size(); ++b) {
    if (bond_broken[b]) continue;
    bond_i[k] = bond_i[b];
    bond_j[k] = bond_j[b];
    bond_pair[k] = bond_pair[b];
    bond_broken[k] = 0;
    if (par) pbond[k] = pbond[b];
    if (rot) rbond[k] = rbond[b];
    ++k;
  }
  if (k == bond_i.size()) return;
  bond_i.resize(k);
  bond_j.resize(k);
  bond_pair.resize(k);
  bond_broken.resize(k);
  if (par) pbond.resize(k);
  if (rot) rbond.resize(k);
  build_bond_adjacency();
}

void DemSystem::initialise() {
  if (settings.skin <= 0) throw Error("internal: DemSystem skin must be set before initialise()");
  particles.force.assign(particles.size(), Vec3::Zero());
  particles.moment.assign(particles.size(), Vec3::Zero());
  particles.inward_force.resize(particles.size(), 0);
  wall_contacts_.resize(walls.size());
  build_bond_adjacency();
  pbond_coeffs_.reserve(materials.parallel.size());
  // Every crack is a broken bond: with this reserve, logging never allocates in the time loop.
  cracks.events.reserve(cracks.events.size() + bond_i.size());
  rebuild_neighbors();
  // Contacts multiply as a sample is compressed and fails: room for 50% more pairs up front.
  const std::size_t room = nl_.size() + nl_.size() / 2 + 64;
  nl_.reserve(room);
  for (auto* v : {&old_i_, &old_j_}) v->reserve(room);
  cstate_.reserve(room);
  old_state_.reserve(room);
  pload_.reserve(room);
}

void DemSystem::rebuild_neighbors() {
  // Keep the old pairs so contact history survives the rebuild.
  reserve_with_headroom(old_i_, nl_.size());
  reserve_with_headroom(old_j_, nl_.size());
  old_i_.assign(nl_.first().begin(), nl_.first().end());
  old_j_.assign(nl_.second().begin(), nl_.second().end());
  old_state_.swap(cstate_);
  nl_.set_parallel_min(settings.parallel_min);
  nl_.build(particles.pos, particles.radius, settings.skin);
  NeighborList::carry_over<ContactState>(old_i_, old_j_, old_state_, nl_.first(), nl_.second(), cstate_, ContactState{});
  reserve_with_headroom(pload_, nl_.size());
  pload_.assign(nl_.size(), PairLoad{});
  // Wall candidates: particles within their radius + skin of the wall surface.
  wall_contacts_.resize(walls.size());
  for (std::size_t w = 0; w < walls.size(); ++w) {
    WallContacts& wc = wall_contacts_[w];
    // Swap with reused buffers: no allocation once the buffers have grown.
    std::vector<Index>& old_p = old_wall_particle_;
    std::vector<ContactState>& old_s = old_wall_state_;
    old_p.swap(wc.particle);
    old_s.swap(wc.state);
    wc.particle.clear();
    wc.state.clear();
    if (walls[w].active) {
      for (std::size_t i = 0; i < particles.size(); ++i) {
        ContactGeom g;
        if (walls[w].geometry(g, particles.pos[i], particles.radius[i]) && g.gap < settings.skin)
          wc.particle.push_back(static_cast<Index>(i));
      }
    }
    reserve_with_headroom(wc.state, wc.particle.size());
    reserve_with_headroom(wc.load, wc.particle.size());
    wc.state.assign(wc.particle.size(), ContactState{});
    std::size_t a = 0;
    for (std::size_t k = 0; k < wc.particle.size(); ++k) {
      while (a < old_p.size() && old_p[a] < wc.particle[k]) ++a;
      if (a < old_p.size() && old_p[a] == wc.particle[k]) wc.state[k] = old_s[a];
    }
    wc.load.assign(wc.particle.size(), PairLoad{});
  }
  wall_motion_since_build_ = 0;
  if (membrane) search_membrane_candidates(0);
  compact_bonds();
}

void DemSystem::search_membrane_candidates(Real travel) {
  membrane->find_candidates(particles.pos, particles.radius, settings.skin);
  membrane_built_at_travel_ = travel;
  ++membrane_builds_;
}

void DemSystem::rebuild_membrane_candidates() {
  if (!membrane) return;
  Real travel = 0;
  nl_.needs_rebuild(particles.pos, 0, &travel);
  search_membrane_candidates(travel);
}

template <class Law>
void DemSystem::contact_forces(const std::vector<typename Law::Params>& params) {
  const auto pi = nl_.first(), pj = nl_.second();
  const std::size_t np = pi.size();
  const Real dt = settings.dt;
  const int dim = settings.dim;
  const Real zeta = materials.normal_damping_ratio;
  const auto& x = particles.pos;
  const auto& v = particles.vel;
  const auto& w = particles.omega;
  const auto& r = particles.radius;
  const auto& grp = particles.group;
  const int ng = materials.groups();
#pragma omp parallel for schedule(static) if (np > settings.parallel_min)
  for (std::size_t p = 0; p < np; ++p) {
    const Index a = pi[p], b = pj[p];
    const Vec3 d = x[b] - x[a];
    const Real rsum = r[a] + r[b];
    const Real d2 = d.squaredNorm();
    PairLoad& out = pload_[p];
    if (d2 >= rsum * rsum || d2 == 0) {
      cstate_[p].fs.setZero();
      out.f.setZero();
      out.mA.setZero();
      out.mB.setZero();
      continue;
    }
    ContactGeom g;
    const Real dist = std::sqrt(d2);
    g.n = d * (1.0 / dist);
    g.gap = dist - rsum;
    g.xc = x[a] + (r[a] + 0.5 * g.gap) * g.n;
    g.rA = r[a];
    g.rB = r[b];
    contact_kinematics(g, x[a], v[a], w[a], x[b], v[b], w[b], dt);
    const auto& prm = params[grp[a] * ng + grp[b]];
    Real fn;
    Vec3 f = Law::force(prm, g, cstate_[p], dt, dim, fn);
    if (zeta > 0) {  // viscous normal dashpot, fraction zeta of critical damping
      Real kn;
      if constexpr (std::is_same_v<Law, LinearContact>) kn = Law::normal_stiffness(prm, g.rA, g.rB, dim);
      else kn = Law::normal_stiffness(prm, g.rA, g.rB, -g.gap);
      const Real meff = particles.mass[a] * particles.mass[b] / (particles.mass[a] + particles.mass[b]);
      f -= 2 * zeta * std::sqrt(meff * kn) * (g.d_delta_n / dt) * g.n;
    }
    const Vec3 nxf = g.n.cross(f);
    out.f = f;
    out.mA = -(g.rA + 0.5 * g.gap) * nxf;
    out.mB = -(g.rB + 0.5 * g.gap) * nxf;
  }
}

template <class Law, class Mat>
void DemSystem::bond_forces(const std::vector<Mat>& mats, std::vector<typename Law::State>& st) {
  const std::size_t nb = bond_i.size();
  const Real dt = settings.dt;
  const int dim = settings.dim;
  const auto& x = particles.pos;
  const auto& r = particles.radius;
#pragma omp parallel for schedule(static) if (nb > settings.parallel_min)
  for (std::size_t b = 0; b < nb; ++b) {
    PairLoad& out = bload_[b];
    if (bond_broken[b]) {
      out = PairLoad{};
      bond_fail_flag_[b] = 0;
      continue;
    }
    const Index i = bond_i[b], j = bond_j[b];
    BondLoad load;
    BondFailure fail;
    if constexpr (std::is_same_v<Law, ParallelBond>) {
      ContactGeom g;
      sphere_sphere(g, x[i], r[i], x[j], r[j]);
      contact_kinematics(g, x[i], particles.vel[i], particles.omega[i], x[j], particles.vel[j], particles.omega[j], dt);
      fail = Law::compute(mats[bond_pair[b]], st[b], g, dt, dim, load);
    } else {
      const BondEnds e{x[i], x[j], particles.orient[i], particles.orient[j], r[i], r[j]};
      fail = Law::compute(mats[bond_pair[b]], st[b], e, load);
    }
    bond_fail_flag_[b] = static_cast<std::uint8_t>(fail);
    if (fail != BondFailure::None) {
      out = PairLoad{};  // a bond that fails carries nothing from this step on
    } else {
      out.f = load.force_on_B;
      out.mA = load.moment_on_A;
      out.mB = load.moment_on_B;
    }
  }
}

void DemSystem::record_bond_failures() {
  const std::size_t nb = bond_i.size();
  for (std::size_t b = 0; b < nb; ++b) {
    if (!bond_fail_flag_[b]) continue;
    bond_broken[b] = bond_fail_flag_[b];
    bond_fail_flag_[b] = 0;
    const Index i = bond_i[b], j = bond_j[b];
    const Vec3 d = particles.pos[j] - particles.pos[i];
    const Real dist = d.norm();
    const Vec3 n = dist > 0 ? Vec3(d / dist) : Vec3::UnitX();
    const Real gap = dist - particles.radius[i] - particles.radius[j];
    Real size = 0;
    if (materials.bond_law == BondLaw::Parallel)
      size = ParallelBond::section(materials.parallel[bond_pair[b]], particles.radius[i], particles.radius[j], settings.dim).R;
    else size = 0.5 * (particles.radius[i] + particles.radius[j]);
    cracks.add(CrackEvent{time, particles.pos[i] + (particles.radius[i] + 0.5 * gap) * n, n, size, bond_broken[b],
                          particles.group[i], particles.group[j], i, j});
  }
}

template <class Law>
void DemSystem::wall_forces(const std::vector<typename Law::Params>& params) {
  const Real dt = settings.dt;
  const int dim = settings.dim;
  const int ng = materials.groups();
  for (std::size_t w = 0; w < walls.size(); ++w) {
    Wall& wall = walls[w];
    WallContacts& wc = wall_contacts_[w];
    const std::size_t nc = wc.particle.size();
#pragma omp parallel for schedule(static) if (nc > settings.parallel_min)
    for (std::size_t k = 0; k < nc; ++k) {
      const Index i = wc.particle[k];
      PairLoad& out = wc.load[k];
      ContactGeom g;
      if (!wall.active || !wall.geometry(g, particles.pos[i], particles.radius[i]) || g.gap >= 0) {
        wc.state[k].fs.setZero();
        out = PairLoad{};
        continue;
      }
      contact_kinematics(g, particles.pos[i], particles.vel[i], particles.omega[i], g.xc, wall.velocity_at(g),
                         Vec3::Zero(), dt);
      auto prm = params[particles.group[i] * ng + particles.group[i]];
      prm.fric = boundary_friction(wall.friction, prm.fric);
      Real fn;
      const Vec3 f = Law::force(prm, g, wc.state[k], dt, dim, fn);  // force on the wall
      out.f = f;
      out.mA = -(g.rA + 0.5 * g.gap) * g.n.cross(f);  // moment on the particle
      if constexpr (std::is_same_v<Law, LinearContact>) out.mB.x() = Law::normal_stiffness(prm, g.rA, 0, dim);
      else out.mB.x() = Law::normal_stiffness(prm, g.rA, 0, -g.gap);
    }
    // Totals in candidate order (deterministic).
    wall.force.setZero();
    wall.contact_stiffness = 0;
    wall.contacts = 0;
    for (std::size_t k = 0; k < nc; ++k) {
      if (wc.load[k].f.squaredNorm() == 0) continue;
      wall.force += wc.load[k].f;
      wall.contact_stiffness += wc.load[k].mB.x();
      ++wall.contacts;
    }
  }
}

template <class Law>
void DemSystem::membrane_forces(const std::vector<typename Law::Params>& params) {
  const MembraneParticles p{particles.pos, particles.vel, particles.omega, particles.radius, particles.group};
  membrane->compute_forces<Law>(p, std::span<const typename Law::Params>(params), materials.groups(), settings.dt);
}

void DemSystem::gather_and_integrate() {
  const std::size_t n = particles.size();
  const auto adj_off = nl_.adjacency_offsets();
  const auto adj = nl_.adjacency();
  auto& F = particles.force;
  auto& M = particles.moment;
  const auto& inward = particles.inward_force;
  const auto& pos = particles.pos;
#pragma omp parallel for schedule(static) if (n > settings.parallel_min)
  for (std::size_t i = 0; i < n; ++i) {
    Vec3 f = Vec3::Zero(), m = Vec3::Zero();
    if (inward[i] != 0) {  // constant magnitude, towards the z axis from where the particle is now
      const Real rho = std::hypot(pos[i].x(), pos[i].y());
      if (rho > 0) f = Vec3(pos[i].x(), pos[i].y(), 0) * (-inward[i] / rho);
    }
    for (std::int64_t k = adj_off[i]; k < adj_off[i + 1]; ++k) {
      const std::int64_t e = adj[k];
      const PairLoad& L = pload_[e >> 1];
      if (e & 1) { f += L.f; m += L.mB; } else { f -= L.f; m += L.mA; }
    }
    for (std::int64_t k = bond_adj_offset_[i]; k < bond_adj_offset_[i + 1]; ++k) {
      const std::int64_t e = bond_adj_[k];
      const PairLoad& L = bload_[e >> 1];
      if (e & 1) { f += L.f; m += L.mB; } else { f -= L.f; m += L.mA; }
    }
    F[i] = f;
    M[i] = m;
  }
  for (std::size_t w = 0; w < walls.size(); ++w) {  // wall contacts, serial and in order
    const WallContacts& wc = wall_contacts_[w];
    for (std::size_t k = 0; k < wc.particle.size(); ++k) {
      F[wc.particle[k]] -= wc.load[k].f;
      M[wc.particle[k]] += wc.load[k].mA;
    }
  }
  if (membrane) membrane->add_loads_to(F, M);  // serial, in candidate order
  const Real dt = settings.dt, alpha = settings.local_damping;
  const Vec3 g = settings.gravity;
  const bool planar = settings.dim == 2;
  int bad = 0;
  auto& x = particles.pos;
  auto& v = particles.vel;
  auto& w = particles.omega;
#pragma omp parallel for schedule(static) reduction(| : bad) if (n > settings.parallel_min)
  for (std::size_t i = 0; i < n; ++i) {
    Vec3 f = F[i] + particles.mass[i] * g;
    Vec3 m = M[i];
    if (planar) {  // disks stay in the x-y plane and spin about z only
      f.z() = 0;
      m.x() = m.y() = 0;
    }
    // Local non-viscous damping (Cundall 1987; METHODS.md 1.5), per component.
    for (int c = 0; c < 3; ++c) {
      const Real sv = v[i][c] > 0 ? 1.0 : (v[i][c] < 0 ? -1.0 : 0.0);
      f[c] -= alpha * std::abs(f[c]) * sv;
      const Real sw = w[i][c] > 0 ? 1.0 : (w[i][c] < 0 ? -1.0 : 0.0);
      m[c] -= alpha * std::abs(m[c]) * sw;
    }
    // Velocity Verlet in PFC's leapfrog form (METHODS.md 1.1).
    v[i] += f * (particles.inv_mass[i] * dt);
    w[i] += m * (particles.inv_inertia[i] * dt);
    const Vec3 dx = v[i] * dt;
    x[i] += dx;
    particles.disp[i] += dx;
    // Orientation: q' = 1/2 (0, w) q (METHODS.md 1.1), first order and renormalised.
    const Vec3 hw = (0.5 * dt) * w[i];
    Quat& q = particles.orient[i];
    q = Quat(q.w() - hw.dot(q.vec()), q.x() + hw.x() * q.w() + hw.y() * q.z() - hw.z() * q.y(),
             q.y() + hw.y() * q.w() + hw.z() * q.x() - hw.x() * q.z(), q.z() + hw.z() * q.w() + hw.x() * q.y() - hw.y() * q.x());
    q.normalize();
    if (!std::isfinite(x[i].x() + x[i].y() + x[i].z() + w[i].x() + w[i].y() + w[i].z())) bad = 1;
  }
  if (bad)
    throw NumericalError(fmt::format(
        "DEM state became NaN/inf at step {} (t = {:.6g} s): the time step {:.3g} s is too large for the stiffness "
        "and mass of the sample; lower dem.time_step_safety (or dem.time_step), or enable mass scaling",
        step_count, time, dt));
}

void DemSystem::step() {
  using Clock = std::chrono::steady_clock;
  auto t0 = Clock::now();
  auto lap = [&](double& acc) {
    const auto t = Clock::now();
    acc += std::chrono::duration<double>(t - t0).count();
    t0 = t;
  };
  Real wall_step = 0;
  for (auto& w : walls) wall_step = std::max(wall_step, w.step_motion(settings.dt));
  // Boundaries that moved since the last build use up the skin like particles do.
  Real travel = 0;
  const bool rebuild = nl_.needs_rebuild(particles.pos, wall_motion_since_build_ + wall_step, &travel);
  if (rebuild) rebuild_neighbors();
  lap(stage_times.neighbors);
  if (!rebuild && membrane) {
    // The membrane keeps its own candidates: a particle-element pair further apart than the
    // particle's radius + skin at the build can touch only once the particle's travel plus the
    // element's (each vertex's travel bounds that of every point of the triangle) reach the
    // skin. The membrane moving does not make the particle pairs' list stale, so it no longer
    // forces a rebuild of the whole neighbour list.
    const Real particle_travel = travel + membrane_built_at_travel_;
    if (particle_travel + membrane->motion_since_build() + membrane->max_step_motion(settings.dt) > settings.skin)
      search_membrane_candidates(travel);
    lap(stage_times.membrane);
  }
  if (materials.contact_law == ContactLaw::Linear) contact_forces<LinearContact>(materials.linear);
  else contact_forces<HertzMindlinContact>(materials.hertz);
  lap(stage_times.contacts);
  if (materials.bond_law == BondLaw::Parallel) {
    pbond_coeffs_.resize(materials.parallel.size());  // no allocation after the first step
    for (std::size_t k = 0; k < materials.parallel.size(); ++k) pbond_coeffs_[k] = ParallelBond::coeffs(materials.parallel[k]);
    bond_forces<ParallelBond>(pbond_coeffs_, pbond);
  }
  else if (materials.bond_law == BondLaw::Rotational) bond_forces<RotationalBond>(materials.rotational, rbond);
  record_bond_failures();
  lap(stage_times.bonds);
  if (materials.contact_law == ContactLaw::Linear) wall_forces<LinearContact>(materials.linear);
  else wall_forces<HertzMindlinContact>(materials.hertz);
  lap(stage_times.walls);
  if (membrane) {
    if (materials.contact_law == ContactLaw::Linear) membrane_forces<LinearContact>(materials.linear);
    else membrane_forces<HertzMindlinContact>(materials.hertz);
    lap(stage_times.membrane);
  }
  gather_and_integrate();
  lap(stage_times.integrate);
  if (membrane) {
    membrane->move(settings.dt, walls[membrane_bottom_wall].point.z(), walls[membrane_top_wall].point.z());
    lap(stage_times.membrane);
  }
  for (auto& w : walls) w.move(settings.dt);
  wall_motion_since_build_ += wall_step;
  time += settings.dt;
  ++step_count;
}

Real DemSystem::pair_stiffness(int pt, Real rA, Real rB, Real overlap) const {
  if (materials.contact_law == ContactLaw::Linear) return LinearContact::normal_stiffness(materials.linear[pt], rA, rB, settings.dim);
  return HertzMindlinContact::normal_stiffness(materials.hertz[pt], rA, rB, std::max(overlap, 0.01 * std::min(rA, rB > 0 ? rB : rA)));
}

Real DemSystem::critical_time_step() const {
  const std::size_t n = particles.size();
  std::vector<Real> kt(n, 0.0), kr(n, 0.0);
  const auto& x = particles.pos;
  const auto& r = particles.radius;
  const auto& grp = particles.group;
  const auto pi = nl_.first(), pj = nl_.second();
  for (std::size_t p = 0; p < pi.size(); ++p) {
    const Index a = pi[p], b = pj[p];
    const Real gap = (x[b] - x[a]).norm() - r[a] - r[b];
    if (gap >= 0) continue;
    const int pt = materials.pair(grp[a], grp[b]);
    const Real k = pair_stiffness(pt, r[a], r[b], -gap);
    kt[a] += k; kt[b] += k;
    kr[a] += k * r[a] * r[a]; kr[b] += k * r[b] * r[b];  // shear springs' lever arms (ks <= kn)
  }
  for (std::size_t b = 0; b < bond_i.size(); ++b) {
    if (bond_broken[b]) continue;
    const Index i = bond_i[b], j = bond_j[b];
    Real k = 0, krot = 0;
    if (materials.bond_law == BondLaw::Parallel) {
      const auto sec = ParallelBond::section(materials.parallel[bond_pair[b]], particles.radius[i], particles.radius[j], settings.dim);
      k = ParallelBond::translational_stiffness(sec);
      krot = ParallelBond::rotational_stiffness(sec);
    } else if (materials.bond_law == BondLaw::Rotational) {
      k = std::max(rbond[b].kr, rbond[b].ks);
      krot = std::max(rbond[b].kt, rbond[b].kb);
    }
    kt[i] += k; kt[j] += k;
    kr[i] += krot + k * r[i] * r[i];
    kr[j] += krot + k * r[j] * r[j];
  }
  for (std::size_t w = 0; w < walls.size(); ++w) {
    for (std::size_t k = 0; k < wall_contacts_[w].particle.size(); ++k) {
      const Index i = wall_contacts_[w].particle[k];
      ContactGeom g;
      if (!walls[w].geometry(g, x[i], r[i]) || g.gap >= 0) continue;
      const Real kw = pair_stiffness(materials.pair(grp[i], grp[i]), r[i], 0, -g.gap);
      kt[i] += kw;
      kr[i] += kw * r[i] * r[i];
    }
  }
  if (membrane) {
    const auto cp = membrane->candidate_particles();
    const auto ck = membrane->candidate_stiffness();
    for (std::size_t c = 0; c < cp.size(); ++c) {
      kt[cp[c]] += ck[c];
      kr[cp[c]] += ck[c] * r[cp[c]] * r[cp[c]];
    }
  }
  Real dt = std::numeric_limits<Real>::infinity();
  for (std::size_t i = 0; i < n; ++i) {
    // A particle with no contact yet still meets one like itself (free particles otherwise
    // give no bound at all).
    const Real k = kt[i] > 0 ? kt[i] : pair_stiffness(materials.pair(grp[i], grp[i]), r[i], r[i], 0.01 * r[i]);
    const Real kk = kr[i] > 0 ? kr[i] : k * r[i] * r[i];
    dt = std::min({dt, std::sqrt(1.0 / (particles.inv_mass[i] * k)), std::sqrt(1.0 / (particles.inv_inertia[i] * kk))});
  }
  return dt;
}

void DemSystem::scale_masses_for(Real dt, Real safety) {
  // m~ = max(m, (dt/s)^2 k_tran) (METHODS.md 1.6): done by scaling until the estimate allows dt.
  const Real dt_now = critical_time_step() * safety;
  if (dt_now >= dt) return;
  const Real f = (dt / dt_now) * (dt / dt_now);
  for (std::size_t i = 0; i < particles.size(); ++i) {
    particles.inv_mass[i] /= f;
    particles.inv_inertia[i] /= f;
  }
}

std::size_t DemSystem::intact_bonds() const {
  return static_cast<std::size_t>(std::count(bond_broken.begin(), bond_broken.end(), 0));
}

long DemSystem::contacts_touching() const {
  long c = 0;
  for (auto& L : pload_) c += L.f.squaredNorm() > 0;
  return c;
}

Real DemSystem::kinetic_energy() const {
  const auto& p = particles;
  return deterministic_sum(p.size(), settings.parallel_min, [&](std::size_t i) {
    return 0.5 * p.mass[i] * p.vel[i].squaredNorm() + 0.5 * p.inertia[i] * p.omega[i].squaredNorm();
  });
}

Real DemSystem::strain_energy() const {
  const auto& x = particles.pos;
  const auto& r = particles.radius;
  const auto pi = nl_.first(), pj = nl_.second();
  Real e = 0;
  for (std::size_t p = 0; p < pi.size(); ++p) {
    const Index a = pi[p], b = pj[p];
    const Real gap = (x[b] - x[a]).norm() - r[a] - r[b];
    if (gap >= 0) continue;
    const int pt = materials.pair(particles.group[a], particles.group[b]);
    if (materials.contact_law == ContactLaw::Linear) {
      const Real kn = LinearContact::normal_stiffness(materials.linear[pt], r[a], r[b], settings.dim);
      const Real ks = kn / materials.linear[pt].kratio;
      e += 0.5 * kn * gap * gap + 0.5 * cstate_[p].fs.squaredNorm() / ks;
    } else {
      Real es, gs;
      HertzMindlinContact::moduli(materials.hertz[pt], false, es, gs);
      const Real d = -gap;
      e += 8.0 / 15.0 * es * std::sqrt(HertzMindlinContact::reduced_radius(r[a], r[b])) * std::pow(d, 2.5);
    }
  }
  if (materials.bond_law == BondLaw::Parallel) {
    for (std::size_t b = 0; b < bond_i.size(); ++b) {
      if (bond_broken[b]) continue;
      const auto& s = pbond[b];
      const auto c = ParallelBond::section(materials.parallel[bond_pair[b]], r[bond_i[b]], r[bond_j[b]], settings.dim);
      e += 0.5 * s.Fn * s.Fn / (c.kn * c.A) + 0.5 * s.Fs.squaredNorm() / (c.ks * c.A) +
           0.5 * s.Mb.squaredNorm() / (c.kn * c.I) + (c.J > 0 ? 0.5 * s.Mt * s.Mt / (c.ks * c.J) : 0.0);
    }
  }
  return e;
}

Real DemSystem::max_unbalanced_force_ratio(std::size_t first) const {
  const std::size_t n = std::min(first, particles.size());
  const Real unbalanced = deterministic_sum(n, settings.parallel_min, [&](std::size_t i) { return particles.force[i].norm(); });
  // Mean over the interactions that carry load (PFC's "average ratio").
  Real contact = 0;
  std::size_t loaded = 0;
  auto add = [&](const PairLoad& L) {
    const Real f = L.f.norm();
    if (f > 0) { contact += f; ++loaded; }
  };
  for (auto& L : pload_) add(L);
  for (auto& L : bload_) add(L);
  for (auto& wc : wall_contacts_)
    for (auto& L : wc.load) add(L);
  if (loaded == 0 || n == 0) return 0;
  return (unbalanced / static_cast<Real>(n)) / (contact / static_cast<Real>(loaded));
}

}  // namespace ff::dem
