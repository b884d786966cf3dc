// Contact laws (src/dem/contact/*.hpp) as pure functions, then two spheres in a DemSystem.
// References: PFC 5/6 linear model with the deformability method (METHODS.md 1.3, Itasca docs);
// Hertz (1882) / Mindlin (1949) as written in Johnson (1985), Contact Mechanics, Eq. 4.23 and
// ch. 7 (METHODS.md via hertz_mindlin.hpp); linear spring-dashpot collision (restitution
// e = exp(-pi zeta / sqrt(1 - zeta^2)), duration pi / omega_d): e.g. Schwager & Poeschel (2007),
// Phys. Rev. E 75:051304, Eqs. 3-6.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>

#include "dem/contact/hertz_mindlin.hpp"
#include "dem/contact/linear_contact.hpp"
#include "dem/dem_system.hpp"
#include "single_threaded.hpp"
#include "dem/diagnostics.hpp"

using namespace ff;
using namespace ff::dem;

namespace {


// Geometry of two bodies along the unit normal n with the given gap and no relative motion.
ContactGeom geom(const Vec3& n, Real gap, Real rA, Real rB) {
  ContactGeom g;
  g.n = n.normalized();
  g.gap = gap;
  g.xc = (rA + 0.5 * gap) * g.n;
  g.rA = rA;
  g.rB = rB;
  g.d_delta_n = 0;
  g.d_delta_s.setZero();
  g.d_theta.setZero();
  g.mean_spin_n = 0;
  return g;
}

LinearContact::Params linear_params(Real emod, Real kratio, Real fric) {
  LinearContact::Params p;
  p.emod = emod;
  p.kratio = kratio;
  p.fric = fric;
  return p;
}

// Two spheres (3D) or disks (2D) of one group with a linear contact, no bonds, no damping.
DemSystem two_bodies(int dim, Real rA, Real rB, const Vec3& xA, const Vec3& xB, const LinearContact::Params& p) {
  DemSystem s;
  s.settings.dim = dim;
  s.settings.dt = 1e-9;
  s.settings.local_damping = 0;
  s.settings.skin = 0.5 * std::min(rA, rB);
  s.materials.group_names = {"matrix"};
  s.materials.density = {2500};
  s.materials.set_contact_law<LinearContact>();
  s.materials.set_bond_law<NoBond>();
  s.materials.contact_params<LinearContact>() = {p};
  s.particles.resize(2);
  s.particles.radius = {rA, rB};
  s.particles.pos = {xA, xB};
  for (std::size_t i = 0; i < 2; ++i) s.particles.set_mass_from_density(i, 2500, dim);
  s.initialise();
  return s;
}

}  // namespace

// --- Linear contact (METHODS.md 1.3) -------------------------------------------------------

TEST(LinearContact, NormalStiffnessFollowsDeformabilityMethod) {
  // kn = A E*/L, A = pi r^2 (3D) or 2 r (2D, t = 1), r = min(RA, RB), L = RA + RB; wall r = L = RA.
  // Tolerance 1e-14 relative (one or two roundings).
  const auto p = linear_params(2e9, 1.5, 0.4);
  const Real rA = 1.2e-3, rB = 0.8e-3;
  EXPECT_NEAR(LinearContact::normal_stiffness(p, rA, rB, 3), kPi * rB * rB * 2e9 / (rA + rB), 1e-14 * 2e9 * rB);
  EXPECT_NEAR(LinearContact::normal_stiffness(p, rA, rB, 2), 2 * rB * 2e9 / (rA + rB), 1e-14 * 2e9);
  EXPECT_NEAR(LinearContact::normal_stiffness(p, rA, 0, 3), kPi * rA * 2e9, 1e-14 * 2e9 * rA);
  EXPECT_NEAR(LinearContact::normal_stiffness(p, rA, 0, 2), 2 * 2e9, 1e-14 * 2e9);
}

TEST(LinearContact, NormalForceIsKnTimesOverlapAlongN) {
  // Closed form: F on B = kn * overlap * n (PFC linear model, METHODS.md 1.3). Tolerance 1e-13 rel.
  const auto p = linear_params(1e9, 2.0, 0.5);
  const Real rA = 1e-3, rB = 2e-3, overlap = 3e-6;
  const Vec3 n = Vec3(0.3, -0.5, 0.8).normalized();
  for (int dim : {2, 3}) {
    ContactGeom g = geom(n, -overlap, rA, rB);
    ContactState st;
    Real fn = -1;
    const Vec3 f = LinearContact::force(p, g, st, 1e-8, dim, fn);
    const Real kn = LinearContact::normal_stiffness(p, rA, rB, dim);
    EXPECT_NEAR(fn, kn * overlap, 1e-13 * kn * overlap) << "dim " << dim;
    EXPECT_LT((f - kn * overlap * n).norm(), 1e-13 * kn * overlap) << "dim " << dim;
  }
}

