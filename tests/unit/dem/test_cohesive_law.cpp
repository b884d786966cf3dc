// Seed 004's cohesive-frictional contact law (src/dem/bond/cohesive_bond.hpp): contact + bond of
// one pair against the closed form of Krzaczek, Tejchman & Nitka (2024), Granular Matter 26:38,
// Appendix A, Eqs. A1-A6, under prescribed relative motion. Tolerance: 1e-12 relative (the law is
// linear in the increments; only rounding separates it from the closed form).
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.hpp"
#include "dem/bond/cohesive_bond.hpp"
#include "dem/dem_params.hpp"
#include "io/scenario.hpp"

using namespace ff;
using namespace ff::dem;

namespace {

constexpr Real kRA = 1e-3, kRB = 2e-3, kEc = 1e9, kNu = 0.3, kFric = 0.5, kC = 20e6, kT = 5e6;
constexpr Real kTol = 1e-12;
const Real kKn = kEc * 2 * kRA * kRB / (kRA + kRB);  // A3: 1.3333e6 N/m
const Real kKs = kNu * kKn;
const Real kR2 = kRA * kRA;  // R = min(RA, RB)

// One pair along +x: the frictional contact (A1-A3, A5) and the cohesive bond (A4, A6).
struct Pair {
  CohesiveContact::Params cp{kEc, kNu, kFric};
  CohesiveContact::State cs;
  CohesiveBond::Material bm{kEc, kNu, kFric, kC, kT};
  CohesiveBond::State bs;
  ContactGeom g;
  bool broken = false;
  BondFailure how = BondFailure::None;
  Vec3 force = Vec3::Zero();  // total force on B

