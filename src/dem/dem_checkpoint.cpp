#include "dem/dem_checkpoint.hpp"

#include <fmt/format.h>

#include "core/error.hpp"

namespace ff {
// Bond and history states are plain aggregates of doubles and Eigen fixed-size members.
template <> struct is_checkpoint_pod<dem::ContactState> : std::true_type {};
template <> struct is_checkpoint_pod<dem::CrackEvent> : std::true_type {};
template <> struct is_checkpoint_pod<dem::PairLoad> : std::true_type {};
}  // namespace ff

namespace ff::dem {

namespace {
// Walls without their name (stored separately) so they can be written as raw bytes.
struct WallRecord {
  std::uint8_t kind, active;
  Vec3 point, normal, velocity, force, displacement;
  Real radius, radial_velocity, friction, contact_stiffness;
  int contacts;
};
}  // namespace
}  // namespace ff::dem

namespace ff {
template <> struct is_checkpoint_pod<dem::WallRecord> : std::true_type {};
}

namespace ff::dem {

void save_dem(CheckpointWriter& w, const DemSystem& s) {
  // Particle fields: every field of the declaration that is saved (particle_store.hpp).
  const auto& P = s.particles;
  ParticleStore::for_each_field([&](const auto& fd) {
    if (fd.checkpoint == CheckpointPolicy::Saved) w.put(std::string("dem.") + fd.name, P.*fd.member);
  });
  w.put_value("dem.next_id", P.next_id);
  w.put("dem.bond_i", s.bonds.i);
  w.put("dem.bond_j", s.bonds.j);
  w.put("dem.bond_pair", s.bonds.pair);
  w.put("dem.bond_broken", s.bonds.broken);
  // Each bond law's states under its own key (the law owns its state: laws.hpp).
  for_each_law(BondLaws{}, [&]<class Law>(std::type_identity<Law>) {
    if constexpr (!Law::checkpoint_key.empty()) w.put(std::string(Law::checkpoint_key), s.bonds.state<Law>());
  });
  w.put_value("dem.time", s.time);
  w.put_value("dem.step", s.step_count);
  w.put_value("dem.dt", s.settings.dt);
  w.put_value("dem.skin", s.settings.skin);
  const auto& nl = s.neighbors();
  w.put("dem.nl_i", std::vector<Index>(nl.first().begin(), nl.first().end()));
  w.put("dem.nl_j", std::vector<Index>(nl.second().begin(), nl.second().end()));
  w.put("dem.nl_ref", const_cast<DemSystem&>(s).neighbors().reference_positions());
  w.put_value("dem.nl_builds", nl.builds());
  w.put("dem.contact_state", const_cast<DemSystem&>(s).contact_state());
  std::vector<WallRecord> walls;
  std::string names;
  for (auto& x : s.walls) {
    walls.push_back(WallRecord{static_cast<std::uint8_t>(x.kind), static_cast<std::uint8_t>(x.active), x.point, x.normal,
                               x.velocity, x.force, x.displacement, x.radius, x.radial_velocity, x.friction,
                               x.contact_stiffness, x.contacts});
    names += x.name + "\n";
  }
  w.put("dem.walls", walls);
  w.put_string("dem.wall_names", names);
  auto& wc = const_cast<DemSystem&>(s).wall_contacts();
  for (std::size_t k = 0; k < wc.size(); ++k) {
    w.put(fmt::format("dem.wall{}.particle", k), wc[k].particle);
    w.put(fmt::format("dem.wall{}.state", k), wc[k].state);
    w.put(fmt::format("dem.wall{}.load", k), wc[k].load);  // servos read the last step's loads
  }
  w.put("dem.cracks", s.cracks.events);
  w.put_value("dem.wall_motion", s.wall_motion_since_build());
  w.put_value("dem.energy", s.energy);
  for (const auto& b : s.boundaries()) b->save(w, s);
}

void load_dem(CheckpointReader& r, DemSystem& s) {
  // Particle fields: the saved ones are read, the recomputed ones start at their fill value.
  auto& P = s.particles;
  r.get("dem.pos", P.pos);
  const std::size_t n = P.pos.size();
  ParticleStore::for_each_field([&](const auto& fd) {
    auto& v = P.*fd.member;
    if (fd.checkpoint == CheckpointPolicy::Recomputed) {
      v.assign(n, fd.fill);
      return;
    }
    r.get(std::string("dem.") + fd.name, v);
    if (v.size() != n)
      throw InputError(fmt::format("checkpoint: dem.{} holds {} particles but dem.pos {}; the file is damaged", fd.name,
                                   v.size(), n));
  });
  P.next_id = r.get_value<std::int64_t>("dem.next_id");
  r.get("dem.bond_i", s.bonds.i);
  r.get("dem.bond_j", s.bonds.j);
  r.get("dem.bond_pair", s.bonds.pair);
  r.get("dem.bond_broken", s.bonds.broken);
  for_each_law(BondLaws{}, [&]<class Law>(std::type_identity<Law>) {
    if constexpr (!Law::checkpoint_key.empty()) {
      const std::string key(Law::checkpoint_key);
      if (r.has(key)) r.get(key, s.bonds.state<Law>());
      else s.bonds.state<Law>().clear();
    }
  });
  s.time = r.get_value<Real>("dem.time");
  s.step_count = r.get_value<long>("dem.step");
  s.settings.dt = r.get_value<Real>("dem.dt");
  s.settings.skin = r.get_value<Real>("dem.skin");
  std::vector<WallRecord> walls;
  r.get("dem.walls", walls);
  const std::string names = r.get_string("dem.wall_names");
  s.walls.clear();
  std::size_t pos = 0;
  for (auto& x : walls) {
    Wall w;
    const auto nl = names.find('\n', pos);
    w.name = names.substr(pos, nl - pos);
    pos = nl + 1;
    w.kind = static_cast<Wall::Kind>(x.kind);
    w.active = x.active;
    w.point = x.point;
    w.normal = x.normal;
    w.velocity = x.velocity;
    w.force = x.force;
    w.displacement = x.displacement;
    w.radius = x.radius;
    w.radial_velocity = x.radial_velocity;
    w.friction = x.friction;
    w.contact_stiffness = x.contact_stiffness;
    w.contacts = x.contacts;
    s.walls.push_back(w);
  }
  r.get("dem.cracks", s.cracks.events);
  s.cracks.tensile = s.cracks.shear = 0;
  for (auto& e : s.cracks.events) (e.mode == 1 ? s.cracks.tensile : s.cracks.shear)++;
  // Rebuild derived storage, then put back the exact neighbour list and histories.
  s.build_bond_adjacency();
  auto& nl = s.neighbors();
  r.get("dem.nl_i", nl.pair_i());
  r.get("dem.nl_j", nl.pair_j());
  r.get("dem.nl_ref", nl.reference_positions());
  nl.restore(s.settings.skin, r.get_value<long>("dem.nl_builds"));
  r.get("dem.contact_state", s.contact_state());
  s.restore_loads_after_load();
  auto& wc = s.wall_contacts();
  wc.assign(s.walls.size(), WallContacts{});
  for (std::size_t k = 0; k < wc.size(); ++k) {
    r.get(fmt::format("dem.wall{}.particle", k), wc[k].particle);
    r.get(fmt::format("dem.wall{}.state", k), wc[k].state);
    r.get(fmt::format("dem.wall{}.load", k), wc[k].load);
  }
  s.wall_motion_since_build() = r.get_value<Real>("dem.wall_motion");
  // Energy book (checkpoints before issue 13 have none: the bookkeeping restarts from zero).
  s.energy = r.has("dem.energy") ? r.get_value<EnergyBook>("dem.energy") : EnergyBook{};
  // Boundaries (the flexible membrane) are attached by the driver from its settings before
  // load_dem(); their state comes back here.
  for (const auto& b : s.boundaries()) b->load(r, s);
}

}  // namespace ff::dem
