// DemSystem as a whole (src/dem/dem_system.*): integrator, energy and momentum conservation,
// critical time step and stability limit, walls, thread independence; 2D and 3D.
// References: leapfrog / velocity Verlet (METHODS.md 1.1; Allen & Tildesley 1987, sec. 3.2;
// Hairer, Lubich & Wanner 2003, Geometric Numerical Integration, ch. I.1 and IX: stable iff
// omega dt < 2, and for a linear system E = 1/2 m v(n-1/2).v(n+1/2) + U(x(n)) is conserved
// exactly); local damping (METHODS.md 1.5, Cundall 1987); time step (METHODS.md 1.6);
// walls as bodies with rB = 0 (METHODS.md 1.2-1.3).
#include <gtest/gtest.h>
#include <omp.h>

#include <cstdio>
#include <cstring>
#include <vector>

#include "core/error.hpp"
#include "core/rng.hpp"
#include "dem/dem_system.hpp"
#include "dem/sample_builder.hpp"
#include "single_threaded.hpp"
#include "dem/diagnostics.hpp"
#include "dem/membrane/membrane_boundary.hpp"

using namespace ff;
using namespace ff::dem;

namespace {


constexpr Real kDensity = 2600, kRadius = 1e-3;

// One-group system: linear contact + parallel bond (unbreakable unless changed), no damping.
DemSystem empty_system(int dim) {
  DemSystem s;
  s.settings.dim = dim;
  s.settings.dt = 1e-8;
  s.settings.local_damping = 0;
  s.settings.skin = 0.2 * kRadius;
  s.materials.group_names = {"rock"};
  s.materials.density = {kDensity};
  s.materials.set_contact_law<LinearContact>();
  s.materials.set_bond_law<ParallelBond>();
  LinearContact::Params lc;
  lc.emod = 1e9;
  lc.kratio = 1.5;
  lc.fric = 0.5;
  s.materials.contact_params<LinearContact>() = {lc};
  ParallelBond::Material pb;
  pb.emod = 2e9;
  pb.kratio = 1.5;
  pb.ten = 1e300;
  pb.coh = 1e300;
  s.materials.bond_params<ParallelBond>() = {pb};
  return s;
}

void add_particle(DemSystem& s, const Vec3& x, Real r) {
  const std::size_t i = s.particles.size();
  s.particles.resize(i + 1);
  s.particles.pos[i] = x;
  s.particles.radius[i] = r;
  s.particles.set_mass_from_density(i, kDensity, s.settings.dim);
}

// n^dim particles on a jittered cubic (square) lattice of spacing 2 r (1 + gap_frac), bonded to
// their lattice neighbours (bond gap 2 r gap_frac + 4 jitter).
DemSystem bonded_lattice(int dim, int n, Real gap_frac, Real jitter, Rng& g) {
  DemSystem s = empty_system(dim);
  const Real a = 2 * kRadius * (1 + gap_frac);
  for (int k = 0; k < (dim == 3 ? n : 1); ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        Vec3 x(a * (i - 0.5 * (n - 1)), a * (j - 0.5 * (n - 1)), dim == 3 ? a * (k - 0.5 * (n - 1)) : 0.0);
        x += jitter * Vec3(g.uniform(-1, 1), g.uniform(-1, 1), dim == 3 ? g.uniform(-1, 1) : 0.0);
        add_particle(s, x, kRadius);
      }
  s.install_bonds(std::max(Real(0), 2 * kRadius * gap_frac) + 4 * jitter);
  s.initialise();
  return s;
}

// Random translational and angular velocities of scale v0 (in-plane in 2D).
void random_velocities(DemSystem& s, Rng& g, Real v0) {
  const bool d3 = s.settings.dim == 3;
  for (std::size_t i = 0; i < s.particles.size(); ++i) {
    s.particles.vel[i] = v0 * Vec3(g.normal(), g.normal(), d3 ? g.normal() : 0.0);
    const Real w = v0 / s.particles.radius[i];
    s.particles.omega[i] = w * (d3 ? Vec3(g.normal(), g.normal(), g.normal()) : Vec3(0, 0, g.normal()));
  }
}

Vec3 linear_momentum(const ParticleStore& p) {
  Vec3 P = Vec3::Zero();
  for (std::size_t i = 0; i < p.size(); ++i) P += p.mass[i] * p.vel[i];
  return P;
}
Vec3 angular_momentum(const ParticleStore& p) {  // about the origin
  Vec3 L = Vec3::Zero();
  for (std::size_t i = 0; i < p.size(); ++i) L += p.mass[i] * p.pos[i].cross(p.vel[i]) + p.inertia[i] * p.omega[i];
  return L;
}

// Removes the rigid-body translation and rotation of the velocity field (zero total momenta).
void remove_rigid_motion(ParticleStore& p) {
  Real m = 0;
  Vec3 xc = Vec3::Zero();
  for (std::size_t i = 0; i < p.size(); ++i) {
    m += p.mass[i];
    xc += p.mass[i] * p.pos[i];
  }
  xc /= m;
  const Vec3 vc = linear_momentum(p) / m;
  Mat3 I = Mat3::Zero();
  Vec3 L = Vec3::Zero();
  for (std::size_t i = 0; i < p.size(); ++i) {
    p.vel[i] -= vc;
    const Vec3 d = p.pos[i] - xc;
    I += p.mass[i] * (d.squaredNorm() * Mat3::Identity() - d * d.transpose()) + p.inertia[i] * Mat3::Identity();
    L += p.mass[i] * d.cross(p.vel[i]) + p.inertia[i] * p.omega[i];
  }
  const Vec3 W = I.ldlt().solve(L);
  for (std::size_t i = 0; i < p.size(); ++i) {
    p.vel[i] -= W.cross(p.pos[i] - xc);
    p.omega[i] -= W;
  }
}

// Leapfrog energy of step n: 1/2 sum m v(n-1/2).v(n+1/2) (+ rotation) + U(x(n)); the bond
// strain energy after step n is that of the forces evaluated at x(n).
Real cross_kinetic(const ParticleStore& p, const std::vector<Vec3>& v_old, const std::vector<Vec3>& w_old) {
  Real e = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    e += 0.5 * p.mass[i] * v_old[i].dot(p.vel[i]) + 0.5 * p.inertia[i] * w_old[i].dot(p.omega[i]);
  return e;
}

struct EnergyRun {
  Real max_dev = 0, drift = 0, max_dev_naive = 0;
  long touching = 0;
};
EnergyRun run_energy(DemSystem& s, long steps) {
  EnergyRun out;
  std::vector<Vec3> v_old(s.particles.size()), w_old(s.particles.size());
  Real e0 = 0, e0_naive = 0, e = 0;
  for (long k = 0; k < steps; ++k) {
    v_old = s.particles.vel;
    w_old = s.particles.omega;
    s.step();
    const Real u = strain_energy(s);
    e = cross_kinetic(s.particles, v_old, w_old) + u;
    const Real e_naive = kinetic_energy(s) + u;  // half-step KE: O(omega dt) fluctuation
    if (k == 0) {
      e0 = e;
      e0_naive = e_naive;
    }
    out.max_dev = std::max(out.max_dev, std::abs(e - e0) / e0);
    out.max_dev_naive = std::max(out.max_dev_naive, std::abs(e_naive - e0_naive) / e0_naive);
    out.touching += contacts_touching(s);
  }
  out.drift = (e - e0) / e0;
  return out;
}

}  // namespace

