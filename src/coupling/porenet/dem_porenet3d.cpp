#include "coupling/porenet/dem_porenet3d.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>

#include "core/error.hpp"
#include "porenet/forces.hpp"
#include "porenet/reduce.hpp"
#include "porenet/remap.hpp"

namespace ff::coupling {

namespace {
double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

void DemPorenet3D::gather(const dem::DemSystem& sys) {
  const auto n = sys.particles.size();
  for (std::size_t k = 0; k < n; ++k) {
    x_[k] = sys.particles.pos[k].x();
    y_[k] = sys.particles.pos[k].y();
    z_[k] = sys.particles.pos[k].z();
    r_[k] = sys.particles.radius[k];
  }
  if (prm_.walls)
    for (int w = 0; w < 6; ++w) {
      const Real plane = sys.walls[static_cast<std::size_t>(wall_ids_[static_cast<std::size_t>(w)])].point[w / 2];
      (w % 2 ? box_.hi : box_.lo)[static_cast<std::size_t>(w / 2)] = plane;
    }
}

namespace {
// The DemSystem's plane wall of each box face: normal +e_a (pointing to the particles) for the lower
// wall of axis a, -e_a for the upper.
std::array<int, 6> find_box_walls(const dem::DemSystem& sys) {
  std::array<int, 6> ids;
  ids.fill(-1);
  for (std::size_t i = 0; i < sys.walls.size(); ++i) {
    const auto& w = sys.walls[i];
    if (w.kind != dem::Wall::Kind::Plane || !w.active) continue;
    for (int a = 0; a < 3; ++a)
      for (int side = 0; side < 2; ++side) {
        const Real s = side ? -1.0 : 1.0;
        if (std::abs(w.normal[a] - s) < 1e-12 && ids[static_cast<std::size_t>(2 * a + side)] < 0)
          ids[static_cast<std::size_t>(2 * a + side)] = static_cast<int>(i);
      }
  }
  for (int w = 0; w < 6; ++w)
    if (ids[static_cast<std::size_t>(w)] < 0)
      throw InputError(fmt::format("coupling.porenet3d: walls = true needs six axis-aligned plane walls around the "
                                   "sample; none has the normal {}{} (pointing to the particles): {} walls in all",
                                   w % 2 ? "-" : "+", "xyz"[w / 2], sys.walls.size()));
  return ids;
}
}  // namespace

void DemPorenet3D::set_boundaries(porenet::TwoPhaseFlow& flow, const porenet::Network2D& net) {
  if (prm_.drained)
    for (Index i = 0; i < net.n_pores(); ++i)
      if (net.pore_hull[i]) flow.set_bc(i, porenet::PoreBc::Pressure, prm_.ambient_pressure, prm_.saturation);
  if (on_network) on_network(flow, net);
  if (prm_.implicit) flow.prepare_implicit();
}

void DemPorenet3D::make_network_and_flow(std::unique_ptr<porenet::Network2D>& net,
                                         std::unique_ptr<porenet::TwoPhaseFlow>& flow) {
  const auto t0 = std::chrono::steady_clock::now();
  net = std::make_unique<porenet::Network2D>(porenet::build_network_3d(view(), prm_.network, prm_.pfv_factor, box()));
  ref_box_ = box_;
  flow = std::make_unique<porenet::TwoPhaseFlow>(*net, prm_.fluid);
  ref_x_ = x_;
  ref_y_ = y_;
  ref_z_ = z_;
  pg_.assign(static_cast<std::size_t>(net->n_pores()), 0);
  pred_g_.clear();  // the prediction's geometry and matrix belong to the old network
  pred_sys_.reset();
  stats_.t_triangulation += seconds_since(t0);
}

void DemPorenet3D::init(const dem::DemSystem& sys, const Porenet3DParams& params) {
  if (sys.settings.dim != 3)
    throw InputError("coupling.porenet3d: the 3D pore-network coupling needs a sphere sample (dem.dim = 3)");
  if (!(params.saturation >= 0 && params.saturation <= 1))
    throw InputError(fmt::format("coupling.porenet3d: saturation {} outside [0, 1]", params.saturation));
  if (!(params.retriangulation_tolerance > 0))
    throw InputError("coupling.porenet3d: retriangulation_tolerance must be > 0");
  prm_ = params;
  if (prm_.walls) wall_ids_ = find_box_walls(sys);
  wall_force_.fill(0);
  const auto n = sys.particles.size();
  x_.assign(n, 0);
  y_ = z_ = r_ = fx_ = fy_ = fz_ = x_;
  gather(sys);
  mean_radius_ = 0;
  for (Real r : r_) mean_radius_ += r;
  mean_radius_ /= static_cast<Real>(n);
  stats_ = {};
  early_flow_steps_ = 0;
  pred_strain_ = 0;
  cracks_at_flow_ = sys.cracks.events.size();
  make_network_and_flow(net_, flow_);
  flow_->init(prm_.initial_pressure, prm_.saturation, prm_.placement);
  set_boundaries(*flow_, *net_);
}

void DemPorenet3D::set_uniform_state(Real p, Real s) {
  for (Index i = 0; i < net_->n_pores(); ++i) flow_->set_pore_state(i, p, s);
}

std::vector<Index> DemPorenet3D::pores_near(const Vec3& c, Real radius) const {
  std::vector<Index> out;
  for (Index i = 0; i < net_->n_pores(); ++i) {
    const Real dx = net_->pore_cx[i] - c.x(), dy = net_->pore_cy[i] - c.y(), dz = net_->pore_cz[i] - c.z();
    if (dx * dx + dy * dy + dz * dz <= radius * radius) out.push_back(i);
  }
  return out;
}

void DemPorenet3D::retriangulate() {
  porenet::update_network_3d(*net_, view(), box());  // old pores at the current positions: the remap's centroids
  auto old_net = std::move(net_);
  auto old_flow = std::move(flow_);
  make_network_and_flow(net_, flow_);
  const auto t0 = std::chrono::steady_clock::now();
  flow_->init(prm_.initial_pressure, prm_.saturation);
  set_boundaries(*flow_, *net_);
  stats_.remap_liquid_change += porenet::remap_two_phase(*old_net, *old_flow, *net_, *flow_, prm_.remap).liquid;
  stats_.t_triangulation += seconds_since(t0);
  ++stats_.retriangulations;
}

void DemPorenet3D::flow_step(Real dt) {
  if (prm_.implicit) {
    flow_->step_implicit(dt);
    stats_.last_substeps = flow_->last_substeps();
    return;
  }
  const Real limit = prm_.dt_safety * flow_->stable_dt();
  long nsub = 1;
  if (limit < dt) nsub = static_cast<long>(std::ceil(dt / limit));
  if (nsub > prm_.max_substeps)
    throw NumericalError(fmt::format("coupling.porenet3d: the explicit flow needs {} sub-steps per DEM step of {:.3g} s "
                                     "(more than {}); use the implicit step", nsub, dt, prm_.max_substeps));
  const Real h = dt / static_cast<Real>(nsub);
  for (long s = 0; s < nsub; ++s) flow_->step_explicit(h);
  stats_.last_substeps = nsub;
}

void DemPorenet3D::compute_fluid_forces(Real p_floor) {
  const auto p = flow_->pressure();
  for (std::size_t i = 0; i < pg_.size(); ++i) pg_[i] = std::max(p[i], p_floor) - prm_.ambient_pressure;
  std::fill(fx_.begin(), fx_.end(), 0.0);
  std::fill(fy_.begin(), fy_.end(), 0.0);
  std::fill(fz_.begin(), fz_.end(), 0.0);
  if (prm_.channel_shear) porenet::add_shear_forces_3d(*net_, view(), pg_, fx_, fy_, fz_);
  if (prm_.walls) wall_force_ = porenet::wall_pressure_forces_3d(*net_, pg_);
  if (prm_.pressure_force == PressureForce::Surface) {
    porenet::add_pressure_forces_3d(*net_, view(), pg_, fx_, fy_, fz_);
    return;
  }
  // p dV/dx_j of the void the flow uses, floors included (zero at the relative floor: the geometric
  // gradient there let a pore's pressure, raised by inflow, do work it never stored; porenet/forces.cpp).
  const auto& net = *net_;
#pragma omp parallel for schedule(static) if (net.n_particles > porenet::kParallelMin)
  for (Index j = 0; j < net.n_particles; ++j) {
    Vec3 f = Vec3::Zero();
    for (Index e = net.pp_start[j]; e < net.pp_start[j + 1]; ++e) {
      Real a[3];
      porenet::unit_patch_force_3d(net, e, a);
      f += pg_[static_cast<std::size_t>(net.pp_pore[e])] * void_gradient(j, e, Vec3(a[0], a[1], a[2]), true);
    }
    fx_[static_cast<std::size_t>(j)] += f.x();
    fy_[static_cast<std::size_t>(j)] += f.y();
    fz_[static_cast<std::size_t>(j)] += f.z();
  }
}

void DemPorenet3D::add_forces(dem::DemSystem& sys) {
  for (std::size_t k = 0; k < fx_.size(); ++k) sys.particles.ext_force[k] += Vec3(fx_[k], fy_[k], fz_[k]);
  if (prm_.walls)  // outward: against the wall's normal, which points to the particles
    for (int w = 0; w < 6; ++w) {
      auto& wall = sys.walls[static_cast<std::size_t>(wall_ids_[static_cast<std::size_t>(w)])];
      wall.force -= wall_force_[static_cast<std::size_t>(w)] * wall.normal;
    }
}

long DemPorenet3D::choose_flow_every(const dem::DemSystem& sys) const {
  const auto k = fluid_stiffness(!prm_.implicit);
  Real t = std::numeric_limits<Real>::infinity();
  for (std::size_t j = 0; j < k.size(); ++j)
    if (k[j] > 0) t = std::min(t, std::sqrt(1 / (sys.particles.inv_mass[j] * k[j])));
  const Real n = std::floor(prm_.flow_safety * t / sys.settings.dt);
  return std::clamp<long>(std::isfinite(n) ? static_cast<long>(std::min<Real>(n, 1e9)) : prm_.max_flow_every, 1,
                          std::max<long>(prm_.max_flow_every, 1));
}

void DemPorenet3D::advance_flow(Real dt) {
  const auto t1 = std::chrono::steady_clock::now();
  flow_step(dt);
  stats_.t_flow += seconds_since(t1);
}

bool DemPorenet3D::sync(const dem::DemSystem& sys) {
  gather(sys);
  Real dmax2 = 0;
  for (std::size_t k = 0; k < x_.size(); ++k) {
    const Real dx = x_[k] - ref_x_[k], dy = y_[k] - ref_y_[k], dz = z_[k] - ref_z_[k];
    dmax2 = std::max(dmax2, dx * dx + dy * dy + dz * dz);
  }
  stats_.max_displacement = std::sqrt(dmax2);
  if (stats_.max_displacement > prm_.retriangulation_tolerance * mean_radius_) {
    retriangulate();
    stats_.max_displacement = 0;
    add_crack_channels(sys);
    return true;
  }
  const auto t0 = std::chrono::steady_clock::now();
  porenet::update_network_3d(*net_, view(), box());
  add_crack_channels(sys);
  stats_.t_update += seconds_since(t0);
  return false;
}

// The DEM's crack log in order (every bond that broke, by the global ids of its spheres; the bond set
// itself drops broken bonds at each neighbour rebuild), each throat whose facet holds both spheres
// (found from the pores of the first; a facet counted from the first of its two pores): serial, the
// same sums on any thread count.
void DemPorenet3D::add_crack_channels(const dem::DemSystem& sys) {
  if (!prm_.crack_channels || sys.cracks.events.empty()) return;
  const auto& ids = sys.particles.id;
  if (id_index_.size() != static_cast<std::size_t>(std::max<std::int64_t>(sys.particles.next_id, 0))) {
    id_index_.assign(static_cast<std::size_t>(std::max<std::int64_t>(sys.particles.next_id, 0)), -1);
    for (std::size_t k = 0; k < ids.size(); ++k)
      if (ids[k] >= 0 && static_cast<std::size_t>(ids[k]) < id_index_.size()) id_index_[static_cast<std::size_t>(ids[k])] = static_cast<Index>(k);
  }
  auto index = [&](std::int64_t id) {
    return id >= 0 && static_cast<std::size_t>(id) < id_index_.size() ? id_index_[static_cast<std::size_t>(id)] : Index(-1);
  };
  auto& net = *net_;
  for (const auto& e : sys.cracks.events) {
    const Index a = index(e.i), c = index(e.j);
    if (a < 0 || c < 0) continue;
    const Real dx = x_[c] - x_[a], dy = y_[c] - y_[a], dz = z_[c] - z_[a];
    const Real w = std::sqrt(dx * dx + dy * dy + dz * dz) - r_[a] - r_[c];
    if (!(w > 0)) continue;
    const Real slit = w * w * w * e.size / 12;  // e.size: the bond's radius
    for (Index q = net.pp_start[a]; q < net.pp_start[a + 1]; ++q) {
      const Index k = net.pp_pore[q];
      for (Index m = net.pc_start[k]; m < net.pc_start[k + 1]; ++m) {
        const Index ch = net.pc_ch[m];
        if (net.ch_pore[2 * ch] != k) continue;
        const Index* v = &net.ch_part[3 * static_cast<std::size_t>(ch)];
        const bool has_a = v[0] == a || v[1] == a || v[2] == a, has_c = v[0] == c || v[1] == c || v[2] == c;
        if (has_a && has_c) net.ch_cond[ch] += slit / net.ch_length[ch];
      }
    }
  }
}

void DemPorenet3D::step(dem::DemSystem& sys) {
  sys.update_neighbors();
  sys.compute_forces();
  bool held = true;
  // (A crack with crack channels adds a channel: the prediction's mobilities and the held forces' flow
  // are the flow step's.)
  const bool cut = stats_.cycle_left > 0 && prm_.flow_every == 0 &&
                   ((prm_.crack_channels && sys.cracks.events.size() != cracks_at_flow_) ||
                    (predicting() ? prm_.hold_strain > 0 && pred_strain_ > prm_.hold_strain : moved_past_hold(sys)));
  if (stats_.cycle_left <= 0 || cut) {  // a flow step for the next N DEM steps
    // The DEM steps since the last flow step: the time this one advances the fluid over.
    const long elapsed = stats_.flow_steps > 0 ? stats_.flow_every - stats_.cycle_left : 0;
    if (cut) ++early_flow_steps_;
    (void)sync(sys);
    bool predict = false;
    if (prm_.flow_every > 0) {
      stats_.flow_every = prm_.flow_every;
      predict = prm_.predict_pressures;
    } else {
      if (stats_.until_choice <= 0) {
        stats_.stiffness_every = choose_flow_every(sys);
        stats_.until_choice = prm_.choose_every;
      }
      // Where the fluid's stiffness bounds N (liquid-full pores), the held steps predict the pressures
      // and N may reach max_flow_every; elsewhere the forces are held as they are (soft gas pores).
      const long cap = std::max<long>(prm_.max_flow_every, 1);
      predict = prm_.predict_pressures && stats_.stiffness_every < cap;
      const long bound = predict ? cap : stats_.stiffness_every;
      // The flow's own transport limit: a flow step that had to halve itself (s transport sub-steps)
      // shrinks the next stride by s; one that did not lets it double, up to the bound.
      const long s = stats_.flow_steps > 0 ? std::max<long>(stats_.last_substeps, 1) : 1;
      stats_.flow_every = s > 1 ? std::max<long>(stats_.flow_every / s, 1)
                                : std::min(bound, std::max<long>(2 * stats_.flow_every, 1));
      stats_.until_choice -= stats_.flow_every;
    }
    stats_.cycle_left = stats_.flow_every;
    if (elapsed > 0) advance_flow(static_cast<Real>(elapsed) * sys.settings.dt);
    const auto t1 = std::chrono::steady_clock::now();
    compute_fluid_forces(-std::numeric_limits<Real>::infinity());
    pred_strain_ = 0;
    cracks_at_flow_ = sys.cracks.events.size();
    if (predict && stats_.flow_every > 1)
      start_prediction(sys.settings.dt);
    else
      stop_prediction();  // no prediction in this cycle (nor a stale size in a checkpoint)
    stats_.t_forces += seconds_since(t1);
    ++stats_.flow_steps;
    held = false;
  }
  --stats_.cycle_left;
  sys.add_external_loads();
  add_forces(sys);
  if (held && !pred_g_.empty()) {  // at the flow step the increment is zero
    const auto t1 = std::chrono::steady_clock::now();
    add_predicted_forces(sys);
    const double t = seconds_since(t1);
    stats_.t_forces += t;
    t_predict_ += t;
  }
  sys.integrate();
}

bool DemPorenet3D::moved_past_hold(const dem::DemSystem& sys) const {
  if (!(prm_.hold_displacement > 0)) return false;
  const Real lim = prm_.hold_displacement * mean_radius_, lim2 = lim * lim;
  const auto& pos = sys.particles.pos;
  for (std::size_t k = 0; k < x_.size(); ++k) {
    const Real dx = pos[k].x() - x_[k], dy = pos[k].y() - y_[k], dz = pos[k].z() - z_[k];
    if (dx * dx + dy * dy + dz * dz > lim2) return true;
  }
  return false;
}

Real DemPorenet3D::max_pressure() const {
  Real m = -std::numeric_limits<Real>::infinity();
  for (Real p : flow_->pressure()) m = std::max(m, p);
  return m;
}

void DemPorenet3D::save(CheckpointWriter& w) const {
  w.put("porenet3d.ref_x", ref_x_);
  w.put("porenet3d.ref_y", ref_y_);
  w.put("porenet3d.ref_z", ref_z_);
  if (prm_.walls) {
    std::vector<Real> b(ref_box_.lo.begin(), ref_box_.lo.end());
    b.insert(b.end(), ref_box_.hi.begin(), ref_box_.hi.end());
    b.insert(b.end(), wall_force_.begin(), wall_force_.end());
    w.put("porenet3d.ref_box", b);
  }
  const auto vec = [](std::span<const Real> s) { return std::vector<Real>(s.begin(), s.end()); };
  w.put("porenet3d.p", vec(flow_->pressure()));
  w.put("porenet3d.alpha", vec(flow_->liquid_fraction()));
  w.put("porenet3d.mq", vec(flow_->liquid_mass()));
  w.put("porenet3d.mp", vec(flow_->gas_mass()));
  w.put("porenet3d.rq", vec(flow_->liquid_density()));
  w.put("porenet3d.rp", vec(flow_->gas_density()));
  w.put("porenet3d.guess", prm_.implicit ? vec(flow_->implicit_guess()) : std::vector<Real>{});
  w.put("porenet3d.amg", prm_.implicit ? flow_->amg_state() : std::vector<Real>{});  // empty unless AMG
  w.put_value("porenet3d.stats", stats_);
  w.put("porenet3d.fx", fx_);  // the forces held until the next flow step
  w.put("porenet3d.fy", fy_);
  w.put("porenet3d.fz", fz_);
  // What ends a held cycle early: the flow step's positions (hold_displacement), and the early cycles'
  // count, the last held step's strain (hold_strain) and the crack log's length at the flow step.
  w.put("porenet3d.flow_x", x_);
  w.put("porenet3d.flow_y", y_);
  w.put("porenet3d.flow_z", z_);
  w.put("porenet3d.hold",
        std::vector<Real>{static_cast<Real>(early_flow_steps_), pred_strain_, static_cast<Real>(cracks_at_flow_)});
  // The prediction of the current cycle (empty without held steps).
  for (const auto& [tag, member] : kPredSections) w.put(std::string("porenet3d.pred_") + tag, this->*member);
  w.put("porenet3d.pred_dt", std::vector<Real>{pred_dt_, static_cast<Real>(pred_geom_age_)});
  w.put("porenet3d.pred_setup_val", pred_g_.empty() ? std::vector<Real>{} : pred_amg_.setup_values());
}

void DemPorenet3D::load(CheckpointReader& r, const dem::DemSystem& sys, const Porenet3DParams& params) {
  prm_ = params;
  if (prm_.walls) wall_ids_ = find_box_walls(sys);
  wall_force_.fill(0);
  const auto n = sys.particles.size();
  x_.assign(n, 0);
  y_ = z_ = r_ = fx_ = fy_ = fz_ = x_;
  gather(sys);
  mean_radius_ = 0;
  for (Real rr : r_) mean_radius_ += rr;
  mean_radius_ /= static_cast<Real>(n);
  // The network as built at the last triangulation (same positions: same numbering); the next step
  // recomputes its geometry from the current positions.
  std::vector<Real> cx = x_, cy = y_, cz = z_;
  r.get("porenet3d.ref_x", x_);
  r.get("porenet3d.ref_y", y_);
  r.get("porenet3d.ref_z", z_);
  if (x_.size() != n) throw InputError(fmt::format("checkpoint: porenet3d positions for {} spheres; the sample has {}", x_.size(), n));
  const porenet::BoxWalls current_box = box_;
  if (prm_.walls) {
    std::vector<Real> b;
    if (r.has("porenet3d.ref_box")) r.get("porenet3d.ref_box", b);
    if (b.size() != 12) throw InputError("checkpoint: porenet3d.ref_box (the walls at the last triangulation) is missing");
    std::copy(b.begin(), b.begin() + 3, box_.lo.begin());
    std::copy(b.begin() + 3, b.begin() + 6, box_.hi.begin());
    std::copy(b.begin() + 6, b.end(), wall_force_.begin());
  }
  make_network_and_flow(net_, flow_);
  box_ = current_box;
  flow_->init(prm_.initial_pressure, prm_.saturation);
  set_boundaries(*flow_, *net_);
  x_ = cx;
  y_ = cy;
  z_ = cz;
  std::vector<Real> p, a, mq, mp, rq, rp, g;
  r.get("porenet3d.p", p);
  r.get("porenet3d.alpha", a);
  r.get("porenet3d.mq", mq);
  r.get("porenet3d.mp", mp);
  r.get("porenet3d.rq", rq);
  r.get("porenet3d.rp", rp);
  r.get("porenet3d.guess", g);
  if (p.size() != static_cast<std::size_t>(net_->n_pores()))
    throw InputError(fmt::format("checkpoint: {} pore states for a rebuilt network of {} pores", p.size(), net_->n_pores()));
  flow_->restore_state(p, a, mq, mp, rq, rp);
  if (prm_.implicit) flow_->restore_implicit_guess(g);
  if (prm_.implicit && r.has("porenet3d.amg")) {  // checkpoints before 2026-11-30 have none (DIC then)
    std::vector<Real> amg;
    r.get("porenet3d.amg", amg);
    flow_->restore_amg_state(amg);
  }
  stats_ = r.get_value<Porenet3DStats>("porenet3d.stats");
  early_flow_steps_ = 0;
  pred_strain_ = 0;
  cracks_at_flow_ = sys.cracks.events.size();
  if (r.has("porenet3d.flow_x")) {  // checkpoints before 2026-11-30: measured from the resume's positions
    std::vector<Real> fx, fy, fz, hold;
    r.get("porenet3d.flow_x", fx);
    r.get("porenet3d.flow_y", fy);
    r.get("porenet3d.flow_z", fz);
    r.get("porenet3d.hold", hold);
    if (fx.size() != n || fy.size() != n || fz.size() != n || hold.size() != 3)
      throw InputError(fmt::format("checkpoint: porenet3d flow-step positions for {} spheres and {} hold values; the "
                                   "sample has {} spheres, the format 3 values", fx.size(), hold.size(), n));
    x_ = std::move(fx);
    y_ = std::move(fy);
    z_ = std::move(fz);
    early_flow_steps_ = static_cast<long>(hold[0]);
    pred_strain_ = hold[1];
    cracks_at_flow_ = static_cast<std::size_t>(hold[2]);
  }
  r.get("porenet3d.fx", fx_);
  r.get("porenet3d.fy", fy_);
  r.get("porenet3d.fz", fz_);
  if (fx_.size() != n || fy_.size() != n || fz_.size() != n)
    throw InputError(fmt::format("checkpoint: porenet3d forces for {} spheres; the sample has {}", fx_.size(), n));
  const auto np = static_cast<std::size_t>(net_->n_pores());
  for (const auto& [tag, member] : kPredSections) {
    auto& v = this->*member;
    v.clear();  // checkpoints before 2026-11-29 have none: forces held as they are until the next flow step
    const std::string key = std::string("porenet3d.pred_") + tag;
    if (r.has(key)) r.get(key, v);
  }
  if (!pred_g_.empty() && pred_v0_.empty())  // checkpoints before 2026-11-30: the network's voids now
    pred_v0_.assign(net_->pore_void.begin(), net_->pore_void.begin() + net_->n_pores());
  if (!pred_g_.empty() &&
      (pred_v0_.size() != np || pred_g_.size() != 12 * np || pred_a_.size() != 3 * static_cast<std::size_t>(net_->pp_start[net_->n_particles]) ||
       pred_x0_.size() != 3 * n || pred_c_.size() != np || pred_q_.size() != np ||
       pred_w_.size() != static_cast<std::size_t>(net_->n_channels()) || pred_b_.size() != np ||
       pred_dp_.size() != np))
    throw InputError("checkpoint: porenet3d pressure prediction does not match the rebuilt network");
  pred_tmp_.assign(np, 0.0);
  pred_rhs_.assign(np, 0.0);
  pred_z_.assign(np, 0.0);
  if (!pred_g_.empty()) {
    std::vector<Real> dt;
    r.get("porenet3d.pred_dt", dt);
    if (dt.size() != 2) throw InputError("checkpoint: porenet3d.pred_dt does not hold two values");
    pred_dt_ = dt[0];
    pred_geom_age_ = static_cast<long>(dt[1]);
    // The multigrid's aggregates from the values they were built from, then the current values.
    const porenet::CsrView v = fill_prediction_matrix();
    std::vector<Real> setup_val;
    r.get("porenet3d.pred_setup_val", setup_val);
    if (setup_val.size() != static_cast<std::size_t>(pred_sys_->matrix().nonZeros()))
      throw InputError("checkpoint: porenet3d.pred_setup_val does not match the rebuilt network");
    pred_amg_.restore(v, setup_val);
    pred_amg_.refresh(v);
  }
}

// dV_i/dx_j of tetrahedral pore i (corner entry e of sphere j) for V = V_tet - sum_k Omega_k R_k^3 / 3
// (porenet/network3d.cpp), by Reynolds transport: a point of a face through j moves by lambda_j dx
// (lambda_j its barycentric weight), sphere j's patch moves by dx. So
// g = a + sum_{faces f through j} n_f [A_f / 3 - sum_{corners k of f} S_kf lambda_j(c_kf)],
// with a the patch force per unit pressure (= -int_patch n dA, porenet::unit_patch_force_3d), n_f the
// face's outward normal, S_kf = theta R_k^2 / 2 the sphere sector that corner k cuts from f and c_kf its
// centroid (4 R sin(theta/2) / (3 theta) along the bisector). Without the sectors g would be the bare
// tetrahedron's, tens of times too large where the spheres fill most of it.
Vec3 DemPorenet3D::void_gradient(Index j, Index e, const Vec3& a, bool floored) const {
  const auto& net = *net_;
  const Index i = net.pp_pore[e];
  const int c = net.pp_corner[e];
  const Index* v = &net.pore_v[4 * static_cast<std::size_t>(i)];
  auto pos = [&](Index k) { return Vec3(x_[k], y_[k], z_[k]); };
  // A pore at the fraction floor (overlapping spheres fill the tetrahedron) has V = phi V_tet:
  // g = phi dV_tet/dx_j, no sectors, no patch.
  if (floored && !(net.pore_void[i] > net.void_floor)) return Vec3::Zero();
  if (net.pore_walls[i]) {
    Real w[3];
    porenet::wall_pore_void_gradient(net, view(), i, c, w);
    return Vec3(w[0], w[1], w[2]);
  }
  const bool at_fraction = net.pore_void[i] <= net.params.min_void_fraction * net.pore_cell[i];
  Vec3 g = at_fraction ? Vec3::Zero() : a;
  for (int f = 0; f < 3; ++f) {  // face (j, b, d); the corner opposite it is o
    const Index b = v[(c + 1 + f) % 4], d = v[(c + 1 + (f + 1) % 3) % 4], o = v[(c + 1 + (f + 2) % 3) % 4];
    const Vec3 xj = pos(j), xb = pos(b), xd = pos(d);
    const Vec3 N = (xb - xj).cross(xd - xj);
    const Real N2 = N.squaredNorm();
    if (!(N2 > 0)) continue;
    const Vec3 n = (N.dot(pos(o) - xj) > 0 ? -1.0 : 1.0) * N / std::sqrt(N2);  // outward unit normal
    // lambda_j at a point q of the face: the signed area of (q, b, d) over the face's.
    auto lambda_j = [&](const Vec3& q) { return (xb - q).cross(xd - q).dot(N) / N2; };
    Real w = 0.5 * std::sqrt(N2) / 3;
    if (at_fraction) {
      g += net.params.min_void_fraction * w * n;
      continue;
    }
    const Index corner[3] = {j, b, d};
    for (int m = 0; m < 3; ++m) {
      const Vec3 xk = pos(corner[m]);
      const Vec3 u1 = (pos(corner[(m + 1) % 3]) - xk).normalized(), u2 = (pos(corner[(m + 2) % 3]) - xk).normalized();
      const Real th = std::atan2(u1.cross(u2).norm(), u1.dot(u2));
      if (!(th > 0)) continue;
      const Real R = r_[corner[m]];
      const Vec3 centroid = xk + (u1 + u2).normalized() * (4 * R * std::sin(0.5 * th) / (3 * th));
      w -= 0.5 * th * R * R * lambda_j(centroid);
    }
    g += w * n;
  }
  return g;
}

std::vector<Real> DemPorenet3D::fluid_stiffness(bool open_floored) const {
  const auto& net = *net_;
  std::vector<Real> k(static_cast<std::size_t>(net.n_particles), 0.0);
  for (Index j = 0; j < net.n_particles; ++j) {
    Real sum = 0;
    for (Index e = net.pp_start[j]; e < net.pp_start[j + 1]; ++e) {
      const Index i = net.pp_pore[e];
      if (flow_->bc(i) == porenet::PoreBc::Pressure) continue;
      const Real K = flow_->mixture_bulk_modulus(i);
      if (!(K > 0)) continue;
      Real a[3];
      porenet::unit_patch_force_3d(net, e, a);
      const Vec3 av(a[0], a[1], a[2]);
      const Real g = void_gradient(j, e, av, !open_floored).norm();
      const Real force_per_p = prm_.pressure_force == PressureForce::Surface ? av.norm() : g;
      sum += K * force_per_p * g / net.pore_void[i];
    }
    k[static_cast<std::size_t>(j)] = sum;
  }
  return k;
}

}  // namespace ff::coupling
