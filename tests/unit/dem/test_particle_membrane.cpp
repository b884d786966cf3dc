// Particle membrane of the triaxial test (src/dem/membrane/particle_membrane.*; [S000] Zhao,
// Konietzky & Herbst 2021 sec. 6 and Fig. 15; de Bono et al. 2012; METHODS.md 3) and the
// constant-magnitude inward load of DemSystem that pushes it.
// References: leapfrog under a constant force (METHODS.md 1.1: v(n+1/2) = v(n-1/2) + F/m dt,
// x(n+1) = x(n) + v(n+1/2) dt); statics of a ring of N links under inward point loads (a link
// shortened by d pulls each end inward by 2 sin(pi/N) k d); linear contact and parallel-bond
// normal stiffness kn = pi min(r)^2 E / (rA + rB) (METHODS.md 1.3-1.4).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <unistd.h>

#include "core/error.hpp"
#include "dem/dem_checkpoint.hpp"
#include "dem/dem_system.hpp"
#include "dem/membrane/particle_membrane.hpp"
#include "io/checkpoint.hpp"
#include "single_threaded.hpp"

using namespace ff;
using namespace ff::dem;

namespace {

// Groups "matrix" and "vein" (two, so that re-indexed pair tables are checked), linear contact,
// parallel bonds.
DemSystem two_group_system() {
  DemSystem s;
  s.settings.dim = 3;
  s.settings.local_damping = 0.7;
  s.materials.group_names = {"matrix", "vein"};
  s.materials.density = {1390, 1810};
  s.materials.set_contact_law<LinearContact>();
  s.materials.set_bond_law<ParallelBond>();
  s.materials.contact_params<LinearContact>().resize(4);
  s.materials.contact_params<HertzMindlinContact>().resize(4);
  s.materials.bond_params<ParallelBond>().resize(4);
  s.materials.bond_params<RotationalBond>().resize(4);
  for (int k = 0; k < 4; ++k) {
    s.materials.contact_params<LinearContact>()[k] = LinearContact::Params{2e9 + 1e8 * k, 1.5 + k, 0.4};
    s.materials.bond_params<ParallelBond>()[k].emod = 3e9 + 1e8 * k;
  }
  return s;
}

ParticleMembraneSpec c1_like_spec() {
  ParticleMembraneSpec s;
  s.sample_radius = 5e-3;
  s.z_bottom = 1e-4;
  s.z_top = 20.1e-3;
  s.particle_radius = 0.5e-3;
  s.clearance = 0.05e-3;
  s.pressure = 5e6;
  return s;
}

// A 4 mm high membrane of c1_like_spec().
ParticleMembraneSpec short_membrane_spec() {
  ParticleMembraneSpec s = c1_like_spec();
  s.z_top = s.z_bottom + 4e-3;
  return s;
}

// Under each sphere of the membrane `plan`, a fixed sphere of radius rk on its radial line,
// touching it when the membrane is built; sets the skin.
void add_fixed_core(DemSystem& s, const ParticleMembraneLayout& plan, Real rk) {
  s.settings.skin = 0.1e-3;
  const Real r = plan.particle_radius;
  for (int j = 0; j < plan.n_z; ++j)
    for (int i = 0; i < plan.n_theta; ++i) {
      const Vec3 x = particle_membrane_position(plan, i, j);
      const std::size_t k = s.particles.size();
      s.particles.resize(k + 1);
      s.particles.pos[k] = Vec3(x.x(), x.y(), 0).normalized() * (plan.centre_radius - r - rk) + Vec3(0, 0, x.z());
      s.particles.radius[k] = rk;
      s.particles.set_mass_from_density(k, 1390, 3);
      s.particles.inv_mass[k] = s.particles.inv_inertia[k] = 0;  // fixed
    }
}

// One undamped sphere of radius 0.5 mm (density 1390) at `pos` with velocity `vel` and inward
// load `inward` [N], dt = 1 us, ready to step.
DemSystem one_free_sphere(const Vec3& pos, const Vec3& vel, Real inward) {
  DemSystem s = two_group_system();
  s.settings.local_damping = 0;
  s.settings.skin = 0.1e-3;
  s.settings.dt = 1e-6;
  s.particles.resize(1);
  s.particles.radius[0] = 0.5e-3;
  s.particles.pos[0] = pos;
  s.particles.vel[0] = vel;
  s.particles.set_mass_from_density(0, 1390, 3);
  s.add_boundary(std::make_unique<InwardLoads>(std::vector<Index>{0}, inward));
  s.initialise();
  return s;
}

}  // namespace