// --- Integrator ----------------------------------------------------------------------------

TEST(DemIntegrator, FreeFallAndLocalDamping) {
  // Constant force, leapfrog (METHODS.md 1.1): v(n+1/2) = v(n-1/2) + g dt, so from rest after N
  // steps v = N g dt and x = x0 + g dt^2 N(N+1)/2. With local damping alpha (METHODS.md 1.5) the
  // force is reduced by alpha |F| once the body moves along it (sign(v) = 0 on the first step):
  // v = g dt (1 + (N-1)(1-alpha)). Tolerance 1e-12 relative (rounding).
  for (Real alpha : {0.0, 0.7}) {
    DemSystem s = empty_system(3);
    s.settings.gravity = Vec3(0, 0, -9.81);
    s.settings.dt = 1e-4;
    s.settings.local_damping = alpha;
    add_particle(s, Vec3(0, 0, 1), kRadius);
    s.initialise();
    const long N = 100;
    s.run(N);
    const Real dt = s.settings.dt;
    const Real v_want = -9.81 * dt * (1 + (N - 1) * (1 - alpha));
    EXPECT_NEAR(s.particles.vel[0].z(), v_want, 1e-12 * std::abs(v_want)) << "alpha " << alpha;
    if (alpha == 0) {
      const Real z_want = 1 - 9.81 * dt * dt * N * (N + 1) / 2;
      EXPECT_NEAR(s.particles.pos[0].z(), z_want, 1e-12);
    }
    EXPECT_NEAR(s.time, N * dt, 1e-12 * N * dt);
    EXPECT_EQ(s.step_count, N);
  }
}

