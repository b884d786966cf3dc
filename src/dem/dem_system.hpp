// The bonded-particle system and its explicit time step (METHODS.md 1.1-1.6):
// neighbour search -> contact forces -> bond forces (+ crack events) -> wall forces ->
// per-particle gather in a fixed order -> local damping -> velocity Verlet -> walls move.
// Every per-pair result is written to its own slot and gathered per particle in increasing
// pair order, so results are bit-identical on any number of OpenMP threads.
#pragma once
#include <limits>
#include <optional>
#include <vector>

#include "dem/crack_log.hpp"
#include "dem/materials.hpp"
#include "dem/membrane/flexible_membrane.hpp"
#include "dem/neighbor_list.hpp"
#include "dem/particle_store.hpp"
#include "dem/walls.hpp"

namespace ff::dem {

struct DemSettings {
  int dim = 3;                  // 3: spheres; 2: disks of unit thickness in the x-y plane
  Real dt = 0;                  // time step [s]
  Real local_damping = 0.7;     // Cundall's local damping coefficient (PFC default 0.7)
  Vec3 gravity = Vec3::Zero();  // [m/s^2]
  Real skin = 0;                // Verlet skin [m]
  std::size_t parallel_min = 2048;  // loops over fewer items run on one thread (fork/join costs more)
};

// Per-pair result slot: force on the second particle and total moments on both.
struct PairLoad {
  Vec3 f = Vec3::Zero(), mA = Vec3::Zero(), mB = Vec3::Zero();
};

struct WallContacts {           // candidate particles of one wall, sorted by index
  std::vector<Index> particle;
  std::vector<ContactState> state;
  std::vector<PairLoad> load;   // f = force on the wall; mA = moment on the particle
};

// Wall-clock seconds spent in each stage of step() (the timing report of benchmarks).
struct StageTimes {
  double neighbors = 0, contacts = 0, bonds = 0, walls = 0, integrate = 0;
  double membrane = 0;  // flexible membrane: own candidate searches, contact forces, servo and vertex update
};

class DemSystem {
 public:
  StageTimes stage_times;
  DemSettings settings;
  ParticleStore particles;
  Materials materials;
  std::vector<Wall> walls;
  CrackLog cracks;
  // Optional flexible membrane (triaxial tests). Its loaded band runs between the planes of
  // walls[membrane_bottom_wall] and walls[membrane_top_wall] (the platens); it steps with the
  // system: candidates at each neighbour rebuild, forces after the walls, loads in the gather,
  // servo and vertex update after the particles move.
  std::optional<FlexibleMembrane> membrane;
  int membrane_bottom_wall = 0, membrane_top_wall = 1;

  // Bonds: flat (i, j) list with i < j, pair type, state of the active law.
  std::vector<Index> bond_i, bond_j;
  std::vector<std::int32_t> bond_pair;
  std::vector<std::uint8_t> bond_broken;  // 0 intact, 1 tensile, 2 shear
  std::vector<ParallelBond::State> pbond;
  std::vector<RotationalBond::State> rbond;

  Real time = 0;
  long step_count = 0;

  // Installs bonds between every pair whose gap is <= max_gap (stress-free).
  std::size_t install_bonds(Real max_gap);
  // Installs one stress-free bond of the active law between particles a and b (e.g. the ring and
  // row neighbours of a particle membrane); call initialise() afterwards.
  void add_bond(Index a, Index b);
  // Prepares neighbour lists and per-pair storage; call after particles/bonds/walls change.
  void initialise();
  // One explicit step.
  void step();
  void run(long steps) { for (long s = 0; s < steps; ++s) step(); }

  // Critical time step sqrt(m/k_tran), sqrt(I/k_rot) over all particles (METHODS.md 1.6),
  // from the current contacts, bonds and wall contacts. `assumed_overlap` is the overlap ratio
  // used for the Hertz tangent stiffness.
  Real critical_time_step() const;
  // Density scaling: inertial masses so that `dt` is `safety` times the critical step.
  void scale_masses_for(Real dt, Real safety);

  std::size_t intact_bonds() const;
  long contacts_touching() const;
  Real kinetic_energy() const;       // translational + rotational [J] (half-step velocities)
  Real strain_energy() const;        // springs of contacts and intact bonds [J]
  // Mean |F_unbalanced| over the first `particles` particles (all by default) / mean |F_contact|
  // over the loaded interactions.
  Real max_unbalanced_force_ratio(std::size_t particles = std::numeric_limits<std::size_t>::max()) const;
  // Love-Weber average stress of the particles whose centres lie in `inside` (tension +),
  // divided by `volume` [Pa] (METHODS.md 1.7).
  template <class Pred> Mat3 average_stress(Pred inside, Real volume) const;
  // The same over the particles i with selected(i) (e.g. the sample without its membrane).
  template <class Pred> Mat3 average_stress_of(Pred selected, Real volume) const;
  // Normal stiffness of a contact of pair type `pair_type` (rB = 0: a wall) [N/m]; Hertz at
  // `overlap`, at least 1% of the smaller radius (time-step estimates).
  Real pair_stiffness(int pair_type, Real rA, Real rB, Real overlap) const;