TEST(ParticleMembraneLayout, SpheresTouchTheirRingAndRowNeighboursAndThePlatens) {
  // Geometry of the layout (file comment of particle_membrane.hpp): ring and row neighbours
  // touch (centre distance 2 r_m), the end rows touch the platens, the inner surface clears the
  // sample by at least the clearance and by at most the ring's step r_m/pi more, r_m within 15%
  // of the requested radius. The total constant force is p x the inner surface 2 pi R_in H.
  // Tolerances: 1e-12 relative (a few roundings of sin, division and sums).
  for (Real r_req : {0.25e-3, 0.5e-3, 0.61e-3}) {
    for (Real h : {14e-3, 20e-3}) {
      ParticleMembraneSpec spec = c1_like_spec();
      spec.particle_radius = r_req;
      spec.z_top = spec.z_bottom + h;
      const auto l = particle_membrane_layout(spec);
      const Real r = l.particle_radius;
      SCOPED_TRACE(::testing::Message() << "r_req " << r_req << " h " << h << ": " << l.n_theta << " x " << l.n_z);
      EXPECT_NEAR(r, r_req, 0.15 * r_req);
      EXPECT_NEAR(2 * r * static_cast<Real>(l.n_z), h, 1e-12 * h);
      for (int j = 0; j < l.n_z; ++j)
        for (int i = 0; i < l.n_theta; ++i) {
          const Vec3 x = particle_membrane_position(l, i, j);
          EXPECT_NEAR((particle_membrane_position(l, (i + 1) % static_cast<int>(l.n_theta), j) - x).norm(), 2 * r, 1e-12 * r);
          if (j + 1 < l.n_z) {
            EXPECT_NEAR((particle_membrane_position(l, i, j + 1) - x).norm(), 2 * r, 1e-12 * r);
          }
          EXPECT_NEAR(std::hypot(x.x(), x.y()), l.centre_radius, 1e-12 * l.centre_radius);
        }
      EXPECT_NEAR(particle_membrane_position(l, 0, 0).z() - r, spec.z_bottom, 1e-12 * h);
      EXPECT_NEAR(particle_membrane_position(l, 0, static_cast<int>(l.n_z) - 1).z() + r, spec.z_top, 1e-12 * h);
      const Real want = spec.sample_radius + spec.clearance;
      EXPECT_GE(l.inner_radius(), want * (1 - 1e-12));
      EXPECT_LE(l.inner_radius(), want + r / kPi);
      const Real total = spec.pressure * 2 * kPi * l.inner_radius() * h;
      EXPECT_NEAR(l.total_force(), total, 1e-12 * total);
    }
  }
  ParticleMembraneSpec bad = c1_like_spec();
  bad.z_top = bad.z_bottom;
  EXPECT_THROW(particle_membrane_layout(bad), InputError);
}

