#include "coupling/porenet/dem_porenet.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <span>

#include "core/error.hpp"
#include "porenet/forces.hpp"
#include "porenet/remap.hpp"

namespace ff::coupling {

namespace {
std::uint64_t pair_key(Index a, Index b) {
  const auto lo = static_cast<std::uint64_t>(std::min(a, b)), hi = static_cast<std::uint64_t>(std::max(a, b));
  return lo << 32 | hi;
}
}  // namespace

void DemPorenetCoupling::gather_positions(const dem::DemSystem& sys) {
  const auto n = sys.particles.size();
  for (std::size_t k = 0; k < n; ++k) {
    x_[k] = sys.particles.pos[k].x();
    y_[k] = sys.particles.pos[k].y();
    r_[k] = sys.particles.radius[k];
  }
}

// Bonds (intact or broken) and touching neighbour pairs that are not bonds.
void DemPorenetCoupling::build_pairs(const dem::DemSystem& sys) {
  pairs_ = porenet::PairList{};
  pair_bond_.clear();
  std::vector<std::uint64_t> bonded;
  bonded.reserve(sys.bonds.size());
  bond_keys_.reserve(sys.bonds.size());  // remap_pair_bonds: the bond set only shrinks
  for (std::size_t b = 0; b < sys.bonds.size(); ++b) {
    const Index a = sys.bonds.i[b], c = sys.bonds.j[b];
    pairs_.add(a, c, sys.bonds.broken[b] ? porenet::PairState::BrokenBond : porenet::PairState::Bond);
    pair_bond_.push_back(static_cast<Index>(b));
    bonded.push_back(pair_key(a, c));
  }
  std::sort(bonded.begin(), bonded.end());
  const auto first = sys.neighbors().first(), second = sys.neighbors().second();
  for (std::size_t k = 0; k < first.size(); ++k) {
    const Index a = first[k], c = second[k];
    const Vec3 d = sys.particles.pos[c] - sys.particles.pos[a];
    if (d.norm() >= sys.particles.radius[a] + sys.particles.radius[c]) continue;
    if (std::binary_search(bonded.begin(), bonded.end(), pair_key(a, c))) continue;
    pairs_.add(a, c, porenet::PairState::Contact);
    pair_bond_.push_back(-1);
  }
}

// The DEM drops broken bonds at each neighbour rebuild (DemSystem::compact_bonds), which shifts the
// indices of the bonds after them: each pair's bond is found again by its two particles; a pair whose
// bond is gone was a bond that broke (only broken bonds are dropped). Before 2026-11-30 the stale
// indices read other bonds' loads (the B1 apertures' sigma_n) and broken flags.
void DemPorenetCoupling::remap_pair_bonds(const dem::DemSystem& sys) {
  bond_keys_.clear();
  for (std::size_t b = 0; b < sys.bonds.size(); ++b)
    bond_keys_.emplace_back(pair_key(sys.bonds.i[b], sys.bonds.j[b]), static_cast<Index>(b));
  std::sort(bond_keys_.begin(), bond_keys_.end());
  for (std::size_t q = 0; q < pairs_.size(); ++q) {
    if (pair_bond_[q] < 0) continue;
    const std::uint64_t key = pair_key(pairs_.i[q], pairs_.j[q]);
    const auto it = std::lower_bound(bond_keys_.begin(), bond_keys_.end(), std::make_pair(key, Index(-1)));
    if (it != bond_keys_.end() && it->first == key) {
      pair_bond_[q] = it->second;
    } else {
      pair_bond_[q] = -1;
      pairs_.state[q] = porenet::PairState::BrokenBond;
    }
  }
}

// sigma_n = F_n / (2 min(R) h), h the force's height (t or 2 min(R)), from the bond's and the
// contact's loads of this step (F on the second particle; compression pushes it away from the first:
// F.n > 0).
void DemPorenetCoupling::fill_pair_state(const dem::DemSystem& sys) {
  for (std::size_t q = 0; q < pairs_.size(); ++q) {
    const Index b = pair_bond_[q];
    if (b >= 0 && (static_cast<std::size_t>(b) >= sys.bonds.size() || pair_key(sys.bonds.i[b], sys.bonds.j[b]) !=
                                                                            pair_key(pairs_.i[q], pairs_.j[q]))) {
      remap_pair_bonds(sys);
      break;
    }
  }
  const auto& P = sys.particles;
  const auto adj_off = sys.neighbors().adjacency_offsets();
  const auto adj = sys.neighbors().adjacency();
  const auto first = sys.neighbors().first(), second = sys.neighbors().second();
  const auto& pl = sys.pair_loads();
  const Real t = prm_.network.thickness;
  // The contact's area is 2 min(R) times the height its force acts over: the disc thickness t, or
  // with sphere forces (ForceHeight::Diameter, the seed's law) the sphere's 2 min(R), the height
  // B27 wets: a force of spheres over a 1 m thick section would leave B1 at h0 under any load.
  const bool sphere_height = prm_.force_height == ForceHeight::Diameter;
  const auto n = static_cast<Index>(pairs_.size());
#pragma omp parallel for schedule(static) if (static_cast<std::size_t>(n) > sys.settings.parallel_min)
  for (Index q = 0; q < n; ++q) {
    const Index a = pairs_.i[q], b = pairs_.j[q];
    const Vec3 d = P.pos[b] - P.pos[a];
    const Real dist = d.norm();
    const Vec3 nrm = d / dist;
    Real fn = 0;
    const Index bond = pair_bond_[q];
    if (bond >= 0) {
      const Vec3& f = sys.bond_loads()[bond].f;
      fn += (sys.bonds.i[bond] == a ? 1.0 : -1.0) * f.dot(nrm);
      if (sys.bonds.broken[bond]) pairs_.state[q] = porenet::PairState::BrokenBond;
    }
    for (auto e = adj_off[a]; e < adj_off[a + 1]; ++e) {  // the contact slot of (a, b), if listed
      const auto k = static_cast<std::size_t>(adj[e] >> 1);
      const Index other = (adj[e] & 1) ? first[k] : second[k];
      if (other != b || k >= pl.size()) continue;
      fn += (first[k] == a ? 1.0 : -1.0) * pl[k].f.dot(nrm);
    }
    const Real rmin = std::min(P.radius[a], P.radius[b]);
    pairs_.sigma_n[q] = std::max(fn, 0.0) / (2 * rmin * (sphere_height ? 2 * rmin : t));
    pairs_.opening[q] = pairs_.state[q] == porenet::PairState::BrokenBond
                            ? std::max(dist - P.radius[a] - P.radius[b], 0.0)
                            : 0.0;
  }
}

void DemPorenetCoupling::set_boundaries(porenet::TwoPhaseFlow& flow, const porenet::Network2D& net) {
  bc_pore_.assign(static_cast<std::size_t>(net.n_pores()), 0);
  if (prm_.drainage == Drainage::Closed) return;
  if (prm_.drainage == Drainage::Hull) {
    for (Index i = 0; i < net.n_pores(); ++i)
      if (net.pore_hull[i]) {
        flow.set_bc(i, porenet::PoreBc::Pressure, prm_.ambient_pressure, prm_.saturation);
        bc_pore_[static_cast<std::size_t>(i)] = 1;
      }
    return;
  }
  Real xmin = x_[0], xmax = x_[0], rmax = 0;
  for (std::size_t k = 0; k < x_.size(); ++k) {
    xmin = std::min(xmin, x_[k]);
    xmax = std::max(xmax, x_[k]);
    rmax = std::max(rmax, r_[k]);
  }
  for (Index i = 0; i < net.n_pores(); ++i)
    if (net.pore_hull[i] && (net.pore_cx[i] < xmin + 2 * rmax || net.pore_cx[i] > xmax - 2 * rmax)) {
      flow.set_bc(i, porenet::PoreBc::Pressure, prm_.ambient_pressure, prm_.saturation);
      bc_pore_[static_cast<std::size_t>(i)] = 1;
    }
}

void DemPorenetCoupling::make_network_and_flow(std::unique_ptr<porenet::Network2D>& net,
                                               std::unique_ptr<porenet::TwoPhaseFlow>& flow) {
  const porenet::Particles2D parts{x_, y_, r_, {}};
  net = std::make_unique<porenet::Network2D>(porenet::build_network_2d(parts, pairs_, prm_.network));
  flow = std::make_unique<porenet::TwoPhaseFlow>(*net, prm_.fluid);
  if (prm_.implicit_above > 0) flow->prepare_implicit();  // no allocation in the time loop
  ref_x_ = x_;
  ref_y_ = y_;
}

void DemPorenetCoupling::init(dem::DemSystem& sys, const PorenetCouplingParams& params) {
  if (sys.settings.dim != 2)
    throw InputError("coupling.porenet: the DEM/pore-network coupling runs on 2D disc samples (dem.dim = 2)");
  if (!(params.saturation >= 0 && params.saturation <= 1))
    throw InputError(fmt::format("coupling.porenet: saturation {} outside [0, 1]", params.saturation));
  if (!(params.retriangulation_tolerance > 0))
    throw InputError("coupling.porenet: retriangulation_tolerance must be > 0");
  prm_ = params;
  const auto n = sys.particles.size();
  x_.assign(n, 0);
  y_ = r_ = fx_ = fy_ = x_;
  gather_positions(sys);
  mean_radius_ = 0;
  for (Real r : r_) mean_radius_ += r;
  mean_radius_ /= static_cast<Real>(n);
  build_pairs(sys);
  make_network_and_flow(net_, flow_);
  flow_->init(prm_.initial_pressure, prm_.saturation, prm_.placement);
  set_boundaries(*flow_, *net_);
  pg_.assign(static_cast<std::size_t>(net_->n_pores()), 0);
  vap_.assign(static_cast<std::size_t>(net_->n_pores()), 0);
  mp_prev_.assign(flow_->gas_mass().begin(), flow_->gas_mass().end());
  stats_ = {};
}

void DemPorenetCoupling::set_uniform_state(Real p, Real s) {
  for (Index i = 0; i < net_->n_pores(); ++i) flow_->set_pore_state(i, p, s);
}

void DemPorenetCoupling::retriangulate(const dem::DemSystem& sys) {
  const auto t0 = std::chrono::steady_clock::now();
  // Old network at the current positions (centroids for the nearest-pore map), then a new one.
  porenet::update_network_2d(*net_, porenet::Particles2D{x_, y_, r_, {}}, pairs_);
  auto old_net = std::move(net_);
  auto old_flow = std::move(flow_);
  build_pairs(sys);
  fill_pair_state(sys);
  make_network_and_flow(net_, flow_);
  flow_->init(prm_.initial_pressure, prm_.saturation);
  set_boundaries(*flow_, *net_);
  const auto change = porenet::remap_two_phase(*old_net, *old_flow, *net_, *flow_, prm_.remap);
  stats_.remap_liquid_change += change.liquid;
  stats_.remap_gas_change += change.gas;
  stats_.remap_liquid_change_max = std::max(stats_.remap_liquid_change_max, std::abs(change.liquid));
  pg_.assign(static_cast<std::size_t>(net_->n_pores()), 0);
  const std::vector<Real> old_vap = vap_;
  carry_vapour(*old_net, old_vap, old_flow->gas_mass());
  ++stats_.retriangulations;
  t_triangulation_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Each new pore's gas takes the vapour fraction of the old pore nearest to it (the composition is
// carried as porenet's remap carries the phase fractions).
void DemPorenetCoupling::carry_vapour(const porenet::Network2D& old_net, std::span<const Real> old_vap,
                                      std::span<const Real> old_mp) {
  const auto np = static_cast<std::size_t>(net_->n_pores());
  const auto mp = flow_->gas_mass();
  vap_.assign(np, 0);
  if (prm_.cavitation_pressure > 0) {
    const std::vector<Index> near = porenet::nearest_pores(old_net, *net_);
    for (std::size_t k = 0; k < np; ++k) {
      const auto o = static_cast<std::size_t>(near[k]);
      if (!bc_pore_[k] && old_mp[o] > 0) vap_[k] = std::min(1.0, old_vap[o] / old_mp[o]) * mp[k];
    }
  }
  mp_prev_.assign(mp.begin(), mp.end());
}

void DemPorenetCoupling::add_forces(dem::DemSystem& sys) {
  compute_fluid_forces(-std::numeric_limits<Real>::infinity());  // no floor: the pores' own pressures
  for (std::size_t k = 0; k < fx_.size(); ++k) {
    sys.particles.ext_force[k].x() += fx_[k];
    sys.particles.ext_force[k].y() += fy_[k];
  }
}

void DemPorenetCoupling::step(dem::DemSystem& sys) {
  sys.update_neighbors();
  sys.compute_forces();
  (void)sync(sys);
  // Flow sub-steps inside the DEM step (the first one sees V^{n+1}: the compaction source). When the
  // stable step is below the DEM step, it is evaluated again before each sub-step: cavitation and
  // condensation reset pores between sub-steps, and a pore whose pressure jumped (a condensed bubble)
  // would otherwise give away more than it holds at the rates of the step's start.
  const Real dt = sys.settings.dt;
  stats_.last_stable_dt = flow_->stable_dt();
  Real limit = prm_.dt_safety * stats_.last_stable_dt;
  long nsub = 0;
  Real left = dt, h = dt;
  while (left > 0) {
    // A zero or NaN stable step (infinite or NaN conductances) would make the sub-step count
    // undefined (a negative step was taken before this guard).
    if (!(limit > 0))
      throw NumericalError(fmt::format("coupling.porenet: the flow's stable step is {} s (a channel's conductance is "
                                       "infinite or not a number)", limit));
    const long need = limit < left ? static_cast<long>(std::min(std::ceil(left / limit), 1e18)) : 1;
    if (prm_.implicit_above > 0 && need > prm_.implicit_above) {
      flow_->step_implicit(left);
      cavitate();
      ++nsub;
      ++stats_.implicit_steps;
      h = left;
      break;
    }
    if (nsub + need > prm_.max_substeps)
      throw NumericalError(fmt::format(
          "coupling.porenet: the flow needs more than {} sub-steps of {:.3g} s per DEM step of {:.3g} s; "
          "the explicit step shrinks with the channels' conductance and grows with the pores' compressibility: lower "
          "the apertures or the liquid bulk modulus, shorten the DEM step, or let the flow go implicit",
          prm_.max_substeps, limit, dt));
    h = need == 1 ? left : left / static_cast<Real>(need);
    flow_->step_explicit(h);
    cavitate();
    ++nsub;
    left = need == 1 ? 0 : left - h;
    if (left > 0) limit = prm_.dt_safety * flow_->stable_dt();
  }
  stats_.last_substeps = nsub;
  stats_.last_flow_dt = h;
  sys.add_external_loads();
  add_forces(sys);
  sys.integrate();
}

// Cavitation and condensation after each flow sub-step (prm_.cavitation_pressure pc).
// 1. Vapour follows the gas: a pore whose gas mass fell since the last call kept its vapour fraction;
//    gas that came in carries the sample's mean vapour fraction (the flow's per-channel rates are not
//    seen here; exact when all the gas is vapour, S = 1 at the start, or when there is no vapour).
//    Note the mechanics barely depend on it: vapour at pc compressed to p keeps pc/p of its volume.
// 2. A pore below pc keeps its liquid mass and fills the rest of its void with vapour at pc.
// 3. Vapour exists only at pc (the liquid's vapour pressure): a vapour pore above pc (compressed)
//    condenses vapour into liquid at constant total mass, back to pc with the vapour volume
//    V - m_q'/rho_q(pc) - m_air/rho_v(pc) if that is positive (m_q' the liquid after condensing),
//    else all of it (the pore is then a compressed liquid, B23 solved for its pressure).
void DemPorenetCoupling::cavitate() {
  const Real pc = prm_.cavitation_pressure;
  if (!(pc > 0)) return;
  const auto p = flow_->pressure();
  const auto mq = flow_->liquid_mass();
  const auto mp = flow_->gas_mass();
  const auto alpha = flow_->liquid_fraction();
  const Index np = net_->n_pores();
  Real vsum = 0, gsum = 0;  // serial fixed-order sums
  for (Index i = 0; i < np; ++i) {
    vsum += vap_[i];
    gsum += mp_prev_[i];
  }
  // A sample filled with liquid at the start holds no air: all its gas is vapour.
  const Real chi = prm_.saturation >= 1 ? 1.0 : gsum > 0 ? std::min(1.0, vsum / gsum) : 0.0;
  const Real rho_q = prm_.fluid.liquid.density(pc, true), rho_v = prm_.fluid.gas.density(pc, false);
  for (Index i = 0; i < np; ++i) {
    if (bc_pore_[i]) {
      vap_[i] = 0;
      continue;
    }
    const Real dm = mp[i] - mp_prev_[i];
    if (dm < 0)
      vap_[i] = mp_prev_[i] > 0 ? vap_[i] * (mp[i] / mp_prev_[i]) : 0.0;
    else
      vap_[i] = std::min(mp[i], vap_[i] + chi * dm);
    const Real V = net_->pore_void[i];
    // A pore without liquid has nothing to cavitate: its gas expands below pc as a gas does (the
    // vapour added to dry pores became liquid when they closed again, and the pressure solved for
    // that liquid with the air was negative: "ideal-gas density asked at p = -1.7e9 Pa").
    if (!(mq[i] > 0) && !(vap_[i] > 0)) continue;
    if (p[i] < pc) {
      // Same liquid mass at the vapour pressure; the rest of the void is vapour at pc. Vapour is only
      // added: a pore whose gas would fill that space already is left alone (gas mass never falls).
      const Real S = std::min(1.0, mq[i] / (V * rho_q));
      const Real needed = (1 - S) * V * rho_v;
      const Real mp_old = mp[i];
      if (needed < mp_old) continue;
      flow_->set_pore_state(i, pc, S);
      const Real added = mp[i] - mp_old;
      stats_.vapour_mass += added;
      vap_[i] = std::min(mp[i], vap_[i] + added);
      ++stats_.cavitations;
    } else if (p[i] > pc && vap_[i] > 0) {
      const Real mv = vap_[i], air = std::max(mp[i] - mv, 0.0), liquid = mq[i];
      const Real keep = (V - (liquid + mv) / rho_q - air / rho_v) / (1 / rho_v - 1 / rho_q);  // vapour at pc
      if (keep >= mv) continue;  // round-off: the pore is at pc already
      if (keep > 0) {
        flow_->set_pore_state(i, pc, (liquid + mv - keep) / (V * rho_q));
        vap_[i] = std::min(keep, mp[i]);
      } else {
        Real pn = 0;
        const Real a = flow_->solve_shared_pressure(liquid + mv, air, V, alpha[i], pn);
        flow_->set_pore_state(i, pn, std::clamp(a, 0.0, 1.0));
        vap_[i] = 0;
      }
      stats_.condensed_mass += mv - std::max(keep, 0.0);
      ++stats_.condensations;
    }
  }
  std::copy(mp.begin(), mp.end(), mp_prev_.begin());
}

Real DemPorenetCoupling::total_vapour() const {
  Real v = 0;
  for (Real x : vap_) v += x;
  return v;
}

Real DemPorenetCoupling::max_pressure() const {
  Real m = -std::numeric_limits<Real>::infinity();
  for (Real p : flow_->pressure()) m = std::max(m, p);
  return m;
}

void DemPorenetCoupling::save(CheckpointWriter& w) const {
  w.put("porenet.ref_x", ref_x_);
  w.put("porenet.ref_y", ref_y_);
  w.put("porenet.pair_i", pairs_.i);
  w.put("porenet.pair_j", pairs_.j);
  w.put("porenet.pair_state", pairs_.state);
  w.put("porenet.pair_bond", pair_bond_);
  const auto vec = [](std::span<const Real> s) { return std::vector<Real>(s.begin(), s.end()); };
  w.put("porenet.p", vec(flow_->pressure()));
  w.put("porenet.alpha", vec(flow_->liquid_fraction()));
  w.put("porenet.mq", vec(flow_->liquid_mass()));
  w.put("porenet.mp", vec(flow_->gas_mass()));
  w.put("porenet.rq", vec(flow_->liquid_density()));
  w.put("porenet.rp", vec(flow_->gas_density()));
  w.put("porenet.vapour", vap_);
  w.put("porenet.implicit_guess", vec(flow_->implicit_guess()));
  w.put_value("porenet.stats", stats_);
}

void DemPorenetCoupling::load(CheckpointReader& r, dem::DemSystem& sys, const PorenetCouplingParams& params) {
  prm_ = params;
  const auto n = sys.particles.size();
  x_.assign(n, 0);
  y_ = r_ = fx_ = fy_ = x_;
  gather_positions(sys);
  mean_radius_ = 0;
  for (Real rr : r_) mean_radius_ += rr;
  mean_radius_ /= static_cast<Real>(n);
  // The network as built at the last triangulation (same positions, same pair list: same numbering).
  std::vector<Real> cur_x = x_, cur_y = y_;
  r.get("porenet.ref_x", x_);
  r.get("porenet.ref_y", y_);
  pairs_ = porenet::PairList{};
  r.get("porenet.pair_i", pairs_.i);
  r.get("porenet.pair_j", pairs_.j);
  r.get("porenet.pair_state", pairs_.state);
  r.get("porenet.pair_bond", pair_bond_);
  pairs_.sigma_n.assign(pairs_.i.size(), 0);
  pairs_.opening.assign(pairs_.i.size(), 0);
  make_network_and_flow(net_, flow_);
  flow_->init(prm_.initial_pressure, prm_.saturation);
  set_boundaries(*flow_, *net_);  // at the triangulation's positions, as when it was built
  x_ = cur_x;
  y_ = cur_y;
  std::vector<Real> p, a, mq, mp, rq, rp;
  r.get("porenet.p", p);
  r.get("porenet.alpha", a);
  r.get("porenet.mq", mq);
  r.get("porenet.mp", mp);
  r.get("porenet.rq", rq);
  r.get("porenet.rp", rp);
  if (p.size() != static_cast<std::size_t>(net_->n_pores()))
    throw InputError(fmt::format("checkpoint: {} pore states for a rebuilt network of {} pores", p.size(), net_->n_pores()));
  flow_->restore_state(p, a, mq, mp, rq, rp);
  pg_.assign(static_cast<std::size_t>(net_->n_pores()), 0);
  if (r.has("porenet.implicit_guess")) {
    std::vector<Real> g;
    r.get("porenet.implicit_guess", g);
    if (!g.empty()) flow_->restore_implicit_guess(g);
  }
  if (r.has("porenet.vapour"))
    r.get("porenet.vapour", vap_);
  else
    vap_.assign(p.size(), 0);  // a checkpoint written before the vapour was tracked
  mp_prev_ = mp;
  stats_ = r.get_value<CouplingStats>("porenet.stats");
}

bool DemPorenetCoupling::sync(const dem::DemSystem& sys) {
  gather_positions(sys);
  Real dmax2 = 0;
  for (std::size_t k = 0; k < x_.size(); ++k)
    dmax2 = std::max(dmax2, (x_[k] - ref_x_[k]) * (x_[k] - ref_x_[k]) + (y_[k] - ref_y_[k]) * (y_[k] - ref_y_[k]));
  stats_.max_displacement = std::sqrt(dmax2);
  fill_pair_state(sys);
  if (stats_.max_displacement > prm_.retriangulation_tolerance * mean_radius_) {
    retriangulate(sys);
    stats_.max_displacement = 0;
    return true;
  }
  porenet::update_network_2d(*net_, porenet::Particles2D{x_, y_, r_, {}}, pairs_);
  return false;
}

void DemPorenetCoupling::compute_fluid_forces(Real p_floor) {
  const auto p = flow_->pressure();
  for (std::size_t i = 0; i < pg_.size(); ++i) pg_[i] = std::max(p[i], p_floor) - prm_.ambient_pressure;
  std::fill(fx_.begin(), fx_.end(), 0.0);
  std::fill(fy_.begin(), fy_.end(), 0.0);
  const porenet::Particles2D parts{x_, y_, r_, {}};
  if (prm_.pressure_force == PressureForce::Surface)
    porenet::add_pressure_forces(*net_, parts, pg_, fx_, fy_);
  else
    porenet::add_pressure_forces_void_gradient(*net_, parts, pg_, fx_, fy_);
  if (prm_.shear_forces) porenet::add_shear_forces(*net_, parts, pg_, fx_, fy_);
  // porenet applies all of them over the seed's height 2 r_j; every term of particle k carries it once.
  if (prm_.force_height == ForceHeight::Thickness)
    for (std::size_t k = 0; k < fx_.size(); ++k) {
      const Real scale = prm_.network.thickness / (2 * r_[k]);
      fx_[k] *= scale;
      fy_[k] *= scale;
    }
}

std::vector<Real> DemPorenetCoupling::fluid_stiffness() const {
  const auto& net = *net_;
  std::vector<Real> K(static_cast<std::size_t>(net.n_pores()), 0.0);
  for (Index i = 0; i < net.n_pores(); ++i)
    if (flow_->bc(i) != porenet::PoreBc::Pressure) K[static_cast<std::size_t>(i)] = flow_->mixture_bulk_modulus(i);
  const Real t = prm_.network.thickness;
  const porenet::Particles2D parts{x_, y_, r_, {}};
  std::vector<Real> k(static_cast<std::size_t>(net.n_particles), 0.0);
  for (Index j = 0; j < net.n_particles; ++j) {
    const Real h = prm_.force_height == ForceHeight::Diameter ? 2 * r_[j] : t;
    Real sum = 0;
    for (Index e = net.pp_start[j]; e < net.pp_start[j + 1]; ++e) {
      const Index i = net.pp_pore[e];
      const int c = net.pp_corner[e];
      const Index b = net.pore_v[3 * i + (c + 1) % 3], d = net.pore_v[3 * i + (c + 2) % 3];
      // At the fraction floor (overlapping discs, V = phi x the triangle) phi of the triangle's change.
      const Real edge = std::hypot(x_[d] - x_[b], y_[d] - y_[b]);
      const Real phi =
          net.pore_void[i] <= net.params.min_void_fraction * net.pore_cell[i] ? net.params.min_void_fraction : 1.0;
      // The force per unit pressure (per unit height) times the void's change (per unit depth and move):
      // the arc's chord and the triangle's change edge / 2 (the estimate of before 2026-11-28), or |g|
      // for both with the void-gradient force (the triangle's phi edge / 2 still at the fraction floor).
      Real force_per_p, dvoid = phi * edge / 2;
      if (prm_.pressure_force == PressureForce::Surface) {
        Real dx, dy;
        porenet::arc_span_2d(net, parts, j, e, dx, dy);
        force_per_p = r_[j] * std::hypot(dx, dy);
      } else {
        Real gx, gy;
        // Floors off: a floored pore counts as if it had just opened (its force then), as before.
        porenet::void_gradient_2d(net, parts, j, e, gx, gy, false);
        force_per_p = std::hypot(gx, gy);
        if (phi == 1.0) dvoid = force_per_p;
      }
      sum += K[static_cast<std::size_t>(i)] * h * force_per_p * t * dvoid / net.pore_void[i];
    }
    k[static_cast<std::size_t>(j)] = sum;
  }
  return k;
}

}  // namespace ff::coupling
