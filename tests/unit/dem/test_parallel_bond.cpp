// Parallel bond (src/dem/bond/parallel_bond.hpp): loads under prescribed relative motion against
// the closed form, then failure of a bond between two spheres moved by prescribed velocities in
// a DemSystem. Reference: Potyondy & Cundall (2004), Int. J. Rock Mech. Min. Sci. 41:1329,
// Eqs. 3-7 (incremental bond forces, peripheral stresses, strengths), in the PFC 5/6 linearpbond
// form of METHODS.md 1.4 (tension positive; tau_c = c - sigma tan(phi)).
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>

#include "dem/bond/parallel_bond.hpp"
#include "dem/dem_system.hpp"
#include "single_threaded.hpp"
#include "dem/diagnostics.hpp"

using namespace ff;
using namespace ff::dem;
using PB = ParallelBond;

namespace {


PB::Material bond_material() {
  PB::Material m;
  m.emod = 2e9;
  m.kratio = 2.0;
  m.ten = 1e300;  // effectively unbreakable unless a test sets strengths
  m.coh = 1e300;
  m.fa_deg = 0;
  m.lambda = 1;
  m.beta = 1;
  return m;
}

// One bond under test: the law's coefficients, section and state, and the stresses of the last step.
struct Bond {
  PB::Coeffs c;
  PB::Section sec;
  PB::State s;
  PB::Stress st{0, 0};
  Bond(const PB::Material& m, Real rA, Real rB, int dim) : c(PB::coeffs(m)), sec(PB::section(m, rA, rB, dim)) {}
  BondFailure step(const ContactGeom& g, int dim, BondLoad& l) { return PB::compute(c, s, g, 1e-8, dim, l, &st); }
};

// Touching pair along n (gap 0), no relative motion.
ContactGeom geom(const Vec3& n, Real rA, Real rB) {
  ContactGeom g;
  g.n = n.normalized();
  g.gap = 0;
  g.xc = rA * g.n;
  g.rA = rA;
  g.rB = rB;
  g.d_delta_n = 0;
  g.d_delta_s.setZero();
  g.d_theta.setZero();
  g.mean_spin_n = 0;
  return g;
}

::testing::AssertionResult near(const Vec3& a, const Vec3& b, Real tol) {
  if ((a - b).norm() <= tol) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "got (" << a.transpose() << "), want (" << b.transpose() << "), |diff| "
                                       << (a - b).norm() << " > " << tol;
}

// Angular momentum balance of one pair load: M_A + M_B + (xB - xA) x F_B = 0.
Vec3 balance(const ContactGeom& g, const BondLoad& l) {
  return l.moment_on_A + l.moment_on_B + (g.rA + g.rB + g.gap) * g.n.cross(l.force_on_B);
}

const Real rA = 1.0e-3, rB = 1.5e-3;
const Vec3 kAxis = Vec3(1, 2, -2) / 3.0;                  // bond axis (3D)
const Vec3 kPerp = Vec3(2, 1, 2) / 3.0;                   // unit, normal to kAxis
const Vec3 kAxis2 = Vec3(0.6, 0.8, 0), kPerp2(-0.8, 0.6, 0);  // 2D: in the x-y plane

}  // namespace

TEST(ParallelBondLaw, SectionAndStiffness) {
  // P&C 2004 Eq. 3 / METHODS.md 1.4: R = lambda min(RA, RB); 3D A = pi R^2, I = pi R^4/4,
  // J = pi R^4/2; 2D (t = 1) A = 2R, I = 2/3 R^3; kn = E/(RA+RB), ks = kn/kratio. Tol 1e-14 rel.
  auto m = bond_material();
  m.lambda = 0.8;
  const Real R = 0.8 * rA, kn = m.emod / (rA + rB);
  const PB::Section s3 = PB::section(m, rA, rB, 3), s2 = PB::section(m, rA, rB, 2);
  EXPECT_NEAR(s3.R, R, 1e-14 * R);
  EXPECT_NEAR(s3.A, kPi * R * R, 1e-14 * s3.A);
  EXPECT_NEAR(s3.I, kPi * std::pow(R, 4) / 4, 1e-14 * s3.I);
  EXPECT_NEAR(s3.J, kPi * std::pow(R, 4) / 2, 1e-14 * s3.J);
  EXPECT_NEAR(s3.kn, kn, 1e-14 * kn);
  EXPECT_NEAR(s3.ks, kn / 2, 1e-14 * kn);
  EXPECT_NEAR(s2.A, 2 * R, 1e-14 * s2.A);
  EXPECT_NEAR(s2.I, 2.0 / 3.0 * R * R * R, 1e-14 * s2.I);
  EXPECT_EQ(s2.J, 0.0);
  const PB::State st = PB::install();
  EXPECT_EQ(st.Fn, 0.0);  // stress-free at install
  EXPECT_EQ(st.Fs.norm() + st.Mb.norm() + std::abs(st.Mt), 0.0);
}