TEST(ParticleMembrane, AddedAsItsOwnBondedGroupWithInwardConstantForces) {
  // A few bonded sample spheres inside; the membrane's spheres form group "membrane" after the
  // sample's, the pair tables grow with old pairs unchanged and old bonds re-indexed, only ring
  // and row neighbours are bonded (n_theta (2 n_z - 1) bonds, none to the sample), each sphere
  // carries f = p 2 pi R_in H / N towards the axis (sum = p x area, 1e-12 relative), sample
  // particles none.
  DemSystem s = two_group_system();
  const ParticleMembraneSpec spec = c1_like_spec();
  for (int k = 0; k < 4; ++k) {
    const std::size_t i = s.particles.size();
    s.particles.resize(i + 1);
    s.particles.pos[i] = Vec3(0, 0, 1e-3 + 0.999e-3 * k);
    s.particles.radius[i] = 0.5e-3;
    s.particles.group[i] = k % 2;
    s.particles.set_mass_from_density(i, 1500, 3);
  }
  s.particles.pos[3].x() = spec.sample_radius - 0.5e-3;  // a sample sphere touching the sample radius
  s.settings.skin = 0.1e-3;
  ASSERT_EQ(s.install_bonds(0.01e-3), 2u);  // (0, 1), (1, 2): a matrix-vein pair each
  const std::vector<std::int32_t> old_pairs = s.bonds.pair;
  const auto old_linear = s.materials.contact_params<LinearContact>();
  s.initialise();
  const auto l = add_particle_membrane(s, spec, ParticleMembraneMaterial{1e7, 1000, 0.2});
  const int n = 3;
  ASSERT_EQ(s.materials.groups(), n);
  EXPECT_EQ(s.materials.group_names[2], "membrane");
  EXPECT_EQ(l.group, 2);
  EXPECT_EQ(l.first, 4);
  ASSERT_EQ(s.materials.contact_params<LinearContact>().size(), 9u);
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b) EXPECT_EQ(s.materials.contact_params<LinearContact>()[a * n + b].emod, old_linear[a * 2 + b].emod);
  EXPECT_EQ(s.materials.contact_params<LinearContact>()[0 * n + 2].emod, old_linear[0].emod);  // membrane-sample: the sample group's own
  EXPECT_EQ(s.materials.contact_params<LinearContact>()[2 * n + 1].kratio, old_linear[3].kratio);
  EXPECT_EQ(s.materials.contact_params<LinearContact>()[2 * n + 1].fric, 0.2);
  EXPECT_EQ(s.materials.contact_params<LinearContact>()[2 * n + 2].emod, 1e7);
  EXPECT_EQ(s.materials.bond_params<ParallelBond>()[2 * n + 2].emod, 1e7);
  EXPECT_GE(s.materials.bond_params<ParallelBond>()[2 * n + 2].ten, 1e90);
  for (std::size_t b = 0; b < old_pairs.size(); ++b) {
    const int a = old_pairs[b] / 2, c = old_pairs[b] % 2;
    EXPECT_EQ(s.bonds.pair[b], a * n + c);
  }
  ASSERT_EQ(s.bonds.i.size(), old_pairs.size() + static_cast<std::size_t>(l.n_theta * (2 * l.n_z - 1)));
  EXPECT_EQ(particle_membrane_bonds(s, l), static_cast<std::size_t>(l.n_theta * (2 * l.n_z - 1)));
  for (std::size_t b = old_pairs.size(); b < s.bonds.i.size(); ++b) {
    EXPECT_GE(s.bonds.i[b], l.first);
    EXPECT_GE(s.bonds.j[b], l.first);
    EXPECT_NEAR((s.particles.pos[s.bonds.j[b]] - s.particles.pos[s.bonds.i[b]]).norm(), 2 * l.particle_radius,
                1e-12 * l.particle_radius);
  }
  // The constant inward loads: one InwardLoads boundary with every membrane sphere, l.force each.
  ASSERT_EQ(s.boundaries().size(), 1u);
  const auto* loads = dynamic_cast<const InwardLoads*>(s.boundaries().begin()->get());
  ASSERT_NE(loads, nullptr);
  ASSERT_EQ(loads->particles().size(), static_cast<std::size_t>(l.count()));
  EXPECT_EQ(loads->force(), l.force);
  for (std::int64_t k = 0; k < l.count(); ++k) EXPECT_EQ(loads->particles()[k], l.first + k);
  Real sum = 0;
  for (std::size_t i = 0; i < s.particles.size(); ++i) {
    const bool loaded = std::find(loads->particles().begin(), loads->particles().end(), static_cast<Index>(i)) !=
                        loads->particles().end();
    if (static_cast<std::int64_t>(i) < l.first) {
      EXPECT_FALSE(loaded);
      continue;
    }
    EXPECT_EQ(s.particles.group[i], 2);
    EXPECT_TRUE(loaded);
    const Real f = l.force;
    sum += f;
    for (Index k = 0; k < 4; ++k)  // no membrane sphere overlaps the sample
      EXPECT_GT((s.particles.pos[i] - s.particles.pos[k]).norm(), s.particles.radius[i] + s.particles.radius[k]);
  }
  const Real area = 2 * kPi * l.inner_radius() * (spec.z_top - spec.z_bottom);
  EXPECT_NEAR(sum, spec.pressure * area, 1e-12 * spec.pressure * area);
  EXPECT_NEAR(particle_membrane_confinement(s.particles, l, spec.z_bottom, spec.z_top), spec.pressure, 1e-12 * spec.pressure);
  const Real v = kPi * l.inner_radius() * l.inner_radius() * (spec.z_top - spec.z_bottom);
  EXPECT_NEAR(particle_membrane_volume(s.particles, l, spec.z_bottom, spec.z_top), v, 1e-12 * v);
}

