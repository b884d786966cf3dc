#include "dem/dem_system.hpp"

#include <fmt/format.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/error.hpp"

namespace ff::dem {

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
  if (!materials.has_bonds()) throw Error("internal: add_bond() with dem.bond_law = none");
  if (a > b) std::swap(a, b);
  const int pt = materials.pair(particles.group[a], particles.group[b]);
  bonds.add(a, b, pt);
  materials.with_bond_law([&]<class Law>(std::type_identity<Law>) {
    const BondEnds e{particles.pos[a], particles.pos[b], particles.orient[a], particles.orient[b], particles.radius[a],
                     particles.radius[b]};
    bonds.state<Law>().push_back(Law::install(materials.bond_params<Law>()[pt], e));
  });
}

Boundary& DemSystem::add_boundary(std::unique_ptr<Boundary> b) {
  return boundaries_.add(std::move(b));
}

void DemSystem::initialise() {
  if (settings.skin <= 0) throw Error("internal: DemSystem skin must be set before initialise()");
  particles.resize(particles.size());  // every declared field as long as pos (fresh ids if missing)
  for (auto* a : {&particles.force, &particles.moment, &particles.ext_force, &particles.ext_moment})
    a->assign(particles.size(), Vec3::Zero());
  wall_contacts_.resize(walls.size());
  build_bond_adjacency();
  materials.with_bond_law([&]<class Law>(std::type_identity<Law>) {
    std::get<law_index<Law>(BondLaws{})>(bond_prepared_).reserve(materials.bond_params<Law>().size());
  });
  // Every crack is a broken bond: with this reserve, logging never allocates in the time loop.
  cracks.events.reserve(cracks.events.size() + bonds.size());
  rebuild_neighbors();
  // Contacts multiply as a sample is compressed and fails: room for 50% more pairs up front.
  const std::size_t room = nl_.size() + nl_.size() / 2 + 64;
  nl_.reserve(room);
  for (auto* v : {&old_i_, &old_j_}) v->reserve(room);
  cstate_.reserve(room);
  old_state_.reserve(room);
  pload_.reserve(room);
  if (settings.track_energy) {
    pair_work_.reserve(room);
    block_sums_.reserve(std::max(room, particles.size()) / 4096 + 16);
    for (auto* v : {&ext_f_, &ext_m_, &particle_work_}) v->assign(particles.size(), Vec3::Zero());
  }
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
  for (auto& b : boundaries_) b->update_neighbors(*this, true, 0);
  compact_bonds();
}

template <class Law, bool kEnergy>
void DemSystem::contact_forces(const std::vector<typename Law::Params>& params) {
  const auto pi = nl_.first(), pj = nl_.second();
  const std::size_t np = pi.size();
  if constexpr (kEnergy) {
    reserve_with_headroom(pair_work_, np);
    pair_work_.resize(np);
  }
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
      if constexpr (kEnergy) pair_work_[p].setZero();
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
    ContactWork work;
    Vec3 f = Law::template force<kEnergy>(prm, g, cstate_[p], dt, dim, fn, &work);
    Real dashpot = 0;
    if (zeta > 0) {  // viscous normal dashpot, fraction zeta of critical damping
      const Real kn = Law::normal_stiffness_at(prm, g.rA, g.rB, -g.gap, dim);
      const Real meff = particles.mass[a] * particles.mass[b] / (particles.mass[a] + particles.mass[b]);
      f -= 2 * zeta * std::sqrt(meff * kn) * (g.d_delta_n / dt) * g.n;
      if constexpr (kEnergy) dashpot = 2 * zeta * std::sqrt(meff * kn) * g.d_delta_n * g.d_delta_n / dt;
    }
    if constexpr (kEnergy) pair_work_[p] = Vec3(work.slip, work.shear, dashpot);
    const Vec3 nxf = g.n.cross(f);
    out.f = f;
    out.mA = -(g.rA + 0.5 * g.gap) * nxf;
    out.mB = -(g.rB + 0.5 * g.gap) * nxf;
  }
  if constexpr (kEnergy) {
    const Vec3 sum = blocked_sum(np, settings.parallel_min, block_sums_, [&](std::size_t p) { return pair_work_[p]; });
    energy.friction += sum.x();
    energy.shear_work += sum.y();
    energy.dashpot += sum.z();
  }
}