TEST(ParallelBondLaw, StretchGivesKnADelta) {
  // Fn = kn A d_n (tension > 0); force on B = -Fn n (pulls B back); no moment (force on the axis).
  // Compression (d_n < 0) pushes B along +n. Tolerance 1e-13 relative.
  const auto m = bond_material();
  for (int dim : {3, 2}) {
    const Vec3 n = dim == 3 ? kAxis : kAxis2;
    for (Real d : {1e-7, -1e-7}) {
      Bond b(m, rA, rB, dim);
      ContactGeom g = geom(n, rA, rB);
      g.d_delta_n = d;
      BondLoad l;
      EXPECT_EQ(b.step(g, dim, l), BondFailure::None);
      const Real F = b.sec.kn * b.sec.A * d;
      EXPECT_NEAR(b.s.Fn, F, 1e-13 * std::abs(F));
      EXPECT_TRUE(near(l.force_on_B, -F * n, 1e-13 * std::abs(F)));
      EXPECT_TRUE(near(l.moment_on_A, Vec3::Zero(), 1e-13 * std::abs(F) * rB));
      EXPECT_TRUE(near(l.moment_on_B, Vec3::Zero(), 1e-13 * std::abs(F) * rB));
      EXPECT_NEAR(b.st.sigma, F / b.sec.A, 1e-13 * std::abs(F) / b.sec.A);
    }
  }
}

TEST(ParallelBondLaw, ShearGivesKsADeltaWithLeverArms) {
  // Fs = -ks A ds on B (opposes B's motion); the force acts at the contact point, so the moments
  // about the centres are M_A = -RA n x F, M_B = -RB n x F (METHODS.md 1.4) and the total
  // angular momentum balance is zero. Two increments accumulate. Tolerance 1e-13 relative.
  const auto m = bond_material();
  for (int dim : {3, 2}) {
    const Vec3 n = dim == 3 ? kAxis : kAxis2, t = dim == 3 ? kPerp : kPerp2;
    Bond b(m, rA, rB, dim);
    ContactGeom g = geom(n, rA, rB);
    g.d_delta_s = 1e-7 * t;
    BondLoad l;
    b.step(g, dim, l);
    b.step(g, dim, l);
    const Real F = b.sec.ks * b.sec.A * 2e-7;
    EXPECT_TRUE(near(l.force_on_B, -F * t, 1e-13 * F));
    EXPECT_TRUE(near(l.moment_on_B, rB * F * n.cross(t), 1e-13 * F * rB));
    EXPECT_TRUE(near(l.moment_on_A, rA * F * n.cross(t), 1e-13 * F * rB));
    EXPECT_TRUE(near(balance(g, l), Vec3::Zero(), 1e-13 * F * rB));
    EXPECT_NEAR(b.st.tau, F / b.sec.A, 1e-13 * F / b.sec.A);
    EXPECT_NEAR(b.s.Fn, 0.0, 1e-300);
  }
}

TEST(ParallelBondLaw, TwistGivesKsJTheta) {
  // 3D: Mt = -ks J theta_t about n, on B; -Mt on A; tau = beta |Mt| R/J (P&C 2004 Eq. 7).
  // 2D: no twist term (J unused), nothing happens. Tolerance 1e-13 relative.
  const auto m = bond_material();
  Bond b(m, rA, rB, 3);
  ContactGeom g = geom(kAxis, rA, rB);
  const Real th = 1e-5;
  g.d_theta = th * kAxis;
  BondLoad l;
  b.step(g, 3, l);
  const Real M = b.sec.ks * b.sec.J * th;
  EXPECT_NEAR(b.s.Mt, -M, 1e-13 * M);
  EXPECT_TRUE(near(l.moment_on_B, -M * kAxis, 1e-13 * M));
  EXPECT_TRUE(near(l.moment_on_A, M * kAxis, 1e-13 * M));
  EXPECT_TRUE(near(l.force_on_B, Vec3::Zero(), 1e-300));
  EXPECT_NEAR(b.st.tau, M * b.sec.R / b.sec.J, 1e-13 * M * b.sec.R / b.sec.J);
  Bond b2(m, rA, rB, 2);
  ContactGeom g2 = geom(kAxis2, rA, rB);
  g2.d_theta = th * kAxis2;
  b2.step(g2, 2, l);
  EXPECT_EQ(b2.s.Mt, 0.0);
  EXPECT_EQ(b2.st.tau, 0.0);
}