TEST(ParticleMembrane, GroupFrictionKeepsEachSampleGroupsOwnFriction) {
  // Membrane friction kGroupFriction (membrane.friction = -1): a membrane sphere touches each
  // sample group with that group's own contact friction, as the group's particles touch each
  // other; the membrane's mutual contacts stay frictionless.
  Materials m;
  m.group_names = {"matrix", "vein"};
  m.density = {1390, 1810};
  m.contact_params<LinearContact>().resize(4);
  m.contact_params<HertzMindlinContact>().resize(4);
  m.contact_params<LinearContact>()[0].fric = m.contact_params<HertzMindlinContact>()[0].fric = 0.4;
  m.contact_params<LinearContact>()[3].fric = m.contact_params<HertzMindlinContact>()[3].fric = 0.3;
  m.contact_params<LinearContact>()[1].fric = m.contact_params<LinearContact>()[2].fric = m.contact_params<HertzMindlinContact>()[1].fric = m.contact_params<HertzMindlinContact>()[2].fric = 0.35;
  ParticleMembraneMaterial pm;
  pm.friction = kGroupFriction;
  ASSERT_EQ(add_particle_membrane_group(m, pm), 2);
  for (int g = 0; g < 2; ++g) {
    const Real own = g == 0 ? 0.4 : 0.3;
    EXPECT_EQ(m.contact_params<LinearContact>()[m.pair(g, 2)].fric, own);
    EXPECT_EQ(m.contact_params<LinearContact>()[m.pair(2, g)].fric, own);
    EXPECT_EQ(m.contact_params<HertzMindlinContact>()[m.pair(g, 2)].fric, own);
  }
  EXPECT_EQ(m.contact_params<LinearContact>()[m.pair(2, 2)].fric, 0);
}

TEST(ParticleMembrane, GroupNameIsReserved) {
  DemSystem s = two_group_system();
  s.materials.group_names[1] = "membrane";
  EXPECT_THROW(add_particle_membrane_group(s.materials, ParticleMembraneMaterial{}), InputError);
}

TEST(ParticleMembrane, PressesOnARigidCoreWithItsConstantForces) {
  // Each membrane sphere rests on one fixed core sphere on its radial line (touching when
  // built). At rest its constant load f is carried by that contact and by the ring's hoop
  // compression: u = f / (k_c + 4 sin^2(pi/N) k_link), with k_c the membrane-core contact
  // (sample group's own properties) and k_link = k_bond + k_contact = E pi r (both kn = E pi r/2
  // for equal spheres); rows move alike, so row links stay unloaded. Friction 0.3 holds the
  // spheres on top of the core spheres (without it the whole ring slides off them together, a
  // ball on a ball, since a rigid turn about the axis meets no bond). Local damping brings it to
  // rest; tolerance 1e-4 u (measured 3e-12 u: the incremental bond and contact laws are exact for
  // this radial motion).
  DemSystem s = two_group_system();
  const ParticleMembraneSpec spec = short_membrane_spec();
  const auto plan = particle_membrane_layout(spec);
  const Real rk = 0.4e-3, r = plan.particle_radius;
  add_fixed_core(s, plan, rk);
  const Real E = 1e7;
  const auto l = add_particle_membrane(s, spec, ParticleMembraneMaterial{E, 1000, 0.3});
  ASSERT_EQ(l.n_theta, plan.n_theta);
  const Real kc = LinearContact::normal_stiffness(s.materials.contact_params<LinearContact>()[0], r, rk, 3);
  const Real sn = std::sin(kPi / static_cast<Real>(l.n_theta));
  const Real u = l.force / (kc + 4 * sn * sn * E * kPi * r);
  const std::size_t k0 = static_cast<std::size_t>(l.first);
  s.settings.dt = 0.2 * std::sqrt(s.particles.mass[k0] / kc);
  s.run(4000);
  EXPECT_NEAR(particle_membrane_mean_radius(s.particles, l), l.centre_radius - u, 1e-4 * u);
  for (std::size_t i = k0; i < s.particles.size(); ++i) EXPECT_LT(s.particles.force[i].norm(), 1e-9 * l.force);
}