TEST(LinearContact, NoTensionAndSeparationForgetsShear) {
  // PFC linear model: Fn = kn max(0, overlap); a separated contact carries nothing (exact zero).
  const auto p = linear_params(1e9, 1.0, 0.5);
  ContactGeom g = geom(Vec3::UnitX(), 1e-7, 1e-3, 1e-3);
  ContactState st;
  st.fs = Vec3(0, 5, 0);
  Real fn = -1;
  const Vec3 f = LinearContact::force(p, g, st, 1e-8, 3, fn);
  EXPECT_EQ(fn, 0.0);
  EXPECT_EQ(f.norm(), 0.0);
  EXPECT_EQ(st.fs.norm(), 0.0);
}

TEST(LinearContact, ElasticShearThenCoulombSlip) {
  // Fs* = Fs - ks d_delta_s; |Fs| <= mu Fn (METHODS.md 1.3). Increments accumulate while elastic,
  // the shear force opposes the motion of B; on slip |Fs| = mu Fn along -d_delta_s.
  // Tolerance 1e-13 relative.
  const auto p = linear_params(1e9, 2.5, 0.4);
  const Real r = 1e-3, overlap = 2e-6;
  const Real kn = LinearContact::normal_stiffness(p, r, r, 3), ks = kn / p.kratio, fn0 = kn * overlap;
  ContactState st;
  ContactGeom g = geom(Vec3::UnitZ(), -overlap, r, r);
  const Vec3 ds(1e-8, 2e-8, 0);  // two elastic increments: ks |2 ds| = 0.18 mu Fn
  Real fn;
  for (int k = 0; k < 2; ++k) {
    g.d_delta_s = ds;
    LinearContact::force(p, g, st, 1e-8, 3, fn);
  }
  EXPECT_LT((st.fs - (-2 * ks * ds)).norm(), 1e-13 * ks * ds.norm());
  g.d_delta_s = Vec3(0, 1e-5, 0);  // far beyond the Coulomb limit
  const Vec3 f = LinearContact::force(p, g, st, 1e-8, 3, fn);
  EXPECT_NEAR(st.fs.norm(), p.fric * fn0, 1e-13 * fn0);
  EXPECT_GT(-st.fs.y(), 0.99 * p.fric * fn0);  // nearly along -y (the stored part is tiny)
  EXPECT_LT((f - (fn0 * Vec3::UnitZ() + st.fs)).norm(), 1e-13 * fn0);
}

TEST(LinearContact, SlipDissipatesMuFnTimesTheSlipDistance) {
  // Energy bookkeeping (shear_work(), contact_geometry.hpp): B slides by L along y in N equal
  // increments under a constant overlap. Elastic up to |Fs| = mu Fn (at u0 = mu Fn / ks), then
  // Coulomb slip: the spring holds U = (mu Fn)^2 / (2 ks) and slip has dissipated
  // mu Fn (L - u0) (rigid-plastic work; Itasca PFC "Energy tracking", slip energy). Their sum is
  // the work done, mu Fn (L - u0) + mu Fn u0 / 2. Tolerance 1e-6 relative (u0 falls on an
  // increment boundary up to rounding).
  const auto p = linear_params(1e9, 2.5, 0.4);
  const Real r = 1e-3, overlap = 2e-6;
  const Real kn = LinearContact::normal_stiffness(p, r, r, 3), ks = kn / p.kratio, fn0 = kn * overlap;
  const Real u0 = p.fric * fn0 / ks, L = 10 * u0;
  const int N = 4000;  // u0 falls on an increment boundary: 400 increments
  ContactState st;
  ContactGeom g = geom(Vec3::UnitZ(), -overlap, r, r);
  g.d_delta_s = Vec3(0, L / N, 0);
  Real fn, shear = 0, slip = 0;
  for (int k = 0; k < N; ++k) {
    ContactWork w;
    LinearContact::force<true>(p, g, st, 1e-8, 3, fn, &w);
    shear += w.shear;
    slip += w.slip;
  }
  const Real mu_fn = p.fric * fn0;
  EXPECT_NEAR(shear, 0.5 * st.fs.squaredNorm() / ks, 1e-9 * mu_fn * u0);
  EXPECT_NEAR(shear, mu_fn * mu_fn / (2 * ks), 1e-6 * mu_fn * u0);
  EXPECT_NEAR(slip, mu_fn * (L - u0), 1e-6 * mu_fn * L);
}

