// "No allocation inside the time loop" (issue 2, item 11): after a warm-up in which the
// work buffers reach their size, stepping a bonded sample that is compressed by moving walls
// (so neighbour lists are rebuilt, contacts form and bonds break) makes no heap allocation.
// The global operator new of this test program counts allocations while `counting` is set.
#include <gtest/gtest.h>
#include <omp.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "core/rng.hpp"
#include "dem/dem_system.hpp"
#include "dem/membrane/particle_membrane.hpp"
#include "dem/diagnostics.hpp"
#include "dem/membrane/membrane_boundary.hpp"

namespace {
std::atomic<bool> counting{false};
std::atomic<long> allocations{0};
}  // namespace

void* operator new(std::size_t n) {
  if (counting.load(std::memory_order_relaxed)) {
    allocations.fetch_add(1, std::memory_order_relaxed);
    if (std::getenv("FRACFLOW_ABORT_ON_ALLOC")) std::abort();  // for finding the culprit in gdb
  }
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
// GCC 12 cannot see that the replaced operator new above also uses malloc and warns when it
// inlines these into the standard allocator; the pairing is correct.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
#pragma GCC diagnostic pop

using namespace ff;
using namespace ff::dem;

namespace {

constexpr Real kR = 0.5e-3, kA = 2 * kR * 1.001;  // particle radius, lattice spacing
constexpr int kN = 6, kH = 12;                     // 6 x 6 x 12 bonded block

// A bonded block between two platens that approach at 0.5 m/s each (initialised).
DemSystem compressed_block() {
  const Real r = kR, a = kA;
  const int n = kN, h = kH;
  DemSystem s;
  s.settings.dim = 3;
  s.settings.local_damping = 0.7;
  s.settings.skin = 0.1 * r;
  s.materials.group_names = {"rock"};
  s.materials.density = {2600};
  LinearContact::Params lc;
  lc.emod = 1e9;
  lc.kratio = 2;
  lc.fric = 0.5;
  s.materials.contact_params<LinearContact>() = {lc};
  s.materials.contact_params<HertzMindlinContact>() = {HertzMindlinContact::Params{}};
  ParallelBond::Material pb;
  pb.emod = 1e9;
  pb.kratio = 2;
  pb.ten = 2e6;
  pb.coh = 2e6;
  s.materials.bond_params<ParallelBond>() = {pb};
  s.materials.bond_params<RotationalBond>().resize(1);
  Rng g(3);
  for (int k = 0; k < h; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const std::size_t p = s.particles.size();
        s.particles.resize(p + 1);
        s.particles.pos[p] = Vec3(a * i, a * j, a * k) + 0.02 * r * Vec3(g.uniform(-1, 1), g.uniform(-1, 1), g.uniform(-1, 1));
        s.particles.radius[p] = r;
        s.particles.set_mass_from_density(p, 2600, 3);
      }
  s.install_bonds(0.1 * r);
  Wall bottom, top;
  bottom.point = Vec3(0, 0, -r);
  bottom.normal = Vec3::UnitZ();
  bottom.velocity = Vec3(0, 0, 0.5);
  top.point = Vec3(0, 0, a * (h - 1) + r);
  top.normal = -Vec3::UnitZ();
  top.velocity = Vec3(0, 0, -0.5);
  s.walls = {bottom, top};
  s.initialise();
  s.settings.dt = 0.5 * critical_time_step(s);
  return s;
}

}  // namespace

TEST(DemAllocation, StepsOfACompressedBondedSampleDoNotAllocate) {
  omp_set_num_threads(1);
  DemSystem s = compressed_block();
  s.run(500);  // warm-up: buffers grow to their working size
  const long builds = s.neighbors().builds();
  const long cracks = s.cracks.total();
  allocations = 0;
  counting = true;
  s.run(3000);
  counting = false;
  EXPECT_GT(s.neighbors().builds(), builds + 2) << "the neighbour list must be rebuilt during the counted steps";
  EXPECT_GT(s.cracks.total(), cracks) << "bonds must break during the counted steps";
  EXPECT_EQ(allocations.load(), 0) << "over " << s.neighbors().builds() - builds << " rebuilds";
}

TEST(DemAllocation, StepsWithEnergyBookkeepingDoNotAllocate) {
  // The same with the energy bookkeeping on (issue 13 item 6), switched on after initialise()
  // as the DEM drivers do: per-pair and per-particle work slots and block sums reuse buffers.
  omp_set_num_threads(1);
  DemSystem s = compressed_block();
  s.settings.track_energy = true;
  start_energy_tracking(s);
  s.run(500);
  const long builds = s.neighbors().builds();
  const long cracks = s.cracks.total();
  allocations = 0;
  counting = true;
  s.run(3000);
  counting = false;
  EXPECT_GT(s.neighbors().builds(), builds + 2);
  EXPECT_GT(s.cracks.total(), cracks);
  EXPECT_GT(s.energy.bond_break, 0);
  EXPECT_EQ(allocations.load(), 0) << "over " << s.neighbors().builds() - builds << " rebuilds";
}

TEST(DemAllocation, StepsInsideAFlexibleMembraneDoNotAllocate) {
  // The same compressed block inside a flexible membrane at 2 MPa (issue 4): candidate
  // searches at neighbour rebuilds, membrane contacts, servo and vertex updates reuse buffers.
  omp_set_num_threads(1);
  DemSystem s = compressed_block();
  MembraneSettings m;
  m.n_theta = 16;
  const Real half = 0.5 * kA * (kN - 1);
  m.axis_x = m.axis_y = half;
  m.radius = membrane_circumradius(half * std::sqrt(2.0) + 1.05 * kR, m.n_theta);  // clears the block's corners
  m.z0 = -2 * kR;
  m.height = kA * (kH - 1) + 4 * kR;
  m.n_z = membrane_square_rows(m.radius, m.n_theta, m.height);
  m.pressure = 2e6;
  m.v_max = 5.0;  // the side elements start ~1 mm from the block
  m.r_min = half;
  attach_membrane(s, m);
  s.rebuild_neighbors();
  s.run(3000);  // warm-up: the membrane closes on the block, buffers reach their size
  int touching = 0;
  for (std::size_t k = 0; k < membrane_of(s)->element_count(); ++k) touching += membrane_of(s)->contacts(k) > 0;
  ASSERT_GT(touching, 0) << "the membrane must press on the block during the counted steps";
  const long builds = s.neighbors().builds();
  allocations = 0;
  counting = true;
  s.run(3000);
  counting = false;
  EXPECT_GT(s.neighbors().builds(), builds + 2) << "the neighbour list must be rebuilt during the counted steps";
  EXPECT_EQ(allocations.load(), 0) << "over " << s.neighbors().builds() - builds << " rebuilds";
}

TEST(DemAllocation, StepsInsideAParticleMembraneDoNotAllocate) {
  // The same compressed block, centred on the z axis, inside a particle membrane at 2 MPa: its
  // bonded spheres (their own group) press on the block with constant inward loads, contacts
  // form and the neighbour list is rebuilt; the triaxial driver's speed cap and measurements run
  // between steps as they do in the isotropic stage.
  omp_set_num_threads(1);
  DemSystem s = compressed_block();
  const Real half = 0.5 * kA * (kN - 1);
  for (auto& x : s.particles.pos) x -= Vec3(half, half, 0);
  s.initialise();
  ParticleMembraneSpec spec;
  spec.sample_radius = half * std::sqrt(2.0) + 1.05 * kR;  // clears the block's corners
  spec.z_bottom = s.walls[0].point.z();
  spec.z_top = s.walls[1].point.z();
  spec.particle_radius = kR;
  spec.pressure = 2e6;
  auto l = add_particle_membrane(s, spec, ParticleMembraneMaterial{1e7, 1000, 0});
  stabilise_particle_membrane(s, l, s.settings.dt, 0.8);
  auto step = [&](int n) {
    for (int k = 0; k < n; ++k) {
      s.step();
      limit_particle_membrane_speed(s.particles, l, 1.0);
    }
    return particle_membrane_confinement(s.particles, l, s.walls[0].point.z(), s.walls[1].point.z());
  };
  step(2000);  // warm-up: the membrane closes on the block, buffers reach their size
  ASSERT_LT(particle_membrane_mean_radius(s.particles, l), l.centre_radius - 0.2 * kR) << "the membrane must press on the block";
  const long builds = s.neighbors().builds();
  allocations = 0;
  counting = true;
  const Real conf = step(2000);
  counting = false;
  EXPECT_GT(conf, 0.0);
  EXPECT_GT(s.neighbors().builds(), builds + 2) << "the neighbour list must be rebuilt during the counted steps";
  EXPECT_EQ(allocations.load(), 0) << "over " << s.neighbors().builds() - builds << " rebuilds";
}