// --- Energy --------------------------------------------------------------------------------

TEST(DemEnergy, UndampedBondedAssemblyConservesEnergy3D2D) {
  // Undamped elastic bonded assembly (4x4x4 spheres / 8x8 disks on a jittered lattice, 144 / 112
  // parallel bonds, small gaps so no contact closes), random velocities and spins with the
  // rigid-body motion removed, dt = 0.1 x critical, 10^4 steps. Energy = leapfrog energy
  // 1/2 m v(n-1/2).v(n+1/2) + strain energy at x(n) (exact invariant of the linearised scheme,
  // Hairer et al. 2003); the half-step kinetic_energy() + strain energy is also reported, it
  // oscillates at O(omega dt) and is not the conserved quantity of the scheme.
  // Tolerance (issue): |E(n) - E(0)| / E(0) < 1e-3 over all steps.
  Rng g(21);
  for (int dim : {3, 2}) {
    DemSystem s = bonded_lattice(dim, dim == 3 ? 4 : 8, 0.01, 0.002 * kRadius, g);
    EXPECT_EQ(s.bonds.i.size(), dim == 3 ? 144u : 112u);
    s.settings.dt = 0.1 * critical_time_step(s);
    random_velocities(s, g, 0.01);
    remove_rigid_motion(s.particles);
    const EnergyRun r = run_energy(s, 10000);
    std::printf("[ measured ] dim %d: leapfrog energy max |dE|/E = %.3e, final drift = %.3e; "
                "half-step KE + U max |dE|/E = %.3e\n", dim, r.max_dev, r.drift, r.max_dev_naive);
    EXPECT_LT(r.max_dev, 1e-3) << "dim " << dim;
    EXPECT_EQ(r.touching, 0) << "a contact closed: the test meant bonds only";
    EXPECT_EQ(intact_bonds(s), s.bonds.i.size());
  }
}

// --- Momentum ------------------------------------------------------------------------------

