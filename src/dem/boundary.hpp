// A boundary the engine steps without knowing what it is (e.g. the flexible membrane that the
// triaxial driver wraps around its sample): its own neighbour search, its forces, its loads on
// the particles and its own motion after the particles move. Hooks are called once per stage
// (virtual calls per stage, never per contact), in the order of DemSystem::step().
#pragma once
#include <memory>
#include <span>
#include <vector>

#include "core/types.hpp"

namespace ff {
class CheckpointWriter;
class CheckpointReader;
}  // namespace ff

namespace ff::dem {

class DemSystem;
struct ParticleStore;

// Load of one boundary contact: f = force ON THE BOUNDARY (the particle receives -f), m = moment
// on the particle, xc = contact point (Love-Weber stress: branch xc - x_particle).
struct BoundaryLoad {
  Vec3 f = Vec3::Zero();
  Vec3 m = Vec3::Zero();
  Vec3 xc = Vec3::Zero();
};

class Boundary {
 public:
  virtual ~Boundary() = default;
  virtual std::unique_ptr<Boundary> clone() const = 0;  // a copy of the system copies its boundaries
  // update_neighbors(): after a full neighbour rebuild (`rebuilt`, then `travel` = 0) or, when
  // there was none, with the particles' largest travel since the last rebuild.
  virtual void update_neighbors(const DemSystem& sys, bool rebuilt, Real travel) = 0;
  // compute_forces(): the contact forces, one slot per candidate contact.
  virtual void compute_forces(const DemSystem& sys) = 0;
  // add_external_loads(): loads from outside the interactions, ADDED to p.ext_force/ext_moment
  // (the particle membrane's confining loads); most boundaries have none.
  virtual void add_external_loads(ParticleStore& /*p*/) const {}
  // integrate(): the loads on the particles, added serially after the walls' (fixed order).
  virtual void add_loads(std::span<Vec3> force, std::span<Vec3> moment) const = 0;
  // integrate(): after the particles moved (servo, own motion).
  virtual void after_integrate(const DemSystem& sys) = 0;
  // Diagnostics: candidate contacts (particle, load, normal stiffness [N/m]).
  virtual std::span<const Index> contact_particles() const = 0;
  virtual std::span<const BoundaryLoad> contact_loads() const = 0;
  virtual std::span<const Real> contact_stiffness() const = 0;
  // reorder_particles(): the particle arrays were permuted; old index i is now new_of_old[i].
  // A boundary that holds particle indices maps them (keeping its contact history).
  virtual void reorder(std::span<const Index> new_of_old) = 0;
  // Checkpoint: the boundary's state (the boundary itself is rebuilt by its owner's set-up).
  virtual void save(CheckpointWriter& w, const DemSystem& sys) const = 0;
  virtual void load(CheckpointReader& r, const DemSystem& sys) = 0;
};

// The boundaries of a system: owned, copied with it (clone), stepped in the order they were added.
class BoundaryList {
 public:
  BoundaryList() = default;
  BoundaryList(const BoundaryList& o) {
    for (const auto& b : o.list_) list_.push_back(b->clone());
  }
  BoundaryList& operator=(const BoundaryList& o) {
    if (this != &o) {
      BoundaryList copy(o);
      list_.swap(copy.list_);
    }
    return *this;
  }
  BoundaryList(BoundaryList&&) noexcept = default;
  BoundaryList& operator=(BoundaryList&&) noexcept = default;

  Boundary& add(std::unique_ptr<Boundary> b) {
    list_.push_back(std::move(b));
    return *list_.back();
  }
  bool empty() const { return list_.empty(); }
  std::size_t size() const { return list_.size(); }
  auto begin() const { return list_.begin(); }
  auto end() const { return list_.end(); }

 private:
  std::vector<std::unique_ptr<Boundary>> list_;
};

}  // namespace ff::dem