TEST(ParticleMembrane, UnbondedSpheresPressOnARigidCoreThroughTheirContactsOnly) {
  // particle_membrane.bonded = false: no bonds at all (so no bond law is needed), and the same
  // statics as above with the hoop link reduced to the sphere-sphere contact, k_link = E pi r / 2:
  // u = f / (k_c + 4 sin^2(pi/N) E pi r / 2). The ring is closed in compression, so its contacts
  // carry the hoop load as the bonds did. Tolerance 1e-4 u.
  DemSystem s = two_group_system();
  s.materials.set_bond_law<NoBond>();
  const ParticleMembraneSpec spec = short_membrane_spec();
  const auto plan = particle_membrane_layout(spec);
  const Real rk = 0.4e-3, r = plan.particle_radius;
  add_fixed_core(s, plan, rk);
  const Real E = 1e7;
  ParticleMembraneMaterial pm{E, 1000, 0.3};
  pm.bonded = false;
  const auto l = add_particle_membrane(s, spec, pm);
  EXPECT_EQ(s.bonds.i.size(), 0u);
  EXPECT_EQ(particle_membrane_bonds(s, l), 0u);
  const Real kc = LinearContact::normal_stiffness(s.materials.contact_params<LinearContact>()[0], r, rk, 3);
  const Real sn = std::sin(kPi / static_cast<Real>(l.n_theta));
  const Real u = l.force / (kc + 4 * sn * sn * E * kPi * r / 2);
  const std::size_t k0 = static_cast<std::size_t>(l.first);
  s.settings.dt = 0.2 * std::sqrt(s.particles.mass[k0] / kc);
  s.run(4000);
  EXPECT_NEAR(particle_membrane_mean_radius(s.particles, l), l.centre_radius - u, 1e-4 * u);
  // A bonded membrane without a bond law is still refused.
  DemSystem t = two_group_system();
  t.materials.set_bond_law<NoBond>();
  EXPECT_THROW(add_particle_membrane(t, spec, ParticleMembraneMaterial{E, 1000, 0.3}), InputError);
}

TEST(ParticleMembrane, StabilisedMassesKeepTheSampleTimeStep) {
  // Density scaling (METHODS.md 1.6) of the membrane spheres only: with half-size spheres their
  // own critical step is shorter; after scaling, a sphere pressing on 4 sample spheres (the
  // assumption) plus its bonds allows dt / safety, and the sample's masses are untouched.
  DemSystem s = two_group_system();
  for (int k = 0; k < 3; ++k) {
    const std::size_t i = s.particles.size();
    s.particles.resize(i + 1);
    s.particles.pos[i] = Vec3(1.5e-3 * k, 0, 5e-3);
    s.particles.radius[i] = 0.5e-3;
    s.particles.set_mass_from_density(i, 1390, 3);
  }
  s.settings.skin = 0.1e-3;
  ParticleMembraneSpec spec = c1_like_spec();
  spec.particle_radius = 0.25e-3;
  auto l = add_particle_membrane(s, spec, ParticleMembraneMaterial{1e7, 1000, 0});
  const Real dt = 1e-7, safety = 0.8;
  const Real inv_m_sample = s.particles.inv_mass[0];
  const Real f = stabilise_particle_membrane(s, l, dt, safety);
  EXPECT_GT(f, 1.0);
  EXPECT_EQ(l.mass_factor, f);
  EXPECT_EQ(s.particles.inv_mass[0], inv_m_sample);
  const std::size_t k0 = static_cast<std::size_t>(l.first);
  const Real r = l.particle_radius;
  const Real kc = LinearContact::normal_stiffness(s.materials.contact_params<LinearContact>()[s.materials.pair(l.group, 0)], r, 0.5e-3, 3);
  const Real kc1 = LinearContact::normal_stiffness(s.materials.contact_params<LinearContact>()[s.materials.pair(l.group, 1)], r, 0.5e-3, 3);
  const Real ktot = 4 * std::max(kc, kc1);  // bonds and soft contacts add < 1%
  EXPECT_GE(std::sqrt(0.4 / (s.particles.inv_mass[k0] * ktot)), dt / safety);  // rotational bound, I = 0.4 m r^2
  EXPECT_NEAR(stabilise_particle_membrane(s, l, dt, safety), 1.0, 1e-12);  // idempotent
}