TEST(DemMomentum, FreeClusterConservesLinearAndAngularMomentum) {
  // Free cluster (5x5x5 / 10x10 jittered lattice, overlapping so contacts act beside the bonds,
  // low friction so they may slide), random velocities and spins, no damping or gravity, 1000 steps.
  // Pair forces are equal and opposite and the moments balance the lever arms, so
  // P = sum m v and L = sum m x x v + I w (positions after the step, half-step velocities: the
  // exact leapfrog invariant) change only by rounding. Tolerance 1e-12 of sum m|v| (P) and of
  // sum |m x x v| + |I w| (L).
  Rng g(31);
  for (int dim : {3, 2}) {
    DemSystem s = bonded_lattice(dim, dim == 3 ? 5 : 10, -0.002, 0.002 * kRadius, g);
    s.materials.contact_params<LinearContact>()[0].fric = 0.05;  // low friction: contacts may slide
    s.settings.dt = 0.2 * critical_time_step(s);
    random_velocities(s, g, 0.2);
    const Vec3 P0 = linear_momentum(s.particles), L0 = angular_momentum(s.particles);
    Real p_scale = 0, l_scale = 0;
    for (std::size_t i = 0; i < s.particles.size(); ++i) {
      p_scale += s.particles.mass[i] * s.particles.vel[i].norm();
      l_scale += s.particles.mass[i] * s.particles.pos[i].cross(s.particles.vel[i]).norm() +
                 s.particles.inertia[i] * s.particles.omega[i].norm();
    }
    s.run(1000);
    EXPECT_GT(contacts_touching(s), 10);
    const Real dP = (linear_momentum(s.particles) - P0).norm() / p_scale;
    const Real dL = (angular_momentum(s.particles) - L0).norm() / l_scale;
    std::printf("[ measured ] dim %d: relative momentum error %.3e, angular momentum error %.3e\n", dim, dP, dL);
    EXPECT_LT(dP, 1e-12) << "dim " << dim;
    EXPECT_LT(dL, 1e-12) << "dim " << dim;
  }
}

// --- Critical time step and stability ------------------------------------------------------

TEST(DemTimeStep, CriticalStepOfTwoBondedBodies) {
  // METHODS.md 1.6: dt = min_i(sqrt(m_i/k_tran), sqrt(I_i/k_rot)) with, for one parallel bond,
  // k_tran = max(kn, ks) A and k_rot = max(kn I, ks J) + k_tran r_i^2 (lever arm); a touching
  // contact adds kn_c to k_tran and kn_c r_i^2 to k_rot. Unequal radii; 3D and 2D; with a gap
  // (bond only) and with an overlap (bond + contact). Tolerance 1e-12 relative.
  const Real rA = 1e-3, rB = 1.4e-3;
  for (int dim : {3, 2}) {
    for (Real gap : {1e-5, -1e-6}) {
      DemSystem s = empty_system(dim);
      add_particle(s, Vec3::Zero(), rA);
      add_particle(s, Vec3(rA + rB + gap, 0, 0), rB);
      ASSERT_EQ(s.install_bonds(2e-5), 1u);
      s.initialise();
      const auto b = ParallelBond::section(s.materials.bond_params<ParallelBond>()[0], rA, rB, dim);
      const Real k = std::max(b.kn, b.ks) * b.A, krot = std::max(b.kn * b.I, b.ks * b.J);
      const Real kc = gap < 0 ? LinearContact::normal_stiffness(s.materials.contact_params<LinearContact>()[0], rA, rB, dim) : 0.0;
      Real want = 1e300;
      for (int i = 0; i < 2; ++i) {
        const Real r = s.particles.radius[i];
        want = std::min({want, std::sqrt(s.particles.mass[i] / (k + kc)),
                         std::sqrt(s.particles.inertia[i] / (krot + (k + kc) * r * r))});
      }
      EXPECT_NEAR(critical_time_step(s), want, 1e-12 * want) << "dim " << dim << " gap " << gap;
    }
  }
}

