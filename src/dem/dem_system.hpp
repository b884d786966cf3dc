// The bonded-particle system and its explicit time step (METHODS.md 1.1-1.6), in public stages:
//   update_neighbors()    walls' step motion, neighbour rebuild when the skin is used up,
//                         boundaries' own candidate searches;
//   compute_forces()      contact, bond (+ crack events), wall and boundary forces, one slot per pair;
//   add_external_loads()  boundaries add their loads from outside the interactions (the particle
//                         membrane's inward loads) to particles.ext_force / ext_moment; a coupled
//                         solver adds its own there too, after this stage or before it;
//   integrate()           gathers the slots onto each particle after its external load, in a fixed
//                         order, and zeroes the external accumulators; local damping; velocity
//                         Verlet; boundaries and walls move.
// step() is their composition; a coupled solver may call them itself (and sub-cycle them).
// Every per-pair result is written to its own slot and gathered per particle in increasing pair
// order, so results are bit-identical on any number of OpenMP threads.
// Bond topology lives in BondSet (bond_set.hpp), diagnostics in diagnostics.hpp, boundaries that
// step with the system (the triaxial flexible membrane) behind the Boundary interface.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "dem/bond_set.hpp"
#include "dem/boundary.hpp"
#include "dem/crack_log.hpp"
#include "dem/energy.hpp"
#include "dem/materials.hpp"
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
  bool track_energy = false;    // energy bookkeeping (energy.hpp; the DEM drivers' run loop sets it)
};

struct WallContacts {           // candidate particles of one wall, sorted by index
  std::vector<Index> particle;
  std::vector<ContactState> state;
  std::vector<PairLoad> load;   // f = force on the wall; mA = moment on the particle
};

// Wall-clock seconds spent in each stage of step() (the timing report of benchmarks).
struct StageTimes {
  double neighbors = 0, contacts = 0, bonds = 0, walls = 0, integrate = 0;
  double boundaries = 0;  // boundaries (flexible membrane): own candidate searches, forces, own motion
};

class DemSystem {
 public:
  StageTimes stage_times;
  DemSettings settings;
  ParticleStore particles;
  Materials materials;
  std::vector<Wall> walls;
  BondSet bonds;
  CrackLog cracks;

  Real time = 0;
  long step_count = 0;
  EnergyBook energy;  // cumulative, while settings.track_energy (energy.hpp)
  // Set-up advice for contacts that did not touch when the step was chosen but are unstable at it
  // (dem_params.cpp, check_contacts_to_come): a blow-up names these rather than the safety factor.
  std::vector<std::string> untouched_unstable_contacts;

  // Installs bonds between every pair whose gap is <= max_gap (stress-free).
  std::size_t install_bonds(Real max_gap);
  // Installs one stress-free bond of the active law between particles a and b (e.g. the ring and
  // row neighbours of a particle membrane); call initialise() afterwards.
  void add_bond(Index a, Index b);
  // Adds a boundary that steps with the system (owned by the system from now on).
  Boundary& add_boundary(std::unique_ptr<Boundary> b);
  const BoundaryList& boundaries() const { return boundaries_; }
  // Prepares neighbour lists and per-pair storage; call after particles/bonds/walls change.
  void initialise();

  // The stages of one explicit step, in this order (see the top of this file).
  void update_neighbors();
  void compute_forces();
  void add_external_loads();
  void integrate();
  void step() {
    update_neighbors();
    compute_forces();
    add_external_loads();
    integrate();
  }
  void run(long steps) { for (long s = 0; s < steps; ++s) step(); }

  const NeighborList& neighbors() const { return nl_; }
  NeighborList& neighbors() { return nl_; }
  std::vector<ContactState>& contact_state() { return cstate_; }
  const std::vector<ContactState>& contact_state() const { return cstate_; }
  const std::vector<PairLoad>& pair_loads() const { return pload_; }
  std::vector<WallContacts>& wall_contacts() { return wall_contacts_; }
  const std::vector<WallContacts>& wall_contacts() const { return wall_contacts_; }
  const std::vector<PairLoad>& bond_loads() const { return bonds.loads(); }
  void rebuild_neighbors();  // forced rebuild (also used after a checkpoint restore)
  // How many times the particle neighbour list was rebuilt.
  long neighbor_builds() const { return static_cast<long>(nl_.builds()); }
  void build_bond_adjacency() { bonds.build_adjacency(particles.size()); }
  void compact_bonds() { bonds.compact(particles.size()); }  // drop broken bonds
  // Checkpoint support: per-pair load slots sized after a restored neighbour list, and the
  // wall travel since the last neighbour build (it decides when the next rebuild happens).
  void restore_loads_after_load() { pload_.assign(nl_.size(), PairLoad{}); }
  Real& wall_motion_since_build() { return wall_motion_since_build_; }
  Real wall_motion_since_build() const { return wall_motion_since_build_; }

 private:
  template <class Law, bool kEnergy> void contact_forces(const std::vector<typename Law::Params>& params);
  template <bool kEnergy> void integrate_particles();
  template <class Law> void bond_forces(const std::vector<typename Law::Prepared>& mats, std::vector<typename Law::State>& st);
  template <class Law> void wall_forces(const std::vector<typename Law::Params>& params);
  void record_bond_failures();
  std::string not_finite_message() const;  // which particle went first, and the advice that fits
  friend void reorder_particles(DemSystem& sys, const std::vector<Index>& order);

  NeighborList nl_;
  BoundaryList boundaries_;
  std::vector<ContactState> cstate_;
  std::vector<PairLoad> pload_;
  BondPrepared bond_prepared_;  // per bond law, its materials as the loop reads them, refreshed each step
  std::vector<WallContacts> wall_contacts_;
  std::vector<Index> old_i_, old_j_;
  std::vector<ContactState> old_state_;
  std::vector<Index> old_wall_particle_;
  std::vector<ContactState> old_wall_state_;
  Real wall_motion_since_build_ = 0;
  Real wall_step_ = 0;  // largest wall motion of this step (update_neighbors -> integrate)
  // Energy bookkeeping scratch (track_energy): per pair (slip, shear work, dashpot), per particle
  // external load and (external work, damping dissipation, -), block sums.
  std::vector<Vec3> pair_work_, ext_f_, ext_m_, particle_work_, block_sums_;
};

}  // namespace ff::dem