TEST(LinearContact, StoredShearFollowsTheContactPlane) {
  // METHODS.md 1.2: the stored shear force is projected into the new plane with its magnitude
  // kept, then rotated by the mean spin about n: v <- v - v x (spin dt) n, a rotation by
  // spin*dt to first order. Tolerances: projection exact to 1e-13; the spin rotation agrees with
  // the exact (Rodrigues) rotation to second order, |error| <= angle^2 |v|.
  const auto p = linear_params(1e9, 1.0, 1e6);  // friction high: no slip
  const Real r = 1e-3, overlap = 1e-6, a = 0.01;
  ContactState st;
  st.fs = Vec3(0, 3.0, 0);
  ContactGeom g = geom(Vec3(std::cos(a), std::sin(a), 0), -overlap, r, r);  // plane tilted about z
  Real fn;
  LinearContact::force(p, g, st, 1e-8, 3, fn);
  EXPECT_NEAR(st.fs.dot(g.n), 0.0, 1e-13 * 3.0);
  EXPECT_NEAR(st.fs.norm(), 3.0, 1e-13 * 3.0);
  EXPECT_NEAR(st.fs.x(), -3.0 * std::sin(a), 1e-13 * 3.0);
  // Spin about n by angle b within one step.
  const Real b = 1e-3, dt = 1e-8;
  ContactGeom h = geom(Vec3::UnitX(), -overlap, r, r);
  h.mean_spin_n = b / dt;
  st.fs = Vec3(0, 3.0, 0);
  LinearContact::force(p, h, st, dt, 3, fn);
  const Vec3 exact = Eigen::AngleAxis<Real>(b, Vec3::UnitX()) * Vec3(0, 3.0, 0);
  EXPECT_LT((st.fs - exact).norm(), b * b * 3.0);
  EXPECT_GT(st.fs.z(), 0.99 * 3.0 * b);  // rotated the right way (right-hand rule about n)
}

// --- Hertz-Mindlin -------------------------------------------------------------------------

TEST(HertzMindlin, NormalForceMatchesHertz) {
  // Johnson (1985) Eq. 4.23: F = 4/3 E* sqrt(R*) delta^1.5, E* = E/(2(1-nu^2)) for two bodies of
  // one material, E = 2G(1+nu), R* = RA RB/(RA+RB); against a rigid wall E* = E/(1-nu^2), R* = RA.
  // Tolerance 1e-13 relative.
  HertzMindlinContact::Params p;
  p.shear_modulus = 3e9;
  p.poisson = 0.3;
  p.fric = 0.5;
  const Real E = 2 * 3e9 * 1.3, rA = 1e-3, rB = 3e-3;
  for (Real delta : {1e-7, 1e-6, 2e-5}) {
    ContactGeom g = geom(Vec3(1, 2, 2), -delta, rA, rB);
    ContactState st;
    Real fn;
    const Vec3 f = HertzMindlinContact::force(p, g, st, 1e-8, 3, fn);
    const Real es = E / (2 * (1 - 0.09)), rs = rA * rB / (rA + rB);
    const Real want = 4.0 / 3.0 * es * std::sqrt(rs) * std::pow(delta, 1.5);
    EXPECT_NEAR(fn, want, 1e-13 * want) << "delta " << delta;
    EXPECT_LT((f - want * g.n).norm(), 1e-13 * want);
    ContactGeom gw = geom(Vec3::UnitZ(), -delta, rA, 0);
    HertzMindlinContact::force(p, gw, st, 1e-8, 3, fn);
    const Real want_w = 4.0 / 3.0 * (E / (1 - 0.09)) * std::sqrt(rA) * std::pow(delta, 1.5);
    EXPECT_NEAR(fn, want_w, 1e-13 * want_w) << "wall, delta " << delta;
  }
}