  const NeighborList& neighbors() const { return nl_; }
  NeighborList& neighbors() { return nl_; }
  std::vector<ContactState>& contact_state() { return cstate_; }
  const std::vector<PairLoad>& pair_loads() const { return pload_; }
  std::vector<WallContacts>& wall_contacts() { return wall_contacts_; }
  const std::vector<WallContacts>& wall_contacts() const { return wall_contacts_; }
  const std::vector<PairLoad>& bond_loads() const { return bload_; }
  void rebuild_neighbors();  // forced rebuild (also used after a checkpoint restore)
  // Rebuilds only the flexible membrane's candidates (also after a checkpoint restore).
  void rebuild_membrane_candidates();
  // How many times the particle neighbour list and the membrane candidates were rebuilt.
  long neighbor_builds() const { return static_cast<long>(nl_.builds()); }
  long membrane_builds() const { return membrane_builds_; }
  void build_bond_adjacency();
  void compact_bonds();      // drop broken bonds (keeps order of the intact ones)
  // Checkpoint support: per-pair load slots sized after a restored neighbour list, and the
  // wall travel since the last neighbour build (it decides when the next rebuild happens).
  void restore_loads_after_load() { pload_.assign(nl_.size(), PairLoad{}); }
  Real& wall_motion_since_build() { return wall_motion_since_build_; }
  Real wall_motion_since_build() const { return wall_motion_since_build_; }

 private:
  template <class Law> void contact_forces(const std::vector<typename Law::Params>& params);
  template <class Law, class Mat> void bond_forces(const std::vector<Mat>& mats, std::vector<typename Law::State>& st);
  template <class Law> void wall_forces(const std::vector<typename Law::Params>& params);
  template <class Law> void membrane_forces(const std::vector<typename Law::Params>& params);
  void record_bond_failures();
  void gather_and_integrate();
  // Searches the membrane's candidates; `travel`: the particles' largest travel since the
  // neighbour build at this moment.
  void search_membrane_candidates(Real travel);

  NeighborList nl_;
  long membrane_builds_ = 0;
  // Largest particle travel since the neighbour build at the membrane's last candidate build:
  // with the travel since the neighbour build it bounds the travel since the membrane's build.
  Real membrane_built_at_travel_ = 0;
  std::vector<ContactState> cstate_;
  std::vector<PairLoad> pload_, bload_;
  std::vector<std::uint8_t> bond_fail_flag_;
  std::vector<ParallelBond::Coeffs> pbond_coeffs_;  // per group pair, refreshed each step
  std::vector<std::int64_t> bond_adj_offset_, bond_adj_;
  std::vector<WallContacts> wall_contacts_;
  std::vector<Index> old_i_, old_j_;
  std::vector<ContactState> old_state_;
  std::vector<std::int64_t> bond_fill_;
  std::vector<Index> old_wall_particle_;
  std::vector<ContactState> old_wall_state_;
  Real wall_motion_since_build_ = 0;
};

template <class Pred>
Mat3 DemSystem::average_stress(Pred inside, Real volume) const {
  return average_stress_of([&](Index i) { return inside(particles.pos[i]); }, volume);
}

template <class Pred>
Mat3 DemSystem::average_stress_of(Pred inside, Real volume) const {
  // sigma_ij = 1/V sum_p sum_c (x^c_i - x^p_i) F^{c,p}_j with F^{c,p} the force on p at c.
  Mat3 s = Mat3::Zero();
  const auto& x = particles.pos;
  auto add_pair = [&](Index a, Index b, const Vec3& xc, const Vec3& f_on_b) {
    if (inside(b)) s += (xc - x[b]) * f_on_b.transpose();
    if (inside(a)) s -= (xc - x[a]) * f_on_b.transpose();
  };
  const auto pi = nl_.first(), pj = nl_.second();
  for (std::size_t p = 0; p < pi.size(); ++p) {
    const Vec3& f = pload_[p].f;
    if (f.squaredNorm() == 0) continue;
    const Real ra = particles.radius[pi[p]];
    const Vec3 n = (x[pj[p]] - x[pi[p]]).normalized();
    add_pair(pi[p], pj[p], x[pi[p]] + ra * n, f);
  }
  for (std::size_t b = 0; b < bond_i.size(); ++b) {
    if (bond_broken[b]) continue;
    const Index a = bond_i[b], c = bond_j[b];
    const Vec3 n = (x[c] - x[a]).normalized();
    add_pair(a, c, x[a] + particles.radius[a] * n, bload_[b].f);
  }
  for (std::size_t w = 0; w < walls.size(); ++w) {
    const auto& wc = wall_contacts_[w];
    for (std::size_t k = 0; k < wc.particle.size(); ++k) {
      const Index p = wc.particle[k];
      const Vec3& f_wall = wc.load[k].f;
      if (f_wall.squaredNorm() == 0 || !inside(p)) continue;
      ContactGeom g;
      if (!walls[w].geometry(g, x[p], particles.radius[p])) continue;
      s += (g.xc - x[p]) * (-f_wall).transpose();
    }
  }
  if (membrane) {  // the element pushes the particle with -f at the contact point
    const auto cp = membrane->candidate_particles();
    const auto cl = membrane->candidate_loads();
    for (std::size_t c = 0; c < cp.size(); ++c)
      if (cl[c].f.squaredNorm() > 0 && inside(cp[c])) s += (cl[c].xc - x[cp[c]]) * (-cl[c].f).transpose();
  }
  return s / volume;
}

}  // namespace ff::dem