TEST(ParallelBondLaw, BendGivesKnITheta) {
  // Mb = -kn I theta_b on B, -Mb on A; sigma = Fn/A + beta |Mb| R/I (P&C 2004 Eq. 6).
  // 3D bend about a direction normal to n; 2D bend about z with I = 2/3 R^3. Tolerance 1e-13.
  const auto m = bond_material();
  for (int dim : {3, 2}) {
    const Vec3 n = dim == 3 ? kAxis : kAxis2;
    const Vec3 axis = dim == 3 ? Vec3(kPerp) : Vec3(Vec3::UnitZ());
    Bond b(m, rA, rB, dim);
    ContactGeom g = geom(n, rA, rB);
    const Real th = 1e-5;
    g.d_theta = th * axis;
    BondLoad l;
    b.step(g, dim, l);
    const Real M = b.sec.kn * b.sec.I * th;
    EXPECT_TRUE(near(b.s.Mb, -M * axis, 1e-13 * M)) << "dim " << dim;
    EXPECT_TRUE(near(l.moment_on_B, -M * axis, 1e-13 * M)) << "dim " << dim;
    EXPECT_TRUE(near(l.moment_on_A, M * axis, 1e-13 * M)) << "dim " << dim;
    EXPECT_NEAR(b.st.sigma, M * b.sec.R / b.sec.I, 1e-13 * M * b.sec.R / b.sec.I) << "dim " << dim;
  }
}

TEST(ParallelBondLaw, FailureCriteria) {
  // P&C 2004 / METHODS.md 1.4: tensile crack when sigma >= ten; else shear crack when
  // tau >= coh - (Fn/A) tan(phi). Loads set 0.1% below and above each threshold.
  auto m = bond_material();
  m.ten = 5e6;
  m.coh = 8e6;
  m.fa_deg = 30;
  const Real tanp = std::tan(kPi / 6);
  auto run = [&](int dim, Real dn, Real ds, Real dtheta_b) {
    Bond b(m, rA, rB, dim);
    ContactGeom g = geom(kAxis2, rA, rB);
    g.d_delta_n = dn;
    g.d_delta_s = ds * kPerp2;
    g.d_theta = dtheta_b * Vec3::UnitZ();
    BondLoad l;
    return b.step(g, dim, l);
  };
  for (int dim : {3, 2}) {
    const PB::Section s = PB::section(m, rA, rB, dim);
    const Real dn_t = m.ten / s.kn;                          // pure tension
    EXPECT_EQ(run(dim, 0.999 * dn_t, 0, 0), BondFailure::None);
    EXPECT_EQ(run(dim, 1.001 * dn_t, 0, 0), BondFailure::Tensile);
    const Real th_t = m.ten * s.I / (s.R * s.kn * s.I);      // pure bending: beta Mb R/I = ten
    EXPECT_EQ(run(dim, 0, 0, 0.999 * th_t), BondFailure::None);
    EXPECT_EQ(run(dim, 0, 0, 1.001 * th_t), BondFailure::Tensile);
    const Real ds_c = m.coh / s.ks;                          // pure shear: tau = coh
    EXPECT_EQ(run(dim, 0, 0.999 * ds_c, 0), BondFailure::None);
    EXPECT_EQ(run(dim, 0, 1.001 * ds_c, 0), BondFailure::Shear);
    // Tension sigma0 = 0.5 ten lowers the shear strength to coh - sigma0 tan(phi); compression
    // raises it by the same amount.
    for (Real sig0 : {0.5 * m.ten, -0.5 * m.ten}) {
      const Real ds = (m.coh - sig0 * tanp) / s.ks;
      EXPECT_EQ(run(dim, sig0 / s.kn, 0.999 * ds, 0), BondFailure::None) << "sigma0 " << sig0;
      EXPECT_EQ(run(dim, sig0 / s.kn, 1.001 * ds, 0), BondFailure::Shear) << "sigma0 " << sig0;
    }
  }
}

