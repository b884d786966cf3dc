// Particle fields declared once (src/dem/particle_store.hpp), global ids through removal, checkpoint
// and reordering (src/dem/reorder_particles.hpp), and the external force/torque accumulators.
// Reference for the external load: leapfrog (PFC form, METHODS.md 1.1) under a constant force F
// from x0, v0: v_N = v0 + N a dt, x_N = x0 + N v0 dt + a dt^2 N (N + 1) / 2, a = F / m (the
// discrete form of x0 + v0 t + F t^2 / (2m)).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <map>
#include <set>
#include <tuple>
#include <unistd.h>

#include "core/rng.hpp"
#include "dem/dem_checkpoint.hpp"
#include "dem/diagnostics.hpp"
#include "dem/dem_system.hpp"
#include "dem/membrane/membrane_boundary.hpp"
#include "dem/membrane/particle_membrane.hpp"
#include "dem/reorder_particles.hpp"
#include "io/checkpoint.hpp"

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

void add_particle(DemSystem& s, const Vec3& x, Real r = kRadius) {
  const std::size_t i = s.particles.size();
  s.particles.resize(i + 1);
  s.particles.pos[i] = x;
  s.particles.radius[i] = r;
  s.particles.set_mass_from_density(i, kDensity, 3);
}

// A bonded 6 x 6 x 6 block of slightly jiggled, slightly overlapping spheres (radii 0.9995-1 mm, centres 2 mm apart) crushed by a wall
// moving up at 5 m/s and sideways at 4 m/s from below, a fixed wall above, inward loads on every 7th particle, local
// damping 0.7: contacts, bonds and wall contacts all carry history and bonds break.
DemSystem crushed_block(bool sleeve = false) {
  DemSystem s = one_group_system();
  Rng g(11);
  const int n = 6;
  const Real a = 2.0 * kRadius;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        add_particle(s, Vec3(a * (i - 2.5), a * (j - 2.5), a * k) + 1e-6 * Vec3(g.uniform(-1, 1), g.uniform(-1, 1), g.uniform(-1, 1)),
                     kRadius * g.uniform(0.9995, 1.0));
  std::vector<Index> loaded;
  for (std::size_t i = 0; i < s.particles.size(); i += 7) loaded.push_back(static_cast<Index>(i));
  s.add_boundary(std::make_unique<InwardLoads>(loaded, 1e-2));
  s.install_bonds(0.1 * kRadius);
  Wall lo, hi;
  lo.point = Vec3(0, 0, -1.02 * kRadius);
  lo.normal = Vec3::UnitZ();
  lo.velocity = Vec3(4.0, 0, 5.0);
  hi.point = Vec3(0, 0, a * (n - 1) + 1.05 * kRadius);
  hi.normal = -Vec3::UnitZ();
  s.walls = {lo, hi};
  s.settings.local_damping = 0.7;
  s.initialise();
  s.settings.dt = 0.3 * critical_time_step(s);
  if (sleeve) {  // a flexible membrane touching the block's vertical edges, 2 MPa
    Real R = 0;
    for (std::size_t i = 0; i < s.particles.size(); ++i)
      R = std::max(R, Vec3(s.particles.pos[i].x(), s.particles.pos[i].y(), 0).norm() + s.particles.radius[i]);
    MembraneSettings m = membrane_around_cylinder(R, lo.point.z(), hi.point.z(), 16, 0, 0.0, 1.2);
    m.pressure = 2e6;
    m.v_max = 2.0;
    m.r_min = 0.5 * R;
    attach_membrane(s, m);
    s.rebuild_neighbors();
  }
  return s;
}

std::map<std::int64_t, std::size_t> index_by_id(const ParticleStore& p) {
  std::map<std::int64_t, std::size_t> m;
  for (std::size_t i = 0; i < p.size(); ++i) m[p.id[i]] = i;
  return m;
}

// Bonds as (smaller id, larger id, broken) of their ends' global ids.
std::set<std::tuple<std::int64_t, std::int64_t, int>> bonds_by_id(const DemSystem& s) {
  std::set<std::tuple<std::int64_t, std::int64_t, int>> b;
  for (std::size_t k = 0; k < s.bonds.size(); ++k) {
    const auto a = s.particles.id[s.bonds.i[k]], c = s.particles.id[s.bonds.j[k]];
    b.emplace(std::min(a, c), std::max(a, c), s.bonds.broken[k]);
  }
  return b;
}

}  // namespace

