#include "drivers/hydrofrac/sleeve_load.hpp"

#include <algorithm>
#include <cmath>

namespace ff::drivers::hydrofrac {

void SleeveLoad::begin(const dem::DemSystem& sys, const BoreholeGeometry& hole, const std::vector<JointPair>& joints) {
  const HoleSurface hs = hole_surface(sys, hole, s_.cell, s_.inflate, s_.reach);
  wall_ = hs.particle;
  area_ = hs.area;
  x0_.resize(wall_.size());
  for (std::size_t k = 0; k < wall_.size(); ++k) x0_[k] = sys.particles.pos[wall_[k]];
  joints_ = joints;
  st_ = State{};
  st_.t0 = sys.time;
  st_.volume0 = st_.volume = hs.volume;
  st_.effective_radius = hs.effective_radius;
  st_.pressure = s_.initial_pressure;
  id_index_ = index_of_ids(sys.particles);
  wetted_.clear();
  wetted_.reserve(sys.bonds.size() + joints_.size());
  visited_.reserve(sys.particles.size() + sys.bonds.size() + joints_.size() + sys.cracks.events.size());
  ev_.reserve(sys.bonds.size() + sys.cracks.events.size());
  jt_.reserve(joints_.size());
  if (s_.penetration) find_wetted(sys);
}

// Cracks connected to the wall that are not yet wetted join the list with their present gap as
// the reference of their opening (their volume counts from there).
void SleeveLoad::find_wetted(const dem::DemSystem& sys) {
  connected_cracks(sys, id_index_, wall_, joints_, ev_, jt_, visited_);
  const auto& P = sys.particles;
  const std::size_t known = wetted_.size();
  auto add = [&](std::int64_t ia, std::int64_t ib, Real area) {
    const Index a = id_index_[static_cast<std::size_t>(ia)], b = id_index_[static_cast<std::size_t>(ib)];
    for (std::size_t k = 0; k < known; ++k)
      if (wetted_[k].a == a && wetted_[k].b == b) return;
    const Real gap = (P.pos[b] - P.pos[a]).norm() - P.radius[a] - P.radius[b];
    wetted_.push_back(Wetted{a, b, area, gap});
  };
  const int dim = sys.settings.dim;
  for (std::size_t k : ev_) {
    const auto& e = sys.cracks.events[k];
    add(e.i, e.j, dim == 3 ? kPi * e.size * e.size : 2 * e.size);
  }
  for (std::size_t k : jt_) add(joints_[k].a, joints_[k].b, joints_[k].area);
}

void SleeveLoad::add_forces(dem::DemSystem& sys) {
  auto& F = sys.particles.ext_force;
  const Real p = st_.pressure;
  // The fluid pushes each wetted surface element n dA with -p n dA (n out of the particle).
  for (std::size_t k = 0; k < wall_.size(); ++k) F[wall_[k]] -= p * area_[k];
  const auto& X = sys.particles.pos;
  for (const Wetted& w : wetted_) {
    const Vec3 d = X[w.b] - X[w.a];
    const Real len = d.norm();
    if (!(len > 0)) continue;
    const Vec3 f = (p * w.area / len) * d;  // pushes the faces apart
    F[w.a] -= f;
    F[w.b] += f;
  }
}

Real SleeveLoad::volume(const dem::DemSystem& sys) const {
  const auto& X = sys.particles.pos;
  // A wall element moving along -n (away from the hole) enlarges it by dA |du|.
  Real v = st_.volume0;
  for (std::size_t k = 0; k < wall_.size(); ++k) v -= area_[k].dot(X[wall_[k]] - x0_[k]);
  const auto& R = sys.particles.radius;
  for (const Wetted& w : wetted_) {
    const Real gap = (X[w.b] - X[w.a]).norm() - R[w.a] - R[w.b];
    v += w.area * std::max<Real>(0, gap - w.gap0);
  }
  return v;
}

void SleeveLoad::advance(const dem::DemSystem& sys) {
  ++st_.steps;
  if (s_.penetration && st_.steps % s_.update_interval == 0) find_wetted(sys);
  const Real v = volume(sys);
  const Real dt = sys.settings.dt;
  if (s_.rate_mode) {
    // dp = K_f / V (Q dt - dV): the pumped volume less what the hole's growth takes.
    st_.pressure += s_.bulk_modulus / v * (s_.flow_rate * dt - (v - st_.volume));
    st_.pressure = std::max<Real>(0, st_.pressure);
    st_.injected += s_.flow_rate * dt;
  } else {
    st_.pressure = s_.initial_pressure + s_.ramp_rate * (sys.time - st_.t0);
    // Fluid mass in the hole over the reference density: V (1 + p/K_f); what was there at the start
    // is subtracted.
    st_.injected = v * (1 + st_.pressure / s_.bulk_modulus) - st_.volume0 * (1 + s_.initial_pressure / s_.bulk_modulus);
  }
  st_.volume = v;
}

FluidState SleeveLoad::state() const {
  FluidState f;
  f.pressure = st_.pressure;
  f.injected_volume = st_.injected;
  f.borehole_volume = st_.volume;
  f.wetted_particles = static_cast<long>(wall_.size());
  f.wetted_cracks = static_cast<long>(wetted_.size());
  return f;
}

void SleeveLoad::save(CheckpointWriter& w) const {
  w.put_value("sleeve.state", st_);
  w.put("sleeve.wall", wall_);
  w.put("sleeve.area", area_);
  w.put("sleeve.x0", x0_);
  w.put("sleeve.joints", joints_);
  w.put("sleeve.wetted", wetted_);
}

void SleeveLoad::load(CheckpointReader& r, const dem::DemSystem& sys) {
  st_ = r.get_value<State>("sleeve.state");
  r.get("sleeve.wall", wall_);
  r.get("sleeve.area", area_);
  r.get("sleeve.x0", x0_);
  r.get("sleeve.joints", joints_);
  r.get("sleeve.wetted", wetted_);
  wetted_.reserve(sys.bonds.size() + joints_.size() + wetted_.size());
  visited_.reserve(sys.particles.size() + sys.bonds.size() + joints_.size() + sys.cracks.events.size());
  ev_.reserve(sys.bonds.size() + sys.cracks.events.size());
  jt_.reserve(joints_.size());
  id_index_ = index_of_ids(sys.particles);
}

}  // namespace ff::drivers::hydrofrac