// --- Bonds in a DemSystem ------------------------------------------------------------------

namespace {

// Two bodies of groups 0 (A, at the origin) and 1 (B, at x = x1 on the x axis), both of infinite
// inertia (inv_mass = inv_inertia = 0), so their velocities stay as prescribed and the relative
// displacement is exactly velocity x time. No bonds yet.
DemSystem pair_system(int dim, const PB::Material& pb, Real r, Real x1) {
  DemSystem s;
  s.settings.dim = dim;
  s.settings.dt = 1e-7;
  s.settings.local_damping = 0;
  s.settings.skin = 0.5 * r;
  s.materials.group_names = {"matrix", "inclusion"};
  s.materials.density = {2500, 2700};
  s.materials.set_contact_law<LinearContact>();
  s.materials.set_bond_law<ParallelBond>();
  LinearContact::Params lc;
  lc.emod = 1e9;
  lc.kratio = 1;
  lc.fric = 0.5;
  s.materials.contact_params<LinearContact>().assign(4, lc);
  s.materials.bond_params<ParallelBond>().assign(4, pb);
  s.particles.resize(2);
  s.particles.radius = {r, r};
  s.particles.pos = {Vec3::Zero(), Vec3(x1, 0, 0)};
  s.particles.group = {0, 1};
  for (std::size_t i = 0; i < 2; ++i) {
    s.particles.set_mass_from_density(i, s.materials.density[s.particles.group[i]], dim);
    s.particles.inv_mass[i] = 0;
    s.particles.inv_inertia[i] = 0;
  }
  return s;
}

// The same pair with a gap, bonded and initialised.
DemSystem bonded_pair(int dim, const PB::Material& pb, Real r, Real gap) {
  DemSystem s = pair_system(dim, pb, r, 2 * r + gap);
  EXPECT_EQ(s.install_bonds(2 * gap), 1u);
  s.initialise();
  return s;
}

// Steps with B moving at velocity v until the bond breaks (at most max_steps); returns the
// number of steps taken (max_steps + 1 if it never broke).
long run_until_break(DemSystem& s, const Vec3& v, long max_steps) {
  s.particles.vel[1] = v;
  for (long k = 1; k <= max_steps; ++k) {
    s.step();
    if (s.bonds.broken[0]) return k;
  }
  return max_steps + 1;
}

}  // namespace

TEST(ParallelBondInSystem, InstallBondsIsInclusiveOfMaxGap) {
  // METHODS.md 1.4 / dem_system.hpp: bonds are installed for every pair with gap <= max_gap.
  // Exactly touching spheres (gap = 0, exactly representable) with max_gap = 0 must be bonded,
  // as must overlapping ones and ones with gap < max_gap; a gap above max_gap must not.
  auto make = [](Real x1) { return pair_system(3, bond_material(), 1e-3, x1); };
  {
    DemSystem s = make(2e-3);  // distance 2e-3 = rA + rB exactly: gap == 0
    EXPECT_EQ((s.particles.pos[1] - s.particles.pos[0]).norm() - 2e-3, 0.0);
    EXPECT_EQ(s.install_bonds(0.0), 1u) << "touching pair (gap 0) not bonded with max_gap 0";
  }
  {
    DemSystem s = make(1.999e-3);  // overlap
    EXPECT_EQ(s.install_bonds(0.0), 1u);
  }
  {
    DemSystem s = make(2.004e-3);  // gap 4e-6 < 5e-6
    EXPECT_EQ(s.install_bonds(5e-6), 1u);
  }
  {
    DemSystem s = make(2.006e-3);  // gap 6e-6 > 5e-6
    EXPECT_EQ(s.install_bonds(5e-6), 0u);
  }
}

