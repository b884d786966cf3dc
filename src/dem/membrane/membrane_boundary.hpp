// The flexible membrane as a Boundary the engine steps (boundary.hpp). Whoever builds the
// triaxial boundary (src/drivers/triaxial/) attaches one; the engine knows only the interface.
// Its loaded band runs between the planes of walls[bottom_wall] and walls[top_wall] (the
// platens). Steps with the system: candidates at each neighbour rebuild or when its own travel
// plus the particles' uses up the skin, forces after the walls, loads after the walls' in the
// gather, servo and vertex update after the particles move (flexible_membrane.hpp, "One step").
#pragma once
#include "dem/dem_system.hpp"
#include "dem/membrane/flexible_membrane.hpp"

namespace ff::dem {

class MembraneBoundary final : public Boundary {
 public:
  MembraneBoundary(const MembraneSettings& s, int bottom_wall, int top_wall)
      : m_(s), bottom_wall_(bottom_wall), top_wall_(top_wall) {}
  FlexibleMembrane& membrane() { return m_; }
  const FlexibleMembrane& membrane() const { return m_; }
  long builds() const { return builds_; }  // candidate searches so far
  // Searches the candidates again now (e.g. after a checkpoint restore or a test's set-up).
  void rebuild_candidates(const DemSystem& sys);

  std::unique_ptr<Boundary> clone() const override { return std::make_unique<MembraneBoundary>(*this); }
  void update_neighbors(const DemSystem& sys, bool rebuilt, Real travel) override;
  void compute_forces(const DemSystem& sys) override;
  void add_loads(std::span<Vec3> force, std::span<Vec3> moment) const override { m_.add_loads_to(force, moment); }
  void after_integrate(const DemSystem& sys) override;
  void reorder(std::span<const Index> new_of_old) override { m_.remap_particles(new_of_old); }
  std::span<const Index> contact_particles() const override { return m_.candidate_particles(); }
  std::span<const BoundaryLoad> contact_loads() const override { return m_.candidate_loads(); }
  std::span<const Real> contact_stiffness() const override { return m_.candidate_stiffness(); }
  void save(CheckpointWriter& w, const DemSystem& sys) const override;
  void load(CheckpointReader& r, const DemSystem& sys) override;

 private:
  void search(const DemSystem& sys, Real travel);

  FlexibleMembrane m_;
  int bottom_wall_, top_wall_;
  long builds_ = 0;
  // Largest particle travel since the neighbour build at the membrane's last candidate build:
  // with the travel since the neighbour build it bounds the travel since the membrane's build.
  Real built_at_travel_ = 0;
};

// Attaches a flexible membrane to `sys` (loaded band between walls[bottom_wall] and
// walls[top_wall]) and returns it.
FlexibleMembrane& attach_membrane(DemSystem& sys, const MembraneSettings& s, int bottom_wall = 0, int top_wall = 1);
// The attached membrane boundary, or nullptr.
MembraneBoundary* membrane_boundary(const DemSystem& sys);
inline FlexibleMembrane* membrane_of(DemSystem& sys) {
  auto* b = membrane_boundary(sys);
  return b ? &b->membrane() : nullptr;
}
inline const FlexibleMembrane* membrane_of(const DemSystem& sys) {
  auto* b = membrane_boundary(sys);
  return b ? &b->membrane() : nullptr;
}

}  // namespace ff::dem