TEST(DemTimeStep, ACoupledStiffnessAddsToAFreeGrainsOwnBound) {
  // A grain with no contact is bounded by a contact with one like itself (METHODS.md 1.6); a coupled
  // module's stiffness per grain (the pore fluid's) adds to that bound and never loosens it. Until
  // session 49 a free grain's fluid stiffness replaced its own contact: a tiny free grain beside a soft
  // pore fluid gave a "critical step with the fluid" 100 x longer than without (fuzzed:
  // saturated_ucs_3d.toml with sample.radius_min = 1e-300). Two free grains of unequal size.
  for (int dim : {3, 2}) {
    DemSystem s = empty_system(dim);
    add_particle(s, Vec3::Zero(), kRadius);
    add_particle(s, Vec3(10 * kRadius, 0, 0), 0.1 * kRadius);
    s.initialise();
    const Real dt_own = critical_time_step(s);
    const Real k_self = LinearContact::normal_stiffness(s.materials.contact_params<LinearContact>()[0], 0.1 * kRadius,
                                                        0.1 * kRadius, dim);
    const std::vector<Real> soft = {1e-6 * k_self, 1e-6 * k_self}, stiff = {0.0, 3 * k_self};
    EXPECT_LE(critical_time_step(s, soft), dt_own) << "dim " << dim;
    EXPECT_NEAR(critical_time_step(s, soft), dt_own, 1e-5 * dt_own) << "dim " << dim;
    // A stiffness as large as three self-contacts on the small grain: its translational bound shrinks by 2.
    const Real m = s.particles.mass[1];
    EXPECT_NEAR(critical_time_step(s, stiff), std::min(dt_own, std::sqrt(m / (4 * k_self))), 1e-12 * dt_own)
        << "dim " << dim;
  }
}

TEST(DemTimeStep, MassScalingReachesTheTargetStep) {
  // Density scaling (METHODS.md 1.6): after scale_masses_for(dt, s) the critical step of the
  // inertial masses allows dt, i.e. s x dt_crit >= dt (equal to 1e-12 relative with the engine's
  // uniform factor); physical masses (kinetic energy, gravity) are unchanged; a dt that is
  // already allowed changes nothing.
  Rng g(51);
  DemSystem s = bonded_lattice(3, 3, 0.0, 0.001 * kRadius, g);
  const Real safety = 0.2, dt0 = critical_time_step(s);
  const std::vector<Real> m0 = s.particles.mass, inv0 = s.particles.inv_mass;
  scale_masses_for(s, 0.1 * safety * dt0, safety);
  EXPECT_EQ(s.particles.inv_mass, inv0);
  const Real dt = 50 * safety * dt0;
  scale_masses_for(s, dt, safety);
  EXPECT_NEAR(safety * critical_time_step(s), dt, 1e-12 * dt);
  EXPECT_GE(safety * critical_time_step(s) * (1 + 1e-12), dt);
  EXPECT_EQ(s.particles.mass, m0);
}

TEST(DemTimeStep, AxialBondOscillatorStableBelowTwoOverOmega) {
  // Two equal spheres bonded along x, moving only along x: a linear oscillator with reduced mass
  // m/2 and stiffness k = kn A, omega = sqrt(2k/m). Leapfrog is stable iff omega dt < 2
  // (Hairer et al. 2003), i.e. dt < sqrt(2 m/k) = sqrt(2) x the single-body estimate sqrt(m/k).
  // At 0.95 x that limit the leapfrog energy stays constant (linear system: to 1e-9 over 2000
  // steps); at 1.05 x the energy grows (|lambda| = 1.88 per step) beyond 1e6 x within 300 steps
  // or the engine's NaN check throws. The engine's estimate must lie below the limit.
  for (Real f : {0.95, 1.05}) {
    DemSystem s = empty_system(3);
    add_particle(s, Vec3::Zero(), kRadius);
    add_particle(s, Vec3(2.02 * kRadius, 0, 0), kRadius);
    ASSERT_EQ(s.install_bonds(0.03 * kRadius), 1u);
    s.initialise();
    const Real m = s.particles.mass[0], k = ParallelBond::section(s.materials.bond_params<ParallelBond>()[0], kRadius, kRadius, 3).kn *
                                         ParallelBond::section(s.materials.bond_params<ParallelBond>()[0], kRadius, kRadius, 3).A;
    const Real dt_lim = std::sqrt(2 * m / k);
    EXPECT_LT(critical_time_step(s), dt_lim);
    s.settings.dt = f * dt_lim;
    s.particles.vel[0] = Vec3(-1e-3, 0, 0);
    s.particles.vel[1] = Vec3(1e-3, 0, 0);
    if (f < 1) {
      const EnergyRun r = run_energy(s, 2000);
      EXPECT_LT(r.max_dev, 1e-9);
      EXPECT_EQ(r.touching, 0);
    } else {
      const Real e0 = kinetic_energy(s);
      bool blew_up = false;
      try {
        for (int q = 0; q < 300 && !blew_up; ++q) {
          s.step();
          blew_up = kinetic_energy(s) > 1e6 * e0;
        }
      } catch (const NumericalError&) {
        blew_up = true;
      }
      EXPECT_TRUE(blew_up);
    }
  }
}