TEST(ParticleFields, ResizeGivesEveryFieldItsFillAndFreshIds) {
  ParticleStore p;
  p.resize(3);
  ParticleStore::for_each_field([&](const auto& fd) { EXPECT_EQ((p.*fd.member).size(), 3u) << fd.name; });
  EXPECT_EQ(p.id, (std::vector<std::int64_t>{0, 1, 2}));
  EXPECT_EQ(p.orient[2].w(), 1.0);
  EXPECT_EQ(p.ext_force[1], Vec3::Zero());
  p.resize(5);
  EXPECT_EQ(p.id, (std::vector<std::int64_t>{0, 1, 2, 3, 4}));
  EXPECT_EQ(p.next_id, 5);
  // Every field has a distinct name; positions are the VTK points, not an array.
  std::set<std::string> names;
  ParticleStore::for_each_field([&](const auto& fd) {
    EXPECT_TRUE(names.insert(fd.name).second) << fd.name;
    if (std::string(fd.name) == "pos") {
      EXPECT_EQ(fd.vtk, nullptr);
    }
  });
}

TEST(ParticleFields, RemovalKeepsIdsAndNewParticlesGetUnusedOnes) {
  ParticleStore p;
  p.resize(10);
  for (std::size_t i = 0; i < 10; ++i) {
    p.pos[i] = Vec3(static_cast<Real>(i), 0, 0);
    p.group[i] = static_cast<std::int32_t>(i % 3);
  }
  std::vector<char> remove(10, 0);
  for (std::size_t i = 1; i < 10; i += 2) remove[i] = 1;
  p.keep(remove);
  ASSERT_EQ(p.size(), 5u);
  ParticleStore::for_each_field([&](const auto& fd) { EXPECT_EQ((p.*fd.member).size(), 5u) << fd.name; });
  for (std::size_t k = 0; k < 5; ++k) {
    EXPECT_EQ(p.id[k], static_cast<std::int64_t>(2 * k));
    EXPECT_EQ(p.pos[k].x(), static_cast<Real>(2 * k));
    EXPECT_EQ(p.group[k], static_cast<std::int32_t>((2 * k) % 3));
  }
  p.resize(6);
  EXPECT_EQ(p.id[5], 10);  // never an id that was used before
}

TEST(ParticleFields, CheckpointKeepsIdsAndSavedFieldsOnly) {
  DemSystem s = crushed_block();
  s.run(100);
  s.particles.ext_force[3] = Vec3(1, 2, 3);  // an accumulator: recomputed, not saved
  const auto path = std::filesystem::temp_directory_path() / ("fracflow_fields_" + std::to_string(::getpid()) + ".ffcp");
  {
    CheckpointWriter w(path);
    save_dem(w, s);
    w.commit();
  }
  DemSystem t = one_group_system();
  CheckpointReader r(path);
  ParticleStore::for_each_field([&](const auto& fd) {
    EXPECT_EQ(r.has(std::string("dem.") + fd.name), fd.checkpoint == CheckpointPolicy::Saved) << fd.name;
  });
  load_dem(r, t);
  std::filesystem::remove(path);
  EXPECT_EQ(t.particles.id, s.particles.id);
  EXPECT_EQ(t.particles.next_id, s.particles.next_id);
  EXPECT_EQ(t.particles.ext_force[3], Vec3::Zero());
  const std::size_t n = s.particles.size();
  EXPECT_EQ(std::memcmp(t.particles.orient.data(), s.particles.orient.data(), n * sizeof(Quat)), 0);
}