TEST(DemInwardForce, PullsAFreeParticleTowardsTheAxisAsLeapfrog) {
  // A free sphere at rest at (x0, 0, z), no damping, inward load f: a constant force -f e_x
  // while x > 0, so v(n+1/2) = (n+1) a dt and x(n) = x0 - a dt^2 n(n+1)/2 with a = f/m
  // (leapfrog from rest). Tolerance 1e-12 relative.
  DemSystem s = one_free_sphere(Vec3(5e-3, 0, 2e-3), Vec3::Zero(), 0.3);
  const int n = 100;
  s.run(n);
  const Real a = 0.3 * s.particles.inv_mass[0], dx = a * s.settings.dt * s.settings.dt * n * (n + 1) / 2.0;
  ASSERT_LT(dx, 5e-3);
  EXPECT_NEAR(s.particles.pos[0].x(), 5e-3 - dx, 1e-12 * dx);
  EXPECT_EQ(s.particles.pos[0].y(), 0.0);
  EXPECT_EQ(s.particles.pos[0].z(), 2e-3);
  EXPECT_NEAR(s.particles.vel[0].x(), -a * n * s.settings.dt, 1e-12 * a * n * s.settings.dt);
}

TEST(DemInwardForce, ExertsNoMomentAboutTheAxis) {
  // A central force keeps the angular momentum about the axis: with the force at x(n) parallel
  // to (x, y) of x(n), x(n) x v(n+1/2) = x(n) x v(n-1/2), and x(n+1) x v(n+1/2) = x(n) x v(n+1/2)
  // (leapfrog), exactly for L_z. A sphere on a circling path keeps L_z to 1e-12 relative over 2000
  // steps (round-off) while its distance from the axis changes by ~10%.
  DemSystem s = one_free_sphere(Vec3(5e-3, 1e-3, 0), Vec3(0.5, 2.0, 0.1), 1e-3);
  // Each step stores the pair (x(n+1), v(n+1/2)), whose L_z is the invariant.
  auto lz = [&] { return s.particles.pos[0].x() * s.particles.vel[0].y() - s.particles.pos[0].y() * s.particles.vel[0].x(); };
  const Real l0 = lz(), r0 = std::hypot(s.particles.pos[0].x(), s.particles.pos[0].y());
  Real rmin = r0, rmax = r0;
  for (int k = 0; k < 2000; ++k) {
    s.step();
    EXPECT_NEAR(lz(), l0, 1e-12 * std::abs(l0)) << "step " << k;
    const Real rho = std::hypot(s.particles.pos[0].x(), s.particles.pos[0].y());
    rmin = std::min(rmin, rho);
    rmax = std::max(rmax, rho);
  }
  EXPECT_GT(rmax - rmin, 0.05 * r0);
}

TEST(DemInwardForce, CheckpointOfAParticleMembraneRunResumesBitForBit) {
  // The inward loads are no particle field any more (format 4: no dem.inward_force): a membrane
  // run resumed from its checkpoint, with the loads attached again from the layout as the
  // triaxial driver does, continues bit for bit like the uninterrupted run.
  DemSystem s = two_group_system();
  s.settings.skin = 0.1e-3;
  s.settings.local_damping = 0.7;
  for (int k = 0; k < 3; ++k) {
    s.particles.resize(static_cast<std::size_t>(k) + 1);
    s.particles.pos[k] = Vec3(1.5e-3 * k, 0, 5e-3);
    s.particles.radius[k] = 0.5e-3;
    s.particles.set_mass_from_density(k, 1390, 3);
  }
  const auto l = add_particle_membrane(s, short_membrane_spec(), ParticleMembraneMaterial{1e7, 1000, 0});
  s.settings.dt = 1e-7;
  s.run(50);
  const auto path = std::filesystem::temp_directory_path() / ("fracflow_inward_loads_" + std::to_string(::getpid()) + ".ffcp");
  {
    CheckpointWriter w(path);
    save_dem(w, s);
    w.commit();
  }
  DemSystem t = two_group_system();
  add_particle_membrane_group(t.materials, ParticleMembraneMaterial{1e7, 1000, 0});
  CheckpointReader r(path);
  EXPECT_FALSE(r.has("dem.inward_force"));
  load_dem(r, t);
  attach_particle_membrane_loads(t, l);
  std::filesystem::remove(path);
  s.run(50);
  t.run(50);
  const std::size_t n = s.particles.size();
  ASSERT_EQ(t.particles.size(), n);
  EXPECT_EQ(t.particles.id, s.particles.id);
  EXPECT_EQ(std::memcmp(s.particles.pos.data(), t.particles.pos.data(), n * sizeof(Vec3)), 0);
  EXPECT_GT((s.particles.pos[l.first] - particle_membrane_position(l, 0, 0)).norm(), 0.0);  // the loads moved it
}