// --- Walls ---------------------------------------------------------------------------------

TEST(DemWalls, SphereOnPlaneWall) {
  // A body overlapping a plane wall by delta: F = kn delta along the wall normal with the wall
  // rule r = L = R (kn = pi R E* in 3D, 2 E* in 2D; METHODS.md 1.3), the wall records minus
  // the force on the body, its stiffness kn and one contact. A body sliding along the wall feels
  // the wall's own friction mu_w Fn (not the material's). Tolerance 1e-9 relative (delta is
  // 1e-3 R, rounding of the positions).
  for (int dim : {3, 2}) {
    const Real delta = 1e-6;
    DemSystem s = empty_system(dim);
    s.materials.set_bond_law<NoBond>();
    Wall w;
    w.kind = Wall::Kind::Plane;
    w.point = Vec3(0, 0.01, 0);
    w.normal = Vec3::UnitY();  // in the x-y plane, so it serves 2D too
    w.friction = 0.3;
    s.walls.push_back(w);
    add_particle(s, Vec3(0.004, 0.01 + kRadius - delta, 0), kRadius);
    s.settings.dt = 1e-6;
    s.particles.vel[0] = Vec3(2.0, 0, 0);  // sliding: ks v dt = 4.4 mu Fn
    s.initialise();
    s.step();
    const Real kn = LinearContact::normal_stiffness(s.materials.contact_params<LinearContact>()[0], kRadius, 0, dim);
    EXPECT_NEAR(kn, dim == 3 ? kPi * kRadius * 1e9 : 2e9, 1e-14 * kn);
    const Vec3 f = s.particles.force[0];
    EXPECT_NEAR(f.y(), kn * delta, 1e-9 * kn * delta) << "dim " << dim;
    EXPECT_NEAR(f.x(), -0.3 * kn * delta, 1e-9 * kn * delta) << "dim " << dim;
    EXPECT_EQ(s.walls[0].force, Vec3(-f));
    EXPECT_NEAR(s.walls[0].contact_stiffness, kn, 1e-14 * kn);
    EXPECT_EQ(s.walls[0].contacts, 1);
    // Friction at the contact point also spins the body: M = (xc - x) x F_on_body.
    EXPECT_NEAR(s.particles.moment[0].z(), -(kRadius - 0.5 * delta) * 0.3 * kn * delta, 1e-9 * kn * delta * kRadius);
  }
}

TEST(DemWalls, GroupFrictionWallTakesTheParticlesContactFriction) {
  // A wall with friction kGroupFriction treats each body as its own group's contacts do: the
  // sliding body of SphereOnPlaneWall feels mu Fn with mu = dem.contact.G-G.friction (0.25 here).
  // Tolerance 1e-9 relative.
  const Real delta = 1e-6;
  DemSystem s = empty_system(3);
  s.materials.set_bond_law<NoBond>();
  s.materials.contact_params<LinearContact>()[0].fric = 0.25;
  Wall w;
  w.kind = Wall::Kind::Plane;
  w.point = Vec3(0, 0.01, 0);
  w.normal = Vec3::UnitY();
  w.friction = kGroupFriction;
  s.walls.push_back(w);
  add_particle(s, Vec3(0.004, 0.01 + kRadius - delta, 0), kRadius);
  s.settings.dt = 1e-6;
  s.particles.vel[0] = Vec3(2.0, 0, 0);
  s.initialise();
  s.step();
  const Real kn = LinearContact::normal_stiffness(s.materials.contact_params<LinearContact>()[0], kRadius, 0, 3);
  EXPECT_NEAR(s.particles.force[0].y(), kn * delta, 1e-9 * kn * delta);
  EXPECT_NEAR(s.particles.force[0].x(), -0.25 * kn * delta, 1e-9 * kn * delta);
}

