#include "coupling/hydrofrac/network_load.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <span>

#include "core/error.hpp"
#include "coupling/porenet/dem_porenet.hpp"
#include "coupling/porenet/dem_porenet3d.hpp"
#include "porenet/two_phase.hpp"

namespace ff::coupling::hydrofrac {

namespace {
double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

porenet::TwoPhaseParams fluid_params(const NetworkSettings& s) {
  porenet::TwoPhaseParams f;
  f.liquid = porenet::Eos::barotropic(s.density, s.pore_pressure, s.bulk_modulus);
  f.gas = porenet::Eos::air_pr(293.15);  // saturated: no gas; the law is only evaluated
  f.mu_liquid = s.viscosity;
  f.preconditioner = s.amg ? porenet::Preconditioner::AMG : porenet::Preconditioner::DIC;
  return f;
}

coupling::PorenetCouplingParams params_2d(const NetworkSettings& s) {
  coupling::PorenetCouplingParams p;
  p.network = s.network;
  p.network.thickness = 1.0;
  p.fluid = fluid_params(s);
  p.initial_pressure = p.ambient_pressure = s.pore_pressure;
  p.saturation = 1.0;
  p.retriangulation_tolerance = s.retriangulation_tolerance;
  p.remap = s.remap;
  p.pressure_force = s.pressure_force;
  p.shear_forces = s.shear_forces;
  p.cavitation_pressure = 0;  // not used by the staged calls: the forces clamp instead
  p.force_height = coupling::ForceHeight::Thickness;
  p.drainage = s.drained_faces ? coupling::Drainage::Hull : coupling::Drainage::Closed;
  return p;
}

coupling::Porenet3DParams params_3d(const NetworkSettings& s) {
  coupling::Porenet3DParams p;
  p.network = s.network;
  p.fluid = fluid_params(s);
  p.pfv_factor = s.pfv_factor;
  p.initial_pressure = p.ambient_pressure = s.pore_pressure;
  p.saturation = 1.0;
  p.retriangulation_tolerance = s.retriangulation_tolerance;
  p.remap = s.remap;
  p.pressure_force = s.pressure_force;
  p.implicit = true;
  p.drained = s.drained_faces;
  p.walls = s.walls;
  p.crack_channels = s.crack_channels;
  return p;
}
// DEM steps per flow step and whether the held steps predict the pressures (3D): from the fluid-grain
// spring period (t_spring, median) unless network.flow_every is set. begin() chooses it, load() derives
// the same from the checkpointed info.
struct Stride {
  long n = 1;
  bool predict = false;
};
Stride flow_stride(const NetworkSettings& s, int dim, Real t_spring, Real dt) {
  Stride st{s.flow_every, dim == 3 && s.predict_pressures};
  if (st.n <= 0) {
    const Real f = std::floor(s.flow_safety * t_spring / dt);
    st.n = std::clamp<long>(std::isfinite(f) ? static_cast<long>(std::min<Real>(f, 1e9)) : 1, 1, s.max_flow_every);
    if (st.predict && st.n < s.predict_every)
      st.n = std::min(s.predict_every, s.max_flow_every);  // the stiffness no longer bounds it
    else
      st.predict = false;  // the held forces alone are stable at n
  }
  st.predict = st.predict && st.n > 1;
  return st;
}
}  // namespace

std::string NetworkInfo::describe() const {
  return fmt::format(
      "{}D pore network: {} pores ({} in the borehole, {:.4g} m^3{}), {} channels over {} particles; flow: one implicit step of "
      "{:.4g} s per {} DEM steps of {:.4g} s (explicit limit {:.3g} s; fluid-grain spring period sqrt(m/k) {:.3g} s, median)",
      dim, pores, hole_pores, hole_volume, dim == 2 ? " per m" : "", channels, particles, dt_flow, flow_every, dt_dem,
      dt_explicit, t_spring);
}

NetworkLoad::NetworkLoad(NetworkSettings s, int dim) : s_(std::move(s)), dim_(dim) {
  if (dim != 2 && dim != 3) throw InputError(fmt::format("injection.fluid = \"network\": dem.dim must be 2 or 3 (got {})", dim));
}

NetworkLoad::~NetworkLoad() = default;

porenet::TwoPhaseFlow& NetworkLoad::flow() { return c2_ ? c2_->flow() : c3_->flow(); }
const porenet::TwoPhaseFlow& NetworkLoad::flow() const { return c2_ ? c2_->flow() : c3_->flow(); }
const porenet::Network2D& NetworkLoad::network() const { return c2_ ? c2_->network() : c3_->network(); }

void NetworkLoad::make_coupling() {
  if (dim_ == 2) {
    c2_ = std::make_unique<coupling::DemPorenetCoupling>();
    return;
  }
  c3_ = std::make_unique<coupling::DemPorenet3D>();
  // Every (re)build: the hole pores and their condition, before the state is carried over.
  c3_->on_network = [this](porenet::TwoPhaseFlow& f, const porenet::Network2D& net) {
    drain_faces(f, net);
    find_hole_pores(net);
    set_hole_bc(f, net, now_);  // the hole's pores where it meets a face: the hole's pressure
  };
}

// Drained faces: besides the hull pores (3D: Porenet3DParams::drained; 2D: Drainage::Hull), every
// pore whose centroid lies within one largest radius of the outermost centres (2D too since
// 2026-11-28: with the void-gradient force the flat pores along closed or hull-drained faces broke
// the 2D test block there, docs/hydrofrac.md). The grains pressed on a flat wall lie
// in a plane, so the tetrahedra among them are flat: a tiny void that the grains' motion changes
// by a large fraction. Closed, such a liquid-full pore reached 0.1-1.7 GPa within 50 flow steps
// at 0.1 MPa in the hole (the 30,000-sphere example), and its grains' bonds broke; not all of
// them are on the hull. The band is fixed at the start (checkpointed with the state).
void NetworkLoad::drain_faces(porenet::TwoPhaseFlow& f, const porenet::Network2D& net) const {
  // With walls in the network the pores on them are the faces (Porenet3DParams::drained holds them):
  // no flat hull tetrahedra, no band.
  if (!s_.drained_faces || s_.walls) return;
  for (Index i = 0; i < net.n_pores(); ++i) {
    const Real c[3] = {net.pore_cx[i], net.pore_cy[i], net.dim == 3 ? net.pore_cz[i] : 0.0};
    bool out = false;
    for (int a = 0; a < net.dim; ++a) out = out || c[a] < st_.band_lo[a] || c[a] > st_.band_hi[a];
    if (out) f.set_bc(i, porenet::PoreBc::Pressure, s_.pore_pressure, 1.0);
  }
}

// Pores in the carved hole (centroid) and slivers between hole-wall particles (all corners on the wall).
void NetworkLoad::find_hole_pores(const porenet::Network2D& net) {
  hole_pores_.clear();
  const int nv = net.dim == 3 ? 4 : 3;
  for (Index i = 0; i < net.n_pores(); ++i) {
    const Vec3 c(net.pore_cx[i], net.pore_cy[i], net.dim == 3 ? net.pore_cz[i] : 0.0);
    bool in = in_hole(hole_, c, 0);
    if (!in) {
      in = true;
      for (int k = 0; k < nv && in; ++k) {
        const Index q = net.pore_v[nv * i + k];
        in = !net.is_wall_vertex(q) && is_wall_[static_cast<std::size_t>(q)] != 0;
      }
    }
    if (in) hole_pores_.push_back(i);
  }
  if (hole_pores_.empty())
    throw InputError("injection.fluid = \"network\": no pore of the network lies in the borehole (is borehole.radius several grains?)");
}

// Ramp: the hole pores at p0 + p(t). Rate: the pumped mass shared by the hole pores in proportion to their voids.
void NetworkLoad::set_hole_bc(porenet::TwoPhaseFlow& f, const porenet::Network2D& net, Real time) {
  if (!s_.rate_mode) {
    const Real p = s_.pore_pressure + s_.initial_pressure + s_.ramp_rate * (time - st_.t0);
    for (Index i : hole_pores_) f.set_bc(i, porenet::PoreBc::Pressure, p, 1.0);
    return;
  }
  Real v = 0;
  for (Index i : hole_pores_) v += net.pore_void[i];
  const Real m_rate = s_.density * s_.flow_rate;
  for (Index i : hole_pores_) f.set_bc(i, porenet::PoreBc::Flux, m_rate * net.pore_void[i] / v, 1.0);
}

// The median over the rock's pores of min over corners of sqrt(m / k), k = K A^2 / V.
Real NetworkLoad::spring_time(const dem::DemSystem& sys) const {
  const auto& net = network();
  const int nv = net.dim == 3 ? 4 : 3;
  std::vector<char> hole(static_cast<std::size_t>(net.n_pores()), 0);
  for (Index i : hole_pores_) hole[static_cast<std::size_t>(i)] = 1;
  std::vector<Real> t;
  t.reserve(static_cast<std::size_t>(net.n_pores()));
  for (Index i = 0; i < net.n_pores(); ++i) {
    if (hole[static_cast<std::size_t>(i)]) continue;
    const Real C = net.pore_void[i] / s_.bulk_modulus;
    Real tmin = std::numeric_limits<Real>::infinity();
    for (int k = 0; k < nv; ++k) {
      const Index q = net.pore_v[nv * i + k];
      if (net.is_wall_vertex(q)) continue;
      const Real r = sys.particles.radius[q], im = sys.particles.inv_mass[q];
      if (!(im > 0)) continue;
      const Real A = net.dim == 3 ? kPi * r * r : 2 * r * net.params.thickness;
      tmin = std::min(tmin, std::sqrt(C / im) / A);
    }
    if (std::isfinite(tmin)) t.push_back(tmin);
  }
  if (t.empty()) return 0;
  std::nth_element(t.begin(), t.begin() + static_cast<std::ptrdiff_t>(t.size() / 2), t.end());
  return t[t.size() / 2];
}

void NetworkLoad::begin(const dem::DemSystem& sys, const BoreholeGeometry& hole, const std::vector<JointPair>& joints) {
  (void)joints;  // natural fractures: their cut bonds are broken-bond channels of the network already (2D)
  hole_ = hole;
  const HoleSurface hs = hole_surface(sys, hole, s_.cell, s_.inflate, s_.reach);
  wall_ = hs.particle;
  is_wall_.assign(sys.particles.size(), 0);
  for (Index k : wall_) is_wall_[static_cast<std::size_t>(k)] = 1;
  st_ = State{};
  st_.t0 = sys.time;
  st_.effective_radius = hs.effective_radius;
  now_ = st_.t_last = sys.time;
  {
    Real rmax = 0;
    for (int a = 0; a < 3; ++a) {
      st_.band_lo[a] = std::numeric_limits<Real>::infinity();
      st_.band_hi[a] = -std::numeric_limits<Real>::infinity();
    }
    for (std::size_t k = 0; k < sys.particles.size(); ++k) {
      rmax = std::max(rmax, sys.particles.radius[k]);
      for (int a = 0; a < 3; ++a) {
        st_.band_lo[a] = std::min(st_.band_lo[a], sys.particles.pos[k][a]);
        st_.band_hi[a] = std::max(st_.band_hi[a], sys.particles.pos[k][a]);
      }
    }
    for (int a = 0; a < 3; ++a) st_.band_lo[a] += rmax, st_.band_hi[a] -= rmax;
  }
  make_coupling();
  if (c2_) {
    c2_->init(const_cast<dem::DemSystem&>(sys), params_2d(s_));  // init only reads the system
    drain_faces(flow(), network());
    find_hole_pores(c2_->network());
    set_hole_bc(flow(), network(), sys.time);
    flow().prepare_implicit();
  } else {
    c3_->init(sys, params_3d(s_));  // on_network set the hole's condition
  }
  const auto& net = network();
  info_ = NetworkInfo{};
  info_.dim = dim_;
  info_.pores = net.n_pores();
  info_.channels = net.n_channels();
  info_.hole_pores = static_cast<long>(hole_pores_.size());
  info_.particles = static_cast<long>(sys.particles.size());
  info_.dt_dem = sys.settings.dt;
  for (Index i : hole_pores_) info_.hole_volume += net.pore_void[i];
  info_.dt_explicit = flow().stable_dt();
  info_.t_spring = spring_time(sys);
  const Stride stride = flow_stride(s_, dim_, info_.t_spring, sys.settings.dt);
  const long n = stride.n;
  predict_ = stride.predict;
  st_.flow_every = info_.flow_every = n;
  info_.dt_flow = static_cast<Real>(n) * sys.settings.dt;
  rho_vapour_liquid_ = fluid_params(s_).liquid.density(s_.vapour_pressure, true);
  id_index_ = index_of_ids(sys.particles);
  force_.assign(sys.particles.size(), Vec3::Zero());
  st_.mass0 = total_mass();
  gather_forces();
  measure(sys);
}

Real NetworkLoad::total_mass() { return flow().total_liquid_mass(); }

void NetworkLoad::gather_forces() {
  const auto t0 = std::chrono::steady_clock::now();
  if (c2_) {
    c2_->compute_fluid_forces(s_.vapour_pressure);
    for (std::size_t k = 0; k < force_.size(); ++k) force_[k] = Vec3(c2_->fluid_fx(static_cast<Index>(k)), c2_->fluid_fy(static_cast<Index>(k)), 0);
  } else {
    c3_->compute_fluid_forces(s_.vapour_pressure);
    for (std::size_t k = 0; k < force_.size(); ++k) force_[k] = c3_->fluid_force(static_cast<Index>(k));
  }
  st_.t_forces += seconds_since(t0);
}

void NetworkLoad::add_forces(dem::DemSystem& sys) {
  auto& F = sys.particles.ext_force;
  for (std::size_t k = 0; k < force_.size(); ++k) F[k] += force_[k];
  // Held steps (not the DEM step right after a flow step, whose positions the flow step saw).
  if (c3_ && c3_->predicting() && st_.steps % st_.flow_every != 0) {
    const auto t0 = std::chrono::steady_clock::now();
    c3_->add_predicted_forces(sys, s_.vapour_pressure);
    st_.t_forces += seconds_since(t0);
  }
}

void NetworkLoad::advance(const dem::DemSystem& sys) {
  ++st_.steps;
  if (st_.steps % st_.flow_every == 0) flow_step(sys);
}

// One flow step over the last N DEM steps: the network to the current positions (new cracks'
// openings, pore volumes), the hole's condition at t, backward Euler, the forces for the next N.
void NetworkLoad::flow_step(const dem::DemSystem& sys) {
  try {
    network_flow_step(sys);
  } catch (const NumericalError& e) {  // the pore network's own words name no keys: add them
    throw NumericalError(fmt::format(
        "{}. The network fluid's inputs to check: {} (the channels' conductance), network.viscosity and "
        "network.density, injection.fluid_bulk_modulus (the liquid's stiffness), network.pore_pressure, "
        "injection.ramp_rate / injection.rate",
        e.what(),
        c2_ ? "network.aperture_h0, network.aperture_hinf and network.b2_gamma"
            : "network.throat_factor and network.max_conductance_ratio"));
  }
}

void NetworkLoad::network_flow_step(const dem::DemSystem& sys) {
  const Real h = static_cast<Real>(st_.flow_every) * sys.settings.dt;
  now_ = st_.t_last = sys.time;
  auto t0 = std::chrono::steady_clock::now();
  const bool rebuilt = c2_ ? c2_->sync(sys) : c3_->sync(sys);
  if (rebuilt) {
    ++st_.retriangulations;
    if (c2_) {
      drain_faces(flow(), network());
      find_hole_pores(c2_->network());
      flow().prepare_implicit();
    }
  }
  set_hole_bc(flow(), network(), sys.time);
  const double sync_s = seconds_since(t0);
  st_.t_sync += sync_s;
  if (rebuilt) t_retriangulation_ += sync_s;
  t0 = std::chrono::steady_clock::now();
  if (c2_) flow().step_implicit(h);
  else c3_->advance_flow(h);
  st_.t_flow += seconds_since(t0);
  st_.max_cg = std::max(st_.max_cg, flow().last_cg_iterations());
  st_.max_sub = std::max(st_.max_sub, flow().last_substeps());
  cavitate();
  if (s_.rate_mode) st_.injected_mass += s_.density * s_.flow_rate * h;
  ++st_.flow_steps;
  gather_forces();
  if (c3_ && predict_) {
    t0 = std::chrono::steady_clock::now();
    c3_->start_prediction(sys.settings.dt);
    st_.t_forces += seconds_since(t0);
  }
  measure(sys);
}

// A liquid cannot be pulled below its vapour pressure: a pore whose pressure fell below it (a
// dilating pore, an opening crack ahead of the fluid) is held at p_vapour, its liquid mass
// unchanged and its density m / V (the rest of the void is vapour, of negligible mass): the next
// flow step sees p_vapour there and no volume error (sum m / rho - V = 0), so the liquid that
// flows in is driven by p - p_vapour, and the pore refills before its pressure rises again. The
// liquid's mass balance is untouched. Without it the barotropic liquid would take GPa of tension
// and suck the hole's fluid into the crack tips at that rate (and the implicit step's transport
// limit would split it thousands of times).
void NetworkLoad::cavitate() {
  const Real pc = s_.vapour_pressure;
  if (!(pc > 0)) return;
  auto& f = flow();
  const auto& net = network();
  const auto p = f.pressure();
  st_.vapour_volume = 0;
  Index first = -1;
  for (Index i = 0; i < net.n_pores() && first < 0; ++i)
    if (p[i] < pc) first = i;
  if (first < 0) return;
  const auto copy = [](std::span<const Real> a, std::vector<Real>& b) { b.assign(a.begin(), a.end()); };
  copy(f.pressure(), cp_);
  copy(f.liquid_fraction(), ca_);
  copy(f.liquid_mass(), cmq_);
  copy(f.gas_mass(), cmp_);
  copy(f.liquid_density(), crq_);
  copy(f.gas_density(), crp_);
  for (Index i = first; i < net.n_pores(); ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (!(cp_[k] < pc)) continue;
    const Real V = net.pore_void[i];
    cp_[k] = pc;
    if (V > 0 && ca_[k] > 0) crq_[k] = cmq_[k] / (ca_[k] * V);
    st_.vapour_volume += std::max<Real>(0, V - cmq_[k] / rho_vapour_liquid_);
    ++st_.cavitations;
  }
  f.restore_state(cp_, ca_, cmq_, cmp_, crq_, crp_);
}

// The cached state the driver reads (identical after a resume): the hole's gauge pressure and
// volume, the mass in the network, the wetted cracks (both grains' pores above half the hole's gauge).
void NetworkLoad::measure(const dem::DemSystem& sys) {
  const auto& net = network();
  const auto p = flow().pressure();
  Real v = 0, pv = 0;
  for (Index i : hole_pores_) {
    v += net.pore_void[i];
    pv += p[i] * net.pore_void[i];
  }
  st_.volume = v;
  st_.pressure = pv / v - s_.pore_pressure;
  st_.mass = total_mass();
  if (!s_.rate_mode) st_.injected_mass = st_.mass - st_.mass0 - remap_change();
  st_.wetted = 0;
  if (!(st_.pressure > 0)) return;
  const auto mean_gauge = [&](Index q) {
    Real s = 0;
    const Index b = net.pp_start[q], e = net.pp_start[q + 1];
    for (Index k = b; k < e; ++k) s += p[net.pp_pore[k]];
    return e > b ? s / static_cast<Real>(e - b) - s_.pore_pressure : 0.0;
  };
  if (id_index_.size() != static_cast<std::size_t>(sys.particles.next_id)) id_index_ = index_of_ids(sys.particles);
  for (const auto& ev : sys.cracks.events) {
    const Index a = id_index_[static_cast<std::size_t>(ev.i)], b = id_index_[static_cast<std::size_t>(ev.j)];
    if (a < 0 || b < 0) continue;
    if (mean_gauge(a) > 0.5 * st_.pressure && mean_gauge(b) > 0.5 * st_.pressure) ++st_.wetted;
  }
}

FluidState NetworkLoad::state() const {
  FluidState f;
  f.pressure = st_.pressure;
  f.injected_volume = st_.injected_mass / s_.density;
  f.borehole_volume = st_.volume;
  f.wetted_particles = static_cast<long>(wall_.size());
  f.wetted_cracks = st_.wetted;
  return f;
}

Real NetworkLoad::remap_change() const {
  return c2_ ? c2_->stats().remap_liquid_change : c3_ ? c3_->stats().remap_liquid_change : 0.0;
}

NetworkBudget NetworkLoad::budget() const {
  NetworkBudget b;
  b.injected_mass = st_.injected_mass;
  b.pore_mass0 = st_.mass0;
  b.pore_mass = st_.mass;
  b.remap_change = remap_change();
  b.residual = (st_.mass - st_.mass0) - st_.injected_mass - b.remap_change;
  b.flow_steps = st_.flow_steps;
  b.retriangulations = st_.retriangulations;
  b.max_cg_iterations = st_.max_cg;
  b.max_substeps = st_.max_sub;
  b.cavitations = st_.cavitations;
  b.vapour_volume = st_.vapour_volume;
  b.t_sync = st_.t_sync;
  b.t_flow = st_.t_flow;
  b.t_triangulation = t_retriangulation_;
  b.t_forces = st_.t_forces;
  return b;
}

void NetworkLoad::save(CheckpointWriter& w) const {
  w.put_value("network.state", st_);
  w.put_value("network.info", info_);
  w.put_value("network.hole", to_record(hole_));
  w.put("network.wall", wall_);
  w.put("network.force", force_);
  if (c2_) {
    c2_->save(w);
    const auto g = flow().implicit_guess();
    w.put("network.guess", std::vector<Real>(g.begin(), g.end()));
  } else {
    c3_->save(w);
  }
}

void NetworkLoad::load(CheckpointReader& r, const dem::DemSystem& sys) {
  st_ = r.get_value<State>("network.state");
  info_ = r.get_value<NetworkInfo>("network.info");
  hole_ = from_record(r.get_value<BoreholeRecord>("network.hole"));
  r.get("network.wall", wall_);
  r.get("network.force", force_);
  // The stride's rule again; a run checkpointed before the prediction existed kept its N (no prediction).
  const Stride stride = flow_stride(s_, dim_, info_.t_spring, info_.dt_dem);
  predict_ = stride.predict && stride.n == st_.flow_every;
  is_wall_.assign(sys.particles.size(), 0);
  for (Index k : wall_) is_wall_[static_cast<std::size_t>(k)] = 1;
  id_index_ = index_of_ids(sys.particles);
  rho_vapour_liquid_ = fluid_params(s_).liquid.density(s_.vapour_pressure, true);
  now_ = st_.t_last;
  make_coupling();
  if (c2_) {
    c2_->load(r, const_cast<dem::DemSystem&>(sys), params_2d(s_));  // load only reads the system
    find_hole_pores(c2_->network());
    // The hole's condition without touching the restored pore states.
    const auto vec = [](std::span<const Real> s) { return std::vector<Real>(s.begin(), s.end()); };
    auto& f = flow();
    const auto p = vec(f.pressure()), a = vec(f.liquid_fraction()), mq = vec(f.liquid_mass()), mp = vec(f.gas_mass()),
               rq = vec(f.liquid_density()), rp = vec(f.gas_density());
    drain_faces(f, network());
    set_hole_bc(f, network(), st_.t_last);
    f.restore_state(p, a, mq, mp, rq, rp);
    std::vector<Real> g;
    r.get("network.guess", g);
    f.restore_implicit_guess(g);
  } else {
    c3_->load(r, sys, params_3d(s_));
  }
}

std::array<Real, 6> NetworkLoad::face_pressures() const {
  std::array<Real, 6> p{};
  if (c3_ && s_.walls)
    for (int w = 0; w < 6; ++w) p[static_cast<std::size_t>(w)] = c3_->wall_fluid_pressure(w);
  return p;
}

void NetworkLoad::write_vtu(const std::filesystem::path& file, const dem::DemSystem& sys) const {
  const auto& net = network();
  const int nv = net.dim == 3 ? 4 : 3;
  const auto p = flow().pressure();
  std::vector<char> hole(static_cast<std::size_t>(net.n_pores()), 0);
  for (Index i : hole_pores_) hole[static_cast<std::size_t>(i)] = 1;
  const auto& X = sys.particles.pos;
  // A pore on a wall (network.walls) is drawn as a tetrahedron whose wall corners are its centroid's
  // projections onto those walls (extra points after the particles).
  std::vector<Vec3> extra;
  std::vector<Index> conn(static_cast<std::size_t>(nv) * static_cast<std::size_t>(net.n_pores()));
  for (Index i = 0; i < net.n_pores(); ++i)
    for (int k = 0; k < nv; ++k) {
      Index q = net.pore_v[nv * i + k];
      if (net.is_wall_vertex(q)) {
        const int w = static_cast<int>(q - net.n_particles);
        Vec3 x(net.pore_cx[i], net.pore_cy[i], net.pore_cz[i]);
        x[w / 2] = net.wall_plane[static_cast<std::size_t>(w)];
        q = static_cast<Index>(X.size() + extra.size());
        extra.push_back(x);
      }
      conn[static_cast<std::size_t>(nv * i + k)] = q;
    }
  std::string out;
  out.reserve(static_cast<std::size_t>(net.n_pores()) * 64 + (X.size() + extra.size()) * 48);
  auto o = std::back_inserter(out);
  fmt::format_to(o,
                 "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
                 "<UnstructuredGrid>\n<Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n<Points>\n"
                 "<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n",
                 X.size() + extra.size(), net.n_pores());
  for (const Vec3& x : X) fmt::format_to(o, "{} {} {}\n", x.x(), x.y(), x.z());
  for (const Vec3& x : extra) fmt::format_to(o, "{} {} {}\n", x.x(), x.y(), x.z());
  fmt::format_to(o, "</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
  for (Index i = 0; i < net.n_pores(); ++i) {
    for (int k = 0; k < nv; ++k) fmt::format_to(o, "{} ", conn[static_cast<std::size_t>(nv * i + k)]);
    out.push_back('\n');
  }
  fmt::format_to(o, "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
  for (Index i = 0; i < net.n_pores(); ++i) fmt::format_to(o, "{}\n", nv * (i + 1));
  fmt::format_to(o, "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
  for (Index i = 0; i < net.n_pores(); ++i) fmt::format_to(o, "{}\n", nv == 3 ? 5 : 10);  // VTK_TRIANGLE, VTK_TETRA
  fmt::format_to(o, "</DataArray>\n</Cells>\n<CellData Scalars=\"pressure\">\n"
                    "<DataArray type=\"Float64\" Name=\"pressure\" format=\"ascii\">\n");
  for (Index i = 0; i < net.n_pores(); ++i) fmt::format_to(o, "{}\n", p[i] - s_.pore_pressure);
  fmt::format_to(o, "</DataArray>\n<DataArray type=\"Float64\" Name=\"void_volume\" format=\"ascii\">\n");
  for (Index i = 0; i < net.n_pores(); ++i) fmt::format_to(o, "{}\n", net.pore_void[i]);
  fmt::format_to(o, "</DataArray>\n<DataArray type=\"UInt8\" Name=\"borehole\" format=\"ascii\">\n");
  for (Index i = 0; i < net.n_pores(); ++i) fmt::format_to(o, "{}\n", int(hole[static_cast<std::size_t>(i)]));
  fmt::format_to(o, "</DataArray>\n</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
  std::ofstream f(file, std::ios::binary);
  if (!f) throw Error(fmt::format("cannot write {}", file.string()));
  f << out;
}

}  // namespace ff::coupling::hydrofrac