  explicit Pair(Real gap0) {
    g.n = Vec3::UnitX();
    g.rA = kRA;
    g.rB = kRB;
    g.d_theta.setZero();
    g.mean_spin_n = 0;
    set(gap0, Vec3::Zero());
    bs = CohesiveBond::install_at_gap(gap0);
  }
  void set(Real gap, const Vec3& ds) {
    g.d_delta_n = gap - g.gap;
    g.gap = gap;
    g.xc = (kRA + 0.5 * gap) * g.n;
    g.d_delta_s = ds;
  }
  // Moves B to `gap` and by `ds` sideways in one step; returns the total force on B.
  Vec3 step(Real gap, const Vec3& ds = Vec3::Zero()) {
    set(gap, ds);
    Real fn;
    force = CohesiveContact::force(cp, g, cs, 1e-7, 2, fn);
    if (!broken) {
      BondLoad load;
      how = CohesiveBond::compute(bm, bs, g, 1e-7, 2, load);
      if (how != BondFailure::None) broken = true;  // the engine drops a failed bond's load
      else force += load.force_on_B;
    }
    return force;
  }
};

// A1, A3: Fn = Kn U in compression (the contact alone; the bond adds nothing).
TEST(CohesiveLaw, NormalForceIsKnTimesOverlap) {
  Pair p(0);
  for (Real U : {1e-7, 5e-7, 2e-6}) {
    const Vec3 f = p.step(-U);
    EXPECT_NEAR(f.x(), kKn * U, kTol * kKn * U) << U;  // pushes B away from A
    EXPECT_NEAR(p.bs.fn_b, 0, kTol * kKn * U);
  }
}

// A1, A6: tension Kn U (U < 0) until Fn_min = T R^2, then the contact breaks and carries nothing.
TEST(CohesiveLaw, CohesiveTensionUntilCriticalThenBreaks) {
  Pair p(0);
  const Real u_crit = kT * kR2 / kKn;  // 3.75e-6 m
  for (Real frac : {0.25, 0.5, 0.99}) {
    const Vec3 f = p.step(frac * u_crit);
    EXPECT_FALSE(p.broken) << frac;
    EXPECT_NEAR(f.x(), -kKn * frac * u_crit, kTol * kT * kR2) << frac;  // pulls B back
  }
  p.step(1.01 * u_crit);
  EXPECT_TRUE(p.broken);
  EXPECT_EQ(p.how, BondFailure::Tensile);
  EXPECT_EQ(p.force.norm(), 0);
  p.step(-1e-7);  // closed again: the broken contact is the frictional one (A5), compression only
  EXPECT_NEAR(p.force.x(), kKn * 1e-7, kTol * kKn * 1e-7);
  p.step(1e-7);
  EXPECT_EQ(p.force.norm(), 0);
}

// A2, A4: at a fixed overlap the shear force grows as Ks s (one spring, although the contact's own
// spring slips at Fn tan(mu)) until C R^2 + Fn tan(mu_c); then shear breakage; afterwards
// Coulomb's limit Fn tan(mu_c) (A5).
TEST(CohesiveLaw, ShearCohesionPlusFrictionThenCoulomb) {
  const Real U = 2e-6;
  Pair p(0);
  p.step(-U);
  const Real fn = kKn * U;
  const Real cap = kC * kR2 + fn * kFric;  // A4: 20 + 1.333 N
  const Real ds = 1e-8;
  Real s = 0;
  while (true) {
    s += ds;
    p.step(-U, Vec3(0, ds, 0));
    if (p.broken) break;
    EXPECT_NEAR(p.force.y(), -kKs * s, 1e-9 * kKs * s) << s;  // opposes B's motion
    EXPECT_NEAR(p.force.x(), fn, kTol * fn);
    EXPECT_LE(p.cs.fs.norm(), kFric * fn * (1 + kTol));  // the contact's half obeys A5 throughout
    ASSERT_LT(s, 1.0);
  }
  EXPECT_EQ(p.how, BondFailure::Shear);
  // Broke on the first increment beyond the cap: Ks s_break >= cap > Ks (s_break - ds).
  EXPECT_GE(kKs * s, cap);
  EXPECT_LT(kKs * (s - ds), cap);
  p.step(-U, Vec3(0, ds, 0));
  EXPECT_NEAR(p.force.y(), -kFric * fn, kTol * fn);  // sliding at Fn tan(mu_c)
}

// A4 with a tensile Fn: the shear capacity falls to C R^2 + Fn tan(mu_c), Fn < 0.
TEST(CohesiveLaw, TensionLowersShearCapacity) {
  const Real u = 0.5 * kT * kR2 / kKn;
  Pair p(0);
  p.step(u);
  const Real cap = kC * kR2 - 0.5 * kT * kR2 * kFric;  // 20 - 1.25 N
  const Real s_break = cap / kKs;
  p.step(u, Vec3(0, 0.999 * s_break, 0));
  EXPECT_FALSE(p.broken);
  EXPECT_NEAR(p.force.y(), -0.999 * cap, kTol * cap);
  p.step(u, Vec3(0, 0.002 * s_break, 0));
  EXPECT_TRUE(p.broken);
  EXPECT_EQ(p.how, BondFailure::Shear);
}

// Bonded at a gap g0 (bonding tolerance): stress-free there, Kn (g0 - gap) on either side.
TEST(CohesiveLaw, InstalledAtGapIsStressFree) {
  const Real g0 = 1e-6;
  Pair p(g0);
  EXPECT_NEAR(p.step(g0).norm(), 0, 1e-20);
  EXPECT_NEAR(p.step(0.5 * g0).x(), kKn * 0.5 * g0, kTol * kKn * g0);
  EXPECT_NEAR(p.step(-g0).x(), kKn * 2 * g0, kTol * kKn * g0);  // contact Kn g0 + bond Kn g0
  EXPECT_NEAR(p.step(2 * g0).x(), -kKn * g0, kTol * kKn * g0);
}

// The moments balance the force's lever arms (no couple in the seed's law): angular momentum.
TEST(CohesiveLaw, MomentsAreLeverArmsOfTheForce) {
  Pair p(0);
  p.step(-1e-6, Vec3(0, 1e-8, 0));
  BondLoad load;
  CohesiveBond::State s = p.bs;
  CohesiveBond::compute(p.bm, s, p.g, 1e-7, 2, load);
  const Vec3 d = (kRA + kRB + p.g.gap) * p.g.n;  // xB - xA
  const Vec3 total = load.moment_on_A + load.moment_on_B + d.cross(load.force_on_B);
  EXPECT_NEAR(total.norm(), 0, 1e-12 * load.force_on_B.norm() * kRB);
}

// The scenario reads Ec, nu_c and tan(mu_c) once, from the contact table, for both halves; the bond
// refuses a different contact law.
TEST(CohesiveLaw, ScenarioSharesTheContactTable) {
  ParamTable t;
  declare_dem_params(t);
  const std::string base =
      "[dem]\ndim = 2\nbond_law = \"cohesive\"\n[dem.group.m]\ndensity = 2400\n"
      "[dem.contact.m-m]\nec = 3e10\nnu_c = 0.2\nfriction = 0.6\n"
      "[dem.bond.m-m]\ncohesion = 1.5e8\ntension = 3e7\n";
  const Config cfg = load_scenario(t, "", "[dem]\ncontact_law = \"cohesive\"\n" + base.substr(6), {});
  const Materials m = build_materials(cfg);
  const auto& b = m.bond_params<CohesiveBond>()[0];
  EXPECT_EQ(b.ec, 3e10);
  EXPECT_EQ(b.nu_c, 0.2);
  EXPECT_EQ(b.fric, 0.6);
  EXPECT_EQ(b.coh, 1.5e8);
  EXPECT_EQ(b.ten, 3e7);
  const Config wrong = load_scenario(  // contact_law stays "linear"
      t, "",
      "[dem]\ndim = 2\nbond_law = \"cohesive\"\n[dem.group.m]\ndensity = 2400\n[dem.contact.m-m]\nfriction = 0.6\n"
      "[dem.bond.m-m]\ncohesion = 1.5e8\ntension = 3e7\n",
      {});
  EXPECT_THROW(build_materials(wrong), InputError);
}

}  // namespace

// The critical time step counts the stiffer spring: Kn, or Ks = nu_c Kn when nu_c > 1 (A3). Before
// (session 48) the contact and the bond gave Kn alone, so nu_c = 100 ran at 10x the stable step.
TEST(CohesiveLaw, TimeStepStiffnessIsTheStifferSpring) {
  for (Real nu : {0.2, 1.0, 3.0, 100.0}) {
    const CohesiveContact::Params cp{kEc, nu, kFric};
    const Real want = kKn * std::max(1.0, nu);
    EXPECT_NEAR(CohesiveContact::time_step_stiffness(cp, kRA, kRB, 0, 2), want, kTol * want) << nu;
    const CohesiveBond::Material bm{kEc, nu, kFric, kC, kT};
    Real k = 0, krot = 0;
    CohesiveBond::time_step_stiffness(bm, CohesiveBond::State{}, kRA, kRB, 2, k, krot);
    EXPECT_NEAR(k, want, kTol * want) << nu;
  }
}