TEST(HertzMindlin, TangentStiffnessesAndSlip) {
  // Tangent normal stiffness dF/d(delta) = 2 E* sqrt(R* delta) against a central difference
  // (tolerance 1e-6 relative: truncation ~ (h/delta)^2 = 1e-8, rounding ~ 1e-10);
  // Mindlin no-slip kt = 8 G* a, a = sqrt(R* delta), G* = G/(2(2-nu)) (Johnson 1985 Eq. 7.35):
  // a small increment gives Fs = -kt ds (1e-13); Coulomb limit |Fs| = mu Fn (1e-13).
  HertzMindlinContact::Params p;
  p.shear_modulus = 3e9;
  p.poisson = 0.25;
  p.fric = 0.3;
  const Real r = 1e-3, delta = 1e-6, h = 1e-10;
  auto fn_at = [&](Real d) {
    ContactGeom g = geom(Vec3::UnitX(), -d, r, r);
    ContactState st;
    Real fn;
    HertzMindlinContact::force(p, g, st, 1e-8, 3, fn);
    return fn;
  };
  const Real kfd = (fn_at(delta + h) - fn_at(delta - h)) / (2 * h);
  EXPECT_NEAR(HertzMindlinContact::normal_stiffness(p, r, r, delta), kfd, 1e-6 * kfd);
  const Real gs = 3e9 / (2 * (2 - 0.25)), a = std::sqrt(0.5 * r * delta), kt = 8 * gs * a;
  ContactGeom g = geom(Vec3::UnitX(), -delta, r, r);
  g.d_delta_s = Vec3(0, 0, 1e-10);
  ContactState st;
  Real fn;
  HertzMindlinContact::force(p, g, st, 1e-8, 3, fn);
  EXPECT_NEAR(st.fs.z(), -kt * 1e-10, 1e-13 * kt * 1e-10);
  g.d_delta_s = Vec3(0, 1e-4, 0);
  HertzMindlinContact::force(p, g, st, 1e-8, 3, fn);
  EXPECT_NEAR(st.fs.norm(), p.fric * fn, 1e-13 * fn);
}

// --- Two bodies in a DemSystem -------------------------------------------------------------

TEST(TwoSphereContact, ForceEqualsClosedFormAndIsEqualAndOpposite) {
  // Two bodies of unequal radii overlapping by delta along a skew axis, at rest: after one step
  // the summed force on B is kn delta n and on A exactly its negative (METHODS.md 1.3; Newton's
  // third law holds bit for bit since both come from the same pair slot). 3D and 2D (the 2D
  // axis lies in the x-y plane). Tolerance 1e-12 relative (the normal is recomputed from x).
  const auto p = linear_params(5e9, 2.0, 0.5);
  const Real rA = 1e-3, rB = 1.5e-3, delta = 2e-6;
  for (int dim : {3, 2}) {
    const Vec3 n = dim == 3 ? Vec3(1, -2, 0.5).normalized() : Vec3(3, 4, 0).normalized();
    const Vec3 xA(0.01, 0.02, dim == 3 ? -0.03 : 0.0);
    DemSystem s = two_bodies(dim, rA, rB, xA, xA + (rA + rB - delta) * n, p);
    s.step();
    const Real kn = LinearContact::normal_stiffness(p, rA, rB, dim);
    const Vec3 want = kn * delta * n;
    EXPECT_LT((s.particles.force[1] - want).norm(), 1e-12 * want.norm()) << "dim " << dim;
    EXPECT_EQ(s.particles.force[0], Vec3(-s.particles.force[1])) << "dim " << dim;
    EXPECT_LT(s.particles.moment[0].norm() + s.particles.moment[1].norm(), 1e-12 * want.norm() * rA);
    EXPECT_EQ(contacts_touching(s), 1);
    // The contact is also the body's only stiffness in the critical time step (METHODS.md 1.6):
    // min(sqrt(m/kn), sqrt(I/(kn r^2))) over the two bodies, the rotational bound being the smaller.
    const Real dt_hand = std::min(std::sqrt(s.particles.inertia[0] / (kn * rA * rA)),
                                  std::sqrt(s.particles.inertia[1] / (kn * rB * rB)));
    EXPECT_NEAR(critical_time_step(s), dt_hand, 1e-12 * dt_hand) << "dim " << dim;
  }
}