TEST(ParticleFields, ExternalForceOnAFreeParticleIsLeapfrogsClosedForm) {
  // A free sphere (no contacts, no damping, no gravity) from x0 with v0 under a constant external
  // force F and torque T added each step after add_external_loads(): the closed form of the file
  // comment, 1e-12 relative (rounding of N sums). The accumulators are zero after each step.
  DemSystem s = one_group_system();
  s.settings.dt = 1e-5;
  add_particle(s, Vec3(1e-3, -2e-3, 0.5e-3));
  s.particles.vel[0] = Vec3(0.3, 0.1, -0.2);
  s.particles.omega[0] = Vec3(1, 0, 0);
  s.initialise();
  const Vec3 x0 = s.particles.pos[0], v0 = s.particles.vel[0], w0 = s.particles.omega[0];
  const Vec3 F(1e-3, -2e-3, 0.5e-3), T(0, 2e-8, 1e-7);
  const long N = 200;
  for (long k = 0; k < N; ++k) {
    s.update_neighbors();
    s.compute_forces();
    s.add_external_loads();
    s.particles.ext_force[0] += F;
    s.particles.ext_moment[0] += T;
    s.integrate();
    ASSERT_EQ(s.particles.ext_force[0], Vec3::Zero());
    ASSERT_EQ(s.particles.ext_moment[0], Vec3::Zero());
  }
  const Real dt = s.settings.dt, m = s.particles.mass[0], I = s.particles.inertia[0];
  const Real Nr = static_cast<Real>(N);
  const Vec3 a = F / m;
  const Vec3 v_want = v0 + a * (Nr * dt);
  const Vec3 x_want = x0 + v0 * (Nr * dt) + a * (dt * dt * Nr * (Nr + 1) / 2);
  const Vec3 w_want = w0 + T * (Nr * dt / I);
  EXPECT_LT((s.particles.vel[0] - v_want).norm(), 1e-12 * v_want.norm());
  EXPECT_LT((s.particles.pos[0] - x_want).norm(), 1e-12 * x_want.norm());
  EXPECT_LT((s.particles.omega[0] - w_want).norm(), 1e-12 * w_want.norm());
  EXPECT_EQ(s.particles.force[0], F);  // the last step's total: the external load alone
}

TEST(ReorderParticles, RandomPermutationMidRunMatchesPerGlobalId) {
  // The crushed block stepped 2N steps, and the same block reordered by a random permutation
  // after N steps, then stepped N more: per global id, positions agree to 1e-12 of the block
  // size (measured 3e-16) and spins to 1e-10 of the largest (measured 1.3e-12); bonds (ends by id,
  // broken or not) and the crack log (ids, modes, times, in order) are identical. Not bit for
  // bit: after the reordering each particle sums its contact loads in another order (partners
  // sorted by their new indices; bond loads keep the bond order), and pairs whose ends swap
  // compute their contact point from the other end, so results differ by rounding (~1e-16
  // relative per step), which the contacts amplify over the N steps.
  const long N = 300;
  DemSystem a = crushed_block(), b = crushed_block();
  a.run(N);
  b.run(N);
  const std::size_t n = b.particles.size();
  std::vector<Index> order(n);
  for (std::size_t k = 0; k < n; ++k) order[k] = static_cast<Index>(k);
  Rng g(5);
  for (std::size_t k = n - 1; k > 0; --k) std::swap(order[k], order[static_cast<std::size_t>(g.uniform() * (k + 1))]);
  const long cracks_before = b.cracks.total();
  reorder_particles(b, order);
  for (std::size_t k = 0; k < n; ++k) ASSERT_EQ(b.particles.id[k], a.particles.id[order[k]]);
  a.run(N);
  b.run(N);
  EXPECT_GT(a.cracks.total(), cracks_before) << "bonds must break after the reordering";
  EXPECT_GT(a.neighbor_builds(), 2);
  const auto ia = index_by_id(a.particles), ib = index_by_id(b.particles);
  ASSERT_EQ(ia.size(), ib.size());
  const Real size = 12 * kRadius;
  Real wmax = 0, dx = 0, dw = 0;
  for (const auto& [id, i] : ia) wmax = std::max(wmax, a.particles.omega[i].norm());
  for (const auto& [id, i] : ia) {
    const std::size_t j = ib.at(id);
    dx = std::max(dx, (a.particles.pos[i] - b.particles.pos[j]).norm());
    dw = std::max(dw, (a.particles.omega[i] - b.particles.omega[j]).norm());
  }
  std::printf("after the reordering: max position difference %.3g of the block size, spin %.3g of the largest; "
              "%ld cracks (%ld before)\n", dx / size, dw / wmax, a.cracks.total(), cracks_before);
  EXPECT_LT(dx, 1e-12 * size);
  EXPECT_LT(dw, 1e-10 * wmax);  // spins come from differences of tangential loads: more sensitive
  EXPECT_EQ(bonds_by_id(a), bonds_by_id(b));
  ASSERT_EQ(a.cracks.events.size(), b.cracks.events.size());
  for (std::size_t k = 0; k < a.cracks.events.size(); ++k) {
    const auto &ea = a.cracks.events[k], &eb = b.cracks.events[k];
    EXPECT_EQ(ea.i, eb.i);
    EXPECT_EQ(ea.j, eb.j);
    EXPECT_EQ(ea.mode, eb.mode);
    EXPECT_EQ(ea.time, eb.time);
    EXPECT_LT((ea.position - eb.position).norm(), 1e-12 * size);
  }
  EXPECT_EQ(a.walls[0].force.z() == 0, b.walls[0].force.z() == 0);
  EXPECT_NEAR(a.walls[0].force.z(), b.walls[0].force.z(), 1e-9 * std::abs(a.walls[0].force.z()));
}