TEST(DemWalls, SphereInsideCylinderWall) {
  // Sphere pressed against the inside of a cylinder (axis z, radius Rc) by delta: the wall
  // pushes it back towards the axis with kn delta, kn by the wall rule (METHODS.md 1.3), and the
  // wall records minus that force. Tolerance 1e-9 relative.
  const Real Rc = 0.01, delta = 1e-6, phi = 0.7;
  DemSystem s = empty_system(3);
  s.materials.set_bond_law<NoBond>();
  Wall w;
  w.kind = Wall::Kind::CylinderInside;
  w.point = Vec3(0, 0, -0.05);
  w.normal = Vec3::UnitZ();
  w.radius = Rc;
  s.walls.push_back(w);
  const Vec3 er(std::cos(phi), std::sin(phi), 0);
  add_particle(s, (Rc - kRadius + delta) * er + Vec3(0, 0, 0.003), kRadius);
  s.initialise();
  s.step();
  const Real kn = LinearContact::normal_stiffness(s.materials.contact_params<LinearContact>()[0], kRadius, 0, 3);
  const Vec3 want = -kn * delta * er;
  EXPECT_LT((s.particles.force[0] - want).norm(), 1e-9 * kn * delta);
  EXPECT_EQ(s.walls[0].force, Vec3(-s.particles.force[0]));
  EXPECT_EQ(s.walls[0].contacts, 1);
  // The wall is the body's only stiffness: dt = sqrt(I/(kn R^2)) (rotational bound, METHODS 1.6).
  const Real dt_want = std::sqrt(s.particles.inertia[0] / (kn * kRadius * kRadius));
  EXPECT_NEAR(critical_time_step(s), dt_want, 1e-9 * dt_want);
}

// --- Thread independence -------------------------------------------------------------------

TEST(DemThreads, BitIdenticalOnOneAndThreeThreads) {
  // STYLE / dem_system.hpp: per-pair slots gathered in fixed order make results independent of
  // the thread count. A 6x6x6 overlapping bonded assembly with weak bonds (some break), damping,
  // gravity and a moving wall, 200 steps: positions, velocities, spins, orientations and the
  // crack log must be bit-identical (memcmp) on 1 and 3 threads (3 threads split the loops
  // unevenly). Not 2 threads here: on a loaded 2-core machine libgomp's active wait makes each
  // barrier cost a time slice with exactly 2 threads (10+ s for this test); 2 threads give the
  // same bits (checked by hand with OMP_WAIT_POLICY=passive).
  auto run = [](int threads) {
    omp_set_num_threads(threads);
    Rng g(41);
    DemSystem s = bonded_lattice(3, 6, -0.003, 0.003 * kRadius, g);
    s.settings.parallel_min = 0;  // every loop parallel, however small the system
    s.materials.bond_params<ParallelBond>()[0].ten = 2e6;
    s.materials.bond_params<ParallelBond>()[0].coh = 2e6;
    s.settings.local_damping = 0.7;
    s.settings.gravity = Vec3(0, 0, -9.81);
    Wall w;
    w.point = Vec3(0, 0, -5.99 * kRadius);
    w.normal = Vec3::UnitZ();
    w.velocity = Vec3(0, 0, 0.5);
    s.walls.push_back(w);
    s.initialise();
    s.settings.dt = 0.2 * critical_time_step(s);
    random_velocities(s, g, 0.3);
    s.run(200);
    return s;
  };
  const int saved = omp_get_max_threads();
  const DemSystem a = run(1), o = run(3);
  omp_set_num_threads(saved);
  EXPECT_GT(a.cracks.total(), 0);
  EXPECT_GT(a.walls[0].contacts, 0);
  const std::size_t n = a.particles.size();
  ASSERT_EQ(o.particles.size(), n);
  EXPECT_EQ(std::memcmp(a.particles.pos.data(), o.particles.pos.data(), n * sizeof(Vec3)), 0);
  EXPECT_EQ(std::memcmp(a.particles.vel.data(), o.particles.vel.data(), n * sizeof(Vec3)), 0);
  EXPECT_EQ(std::memcmp(a.particles.omega.data(), o.particles.omega.data(), n * sizeof(Vec3)), 0);
  EXPECT_EQ(std::memcmp(a.particles.orient.data(), o.particles.orient.data(), n * sizeof(Quat)), 0);
  ASSERT_EQ(o.cracks.events.size(), a.cracks.events.size());
  for (std::size_t k = 0; k < a.cracks.events.size(); ++k) {
    EXPECT_EQ(o.cracks.events[k].i, a.cracks.events[k].i);
    EXPECT_EQ(o.cracks.events[k].j, a.cracks.events[k].j);
    EXPECT_EQ(o.cracks.events[k].time, a.cracks.events[k].time);
  }
  EXPECT_EQ(o.walls[0].force, a.walls[0].force);
}