template <class Law>
void DemSystem::bond_forces(const std::vector<typename Law::Prepared>& mats, std::vector<typename Law::State>& st) {
  const std::size_t nb = bonds.size();
  const Real dt = settings.dt;
  const int dim = settings.dim;
  const auto& bond_i = bonds.i;
  const auto& bond_j = bonds.j;
  const auto& bond_pair = bonds.pair;
  const auto& bond_broken = bonds.broken;
  auto& bload_ = bonds.loads();
  auto& bond_fail_flag_ = bonds.fail_flags();
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
    const BondFailure fail = Law::compute_bond(mats[bond_pair[b]], st[b], particles, i, j, dt, dim, load);
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
  const std::size_t nb = bonds.size();
  const auto& bond_i = bonds.i;
  const auto& bond_j = bonds.j;
  const auto& bond_pair = bonds.pair;
  auto& bond_broken = bonds.broken;
  auto& bond_fail_flag_ = bonds.fail_flags();
  materials.with_bond_law([&]<class Law>(std::type_identity<Law>) {
    const auto& mats = materials.bond_params<Law>();
    for (std::size_t b = 0; b < nb; ++b) {
      if (!bond_fail_flag_[b]) continue;
      bond_broken[b] = bond_fail_flag_[b];
      bond_fail_flag_[b] = 0;
      const Index i = bond_i[b], j = bond_j[b];
      const Real ri = particles.radius[i], rj = particles.radius[j];
      const Vec3 d = particles.pos[j] - particles.pos[i];
      const Real dist = d.norm();
      const Vec3 n = dist > 0 ? Vec3(d / dist) : Vec3::UnitX();
      const Real gap = dist - ri - rj;
      const Real size = Law::crack_size(mats[bond_pair[b]], ri, rj, settings.dim);
      cracks.add(CrackEvent{time, particles.pos[i] + (ri + 0.5 * gap) * n, n, size, bond_broken[b], particles.group[i],
                            particles.group[j], particles.id[i], particles.id[j]});
      // Its springs stop acting at once: their energy leaves the system (serial, bond order).
      if (settings.track_energy)
        energy.bond_break += Law::energy(mats[bond_pair[b]], bonds.state<Law>()[b], ri, rj, settings.dim);
    }
  });
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
      out.mB.x() = Law::normal_stiffness_at(prm, g.rA, 0, -g.gap, dim);
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

void DemSystem::add_external_loads() {
  // The accumulators are zero here (integrate() zeroed them); loads are ADDED.
  for (auto& b : boundaries_) b->add_external_loads(particles);
}

void DemSystem::integrate() {
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  if (settings.track_energy) integrate_particles<true>();
  else integrate_particles<false>();
  auto t1 = Clock::now();
  stage_times.integrate += std::chrono::duration<double>(t1 - t0).count();
  if (!boundaries_.empty()) {
    for (auto& b : boundaries_) b->after_integrate(*this);
    const auto t2 = Clock::now();
    stage_times.boundaries += std::chrono::duration<double>(t2 - t1).count();
  }
  for (auto& wall : walls) wall.move(settings.dt);
  wall_motion_since_build_ += wall_step_;
  time += settings.dt;
  ++step_count;
}

template <bool kEnergy>
void DemSystem::integrate_particles() {
  const std::size_t n = particles.size();
  if constexpr (kEnergy) {
    if (ext_f_.size() != n)  // tracking switched on after initialise(): sized once here
      for (auto* v : {&ext_f_, &ext_m_, &particle_work_}) v->assign(n, Vec3::Zero());
  }
  const auto adj_off = nl_.adjacency_offsets();
  const auto adj = nl_.adjacency();
  const auto bond_adj_offset_ = bonds.adjacency_offsets();
  const auto bond_adj_ = bonds.adjacency();
  const auto& bload_ = bonds.loads();
  auto& F = particles.force;
  auto& M = particles.moment;
  auto& Fe = particles.ext_force;
  auto& Me = particles.ext_moment;
  // The external loads come first (their order is part of the bit-identical result); the
  // accumulators are zeroed for the next step as they are read.
#pragma omp parallel for schedule(static) if (n > settings.parallel_min)
  for (std::size_t i = 0; i < n; ++i) {
    Vec3 f = Fe[i], m = Me[i];
    Fe[i].setZero();
    Me[i].setZero();
    if constexpr (kEnergy) {  // the loads from outside the particles' interactions (work bookkeeping)
      ext_f_[i] = f;
      ext_m_[i] = m;
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
      if constexpr (kEnergy) {
        ext_f_[wc.particle[k]] -= wc.load[k].f;
        ext_m_[wc.particle[k]] += wc.load[k].mA;
      }
    }
  }
  for (auto& b : boundaries_) {  // serial, in candidate order
    b->add_loads(F, M);
    if constexpr (kEnergy) b->add_loads(ext_f_, ext_m_);
  }
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
    [[maybe_unused]] Vec3 f_undamped, m_undamped, v_old, w_old;
    if constexpr (kEnergy) {
      f_undamped = f;
      m_undamped = m;
      v_old = v[i];
      w_old = w[i];
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
    if constexpr (kEnergy) {  // works with the step's mean velocity and spin (energy.hpp)
      const Vec3 vm = (0.5 * dt) * (v_old + v[i]), wm = (0.5 * dt) * (w_old + w[i]);
      Vec3 fe = ext_f_[i] + particles.mass[i] * g;
      if (planar) fe.z() = 0;
      Real w_ext = 0, d_damp = 0;
      // A particle held at a prescribed velocity (zero inverse mass, e.g. a grip) is part of the
      // boundary: what holds it does minus the work of the interactions on it.
      if (particles.inv_mass[i] != 0) {
        w_ext += fe.dot(vm);
        d_damp -= (f - f_undamped).dot(vm);
      } else {
        w_ext -= (f_undamped - fe).dot(vm);
      }
      if (particles.inv_inertia[i] != 0) {
        w_ext += ext_m_[i].dot(wm);
        d_damp -= (m - m_undamped).dot(wm);
      } else {
        w_ext -= (m_undamped - ext_m_[i]).dot(wm);
      }
      particle_work_[i] = Vec3(w_ext, d_damp, 0);
    }
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
  if (bad) throw DemNotFiniteError(not_finite_message());
  if constexpr (kEnergy) {
    const Vec3 sum = blocked_sum(n, settings.parallel_min, block_sums_, [&](std::size_t i) { return particle_work_[i]; });
    energy.boundary_work += sum.x();
    energy.damping += sum.y();
  }
}

std::string DemSystem::not_finite_message() const {
  const auto& x = particles.pos;
  const auto& w = particles.omega;
  std::size_t first = 0;  // the lowest index, whatever the thread count
  while (first < x.size() && std::isfinite(x[first].x() + x[first].y() + x[first].z() + w[first].x() + w[first].y() +
                                           w[first].z()))
    ++first;
  std::string who;
  if (first < x.size())
    who = fmt::format(" (first particle: id {} of group {})", particles.id[first],
                      materials.group_names.at(static_cast<std::size_t>(particles.group[first])));
  const std::string head = fmt::format("DEM state became NaN/inf at step {} (t = {:.6g} s){}", step_count, time, who);
  if (!untouched_unstable_contacts.empty()) {
    std::string list;
    for (const auto& a : untouched_unstable_contacts) list += (list.empty() ? "" : "; ") + a;
    return fmt::format("{}: the time step {:.3g} s was chosen for the contacts that touched at the start; the set-up "
                       "warned that contacts formed later are unstable at it: {} (lowering dem.time_step_safety "
                       "also works, it scales the whole step)",
                       head, settings.dt, list);
  }
  return fmt::format("{}: the time step {:.3g} s is too large for the stiffness and mass of the sample; lower "
                     "dem.time_step_safety (or dem.time_step), or enable mass scaling",
                     head, settings.dt);
}

namespace {
// Adds the wall-clock seconds since t0 to acc and restarts the clock (stage timing).
struct Lap {
  std::chrono::steady_clock::time_point t0 = std::chrono::steady_clock::now();
  void operator()(double& acc) {
    const auto t = std::chrono::steady_clock::now();
    acc += std::chrono::duration<double>(t - t0).count();
    t0 = t;
  }
};
}  // namespace

void DemSystem::update_neighbors() {
  Lap lap;
  wall_step_ = 0;
  for (auto& w : walls) wall_step_ = std::max(wall_step_, w.step_motion(settings.dt));
  // Boundaries that moved since the last build use up the skin like particles do.
  Real travel = 0;
  const bool rebuild = nl_.needs_rebuild(particles.pos, wall_motion_since_build_ + wall_step_, &travel);
  if (rebuild) rebuild_neighbors();  // boundaries search again there, after the walls
  lap(stage_times.neighbors);
  if (!rebuild && !boundaries_.empty()) {
    // Boundaries keep their own candidates: their motion does not make the particle pairs' list
    // stale, so it does not force a rebuild of the whole neighbour list.
    for (auto& b : boundaries_) b->update_neighbors(*this, false, travel);
    lap(stage_times.boundaries);
  }
}

void DemSystem::compute_forces() {
  Lap lap;
  // The active laws are picked once per stage (laws.hpp); the loops are templated on them.
  materials.with_contact_law([&]<class Law>(std::type_identity<Law>) {
    if (settings.track_energy) contact_forces<Law, true>(materials.contact_params<Law>());
    else contact_forces<Law, false>(materials.contact_params<Law>());
  });
  lap(stage_times.contacts);
  materials.with_bond_law([&]<class Law>(std::type_identity<Law>) {
    if constexpr (Law::installs_bonds) {
      const auto& mats = materials.bond_params<Law>();
      auto& prep = std::get<law_index<Law>(BondLaws{})>(bond_prepared_);
      prep.resize(mats.size());  // no allocation after the first step
      for (std::size_t k = 0; k < mats.size(); ++k) prep[k] = Law::prepare(mats[k]);
      bond_forces<Law>(prep, bonds.state<Law>());
    }
  });
  record_bond_failures();
  lap(stage_times.bonds);
  materials.with_contact_law([&]<class Law>(std::type_identity<Law>) { wall_forces<Law>(materials.contact_params<Law>()); });
  lap(stage_times.walls);
  if (!boundaries_.empty()) {
    for (auto& b : boundaries_) b->compute_forces(*this);
    lap(stage_times.boundaries);
  }
}

}  // namespace ff::dem