TEST(ParallelBondInSystem, BreaksInPureTensionAtTensileStrength) {
  // B pulled along the axis at constant speed: Fn = kn A u t (P&C 2004 Eq. 3), the bond breaks
  // in the first step where Fn/A >= ten (Eq. 6 with Mb = 0). Stress increment per step is 0.1%
  // of ten, so the stress at failure is within 0.1% (stated tolerance 1%) of ten; Fn matches the
  // closed form to 1e-9 (summation rounding). The crack event records mode 1, groups (0, 1),
  // the contact point, the axis and the bond radius (METHODS.md 1.4). 3D and 2D.
  for (int dim : {3, 2}) {
    auto pb = bond_material();
    pb.ten = 1e7;
    pb.coh = 1e9;
    const Real r = 1e-3, gap = 1e-5;
    DemSystem s = bonded_pair(dim, pb, r, gap);
    const PB::Section st0 = PB::section(pb, r, r, dim);
    const Real du = pb.ten / (1000.5 * st0.kn);  // opening per step: ten falls between steps 1000 and 1001
    const Real u = du / s.settings.dt;
    const long k = run_until_break(s, Vec3(u, 0, 0), 2000);
    ASSERT_LE(k, 2000) << "dim " << dim << ": bond never broke";
    const Real sigma_break = st0.kn * du * static_cast<Real>(k);  // closed form at failure
    EXPECT_GE(sigma_break, pb.ten * (1 - 1e-12));
    EXPECT_LT(sigma_break - st0.kn * du, pb.ten);
    EXPECT_NEAR(sigma_break, pb.ten, 0.01 * pb.ten);
    EXPECT_NEAR(s.bonds.state<ParallelBond>()[0].Fn, sigma_break * st0.A, 1e-9 * sigma_break * st0.A);
    EXPECT_EQ(s.bonds.broken[0], 1);
    EXPECT_EQ(intact_bonds(s), 0u);
    ASSERT_EQ(s.cracks.events.size(), 1u);
    const CrackEvent& e = s.cracks.events[0];
    EXPECT_EQ(e.mode, 1);
    EXPECT_EQ(e.group_a, 0);
    EXPECT_EQ(e.group_b, 1);
    EXPECT_EQ(e.i, 0);
    EXPECT_EQ(e.j, 1);
    EXPECT_EQ(s.cracks.tensile, 1);
    EXPECT_EQ(s.cracks.count(1, 0, 1), 1);
    EXPECT_NEAR(e.size, r, 1e-15);
    EXPECT_TRUE(near(e.normal, Vec3::UnitX(), 1e-15));
    EXPECT_NEAR(e.time, s.time - s.settings.dt, 1e-12 * s.time);
    // Contact point of the positions the failure was detected at (before this step's move).
    const Real d_then = 2 * r + gap + (k - 1) * du;
    EXPECT_TRUE(near(e.position, Vec3(r + 0.5 * (d_then - 2 * r), 0, 0), 1e-9 * r));
    // A broken bond carries nothing, from the failing step on.
    EXPECT_EQ(s.bond_loads()[0].f.norm(), 0.0);
    EXPECT_EQ(s.particles.force[1].norm(), 0.0);
    // Pushed back into overlap, only the linear contact acts: F = kn_contact overlap
    // (the bond stays broken; METHODS.md 1.3-1.4, "the linear contact takes over").
    s.particles.vel[1] = Vec3(-u, 0, 0);
    Real overlap = 0;
    for (int q = 0; q < 100000 && overlap <= 0; ++q) {
      overlap = 2 * r - (s.particles.pos[1] - s.particles.pos[0]).norm();
      s.step();
    }
    ASSERT_GT(overlap, 0);
    const Real kn_c = LinearContact::normal_stiffness(s.materials.contact_params<LinearContact>()[1], r, r, dim);
    EXPECT_NEAR(s.particles.force[1].x(), kn_c * overlap, 1e-9 * kn_c * overlap);
    EXPECT_EQ(s.cracks.total(), 1);
  }
}