// The flexible membrane keeps its own candidate list (DemSystem::step): it is searched again
// when the particles' travel plus the vertices' travel since its last search could close the
// skin, without rebuilding the particle pairs. A 6 x 6 x 6 bonded lattice is squeezed by the
// platens inside a 16-unit sleeve that starts 5% of R outside it (more than the skin, so the
// sleeve must move further than the skin before it touches): rebuilding the membrane's
// candidates before every step changes no bit of the particles or the sleeve, and the sleeve
// was searched again on its own at least once.
TEST(DemMembrane, OwnCandidateSearchesMissNoContact) {
  auto make = [] {
    Rng g(11);
    DemSystem s = bonded_lattice(3, 6, 0.0, 0.02 * kRadius, g);
    s.settings.local_damping = 0.7;
    SampleInfo info;
    add_platens(s, info, 0.1);
    s.settings.dt = 0.5 * critical_time_step(s);
    s.walls[0].velocity.z() = 0.05;
    s.walls[1].velocity.z() = -0.05;
    Real R = 0;
    for (std::size_t i = 0; i < s.particles.size(); ++i)
      R = std::max(R, Vec3(s.particles.pos[i].x(), s.particles.pos[i].y(), 0).norm() + s.particles.radius[i]);
    MembraneSettings m = membrane_around_cylinder(R, s.walls[0].point.z(), s.walls[1].point.z(), 16, 0, 0.05, 1.2);
    m.pressure = 2e6;
    m.v_max = 2.0;
    m.r_min = 0.5 * R;
    attach_membrane(s, m);
    s.rebuild_neighbors();
    return s;
  };
  DemSystem a = make(), b = make();
  const int steps = 3000;
  a.run(steps);
  for (int k = 0; k < steps; ++k) {
    membrane_boundary(b)->rebuild_candidates(b);
    b.step();
  }
  int touching = 0;
  for (std::size_t k = 0; k < membrane_of(a)->element_count(); ++k) touching += membrane_of(a)->contacts(k) > 0;
  EXPECT_GT(touching, 16);  // the sleeve reached the lattice's edges
  EXPECT_GT(membrane_boundary(a)->builds(), a.neighbor_builds());  // searched again on its own
  ASSERT_EQ(a.particles.size(), b.particles.size());
  EXPECT_EQ(std::memcmp(a.particles.pos.data(), b.particles.pos.data(), a.particles.size() * sizeof(Vec3)), 0);
  const auto va = membrane_of(a)->vertices(), vb = membrane_of(b)->vertices();
  EXPECT_EQ(std::memcmp(va.data(), vb.data(), va.size() * sizeof(Vec3)), 0);
}