TEST(TwoSphereContact, CriticalStepCountsAShearSpringStifferThanTheNormalOne) {
  // kratio = kn/ks < 1 makes the shear spring the stiffer one (ks = 100 kn here). The critical step
  // must bound it: min(sqrt(m/ks), sqrt(I/(ks r^2))) (METHODS.md 1.6 with the stiffest spring), and
  // the shear spring's oscillation during a slow collision, run at 0.8 of that step, must stay
  // bounded (its energy is the bodies' initial kinetic energy). Before (session 48, fuzzed:
  // `dem.contact.*.kratio = 1e-300` ended in NaN at step 0 with the advice to lower the safety
  // factor) the step counted kn alone, 10x too long here, and the velocities grew 1e30-fold.
  const Real kratio = 0.01;
  const auto p = linear_params(5e9, kratio, 1e12);  // friction high enough that the contact never slips
  const Real rA = 1e-3, rB = 1.5e-3, delta = 1e-11;
  for (int dim : {3, 2}) {
    DemSystem s = two_bodies(dim, rA, rB, Vec3::Zero(), Vec3(rA + rB - delta, 0, 0), p);
    const Real ks = LinearContact::normal_stiffness(p, rA, rB, dim) / kratio;
    const Real dt_hand = std::min({std::sqrt(s.particles.mass[0] / ks), std::sqrt(s.particles.mass[1] / ks),
                                   std::sqrt(s.particles.inertia[0] / (ks * rA * rA)),
                                   std::sqrt(s.particles.inertia[1] / (ks * rB * rB))});
    const Real dt = critical_time_step(s);
    EXPECT_NEAR(dt, dt_hand, 1e-12 * dt_hand) << "dim " << dim;
    s.settings.dt = 0.8 * dt;
    const Real v0 = 1e-3;  // approach along x, slide along y
    s.particles.vel[0] = Vec3(v0, 0, 0);
    s.particles.vel[1] = Vec3(-v0, v0, 0);
    const auto kinetic = [&s] {
      Real e = 0;
      for (int i = 0; i < 2; ++i)
        e += 0.5 * (s.particles.mass[i] * s.particles.vel[i].squaredNorm() +
                    s.particles.inertia[i] * s.particles.omega[i].squaredNorm());
      return e;
    };
    const Real e0 = kinetic();
    long touching_steps = 0;
    for (int k = 0; k < 2000; ++k) {
      s.step();
      touching_steps += contacts_touching(s);
    }
    EXPECT_GT(touching_steps, 20) << "dim " << dim;  // the shear spring worked for many steps
    EXPECT_EQ(contacts_touching(s), 0) << "dim " << dim;  // and the bodies parted again
    // with the energy they had (elastic, no damping), up to the leapfrog's error near its stability limit
    // (+1.1 % in 2D; an unstable step multiplies it by orders of magnitude)
    EXPECT_LT(kinetic(), 1.05 * e0) << "dim " << dim;
  }
}

TEST(TwoSphereContact, HeadOnCollisionRestitutionAndDuration) {
  // Head-on collision of two equal spheres with the linear spring (and optional normal dashpot,
  // zeta = fraction of critical damping with m* = m/2): the closed form of the damped oscillator
  // gives e = exp(-pi zeta / sqrt(1 - zeta^2)) and contact time pi / (omega0 sqrt(1 - zeta^2)),
  // omega0 = sqrt(kn/m*) (Schwager & Poeschel 2007, Eqs. 3-6). dt = T/400: the leapfrog and the
  // discrete contact start/end give O(dt/T) errors. Tolerances: e within 1%, duration within 1%.
  const auto p = linear_params(1e9, 1.0, 0.5);
  const Real r = 1e-3, v0 = 0.1;
  for (Real zeta : {0.0, 0.2}) {
    DemSystem s = two_bodies(3, r, r, Vec3::Zero(), Vec3(2 * r + 1e-6, 0, 0), p);
    s.materials.normal_damping_ratio = zeta;
    const Real m = s.particles.mass[0], kn = LinearContact::normal_stiffness(p, r, r, 3);
    const Real omega0 = std::sqrt(kn / (0.5 * m)), wd = omega0 * std::sqrt(1 - zeta * zeta);
    const Real tc = kPi / wd;
    s.settings.dt = tc / 400;
    s.particles.vel[0] = Vec3(v0, 0, 0);
    s.particles.vel[1] = Vec3(-v0, 0, 0);
    long touching_steps = 0;
    for (int k = 0; k < 4000; ++k) {
      s.step();
      touching_steps += contacts_touching(s);
    }
    const Real e = (s.particles.vel[1].x() - s.particles.vel[0].x()) / (2 * v0);
    const Real e_want = std::exp(-kPi * zeta / std::sqrt(1 - zeta * zeta));
    EXPECT_NEAR(e, e_want, 0.01 * e_want) << "zeta " << zeta;
    EXPECT_NEAR(touching_steps * s.settings.dt, tc, 0.01 * tc) << "zeta " << zeta;
    // Momentum stays zero to rounding (equal and opposite forces).
    EXPECT_LT(std::abs(s.particles.vel[0].x() + s.particles.vel[1].x()), 1e-12 * v0);
  }
}
