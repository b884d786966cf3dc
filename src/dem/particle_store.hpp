// Particles as structure of arrays: one contiguous array per property (STYLE.md C).
// 2D runs use the same arrays: disks of unit thickness in the x-y plane (z, vz, wx, wy stay 0).
//
// Every field is declared ONCE, in for_each_field() below, with its checkpoint policy (saved, or
// recomputed every step) and its policy for a ghost copy on another MPI rank (copied every step,
// copied when the lists are rebuilt, or owner only). resize(), removal (keep()), reordering
// (permute()), the checkpoint (dem_checkpoint.cpp) and the VTK particle output (dem_output.cpp)
// iterate that list, so adding a field is its member here plus its line in the list.
//
// Particles keep a 64-bit global id (`id`) from creation (resize() hands out the next free ids)
// through removal and reordering; bonds and contacts use array indices, the crack log ids.
#pragma once
#include <cstdint>
#include <vector>

#include "core/types.hpp"

namespace ff::dem {

struct ParticleStore;

enum class CheckpointPolicy : std::uint8_t {
  Saved,       // written to checkpoints (key dem.<name>)
  Recomputed,  // rebuilt every step (accumulators): zero after a restore
};
enum class GhostPolicy : std::uint8_t {
  EveryStep,  // a ghost needs it every step (positions, velocities, orientation)
  AtRebuild,  // changes only when lists are rebuilt (radius, group, mass, id)
  OwnerOnly,  // never copied (accumulators, output-only state)
};

// One field of the declaration: its array, the value of a new particle, its policies and its
// VTK point-data name (nullptr: not written; positions are the points themselves).
template <class T>
struct ParticleField {
  const char* name;
  std::vector<T> ParticleStore::*member;
  T fill;
  CheckpointPolicy checkpoint;
  GhostPolicy ghost;
  const char* vtk;
};

struct ParticleStore {
  std::vector<std::int64_t> id;           // global id, unique for the life of the system
  std::vector<Vec3> pos, vel, omega;      // [m], [m/s], [rad/s]
  std::vector<Real> radius;               // [m]
  std::vector<std::int32_t> group;        // material group index
  std::vector<Vec3> disp;                 // displacement since the sample was built [m] (output)
  std::vector<Quat> orient;               // body orientation (needed by rotational bonds)
  std::vector<Real> mass, inertia;        // physical mass [kg], moment of inertia [kg m^2]
  std::vector<Real> inv_mass, inv_inertia;  // inertial (possibly density-scaled) inverses
  // Total force and moment of the last step (external loads + interactions + gravity-free sum).
  std::vector<Vec3> force, moment;
  // External loads [N], [N m]: any module (fluid coupling, membrane loads, body loads) ADDS to
  // them between compute_forces() and integrate(); integrate() starts each particle's sum from
  // them and sets them back to zero, so they are zero between steps.
  std::vector<Vec3> ext_force, ext_moment;
  std::int64_t next_id = 0;  // the id the next new particle gets

  // The declaration (see the file comment): one line per field.
  template <class F>
  static void for_each_field(F&& f) {
    using S = ParticleStore;
    constexpr auto Saved = CheckpointPolicy::Saved, Recomputed = CheckpointPolicy::Recomputed;
    constexpr auto Every = GhostPolicy::EveryStep, Rebuild = GhostPolicy::AtRebuild, Owner = GhostPolicy::OwnerOnly;
    const Vec3 z = Vec3::Zero();
    f(ParticleField<std::int64_t>{"id", &S::id, -1, Saved, Rebuild, "id"});
    f(ParticleField<Vec3>{"pos", &S::pos, z, Saved, Every, nullptr});
    f(ParticleField<Real>{"radius", &S::radius, 0, Saved, Rebuild, "radius"});
    f(ParticleField<std::int32_t>{"group", &S::group, 0, Saved, Rebuild, "group"});
    f(ParticleField<Vec3>{"vel", &S::vel, z, Saved, Every, "velocity"});
    f(ParticleField<Vec3>{"omega", &S::omega, z, Saved, Every, "angular_velocity"});
    f(ParticleField<Vec3>{"disp", &S::disp, z, Saved, Owner, "displacement"});
    f(ParticleField<Vec3>{"force", &S::force, z, Recomputed, Owner, "force"});
    f(ParticleField<Quat>{"orient", &S::orient, Quat::Identity(), Saved, Every, nullptr});
    f(ParticleField<Real>{"mass", &S::mass, 0, Saved, Rebuild, nullptr});
    f(ParticleField<Real>{"inertia", &S::inertia, 0, Saved, Rebuild, nullptr});
    f(ParticleField<Real>{"inv_mass", &S::inv_mass, 0, Saved, Rebuild, nullptr});
    f(ParticleField<Real>{"inv_inertia", &S::inv_inertia, 0, Saved, Rebuild, nullptr});
    f(ParticleField<Vec3>{"moment", &S::moment, z, Recomputed, Owner, nullptr});
    f(ParticleField<Vec3>{"ext_force", &S::ext_force, z, Recomputed, Owner, nullptr});
    f(ParticleField<Vec3>{"ext_moment", &S::ext_moment, z, Recomputed, Owner, nullptr});
  }

  std::size_t size() const { return pos.size(); }
  // Grows (new particles: the fields' fill values and fresh ids) or shrinks every field.
  void resize(std::size_t n) {
    const std::size_t old = id.size();
    for_each_field([&](const auto& fd) { (this->*fd.member).resize(n, fd.fill); });
    for (std::size_t i = old; i < n; ++i) id[i] = next_id++;
  }
  // Keeps the particles with !remove[i], in order (ids stay with their particles).
  void keep(const std::vector<char>& remove) {
    for_each_field([&](const auto& fd) {
      auto& v = this->*fd.member;
      std::size_t k = 0;
      for (std::size_t i = 0; i < v.size(); ++i)
        if (!remove[i]) v[k++] = v[i];
      v.resize(k);
    });
  }
  // New order: the particle at k is the one that was at order[k] (order: a permutation).
  void permute(const std::vector<Index>& order) {
    for_each_field([&](const auto& fd) {
      auto& v = this->*fd.member;
      auto copy = v;
      for (std::size_t k = 0; k < order.size(); ++k) v[k] = copy[static_cast<std::size_t>(order[k])];
    });
  }
  // Sets mass and inertia from density: spheres in 3D, disks of thickness 1 m in 2D.
  void set_mass_from_density(std::size_t i, Real density, int dim) {
    const Real r = radius[i];
    if (dim == 3) {
      mass[i] = density * 4.0 / 3.0 * kPi * r * r * r;
      inertia[i] = 0.4 * mass[i] * r * r;
    } else {
      mass[i] = density * kPi * r * r;  // unit thickness
      inertia[i] = 0.5 * mass[i] * r * r;
    }
    inv_mass[i] = 1.0 / mass[i];
    inv_inertia[i] = 1.0 / inertia[i];
  }
};

}  // namespace ff::dem
