// Six-DOF rotational bond (src/dem/bond/rotational_bond.hpp). Reference for the load checks: the
// closed form of a linear beam/spring, load = stiffness x imposed displacement or angle
// (METHODS.md 1.8). Tolerance 1e-9 relative: imposed motions are 1e-5 (relative length or rad),
// so the neglected second-order terms are ~1e-10 and rounding ~eps/1e-5 ~ 2e-11. Finite-angle
// twist and bending are exact in the model, checked to 1e-12.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <atomic>
#include <cstdlib>
#include <new>

#include "core/error.hpp"
#include "core/rng.hpp"
#include "dem/bond/rotational_bond.hpp"

// Counts heap allocations to show that compute() allocates nothing.
namespace {
std::atomic<long> g_allocations{0};
}
void* operator new(std::size_t n) {
  ++g_allocations;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

using namespace ff;
using namespace ff::dem;
using RB = RotationalBond;

namespace {
constexpr Real kRel = 1e-9;

RB::Material rock() {
  RB::Material m{};
  m.youngs_modulus = 10e9;
  m.poisson_ratio = 0.25;
  m.cohesion = 20e6;
  m.friction_angle_deg = 30;
  return m;
}

Quat rotation(const Vec3& rv) {
  const Real a = rv.norm();
  return a > 0 ? Quat(Eigen::AngleAxis<Real>(a, rv / a)) : Quat::Identity();
}
Vec3 random_unit(Rng& g) {
  Vec3 v(g.normal(), g.normal(), g.normal());
  return v.normalized();
}
Quat random_quat(Rng& g) { return rotation(g.uniform(0.1, 3.0) * random_unit(g)); }
// A unit vector normal to a.
Vec3 normal_to(const Vec3& a, Rng& g) { return a.cross(random_unit(g)).normalized(); }

// Two touching particles of unequal radii (lamA = 0.4), bond along g, random orientations.
BondEnds pair(Rng& g, Vec3* axis = nullptr) {
  BondEnds e{};
  e.rA = 1.0e-3;
  e.rB = 1.5e-3;
  const Vec3 dir = random_unit(g);
  e.xA = Vec3(0.3, -0.2, 0.1) + 1e-3 * random_unit(g);
  e.xB = e.xA + (e.rA + e.rB) * dir;
  e.qA = random_quat(g);
  e.qB = random_quat(g);
  if (axis) *axis = dir;
  return e;
}

BondLoad load(const RB::Material& m, RB::State& s, const BondEnds& e, BondFailure* f = nullptr) {
  BondLoad out;
  const BondFailure r = RB::compute(m, s, e, out);
  if (f) *f = r;
  return out;
}

// |a - b| <= tol * scale, printed with both vectors when it fails.
::testing::AssertionResult near(const Vec3& a, const Vec3& b, Real tol, Real scale) {
  const Real err = (a - b).norm();
  if (err <= tol * scale) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "got (" << a.transpose() << "), want (" << b.transpose()
                                       << "), |diff| = " << err << " > " << tol * scale;
}
Vec3 balance(const BondEnds& e, const BondLoad& l) {
  return l.moment_on_A + l.moment_on_B + (e.xB - e.xA).cross(l.force_on_B);
}
}  // namespace

TEST(RotationalBond, StiffnessAndStrengthFromMaterial) {
  // METHODS 1.8: beam of radius R = L0/2 and length L0; strengths from c and phi (ESyS).
  Rng g(1);
  const auto m = rock();
  const BondEnds e = pair(g);
  const RB::State s = RB::install(m, e);
  const Real L0 = e.rA + e.rB, R = L0 / 2, E = m.youngs_modulus, G = E / 2.5, c = m.cohesion;
  const Real tan_phi = std::tan(kPi / 6);
  EXPECT_NEAR(s.r0, L0, 1e-14 * L0);  // |D0| after a rotation: a few eps
  EXPECT_NEAR(s.kr, E * kPi * R * R / L0, 1e-13 * s.kr);
  EXPECT_NEAR(s.ks, G * kPi * R * R / L0, 1e-13 * s.ks);
  EXPECT_NEAR(s.kb, E * kPi * std::pow(R, 4) / 4 / L0, 1e-13 * s.kb);
  EXPECT_NEAR(s.kt, G * kPi * std::pow(R, 4) / 2 / L0, 1e-13 * s.kt);
  EXPECT_NEAR(s.Fn0, kPi * R * R * c / tan_phi, 1e-13 * s.Fn0);
  EXPECT_NEAR(s.Fs0, kPi * R * R * c, 1e-13 * s.Fs0);
  EXPECT_NEAR(s.Mb0, kPi * std::pow(R, 3) * c / (4 * tan_phi), 1e-13 * s.Mb0);
  EXPECT_NEAR(s.Mt0, kPi * std::pow(R, 3) * c / 2, 1e-13 * s.Mt0);
}

TEST(RotationalBond, RejectsBadInput) {
  Rng g(2);
  const BondEnds e = pair(g);
  auto with = [](auto change) { auto m = rock(); change(m); return m; };
  EXPECT_THROW(RB::install(with([](RB::Material& m) { m.friction_angle_deg = 0; }), e), InputError);
  EXPECT_THROW(RB::install(with([](RB::Material& m) { m.truncation = 1.5; }), e), InputError);
  EXPECT_THROW(RB::install(with([](RB::Material& m) { m.poisson_ratio = -1; }), e), InputError);
  EXPECT_THROW(RB::install(with([](RB::Material& m) { m.dim = 1; }), e), InputError);
  BondEnds same = e;
  same.xB = same.xA;
  EXPECT_THROW(RB::install(rock(), same), InputError);
}

TEST(RotationalBond, InstalledBondWithoutMotionCarriesExactlyZeroLoad) {
  Rng g(3);
  const auto m = rock();
  for (int k = 0; k < 20; ++k) {
    const BondEnds e = pair(g);
    RB::State s = RB::install(m, e);
    BondFailure f;
    const BondLoad l = load(m, s, e, &f);
    EXPECT_EQ(f, BondFailure::None);
    for (int i = 0; i < 3; ++i) {
      EXPECT_EQ(l.force_on_B[i], 0.0);
      EXPECT_EQ(l.moment_on_A[i], 0.0);
      EXPECT_EQ(l.moment_on_B[i], 0.0);
    }
    EXPECT_EQ(s.Fn, 0.0);
    EXPECT_EQ(s.Fs, 0.0);
    EXPECT_EQ(s.Mt, 0.0);
    EXPECT_EQ(s.Mb, 0.0);
  }
}

TEST(RotationalBond, PureStretchAndCompression) {
  // F_B = -kr d g (pulls B back in tension, pushes it away in compression), no moments.
  Rng g(4);
  const auto m = rock();
  for (const Real sign : {1.0, -1.0}) {
    Vec3 axis;
    BondEnds e = pair(g, &axis);
    RB::State s = RB::install(m, e);
    const Real d = sign * 1e-5 * s.r0;
    e.xB += d * axis;
    const BondLoad l = load(m, s, e);
    EXPECT_TRUE(near(l.force_on_B, -s.kr * d * axis, kRel, s.kr * std::abs(d)));
    EXPECT_NEAR(s.Fn, s.kr * d, kRel * s.kr * std::abs(d));
    EXPECT_NEAR(RB::energy(s), 0.5 * s.kr * d * d, 1e-8 * s.kr * d * d);  // 1/2 kr d^2
    // "Zero" = rounding of r - D0 (~eps L0) times the shear stiffness, ~1e-11 of the signal.
    EXPECT_LT(l.moment_on_A.norm(), kRel * s.kr * std::abs(d) * s.r0);
    EXPECT_LT(l.moment_on_B.norm(), kRel * s.kr * std::abs(d) * s.r0);
    EXPECT_LT(s.Fs + s.Mt / s.r0 + s.Mb / s.r0, kRel * s.kr * std::abs(d));
  }
}

TEST(RotationalBond, PureShear) {
  // B moves by delta along t (normal to the bond g), orientations fixed:
  // F_B = -ks delta t; the force acts at the contact point x_c = xA + lamA (xB - xA), so
  // M_A = lamA ks delta L0 (g x t), M_B = lamB ks delta L0 (g x t). The normal force is
  // kr delta^2/(2 L0), second order, bounded separately.
  Rng g(5);
  const auto m = rock();
  Vec3 axis;
  BondEnds e = pair(g, &axis);
  RB::State s = RB::install(m, e);
  const Vec3 t = normal_to(axis, g);
  const Real delta = 1e-5 * s.r0, L0 = s.r0, lamA = e.rA / (e.rA + e.rB), lamB = 1 - lamA;
  e.xB += delta * t;
  const BondLoad l = load(m, s, e);
  const Real Fs = s.ks * delta;
  EXPECT_NEAR(s.Fs, Fs, kRel * Fs);
  EXPECT_NEAR(l.force_on_B.dot(t), -Fs, kRel * Fs);
  EXPECT_LT(std::abs(l.force_on_B.dot(axis)), (s.kr + s.ks) * delta * delta / L0);
  EXPECT_TRUE(near(l.moment_on_A, lamA * Fs * L0 * axis.cross(t), kRel, Fs * L0));
  EXPECT_TRUE(near(l.moment_on_B, lamB * Fs * L0 * axis.cross(t), kRel, Fs * L0));
  EXPECT_LT(balance(e, l).norm(), 1e-14 * Fs * L0);
  EXPECT_LT(s.Mt + s.Mb, 1e-9 * Fs * L0);
}

TEST(RotationalBond, MomentBalanceForArbitraryMotions) {
  // Angular momentum conservation: M_A + M_B + (xB - xA) x F_B = 0 to rounding, small or large motion.
  Rng g(6);
  const auto m = rock();
  for (const Real amp : {1e-6, 1e-3, 0.2}) {
    for (int k = 0; k < 100; ++k) {
      BondEnds e = pair(g);
      RB::State s = RB::install(m, e);
      e.xA += amp * s.r0 * Vec3(g.normal(), g.normal(), g.normal());
      e.xB += amp * s.r0 * Vec3(g.normal(), g.normal(), g.normal());
      e.qA = rotation(amp * Vec3(g.normal(), g.normal(), g.normal())) * e.qA;
      e.qB = rotation(amp * Vec3(g.normal(), g.normal(), g.normal())) * e.qB;
      const BondLoad l = load(m, s, e);
      const Real scale = (e.xB - e.xA).norm() * l.force_on_B.norm() + l.moment_on_A.norm() + l.moment_on_B.norm();
      ASSERT_GT(scale, 0);
      EXPECT_LT(balance(e, l).norm(), 1e-14 * scale) << "amplitude " << amp;
    }
  }
}

TEST(RotationalBond, PureTwist) {
  // B turned by psi about the bond axis: M_B = -kt psi g, M_A = +kt psi g, no force.
  // The model measures the twist angle exactly, so a finite angle is checked too.
  Rng g(7);
  const auto m = rock();
  for (const Real psi : {1e-5, -1e-5, 0.5}) {
    Vec3 axis;
    BondEnds e = pair(g, &axis);
    RB::State s = RB::install(m, e);
    e.qB = rotation(psi * axis) * e.qB;
    const BondLoad l = load(m, s, e);
    const Real Mt = s.kt * psi, tol = std::abs(psi) < 1e-3 ? kRel : 1e-12;
    EXPECT_NEAR(s.Mt, std::abs(Mt), tol * std::abs(Mt));
    EXPECT_TRUE(near(l.moment_on_B, -Mt * axis, tol, std::abs(Mt)));
    EXPECT_TRUE(near(l.moment_on_A, Mt * axis, tol, std::abs(Mt)));
    EXPECT_LT(l.force_on_B.norm(), kRel * std::abs(Mt) / s.r0);
    EXPECT_LT(s.Mb, kRel * std::abs(Mt));
  }
  // Twist is relative: turning A by -psi instead loads the bond the same way.
  Vec3 axis;
  BondEnds e = pair(g, &axis);
  RB::State s = RB::install(m, e);
  const Real psi = 1e-5;
  e.qA = rotation(-psi * axis) * e.qA;
  const BondLoad l = load(m, s, e);
  EXPECT_TRUE(near(l.moment_on_A, s.kt * psi * axis, kRel, s.kt * psi));
}

TEST(RotationalBond, PureBending) {
  // B turned by theta about b normal to the bond g. Bending couple = kb theta (Euler-Bernoulli
  // EI/L0 x relative rotation; ESyS uses kb theta/2, see the header). Turning B also moves its
  // contact point by lamB L0 theta (b x g), which loads the shear spring:
  //   F_B = ks lamB L0 theta (b x g),
  //   M_A = (kb - ks lamA lamB L0^2) theta b,   M_B = -(kb + ks lamB^2 L0^2) theta b.
  Rng g(8);
  const auto m = rock();
  for (const Real theta : {1e-5, 0.4}) {
    Vec3 axis;
    BondEnds e = pair(g, &axis);
    RB::State s = RB::install(m, e);
    const Vec3 b = normal_to(axis, g);
    const Real L0 = s.r0, lamA = e.rA / (e.rA + e.rB), lamB = 1 - lamA;
    e.qB = rotation(theta * b) * e.qB;
    const BondLoad l = load(m, s, e);
    const Real tol = theta < 1e-3 ? kRel : 1e-12;             // the angle is exact at any size
    EXPECT_NEAR(s.Mb, s.kb * theta, tol * s.kb * theta);
    EXPECT_LT(s.Mt, tol * s.kb * theta);
    if (theta > 1e-3) continue;  // the closed forms below are first order
    const Vec3 F = s.ks * lamB * L0 * theta * b.cross(axis);
    const Vec3 MA = (s.kb - s.ks * lamA * lamB * L0 * L0) * theta * b;
    const Vec3 MB = -(s.kb + s.ks * lamB * lamB * L0 * L0) * theta * b;
    EXPECT_TRUE(near(l.force_on_B, F, kRel, F.norm()));
    EXPECT_TRUE(near(l.moment_on_A, MA, kRel, MB.norm()));
    EXPECT_TRUE(near(l.moment_on_B, MB, kRel, MB.norm()));
    EXPECT_NEAR(s.Fs, F.norm(), kRel * F.norm());
  }
}

TEST(RotationalBond, RigidBodyMotionGivesNoLoadAndLoadsRotateWithThePair) {
  // Objectivity: rotating both positions and orientations by one finite rotation (plus a
  // translation) leaves the bond unloaded, and turns the load of a deformed bond with it.
  Rng g(9);
  const auto m = rock();
  for (int k = 0; k < 20; ++k) {
    BondEnds e = pair(g);
    RB::State s = RB::install(m, e);
    const Quat R = rotation(g.uniform(0.5, 3.0) * random_unit(g));
    const Vec3 pivot = random_unit(g), shift = 0.01 * random_unit(g);
    auto move = [&](BondEnds x) {
      x.xA = R * (x.xA - pivot) + pivot + shift;
      x.xB = R * (x.xB - pivot) + pivot + shift;
      x.qA = R * x.qA;
      x.qB = R * x.qB;
      return x;
    };
    const BondLoad l0 = load(m, s, move(e));
    EXPECT_LT(l0.force_on_B.norm(), 1e-12 * s.kr * s.r0);
    EXPECT_LT(l0.moment_on_A.norm() + l0.moment_on_B.norm(), 1e-12 * s.kr * s.r0 * s.r0);

    e.xB += 1e-3 * s.r0 * random_unit(g);
    e.qB = rotation(1e-3 * random_unit(g)) * e.qB;
    e.qA = rotation(1e-3 * random_unit(g)) * e.qA;
    const BondLoad l1 = load(m, s, e);
    const BondLoad l2 = load(m, s, move(e));
    const Real Fs = l1.force_on_B.norm(), Ms = l1.moment_on_A.norm() + l1.moment_on_B.norm();
    // Rounding of the moved coordinates (~eps x 1 m) against a 2.5 um deformation: ~1e-10.
    EXPECT_TRUE(near(l2.force_on_B, R * l1.force_on_B, kRel, Fs));
    EXPECT_TRUE(near(l2.moment_on_A, R * l1.moment_on_A, kRel, Ms));
    EXPECT_TRUE(near(l2.moment_on_B, R * l1.moment_on_B, kRel, Ms));
  }
}

TEST(RotationalBond, SwappingTheEndsGivesTheSameLoadToFirstOrder) {
  // A's frame is the reference, but the physics must not depend on which end is A: with the
  // ends swapped, force on the new B = -force on the old B and the moments trade places, up to
  // second-order terms (relative size ~ the motion, 1e-7 here).
  Rng g(10);
  const auto m = rock();
  for (int k = 0; k < 50; ++k) {
    BondEnds e = pair(g);
    const BondEnds f0{e.xB, e.xA, e.qB, e.qA, e.rB, e.rA};
    RB::State s = RB::install(m, e), t = RB::install(m, f0);
    const Real eps = 1e-7;
    e.xA += eps * s.r0 * random_unit(g);
    e.xB += eps * s.r0 * random_unit(g);
    e.qA = rotation(eps * random_unit(g)) * e.qA;
    e.qB = rotation(eps * random_unit(g)) * e.qB;
    const BondEnds f{e.xB, e.xA, e.qB, e.qA, e.rB, e.rA};
    const BondLoad l = load(m, s, e), lf = load(m, t, f);
    const Real Fs = l.force_on_B.norm(), Ms = l.moment_on_A.norm() + l.moment_on_B.norm();
    EXPECT_TRUE(near(lf.force_on_B, -l.force_on_B, 1e-5, Fs));
    EXPECT_TRUE(near(lf.moment_on_A, l.moment_on_B, 1e-5, Ms));
    EXPECT_TRUE(near(lf.moment_on_B, l.moment_on_A, 1e-5, Ms));
  }
}

TEST(RotationalBond, TangentStiffnessIsSymmetricWithSixRigidModes) {
  // A linear elastic bond derives from a potential: its 12x12 tangent stiffness at the
  // installed state is symmetric (Maxwell-Betti), positive semi-definite, and its null space is
  // the six rigid-body modes. Central differences, h = 1e-6: truncation ~1e-12, rounding ~1e-10.
  Rng g(11);
  const auto m = rock();
  const BondEnds e0 = pair(g);
  RB::State s = RB::install(m, e0);
  const Real L0 = s.r0, h = 1e-6;
  // Coordinates (xA/L0, xB/L0, thetaA, thetaB) -> conjugate forces (F_A L0, F_B L0, M_A, M_B).
  auto forces = [&](int j, Real step) {
    BondEnds e = e0;
    Vec3 dq = Vec3::Zero();
    dq[j % 3] = step;
    if (j < 3) e.xA += L0 * dq;
    else if (j < 6) e.xB += L0 * dq;
    else if (j < 9) e.qA = rotation(dq) * e.qA;
    else e.qB = rotation(dq) * e.qB;
    const BondLoad l = load(m, s, e);
    Eigen::Matrix<Real, 12, 1> f;
    f << -L0 * l.force_on_B, L0 * l.force_on_B, l.moment_on_A, l.moment_on_B;
    return f;
  };
  Eigen::Matrix<Real, 12, 12> K;
  for (int j = 0; j < 12; ++j) K.col(j) = -(forces(j, h) - forces(j, -h)) / (2 * h);
  const Real kmax = K.cwiseAbs().maxCoeff();
  EXPECT_LT((K - K.transpose()).cwiseAbs().maxCoeff(), 1e-7 * kmax);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<Real, 12, 12>> eig(0.5 * (K + K.transpose()));
  const auto ev = eig.eigenvalues();  // ascending
  for (int i = 0; i < 6; ++i) EXPECT_LT(std::abs(ev[i]), 1e-7 * kmax) << "mode " << i;
  for (int i = 6; i < 12; ++i) EXPECT_GT(ev[i], 1e-3 * kmax) << "mode " << i;
}

namespace {
// Raises the imposed motion in steps of 1/2000 of `to_failure` until the bond breaks; returns
// the mode and leaves the state of the breaking step in s.
template <class Apply>
BondFailure load_until_break(const RB::Material& m, RB::State& s, const BondEnds& e0, Real to_failure,
                             Apply apply, BondLoad* last = nullptr) {
  for (int i = 1; i <= 4000; ++i) {
    BondEnds e = e0;
    apply(e, i * to_failure / 2000);
    BondLoad l;
    const BondFailure f = RB::compute(m, s, e, l);
    if (last) *last = l;
    if (f != BondFailure::None) return f;
  }
  return BondFailure::None;
}
}  // namespace

TEST(RotationalBond, TensileFailureAtTheTensileStrength) {
  // ESyS RotBond criterion, pure tension: N = Fn/Fn0 > t = 1 -> tensile crack at Fn = Fn0.
  Rng g(12);
  const auto m = rock();
  Vec3 axis;
  const BondEnds e0 = pair(g, &axis);
  RB::State s = RB::install(m, e0);
  BondLoad l;
  const auto f = load_until_break(m, s, e0, s.Fn0 / s.kr, [&](BondEnds& e, Real d) { e.xB += d * axis; }, &l);
  EXPECT_EQ(f, BondFailure::Tensile);
  EXPECT_NEAR(s.Fn, s.Fn0, 0.01 * s.Fn0);
  EXPECT_NEAR(l.force_on_B.norm(), s.Fn, 1e-6 * s.Fn);  // the load is still reported

  // Truncation t = 0.5: the tension cut-off halves the tensile strength.
  auto mt = rock();
  mt.truncation = 0.5;
  RB::State st = RB::install(mt, e0);
  EXPECT_EQ(load_until_break(mt, st, e0, st.Fn0 / st.kr, [&](BondEnds& e, Real d) { e.xB += d * axis; }),
            BondFailure::Tensile);
  EXPECT_NEAR(st.Fn, 0.5 * st.Fn0, 0.01 * st.Fn0);
}

TEST(RotationalBond, TwistFailureAtTheTorsionalStrength) {
  // S = Mt/Mt0 (beta2 = 1) > 1 - N = 1 -> shear crack at Mt = Mt0.
  Rng g(13);
  const auto m = rock();
  Vec3 axis;
  const BondEnds e0 = pair(g, &axis);
  RB::State s = RB::install(m, e0);
  const auto f = load_until_break(m, s, e0, s.Mt0 / s.kt, [&](BondEnds& e, Real psi) { e.qB = rotation(psi * axis) * e.qB; });
  EXPECT_EQ(f, BondFailure::Shear);
  EXPECT_NEAR(s.Mt, s.Mt0, 0.01 * s.Mt0);
}

TEST(RotationalBond, ShearFailureAtTheShearStrengthRaisedByCompression) {
  // S = Fs/Fs0 > 1 - N: shear crack at Fs = Fs0 without normal load (the second-order stretch
  // of a sheared bond lowers it by < 0.1%), and at Fs = 1.5 Fs0 under a compression Fn = -Fn0/2
  // (ESyS "direct Mohr-Coulomb": the signed Fn enters N).
  Rng g(14);
  const auto m = rock();
  for (const Real pre : {0.0, -0.5}) {
    Vec3 axis;
    const BondEnds e0 = pair(g, &axis);
    RB::State s = RB::install(m, e0);
    const Vec3 t = normal_to(axis, g);
    const Real squeeze = pre * s.Fn0 / s.kr;
    const auto f = load_until_break(m, s, e0, s.Fs0 / s.ks,
                                    [&](BondEnds& e, Real d) { e.xB += squeeze * axis + d * t; });
    EXPECT_EQ(f, BondFailure::Shear);
    EXPECT_NEAR(s.Fn, pre * s.Fn0, 0.01 * s.Fn0);
    EXPECT_NEAR(s.Fs, (1 - pre) * s.Fs0, 0.01 * s.Fs0) << "precompression " << pre;
  }
}

TEST(RotationalBond, DisksInThePlaneMatchTheClosedForms) {
  // dim = 2: positions in the x-y plane, rotations about z only. Stretch and shear follow the
  // same closed forms as in 3-D; twist and out-of-plane components vanish exactly; an in-plane
  // rotation of B is pure bending about z with couple kb theta.
  Rng g(15);
  auto m = rock();
  m.dim = 2;
  const Vec3 z = Vec3::UnitZ();
  auto disks = [&]() {
    BondEnds e{};
    e.rA = 1.0e-3;
    e.rB = 1.5e-3;
    const Real a = g.uniform(0, 2 * kPi);
    e.xA = Vec3(0.1, 0.2, 0);
    e.xB = e.xA + (e.rA + e.rB) * Vec3(std::cos(a), std::sin(a), 0);
    e.qA = rotation(g.uniform(-3, 3) * z);
    e.qB = rotation(g.uniform(-3, 3) * z);
    return e;
  };
  {  // stretch
    BondEnds e = disks();
    RB::State s = RB::install(m, e);
    const Vec3 axis = (e.xB - e.xA).normalized();
    const Real d = 1e-5 * s.r0;
    e.xB += d * axis;
    const BondLoad l = load(m, s, e);
    EXPECT_TRUE(near(l.force_on_B, -s.kr * d * axis, kRel, s.kr * d));
    EXPECT_LT(l.moment_on_A.norm() + l.moment_on_B.norm(), kRel * s.kr * d * s.r0);
  }
  {  // shear
    BondEnds e = disks();
    RB::State s = RB::install(m, e);
    const Vec3 axis = (e.xB - e.xA).normalized(), t = z.cross(axis);
    const Real delta = 1e-5 * s.r0, lamA = 0.4, Fs = s.ks * delta;
    e.xB += delta * t;
    const BondLoad l = load(m, s, e);
    EXPECT_NEAR(s.Fs, Fs, kRel * Fs);
    EXPECT_NEAR(l.force_on_B.dot(t), -Fs, kRel * Fs);
    EXPECT_TRUE(near(l.moment_on_A, lamA * Fs * s.r0 * z, kRel, Fs * s.r0));
    EXPECT_TRUE(near(l.moment_on_B, (1 - lamA) * Fs * s.r0 * z, kRel, Fs * s.r0));
  }
  {  // in-plane rotation of B = bending about z
    BondEnds e = disks();
    RB::State s = RB::install(m, e);
    const Real theta = 1e-5;
    e.qB = rotation(theta * z) * e.qB;
    const BondLoad l = load(m, s, e);
    EXPECT_NEAR(s.Mb, s.kb * theta, 1e-12 * s.kb * theta);
    EXPECT_EQ(s.Mt, 0.0);
    const Real MB = -(s.kb + s.ks * 0.36 * s.r0 * s.r0) * theta;  // lamB = 0.6
    EXPECT_NEAR(l.moment_on_B.z(), MB, kRel * std::abs(MB));
  }
  for (int k = 0; k < 50; ++k) {  // random in-plane motion: nothing leaves the plane
    BondEnds e = disks();
    RB::State s = RB::install(m, e);
    e.xA += 1e-3 * s.r0 * Vec3(g.normal(), g.normal(), 0);
    e.xB += 1e-3 * s.r0 * Vec3(g.normal(), g.normal(), 0);
    e.qA = rotation(0.01 * g.normal() * z) * e.qA;
    e.qB = rotation(0.01 * g.normal() * z) * e.qB;
    const BondLoad l = load(m, s, e);
    EXPECT_EQ(l.force_on_B.z(), 0.0);
    EXPECT_EQ(l.moment_on_A.x(), 0.0);
    EXPECT_EQ(l.moment_on_A.y(), 0.0);
    EXPECT_EQ(l.moment_on_B.x(), 0.0);
    EXPECT_EQ(l.moment_on_B.y(), 0.0);
    EXPECT_EQ(s.Mt, 0.0);
    EXPECT_GT(l.force_on_B.norm(), 0.0);
  }
}

TEST(RotationalBond, ComputeDoesNotAllocate) {
  Rng g(16);
  const auto m = rock();
  BondEnds e = pair(g);
  RB::State s = RB::install(m, e);
  e.xB += 1e-4 * random_unit(g);
  BondLoad l;
  Real sink = 0;
  const long before = g_allocations.load();
  for (int i = 0; i < 1000; ++i) {
    e.qB = rotation(1e-6 * Vec3::UnitX()) * e.qB;
    RB::compute(m, s, e, l);
    sink += l.force_on_B.x();
  }
  EXPECT_EQ(g_allocations.load(), before);
  EXPECT_TRUE(std::isfinite(sink));
}
