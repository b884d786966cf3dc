// The public stages of a DEM step (src/dem/dem_system.hpp): update_neighbors(),
// compute_forces(), add_external_loads(), integrate(). A coupled solver adds its forces between
// the last two, possibly sub-cycling the DEM inside one of its own steps.
// Reference: leapfrog under a constant force (METHODS.md 1.1): from rest after N steps
// v = N a dt, x = x0 + a dt^2 N (N + 1) / 2; the same for the spin under a constant torque.
#include <gtest/gtest.h>

#include <cstring>

#include "core/rng.hpp"
#include "dem/diagnostics.hpp"
#include "dem/dem_system.hpp"
#include "dem/membrane/particle_membrane.hpp"

using namespace ff;
using namespace ff::dem;

namespace {

constexpr Real kDensity = 2600, kRadius = 1e-3;

DemSystem one_group_system() {
  DemSystem s;
  s.settings.dim = 3;
  s.settings.local_damping = 0;
  s.settings.skin = 0.2 * kRadius;
  s.materials.group_names = {"rock"};
  s.materials.density = {kDensity};
  LinearContact::Params lc;
  lc.emod = 1e9;
  lc.kratio = 1.5;
  lc.fric = 0.5;
  s.materials.contact_params<LinearContact>() = {lc};
  ParallelBond::Material pb;
  pb.emod = 2e9;
  pb.kratio = 1.5;
  pb.ten = 3e6;
  pb.coh = 3e6;
  s.materials.bond_params<ParallelBond>() = {pb};
  return s;
}

void add_particle(DemSystem& s, const Vec3& x) {
  const std::size_t i = s.particles.size();
  s.particles.resize(i + 1);
  s.particles.pos[i] = x;
  s.particles.radius[i] = kRadius;
  s.particles.set_mass_from_density(i, kDensity, 3);
}

}  // namespace

TEST(DemStages, ExternalLoadAddedBetweenStagesIsIntegrated) {
  // Constant force and torque added by "a fluid" after add_external_loads(), with 10 DEM
  // sub-steps per fluid step: the leapfrog closed form above, relative tolerance 1e-12.
  DemSystem s = one_group_system();
  s.settings.dt = 1e-5;
  add_particle(s, Vec3::Zero());
  s.initialise();
  const Vec3 F(1e-3, -2e-3, 0.5e-3), T(0, 0, 1e-7);
  const long fluid_steps = 5, sub = 10;
  for (long k = 0; k < fluid_steps; ++k)
    for (long c = 0; c < sub; ++c) {
      s.update_neighbors();
      s.compute_forces();
      s.add_external_loads();
      s.particles.ext_force[0] += F;
      s.particles.ext_moment[0] += T;
      s.integrate();
    }
  const long N = fluid_steps * sub;
  const Real dt = s.settings.dt, m = s.particles.mass[0], I = s.particles.inertia[0];
  const Vec3 v_want = F * (N * dt / m), x_want = F * (dt * dt * N * (N + 1) / 2 / m);
  const Vec3 w_want = T * (N * dt / I);
  EXPECT_LT((s.particles.vel[0] - v_want).norm(), 1e-12 * v_want.norm());
  EXPECT_LT((s.particles.pos[0] - x_want).norm(), 1e-12 * x_want.norm());
  EXPECT_LT((s.particles.omega[0] - w_want).norm(), 1e-12 * w_want.norm());
  EXPECT_EQ(s.step_count, N);
}

TEST(DemStages, StagesCalledOneByOneGiveTheStepBitForBit) {
  // A bonded block crushed by a moving wall, some particles with an inward (membrane) load: the
  // stages called one by one (adding a zero external force) reproduce step() bit for bit,
  // across neighbour rebuilds and bond breakage.
  auto build = [] {
    DemSystem s = one_group_system();
    Rng g(7);
    const int n = 6;
    const Real a = 2.01 * kRadius;
    for (int k = 0; k < n; ++k)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i)
          add_particle(s, Vec3(a * i, a * j, a * k) + 1e-5 * Vec3(g.uniform(-1, 1), g.uniform(-1, 1), g.uniform(-1, 1)));
    std::vector<Index> loaded;
    for (std::size_t i = 0; i < s.particles.size(); i += 5) loaded.push_back(static_cast<Index>(i));
    s.add_boundary(std::make_unique<InwardLoads>(loaded, 1e-2));
    s.install_bonds(0.1 * kRadius);
    Wall w;
    w.point = Vec3(0, 0, -1.05 * kRadius);
    w.normal = Vec3::UnitZ();
    w.velocity = Vec3(0, 0, 2.0);
    s.walls.push_back(w);
    s.settings.local_damping = 0.7;
    s.initialise();
    s.settings.dt = 0.3 * critical_time_step(s);
    return s;
  };
  DemSystem a = build(), b = build();
  for (int k = 0; k < 1500; ++k) {
    a.step();
    b.update_neighbors();
    b.compute_forces();
    b.add_external_loads();
    for (auto& f : b.particles.ext_force) f += Vec3::Zero();
    b.integrate();
  }
  EXPECT_GT(a.cracks.total(), 0) << "bonds must break during the comparison";
  EXPECT_GT(a.neighbor_builds(), 2);
  const std::size_t n = a.particles.size();
  EXPECT_EQ(std::memcmp(a.particles.pos.data(), b.particles.pos.data(), n * sizeof(Vec3)), 0);
  EXPECT_EQ(std::memcmp(a.particles.omega.data(), b.particles.omega.data(), n * sizeof(Vec3)), 0);
  EXPECT_EQ(a.cracks.total(), b.cracks.total());
}