TEST(ReorderParticles, IdentityKeepsTheRunBitForBit) {
  // Reordering by the identity changes no summation order: the run goes on bit for bit.
  DemSystem a = crushed_block(), b = crushed_block();
  a.run(200);
  b.run(200);
  std::vector<Index> order(b.particles.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = static_cast<Index>(k);
  reorder_particles(b, order);
  a.run(200);
  b.run(200);
  const std::size_t n = a.particles.size();
  EXPECT_EQ(std::memcmp(a.particles.pos.data(), b.particles.pos.data(), n * sizeof(Vec3)), 0);
}

TEST(ReorderParticles, FlexibleMembraneKeepsItsContactsAcrossAReordering) {
  // The crushed block inside a flexible membrane: the membrane's candidates are renumbered and
  // sorted again with their history (FlexibleMembrane::remap_particles). Reordered by a random
  // permutation after N steps and stepped N more, particles (per id) and membrane vertices agree
  // with the unreordered run to 1e-12 of the block size (rounding: see the test above).
  const long N = 300;
  DemSystem a = crushed_block(true), b = crushed_block(true);
  a.run(N);
  b.run(N);
  const std::size_t n = b.particles.size();
  std::vector<Index> order(n);
  for (std::size_t k = 0; k < n; ++k) order[k] = static_cast<Index>(n - 1 - k);
  Rng g(9);
  for (std::size_t k = n - 1; k > 0; --k) std::swap(order[k], order[static_cast<std::size_t>(g.uniform() * (k + 1))]);
  const auto ca = membrane_of(a)->candidate_particles();
  std::vector<std::int64_t> ids_a;
  for (Index i : ca) ids_a.push_back(a.particles.id[i]);
  reorder_particles(b, order);
  const auto cb = membrane_of(b)->candidate_particles();
  ASSERT_EQ(ca.size(), cb.size());
  std::vector<std::int64_t> ids_b;
  for (Index i : cb) ids_b.push_back(b.particles.id[i]);
  std::sort(ids_a.begin(), ids_a.end());
  std::sort(ids_b.begin(), ids_b.end());
  EXPECT_EQ(ids_a, ids_b);
  for (std::size_t c = 1; c < cb.size(); ++c) ASSERT_LE(cb[c - 1], cb[c]);  // sorted by particle again
  a.run(N);
  b.run(N);
  int touching = 0;
  for (std::size_t k = 0; k < membrane_of(a)->element_count(); ++k) touching += membrane_of(a)->contacts(k) > 0;
  EXPECT_GT(touching, 2);  // the sleeve presses on the block's edges (5 elements)
  const auto ia = index_by_id(a.particles), ib = index_by_id(b.particles);
  const Real size = 12 * kRadius;
  Real dx = 0;
  for (const auto& [id, i] : ia) dx = std::max(dx, (a.particles.pos[i] - b.particles.pos[ib.at(id)]).norm());
  const auto va = membrane_of(a)->vertices(), vb = membrane_of(b)->vertices();
  Real dv = 0;
  for (std::size_t k = 0; k < va.size(); ++k) dv = std::max(dv, (va[k] - vb[k]).norm());
  std::printf("membrane run: max particle position difference %.3g, vertex %.3g of the block size; %d elements touch\n",
              dx / size, dv / size, touching);
  EXPECT_LT(dx, 1e-12 * size);
  EXPECT_LT(dv, 1e-12 * size);
  EXPECT_EQ(bonds_by_id(a), bonds_by_id(b));
  EXPECT_EQ(a.cracks.total(), b.cracks.total());
}

TEST(ReorderParticles, RefusesWhatIsNotAPermutation) {
  DemSystem s = crushed_block();
  std::vector<Index> order(s.particles.size(), 0);
  EXPECT_THROW(reorder_particles(s, order), Error);
  order.pop_back();
  EXPECT_THROW(reorder_particles(s, order), Error);
}