TEST(ParallelBondInSystem, BreaksInPureShearAtCohesion) {
  // B moved normal to the axis (no rotation, so Mb = Mt = 0 and beta does not enter), friction
  // angle 0: tau = ks us = |Fs|/A (P&C 2004 Eq. 3, 7) and the bond breaks in shear when tau
  // reaches coh. The axis tilts by us/L ~ 1%, so the closed form tau = ks us holds to ~1e-4;
  // increments are 0.1% of coh. Tolerances: tau vs ks us 1e-3, failure stress within 1% of coh.
  for (int dim : {3, 2}) {
    auto pb = bond_material();
    pb.ten = 1e9;
    pb.coh = 1e7;
    pb.fa_deg = 0;
    const Real r = 1e-3, gap = 1e-5;
    DemSystem s = bonded_pair(dim, pb, r, gap);
    const PB::Section st0 = PB::section(pb, r, r, dim);
    const Real du = 1e-3 * pb.coh / st0.ks;
    const long k = run_until_break(s, Vec3(0, du / s.settings.dt, 0), 2000);
    ASSERT_LE(k, 2000) << "dim " << dim << ": bond never broke";
    const Real tau_closed = st0.ks * du * static_cast<Real>(k);
    EXPECT_NEAR(PB::stress(PB::coeffs(pb), st0, s.bonds.state<ParallelBond>()[0]).tau, tau_closed, 1e-3 * tau_closed);
    EXPECT_GE(PB::stress(PB::coeffs(pb), st0, s.bonds.state<ParallelBond>()[0]).tau, pb.coh);
    EXPECT_NEAR(PB::stress(PB::coeffs(pb), st0, s.bonds.state<ParallelBond>()[0]).tau, pb.coh, 0.01 * pb.coh);
    EXPECT_EQ(s.bonds.state<ParallelBond>()[0].Mb.norm() + std::abs(s.bonds.state<ParallelBond>()[0].Mt), 0.0);
    EXPECT_LT(PB::stress(PB::coeffs(pb), st0, s.bonds.state<ParallelBond>()[0]).sigma, 0.01 * pb.coh);  // the small geometric opening, far from ten
    EXPECT_EQ(s.bonds.broken[0], 2);
    ASSERT_EQ(s.cracks.events.size(), 1u);
    EXPECT_EQ(s.cracks.events[0].mode, 2);
    EXPECT_EQ(s.cracks.shear, 1);
    EXPECT_EQ(s.cracks.count(0, 1, 2), 1);
  }
}

TEST(ParallelBondInSystem, ShearStrengthFollowsFrictionAngle) {
  // Pre-stretch (sigma0 = +0.4 ten) or pre-compress (-0.4 ten) along the axis, then shear:
  // failure at tau = coh - (Fn/A) tan(phi) (METHODS.md 1.4; P&C 2004 with tension positive).
  // Increments are 0.1% of the strength. The sideways move also opens the bond by ~us^2/(2L)
  // (Fn/A changes by ~0.1% of ten with this stiff bond), so: tolerance 1% against
  // coh - sigma0 tan(phi), and 0.2% against coh - (Fn/A) tan(phi) with Fn at failure.
  for (Real frac : {0.4, -0.4}) {
    auto pb = bond_material();
    pb.emod = 2e10;
    pb.ten = 2e7;
    pb.coh = 2e7;
    pb.fa_deg = 30;
    const Real r = 1e-3, gap = 1e-5, tanp = std::tan(kPi / 6);
    DemSystem s = bonded_pair(3, pb, r, gap);
    const PB::Section st0 = PB::section(pb, r, r, 3);
    const Real dt = s.settings.dt, sigma0 = frac * pb.ten;
    const long kn_steps = 400;
    s.particles.vel[1] = Vec3(sigma0 / st0.kn / (kn_steps * dt), 0, 0);
    s.run(kn_steps);
    ASSERT_EQ(s.bonds.broken[0], 0);
    EXPECT_NEAR(s.bonds.state<ParallelBond>()[0].Fn / st0.A, sigma0, 1e-9 * pb.ten);
    const Real tau_c = pb.coh - sigma0 * tanp;
    const Real du = 1e-3 * tau_c / st0.ks;
    const long k = run_until_break(s, Vec3(0, du / dt, 0), 3000);
    ASSERT_LE(k, 3000) << "sigma0 " << sigma0 << ": bond never broke";
    EXPECT_EQ(s.bonds.broken[0], 2) << "sigma0 " << sigma0;
    EXPECT_NEAR(PB::stress(PB::coeffs(pb), st0, s.bonds.state<ParallelBond>()[0]).tau, tau_c, 0.01 * tau_c) << "sigma0 " << sigma0;
    const Real tau_c_now = pb.coh - s.bonds.state<ParallelBond>()[0].Fn / st0.A * tanp;
    EXPECT_GE(PB::stress(PB::coeffs(pb), st0, s.bonds.state<ParallelBond>()[0]).tau, tau_c_now);
    EXPECT_NEAR(PB::stress(PB::coeffs(pb), st0, s.bonds.state<ParallelBond>()[0]).tau, tau_c_now, 0.002 * tau_c_now);
  }
}
