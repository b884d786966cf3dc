// Flexible-wall membrane (src/dem/membrane): triangle closest point and contact geometry,
// sleeve geometry, servo law, vertex update rule, contacts at shared edges/vertices, and the
// confinement reached around a rigid cylinder of fixed spheres.
// References: METHODS.md 3 ([S000] Zhao, Konietzky & Herbst 2021, sec. 5.1, Figs. 8-9; Itasca
// PFC "wall servo"), METHODS.md 1.2-1.3 (ball-facet geometry, linear contact kn = pi r E*),
// Ericson (2005) Real-Time Collision Detection sec. 5.1.5 (closest point on a triangle).
#include <gtest/gtest.h>
#include <omp.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <new>
#include <sstream>
#include <vector>

#include "core/error.hpp"
#include "core/rng.hpp"
#include "dem/contact/hertz_mindlin.hpp"
#include "dem/contact/linear_contact.hpp"
#include "dem/membrane/flexible_membrane.hpp"
#include "single_threaded.hpp"  // one thread by default; MembraneThreads checks 1 vs 3

// Heap allocations are counted while `counting` is set (MembraneAllocation). Not inlined, so
// GCC does not see malloc/free through new/delete at the call sites (-Wmismatched-new-delete).
namespace {
std::atomic<bool> counting{false};
std::atomic<long> allocations{0};
}  // namespace
[[gnu::noinline]] void* operator new(std::size_t n) {
  if (counting.load(std::memory_order_relaxed)) allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
[[gnu::noinline]] void operator delete(void* p) noexcept { std::free(p); }
[[gnu::noinline]] void operator delete(void* p, std::size_t) noexcept { std::free(p); }

using namespace ff;
using namespace ff::dem;

namespace {

constexpr Real kE = 1e9;  // linear contact modulus E* [Pa]

std::vector<LinearContact::Params> linear_params() {
  LinearContact::Params p;
  p.emod = kE;
  p.kratio = 1.5;
  p.fric = 0.5;
  return {p};
}

// A handful of particles at rest (the membrane tests never integrate them).
struct Balls {
  std::vector<Vec3> pos, vel, omega;
  std::vector<Real> radius;
  std::vector<std::int32_t> group;
  void add(const Vec3& x, Real r) {
    pos.push_back(x);
    vel.push_back(Vec3::Zero());
    omega.push_back(Vec3::Zero());
    radius.push_back(r);
    group.push_back(0);
  }
  MembraneParticles view() const { return {pos, vel, omega, radius, group}; }
};

MembraneSettings sleeve(int nt, int nz, Real R, Real H) {
  MembraneSettings s;
  s.n_theta = nt;
  s.n_z = nz;
  s.radius = R;
  s.z0 = 0;
  s.height = H;
  s.pressure = 1e6;
  s.r_min = 0.5 * R;
  return s;
}

// Sum of the forces on the particle (minus the forces on the elements) and the number of
// candidates carrying a force.
Vec3 force_on_particles(const FlexibleMembrane& m, int& active) {
  Vec3 f = Vec3::Zero();
  active = 0;
  for (const auto& L : m.candidate_loads()) {
    f -= L.f;
    active += L.f.squaredNorm() > 0;
  }
  return f;
}

Real point_triangle_brute(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, int n) {
  Real best = std::numeric_limits<Real>::infinity();
  for (int i = 0; i <= n; ++i)
    for (int j = 0; i + j <= n; ++j) {
      const Real u = Real(i) / n, v = Real(j) / n;
      best = std::min(best, (a + u * (b - a) + v * (c - a) - p).norm());
    }
  return best;
}

}  // namespace

// Ericson (2005) sec. 5.1.5 against brute-force sampling of the triangle (n = 300 subdivisions:
// the sample nearest the true closest point is within h = max edge / 300 of it, so the sampled
// distance exceeds the exact one by at most h; it can never be smaller, to round-off 1e-12).
// Feature checked from the barycentric weights (zero weight = off that corner's opposite side).
TEST(MembraneTriangle, ClosestPointMatchesBruteForceAndFeature) {
  Rng rng(7);
  int seen[7] = {};
  for (int t = 0; t < 60; ++t) {
    const Vec3 a(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    const Vec3 b(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    const Vec3 c(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    const Vec3 p(rng.uniform(-2, 2), rng.uniform(-2, 2), rng.uniform(-2, 2));
    const TriClosest cp = closest_point_on_triangle(p, a, b, c);
    const Real exact = (cp.point - p).norm();
    const Real h = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()}) / 300;
    const Real brute = point_triangle_brute(p, a, b, c, 300);
    EXPECT_GE(brute, exact - 1e-12);
    EXPECT_LE(brute, exact + h);
    // Barycentric weights reproduce the point and match the feature.
    EXPECT_LT((cp.bary[0] * a + cp.bary[1] * b + cp.bary[2] * c - cp.point).norm(), 1e-12);
    const unsigned mask = feature_corners(cp.feature);
    for (int q = 0; q < 3; ++q) {
      if (mask >> q & 1u) EXPECT_GE(cp.bary[q], -1e-12);
      else EXPECT_EQ(cp.bary[q], 0.0);
    }
    ++seen[static_cast<int>(cp.feature)];
  }
  // Each Voronoi region by construction: the right triangle (0,0,0), (1,0,0), (0,1,0).
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  struct Case { Vec3 p; TriFeature f; Vec3 q; };
  const Case cases[] = {{{0.2, 0.2, 0.5}, TriFeature::Face, {0.2, 0.2, 0}},
                        {{0.5, -0.3, 0.1}, TriFeature::Edge01, {0.5, 0, 0}},
                        {{0.8, 0.8, -0.2}, TriFeature::Edge12, {0.5, 0.5, 0}},
                        {{-0.4, 0.5, 0.3}, TriFeature::Edge20, {0, 0.5, 0}},
                        {{-0.3, -0.2, 0.4}, TriFeature::Vertex0, {0, 0, 0}},
                        {{1.5, -0.1, 0.0}, TriFeature::Vertex1, {1, 0, 0}},
                        {{-0.1, 1.4, 0.2}, TriFeature::Vertex2, {0, 1, 0}}};
  for (const auto& k : cases) {
    const TriClosest cp = closest_point_on_triangle(k.p, a, b, c);
    EXPECT_EQ(cp.feature, k.f);
    EXPECT_LT((cp.point - k.q).norm(), 1e-14);
  }
  EXPECT_GT(seen[0] + seen[1] + seen[2] + seen[3] + seen[4] + seen[5] + seen[6], 0);
}

// METHODS.md 1.2 ball-facet geometry: n from the centre to the closest point, gap = d - R,
// xc = x + (R + gap/2) n; no contact for a centre behind the facet (exact arithmetic).
TEST(MembraneTriangle, BallFacetGeometry) {
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0), inward(0, 0, 1);
  const Vec3 x(0.25, 0.25, 0.1);
  ContactGeom g;
  ASSERT_TRUE(ball_triangle(g, closest_point_on_triangle(x, a, b, c), x, 0.125, inward));
  EXPECT_DOUBLE_EQ(g.gap, 0.1 - 0.125);
  EXPECT_EQ(g.n, Vec3(0, 0, -1));
  EXPECT_NEAR((g.xc - Vec3(0.25, 0.25, 0.1 - 0.125 - 0.5 * g.gap)).norm(), 0, 1e-15);
  EXPECT_EQ(g.rB, 0.0);
  const Vec3 behind(0.25, 0.25, -0.05);
  EXPECT_FALSE(ball_triangle(g, closest_point_on_triangle(behind, a, b, c), behind, 0.125, inward));
}

// Undeformed sleeve vs the polygonal cylinder (METHODS.md 3 geometry): every triangle is half a
// planar chord x dh rectangle, A = R sin(pi/N) dh, normal horizontal towards the axis at the unit's
// mid-angle; total area N chord H = 2 pi R H sin(pi/N)/(pi/N); enclosed volume between any two
// planes = (N/2) R^2 sin(2 pi/N) (z_hi - z_lo). Tolerance: round-off, 1e-12 relative.
TEST(MembraneGeometry, UndeformedSleeveMatchesPolygonalCylinder) {
  const int nt = 16, nz = 6;
  const Real R = 0.02, H = 0.05, dh = H / nz;
  MembraneSettings s = sleeve(nt, nz, R, H);
  s.axis_x = 0.003;
  s.axis_y = -0.001;
  const FlexibleMembrane m(s);
  ASSERT_EQ(m.element_count(), 2u * nt * nz);
  ASSERT_EQ(m.vertex_count(), std::size_t(nt) * (nz + 1));
  const Real a_exp = R * std::sin(kPi / nt) * dh;
  Real total = 0;
  for (std::size_t k = 0; k < m.element_count(); ++k) {
    const int unit = static_cast<int>(k / 2), i = unit % nt;
    const Real mid = 2 * kPi * (i + 0.5) / nt;
    EXPECT_NEAR(m.area(k), a_exp, 1e-12 * a_exp);
    EXPECT_LT((m.normal(k) - Vec3(-std::cos(mid), -std::sin(mid), 0)).norm(), 1e-12);
    const auto& t = m.element_vertices(k);
    const Vec3 c = (m.vertices()[t[0]] + m.vertices()[t[1]] + m.vertices()[t[2]]) / 3.0;
    EXPECT_LT((m.centroid(k) - c).norm(), 1e-15);
    total += m.area(k);
  }
  EXPECT_NEAR(total, 2 * kPi * R * H * std::sin(kPi / nt) / (kPi / nt), 1e-12 * total);
  const Real z_lo = 0.3 * dh, z_hi = 4.6 * dh;
  const Real v_exp = 0.5 * nt * R * R * std::sin(2 * kPi / nt) * (z_hi - z_lo);
  EXPECT_NEAR(m.enclosed_volume(z_lo, z_hi), v_exp, 1e-12 * v_exp);
  std::vector<Real> rr(nz + 1), zz(nz + 1);
  m.radial_profile(rr, zz);
  for (int j = 0; j <= nz; ++j) {
    EXPECT_NEAR(rr[j], R, 1e-15);
    EXPECT_NEAR(zz[j], j * dh, 1e-15);
  }
  EXPECT_EQ(membrane_square_rows(R, nt, H), static_cast<int>(std::lround(H / (2 * R * std::sin(kPi / nt)))));
}

// Enclosed volume of a randomly dented sleeve against slicing: the cross-section area A(z)
// (shoelace over the triangle/plane intersection segments, oriented by the outward normal)
// integrated with the composite midpoint rule on 4000 slices. A(z) is piecewise quadratic with
// kinks at the vertex heights, so the quadrature error is ~1e-7 relative; tolerance 1e-5.
TEST(MembraneGeometry, EnclosedVolumeOfDeformedSleeveMatchesSlicing) {
  const int nt = 12, nz = 5;
  const Real R = 0.02, H = 0.05;
  FlexibleMembrane m(sleeve(nt, nz, R, H));
  Rng rng(3);
  std::vector<Vec3> x(m.vertices().begin(), m.vertices().end()), v(x.size(), Vec3::Zero());
  for (auto& p : x) {
    const Vec3 rad(p.x(), p.y(), 0);
    p += rng.uniform(-0.15, 0.15) * rad + Vec3(0, 0, rng.uniform(-1e-3, 1e-3));
  }
  m.restore_vertices(x, v);
  const Real z_lo = 0.012, z_hi = 0.041;
  auto section = [&](Real z) {
    Real area = 0;
    for (std::size_t k = 0; k < m.element_count(); ++k) {
      const auto& t = m.element_vertices(k);
      Vec3 pts[2];
      int np = 0;
      for (int e = 0; e < 3; ++e) {
        const Vec3 &P = m.vertices()[t[e]], &Q = m.vertices()[t[(e + 1) % 3]];
        if ((P.z() - z) * (Q.z() - z) < 0 && np < 2) pts[np++] = P + (z - P.z()) / (Q.z() - P.z()) * (Q - P);
      }
      if (np < 2) continue;
      Vec3 d = pts[1] - pts[0];
      const Vec3 tangent = Vec3::UnitZ().cross(-m.normal(k));  // counter-clockwise seen from +z
      if (d.dot(tangent) < 0) std::swap(pts[0], pts[1]);
      area += 0.5 * (pts[0].x() * pts[1].y() - pts[1].x() * pts[0].y());
    }
    return area;
  };
  const int ns = 4000;
  Real vol = 0;
  for (int q = 0; q < ns; ++q) vol += section(z_lo + (q + 0.5) * (z_hi - z_lo) / ns) * (z_hi - z_lo) / ns;
  EXPECT_NEAR(m.enclosed_volume(z_lo, z_hi), vol, 1e-5 * vol);
}

// Servo law of METHODS.md 3 (PFC wall servo): v_n = alpha (F^t + F^c)/(K^c dt), |v_n| <= v_max,
// v_max inward without contact; F^c < 0 when the sample pushes back. Tolerance: round-off.
TEST(MembraneServo, SignAndCap) {
  const Real ft = 10, dt = 1e-6, a = 0.8, vmax = 0.01, K = 1e7;
  EXPECT_EQ(FlexibleMembrane::servo_law(ft, 0, 0, dt, a, vmax), vmax);             // no contact: inward
  // Too little push: inward, alpha (F^t + F^c)/(K dt).
  EXPECT_NEAR(FlexibleMembrane::servo_law(ft, -9.9, K, dt, a, vmax), a * 0.1 / (K * dt), 1e-12);
  EXPECT_LT(FlexibleMembrane::servo_law(ft, -10.1, K, dt, a, vmax), 0);           // pushed harder than p A: outward
  EXPECT_EQ(FlexibleMembrane::servo_law(ft, -1e3, K, dt, a, vmax), -vmax);        // capped
  EXPECT_EQ(FlexibleMembrane::servo_law(ft, 0, K, dt, a, vmax), vmax);
}

// The same signs through the membrane: with no particle every vertex moves inward at v_max
// (Nodal rule: along its radial line) and stops at r_min (the clamp); an element pressed by a
// sphere harder than p A gets v_n = alpha (p A - kn delta)/(kn dt) < 0 and its owned vertex P(i,j)
// moves outward by v_n n dt (Owner rule of METHODS.md 3). Tolerance: round-off.
TEST(MembraneServo, FreeRowsMoveInAndClampAtRMinPressedElementMovesOut) {
  const int nt = 12, nz = 3;
  const Real R = 0.02, H = 0.03, dt = 1e-4;
  MembraneSettings s = sleeve(nt, nz, R, H);
  s.v_max = 0.5;  // 5e-5 m per step
  s.r_min = 0.017;
  FlexibleMembrane m(s);
  Balls none;
  m.find_candidates(none.pos, none.radius, 1e-3);
  m.compute_forces<LinearContact>(none.view(), linear_params(), 1, dt);
  m.move(dt, 0, H);
  // Nodal rule: each vertex moved by d = v_max dt along its radial line.
  const Real r1 = R - s.v_max * dt;
  for (std::size_t k = 0; k < m.element_count(); ++k) EXPECT_EQ(m.servo_velocity(k), s.v_max);
  for (std::size_t v = 0; v < m.vertex_count(); ++v)
    EXPECT_NEAR(Vec3(m.vertices()[v].x(), m.vertices()[v].y(), 0).norm(), r1, 1e-15);
  for (int step = 0; step < 200; ++step) {
    m.compute_forces<LinearContact>(none.view(), linear_params(), 1, dt);
    m.move(dt, 0, H);
  }
  for (const Vec3& x : m.vertices()) EXPECT_NEAR(Vec3(x.x(), x.y(), 0).norm(), s.r_min, 1e-12);

  // Pressed element (Owner rule): T1 of unit (2,1), sphere overlapping it by kn delta = 3 p A.
  s.rule = MembraneVertexRule::Owner;
  FlexibleMembrane m2(s);
  const std::size_t k = 2 * (1 * nt + 2);
  const Real r = 1e-3, kn = kPi * r * kE;
  const Real delta = 3 * s.pressure * m2.area(k) / kn;
  Balls b;
  b.add(m2.centroid(k) + (r - delta) * m2.normal(k), r);
  m2.find_candidates(b.pos, b.radius, 1e-4);
  m2.compute_forces<LinearContact>(b.view(), linear_params(), 1, dt);
  EXPECT_NEAR(m2.contact_force(k), -kn * delta, 1e-9 * kn * delta);
  EXPECT_EQ(m2.contact_stiffness(k), kn);
  const Vec3 owned = m2.vertices()[m2.vertex_index(2, 1)], n_before = m2.normal(k);
  const Real v_exp = std::max(-s.v_max, s.relaxation * (s.pressure * m2.area(k) - kn * delta) / (kn * dt));
  m2.move(dt, 0, H);
  EXPECT_LT(v_exp, 0);
  EXPECT_NEAR(m2.servo_velocity(k), v_exp, 1e-12 * std::abs(v_exp));
  const Vec3 moved = m2.vertices()[m2.vertex_index(2, 1)] - owned;
  EXPECT_LT((moved - v_exp * dt * n_before).norm(), 1e-12 * std::abs(v_exp) * dt);
  EXPECT_GT(moved.dot(Vec3(owned.x(), owned.y(), 0)), 0);  // outward
}

// One element (a lone translating triangle) servo-controlled against a fixed sphere, linear and
// Hertz contact: F^c -> -p A. METHODS.md 3 asks 1 % at equilibrium; a single contact relaxes
// geometrically (factor 1 - alpha_s per step for the linear law, Newton-like for Hertz), so after
// 400 steps the error is below 1e-6 relative.
TEST(MembraneServo, SingleElementReachesTargetForceAgainstFixedSphere) {
  const Real L = 0.01, p = 1e6, pA = p * 0.5 * L * L, r = 1e-3, dt = 1e-6, vmax = 1.0, alpha = 0.8;
  const Vec3 a(0, 0, 0), b(L, 0, 0), c(0, L, 0), inward = Vec3::UnitZ();
  const Vec3 x(L / 3, L / 3, r + 1e-4);
  auto run = [&](auto law, const auto& prm) {
    using Law = decltype(law);
    Real u = 0, v = 0, fc = 0;
    ContactState st;
    for (int step = 0; step < 400; ++step) {
      const Vec3 du = u * inward;
      const TriClosest cp = closest_point_on_triangle(x, a + du, b + du, c + du);
      ContactGeom g;
      fc = 0;
      Real kc = 0;
      if (ball_triangle(g, cp, x, r, inward) && g.gap < 0) {
        contact_kinematics(g, x, Vec3::Zero(), Vec3::Zero(), g.xc, v * inward, Vec3::Zero(), dt);
        Real fn;
        fc = Law::force(prm, g, st, dt, 3, fn).dot(inward);
        if constexpr (std::is_same_v<Law, LinearContact>) kc = Law::normal_stiffness(prm, r, 0, 3);
        else kc = Law::normal_stiffness(prm, r, 0, -g.gap);
      }
      v = FlexibleMembrane::servo_law(pA, fc, kc, dt, alpha, vmax);
      u += v * dt;
    }
    return fc;
  };
  EXPECT_NEAR(-run(LinearContact{}, linear_params()[0]), pA, 1e-6 * pA);
  HertzMindlinContact::Params hp;
  hp.shear_modulus = 4e8;
  hp.poisson = 0.25;
  EXPECT_NEAR(-run(HertzMindlinContact{}, hp), pA, 1e-6 * pA);
}

namespace {
// Sphere of radius r whose centre sits at distance r - delta from `surface_point` along `inward`.
struct Probe {
  FlexibleMembrane m;
  Balls b;
  explicit Probe(const MembraneSettings& s) : m(s) {}
  Vec3 press(const Vec3& surface_point, const Vec3& inward, Real r, Real delta, int& active) {
    b = Balls{};
    b.add(surface_point + (r - delta) * inward, r);
    m.find_candidates(b.pos, b.radius, 0.2 * r);
    m.compute_forces<LinearContact>(b.view(), linear_params(), 1, 1e-6);
    return force_on_particles(m, active);
  }
};
}  // namespace

// Friction of the element contacts (issue 4: "the same contact law and friction as everything
// else"). A sphere pressed by delta on the middle of a face slides along the axis, faster than
// its shear spring can hold in one step (ks v dt = 6.7 mu Fn at mu = 0.5), so the shear force on
// it is mu Fn against the motion: mu = the particle's own contact friction (0.5 here) with
// kGroupFriction, the membrane's friction otherwise (0.2, and 0 for a lubricated sleeve).
// Tolerance: round-off, 1e-9 relative.
TEST(MembraneContact, SlidingSphereFeelsTheMembraneOrItsOwnFriction) {
  const Real R = 0.01, H = 0.02, r = 1e-3, delta = 1e-6, v = 5.0, dt = 1e-6;
  const Real kn = kPi * r * kE;  // linear contact, rB = 0 (METHODS.md 1.3)
  for (Real mu : {kGroupFriction, 0.2, 0.0}) {
    MembraneSettings s = sleeve(16, 4, R, H);
    s.friction = mu;
    FlexibleMembrane m(s);
    const std::size_t k = 2 * (16 + 3);  // lower triangle of unit (3, 1), away from every edge
    Balls b;
    b.add(m.centroid(k) + (r - delta) * m.normal(k), r);
    b.vel[0] = Vec3(0, 0, v);
    m.find_candidates(b.pos, b.radius, 0.2 * r);
    m.compute_forces<LinearContact>(b.view(), linear_params(), 1, dt);
    int active = 0;
    const Vec3 f = force_on_particles(m, active);
    ASSERT_EQ(active, 1);
    const Real want_mu = mu == kGroupFriction ? linear_params()[0].fric : mu;
    EXPECT_NEAR(f.dot(m.normal(k)), kn * delta, 1e-9 * kn * delta) << "mu " << mu;  // pushed towards the axis
    EXPECT_NEAR(f.z(), -want_mu * kn * delta, 1e-9 * kn * delta) << "mu " << mu;
  }
}

// No double counting (file comment of flexible_membrane.hpp): a sphere pressed by delta on a
// face, on the shared diagonal of a (flat) unit, on the shared edge between two rows, and on an
// inward-pushed vertex (a ridge: one vertex contact over six elements) gets exactly one contact
// of force kn delta along the surface normal, kn = pi r E* (METHODS.md 1.3, rB = 0). In a concave
// crease (vertical edge between two units) it touches both faces, each with kn x its own overlap.
// Tolerance: round-off, 1e-9 relative.
TEST(MembraneContact, SharedEdgesAndVerticesCountOnce) {
  const int nt = 16, nz = 4;
  const Real R = 0.02, H = 0.04, r = 1e-3, delta = 2e-5, kn = kPi * r * kE;
  Probe pr(sleeve(nt, nz, R, H));
  FlexibleMembrane& m = pr.m;
  const std::size_t t1 = 2 * (1 * nt + 2), t2 = t1 + 1;  // unit (2,1)
  const Vec3 n = m.normal(t1);
  auto P = [&](int i, int j) { return m.vertices()[m.vertex_index(i, j)]; };
  int active = 0;
  Vec3 f = pr.press(m.centroid(t1), n, r, delta, active);  // face
  EXPECT_EQ(active, 1);
  EXPECT_LT((f - kn * delta * n).norm(), 1e-9 * kn * delta);
  EXPECT_NEAR(m.contact_force(t1), -kn * delta, 1e-9 * kn * delta);
  f = pr.press(0.5 * (P(3, 1) + P(2, 2)), n, r, delta, active);  // diagonal shared by T1, T2
  EXPECT_EQ(active, 1);
  EXPECT_LT((f - kn * delta * n).norm(), 1e-9 * kn * delta);
  EXPECT_NEAR(m.contact_force(t1) + m.contact_force(t2), -kn * delta, 1e-9 * kn * delta);
  f = pr.press(0.7 * P(2, 1) + 0.3 * P(3, 1), n, r, delta, active);  // edge between rows 0 and 1
  EXPECT_EQ(active, 1);
  EXPECT_LT((f - kn * delta * n).norm(), 1e-9 * kn * delta);

  // Concave crease: the vertical edge P(3,1)-P(3,2) between units 2 and 3. Centre on the
  // bisector at distance h from the edge; each face (at half the crease angle) is at h cos(pi/N).
  const Vec3 e_mid = 0.5 * (P(3, 1) + P(3, 2));
  const Vec3 bis = -Vec3(e_mid.x(), e_mid.y(), 0).normalized();
  const Real h = r - delta;
  f = pr.press(e_mid, bis, r, delta, active);
  EXPECT_EQ(active, 2);
  const Real each = kn * (r - h * std::cos(kPi / nt));
  EXPECT_NEAR(f.dot(bis), 2 * each * std::cos(kPi / nt), 1e-9 * each);
  EXPECT_NEAR(f.z(), 0.0, 1e-9 * each);

  // Ridge: push vertex (3,2) 2.5 mm towards the axis; a sphere on the radial line through it
  // finds the vertex as the closest point of all six elements around it -> one contact.
  std::vector<Vec3> x(m.vertices().begin(), m.vertices().end()), v(x.size(), Vec3::Zero());
  const std::size_t vi = m.vertex_index(3, 2);
  const Vec3 rad_in = -Vec3(x[vi].x(), x[vi].y(), 0).normalized();
  x[vi] += 2.5e-3 * rad_in;
  m.restore_vertices(x, v);
  f = pr.press(x[vi], rad_in, r, delta, active);
  EXPECT_EQ(active, 1);
  EXPECT_LT((f - kn * delta * rad_in).norm(), 1e-9 * kn * delta);
  int touched = 0;
  for (std::size_t k = 0; k < m.element_count(); ++k) touched += m.contact_force(k) != 0;
  EXPECT_EQ(touched, 1);
}

namespace {
// Fixed spheres of radius r centred on a cylinder of radius rc (axis z), rings of n spheres
// every sqrt(3) r in z, alternate rings rotated by half a spacing (a "rigid cylinder").
Balls sphere_cylinder(Real rc, Real r, Real z_lo, Real z_hi) {
  Balls b;
  const int n = static_cast<int>(std::floor(2 * kPi * rc / (2 * r)));
  int ring = 0;
  for (Real z = z_lo; z <= z_hi + 1e-12; z += std::sqrt(3.0) * r, ++ring)
    for (int q = 0; q < n; ++q) {
      const Real a = 2 * kPi * (q + 0.5 * (ring % 2)) / n;
      b.add(Vec3(rc * std::cos(a), rc * std::sin(a), z), r);
    }
  return b;
}

constexpr Real kCylR = 0.02, kBallR = 1e-3, kDt = 1e-6, kSkin = 2e-4;

// Membrane around sphere_cylinder(kCylR, kBallR, 12 mm, 48 mm): 16 x 7 nearly square units,
// vertices 0.5 mm off the spheres (facet middles 0.09 mm), 60 mm long (free rows above and
// below the spheres), p = 1 MPa.
MembraneSettings cylinder_settings(MembraneVertexRule rule) {
  MembraneSettings s;
  s.n_theta = 16;
  s.radius = kCylR + kBallR + 5e-4;
  s.height = 0.06;
  s.n_z = membrane_square_rows(s.radius, s.n_theta, s.height);
  s.pressure = 1e6;
  s.v_max = 2.0;  // 2 um per step at dt = 1 us: the servo is not speed-capped near equilibrium
  s.r_min = 0.019;
  s.rule = rule;
  return s;
}

// Steps the membrane against fixed particles (forces, then move), rebuilding candidates with
// the engine's skin criterion; ends with fresh forces at the final position.
template <class Law>
void step_fixed(FlexibleMembrane& m, const Balls& b, std::span<const typename Law::Params> prm, int steps) {
  Real z_lo = 1e300, z_hi = -1e300;  // "platens" touching the first and last ring
  for (std::size_t i = 0; i < b.pos.size(); ++i) {
    z_lo = std::min(z_lo, b.pos[i].z() - b.radius[i]);
    z_hi = std::max(z_hi, b.pos[i].z() + b.radius[i]);
  }
  m.find_candidates(b.pos, b.radius, kSkin);
  for (int step = 0; step < steps; ++step) {
    if (m.motion_since_build() + m.max_step_motion(kDt) > 0.5 * kSkin) m.find_candidates(b.pos, b.radius, kSkin);
    m.compute_forces<Law>(b.view(), prm, 1, kDt);
    m.move(kDt, z_lo, z_hi);
  }
  m.find_candidates(b.pos, b.radius, kSkin);
  m.compute_forces<Law>(b.view(), prm, 1, kDt);
}
}  // namespace

// METHODS.md 3 acceptance: sum F^c / sum A = p within ~1 % at equilibrium. Around a rigid
// cylinder of fixed spheres the Nodal rule reaches it (tolerance 1 %; measured 1e-8 for both
// laws) and stops where it touches; the free rows above and below the spheres fall to r_min.
// Single elements are balanced only on average (their load depends on where the discrete
// contacts sit: 0.04-1.8 p A measured), so per element we check no deep overlap instead.
TEST(MembraneCylinder, NodalRuleReachesConfiningPressure) {
  const Balls b = sphere_cylinder(kCylR, kBallR, 0.012, 0.048);
  FlexibleMembrane m(cylinder_settings(MembraneVertexRule::Nodal));
  step_fixed<LinearContact>(m, b, linear_params(), 1500);
  EXPECT_NEAR(m.mean_confinement(), 1e6, 1e4);
  const int nt = m.settings().n_theta, nz = m.settings().n_z;
  std::vector<Real> rr(nz + 1), zz(nz + 1);
  m.radial_profile(rr, zz);
  EXPECT_NEAR(rr[0], m.settings().r_min, 1e-12);
  EXPECT_NEAR(rr[nz], m.settings().r_min, 1e-12);
  for (int j = 2; j <= nz - 2; ++j)  // rings inside the sphere band are at rest
    for (int i = 0; i < nt; ++i)
      EXPECT_LT(m.vertex_velocities()[m.vertex_index(i, j)].norm(), 1e-3 * m.settings().v_max);
  Real fmax = 0;
  int loaded = 0, in_band = 0;
  for (const auto& L : m.candidate_loads()) fmax = std::max(fmax, L.f.norm());
  for (std::size_t k = 0; k < m.element_count(); ++k) {
    in_band += m.loaded_area(k) > 0;
    loaded += m.contacts(k) > 0;
  }
  // Nothing pushed deep (a single contact at p A needs 11 um) and most band elements carry load.
  EXPECT_LT(fmax / (kPi * kBallR * kE), 3e-5);
  EXPECT_GT(loaded, in_band * 3 / 4);
  HertzMindlinContact::Params hp;
  hp.shear_modulus = 4e8;
  hp.poisson = 0.25;
  const HertzMindlinContact::Params hps[] = {hp};
  FlexibleMembrane mh(cylinder_settings(MembraneVertexRule::Nodal));
  step_fixed<HertzMindlinContact>(mh, b, hps, 1500);
  EXPECT_NEAR(mh.mean_confinement(), 1e6, 1e4);
}

// The Owner rule as read in METHODS.md 3 (vertex follows T1 of its unit) does not converge:
// each T1 drives one vertex but feels three, and T2 gets no feedback, so some vertices are driven
// deep into the spheres. Same run as above: the mean confinement overshoots p many times over
// (measured 16-100 MPa over 200-2000 steps; 29-86 MPa even with v_max 40x lower). This test
// documents why Nodal is the default; it fails if the Owner rule ever converges.
TEST(MembraneCylinder, OwnerRuleOverPresses) {
  const Balls b = sphere_cylinder(kCylR, kBallR, 0.012, 0.048);
  FlexibleMembrane m(cylinder_settings(MembraneVertexRule::Owner));
  step_fixed<LinearContact>(m, b, linear_params(), 300);
  EXPECT_GT(m.mean_confinement(), 5e6);
}

// Closure (METHODS.md 3: the sleeve stays closed while it bulges unevenly). Random spheres give
// every element its own servo velocity; after the update (both rules) the triangles still tile
// the sleeve: their outward vector areas sum to VA(bottom ring) - VA(top ring) (any gap or
// overlap breaks this; round-off 1e-12 relative). Owner: each vertex moved exactly by its owner's
// translation v_n n dt (T1 of its unit; T2 of the unit below for the top row). Nodal: each vertex
// moved along its own radial line by at most v_max dt.
TEST(MembraneVertexUpdate, SleeveStaysClosedAfterRandomElementMotions) {
  const int nt = 12, nz = 4;
  const Real R = 0.02, H = 0.04, dt = 1e-5;
  for (auto rule : {MembraneVertexRule::Owner, MembraneVertexRule::Nodal}) {
    MembraneSettings s = sleeve(nt, nz, R, H);
    s.rule = rule;
    s.v_max = 1.0;
    FlexibleMembrane m(s);
    Rng rng(11);
    Balls b;
    for (std::size_t k = 0; k < m.element_count(); k += 1 + k % 3) {
      const Real r = rng.uniform(0.5e-3, 1.5e-3), delta = rng.uniform(0, 4e-5);
      b.add(m.centroid(k) + (r - delta) * m.normal(k), r);
    }
    const std::vector<Vec3> x0(m.vertices().begin(), m.vertices().end());
    for (int step = 0; step < 5; ++step) {
      std::vector<Vec3> before(m.vertices().begin(), m.vertices().end()), n_before(m.element_count());
      for (std::size_t k = 0; k < m.element_count(); ++k) n_before[k] = m.normal(k);
      m.find_candidates(b.pos, b.radius, 1e-4);
      m.compute_forces<LinearContact>(b.view(), linear_params(), 1, dt);
      m.move(dt, 0.25 * H, 0.8 * H);
      for (int j = 0; j <= nz; ++j)
        for (int i = 0; i < nt; ++i) {
          const std::size_t v = m.vertex_index(i, j);
          const Vec3 d = m.vertices()[v] - before[v];
          if (rule == MembraneVertexRule::Owner) {
            const std::size_t owner = j < nz ? 2 * (j * nt + i) : 2 * ((nz - 1) * nt + i) + 1;
            EXPECT_LT((d - m.servo_velocity(owner) * dt * n_before[owner]).norm(), 1e-12 * s.v_max * dt);
          } else {
            EXPECT_LT(d.cross(Vec3(x0[v].x(), x0[v].y(), 0)).norm(), 1e-12 * R * s.v_max * dt);
            EXPECT_EQ(d.z(), 0.0);
            EXPECT_LE(d.norm(), s.v_max * dt * (1 + 1e-12));
          }
        }
      Real vmin = 1e300, vmax = -1e300;
      for (std::size_t k = 0; k < m.element_count(); ++k) {
        vmin = std::min(vmin, m.servo_velocity(k));
        vmax = std::max(vmax, m.servo_velocity(k));
      }
      EXPECT_LT(vmin, 0.5 * vmax);  // the elements really moved differently
    }
    Vec3 sleeve_area = Vec3::Zero(), bottom = Vec3::Zero(), top = Vec3::Zero();
    for (std::size_t k = 0; k < m.element_count(); ++k) {
      const auto& t = m.element_vertices(k);
      const Vec3 &a = m.vertices()[t[0]], &bb = m.vertices()[t[1]], &c = m.vertices()[t[2]];
      Vec3 va = 0.5 * (bb - a).cross(c - a);
      if (va.dot(m.normal(k)) > 0) va = -va;  // outward
      sleeve_area += va;
    }
    for (int i = 0; i < nt; ++i) {
      bottom += 0.5 * m.vertices()[m.vertex_index(i, 0)].cross(m.vertices()[m.vertex_index(i + 1, 0)]);
      top += 0.5 * m.vertices()[m.vertex_index(i, nz)].cross(m.vertices()[m.vertex_index(i + 1, nz)]);
    }
    EXPECT_LT((sleeve_area - (bottom - top)).norm(), 1e-12 * R * H);
  }
}

// Candidate search (uniform grid over element boxes) against brute force over every
// (particle, element) pair of a dented sleeve: same pairs (distance < r + skin), same order.
TEST(MembraneCandidates, MatchBruteForce) {
  const int nt = 14, nz = 5;
  const Real R = 0.02, H = 0.05, skin = 3e-4;
  FlexibleMembrane m(sleeve(nt, nz, R, H));
  Rng rng(5);
  std::vector<Vec3> x(m.vertices().begin(), m.vertices().end()), v(x.size(), Vec3::Zero());
  for (auto& p : x) p += rng.uniform(-0.1, 0.1) * Vec3(p.x(), p.y(), 0);
  m.restore_vertices(x, v);
  Balls b;
  for (int i = 0; i < 3000; ++i) {
    const Real a = rng.uniform(0, 2 * kPi), rho = rng.uniform(0.0, 1.2 * R);
    b.add(Vec3(rho * std::cos(a), rho * std::sin(a), rng.uniform(-0.005, H + 0.005)), rng.uniform(2e-4, 1.5e-3));
  }
  m.find_candidates(b.pos, b.radius, skin);
  std::vector<std::pair<Index, Index>> brute;
  for (std::size_t i = 0; i < b.pos.size(); ++i)
    for (std::size_t k = 0; k < m.element_count(); ++k) {
      const auto& t = m.element_vertices(k);
      const TriClosest cp = closest_point_on_triangle(b.pos[i], x[t[0]], x[t[1]], x[t[2]]);
      if ((cp.point - b.pos[i]).norm() < b.radius[i] + skin) brute.emplace_back(Index(i), Index(k));
    }
  ASSERT_EQ(m.candidate_particles().size(), brute.size());
  for (std::size_t c = 0; c < brute.size(); ++c) {
    EXPECT_EQ(m.candidate_particles()[c], brute[c].first);
    EXPECT_EQ(m.candidate_elements()[c], brute[c].second);
  }
  EXPECT_GT(brute.size(), 300u);
}

// Results do not depend on the thread count (STYLE rules): the parallel contact loop writes
// per-candidate slots and every sum runs serially in candidate order. Bit-identical vertices.
TEST(MembraneThreads, BitIdenticalOnOneAndThreeThreads) {
  const Balls b = sphere_cylinder(kCylR, kBallR, 0.012, 0.048);
  auto run = [&](int threads) {
    omp_set_num_threads(threads);
    MembraneSettings s = cylinder_settings(MembraneVertexRule::Nodal);
    s.parallel_min = 0;
    FlexibleMembrane m(s);
    step_fixed<LinearContact>(m, b, linear_params(), 300);
    omp_set_num_threads(1);
    return std::vector<Vec3>(m.vertices().begin(), m.vertices().end());
  };
  const auto one = run(1), three = run(3);
  ASSERT_EQ(one.size(), three.size());
  for (std::size_t v = 0; v < one.size(); ++v) EXPECT_EQ(one[v], three[v]);
}

// VTK PolyData of the sleeve (io/vtk.hpp): one triangle cell per element and the per-element
// arrays ParaView needs to show the bulge.
TEST(MembraneOutput, WritesTrianglesWithCellArrays) {
  FlexibleMembrane m(sleeve(8, 3, 0.02, 0.03));
  const auto path = std::filesystem::temp_directory_path() / "fracflow_test_membrane.vtp";
  m.write_vtk(path);
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  EXPECT_NE(text.find("NumberOfPoints=\"32\""), std::string::npos);
  EXPECT_NE(text.find("NumberOfPolys=\"48\""), std::string::npos);
  for (const char* name : {"area", "pressure", "servo_velocity", "velocity", "normal", "contacts"})
    EXPECT_NE(text.find(std::string("Name=\"") + name + "\""), std::string::npos) << name;
  std::filesystem::remove(path);
}

// Bad settings are input errors naming the parameter.
TEST(MembraneSettings, RejectsBadInput) {
  MembraneSettings s = sleeve(16, 4, 0.02, 0.04);
  s.r_min = 0;
  EXPECT_THROW(FlexibleMembrane{s}, InputError);
  s = sleeve(2, 4, 0.02, 0.04);
  EXPECT_THROW(FlexibleMembrane{s}, InputError);
  s = sleeve(16, 4, 0.02, 0.04);
  s.relaxation = 1.5;
  EXPECT_THROW(FlexibleMembrane{s}, InputError);
}

namespace {
// Spheres of the cylinder tied to their places by springs ks (an elastic "sample"), stepped with
// the membrane in the engine's order; `rebuild_every` > 0 forces extra candidate rebuilds.
struct SpringSample {
  static constexpr Real ks = 1e6;
  Balls b = sphere_cylinder(kCylR, kBallR, 0.012, 0.048);
  std::vector<Vec3> anchor = b.pos, at_build = b.pos, F = b.pos, M = b.pos;
  Real mass = 2600 * 4.0 / 3.0 * kPi * kBallR * kBallR * kBallR;
  Real dt = 0.2 * std::sqrt(mass / (kPi * kBallR * kE + ks));
  FlexibleMembrane m;
  static MembraneSettings settings() {
    MembraneSettings s = cylinder_settings(MembraneVertexRule::Nodal);
    s.radius = membrane_circumradius(kCylR + kBallR + 2e-5, s.n_theta);
    s.v_max = 5;
    return s;
  }
  SpringSample() : m(settings()) { m.find_candidates(b.pos, b.radius, kSkin); }
  void run(int steps, int rebuild_every, std::span<const LinearContact::Params> prm) {
    for (int step = 0; step < steps; ++step) {
      Real moved = 0;
      for (std::size_t i = 0; i < b.pos.size(); ++i) moved = std::max(moved, (b.pos[i] - at_build[i]).norm());
      if (moved + m.motion_since_build() + m.max_step_motion(dt) > 0.5 * kSkin ||
          (rebuild_every > 0 && step % rebuild_every == 0)) {
        m.find_candidates(b.pos, b.radius, kSkin);
        at_build = b.pos;
      }
      m.compute_forces<LinearContact>(b.view(), prm, 1, dt);
      for (std::size_t i = 0; i < b.pos.size(); ++i) {
        F[i] = -ks * (b.pos[i] - anchor[i]);
        M[i].setZero();
      }
      m.add_loads_to(F, M);
      for (std::size_t i = 0; i < b.pos.size(); ++i) {  // local damping 0.7 + leapfrog
        Vec3 f = F[i];
        for (int c = 0; c < 3; ++c) f[c] -= 0.7 * std::abs(f[c]) * (b.vel[i][c] > 0 ? 1 : (b.vel[i][c] < 0 ? -1 : 0));
        b.vel[i] += f / mass * dt;
        b.pos[i] += b.vel[i] * dt;
      }
      m.move(dt, 0.011, 0.048);
    }
  }
};
}  // namespace

// Moving particles, in the engine's step order (forces, gather, local damping 0.7 + leapfrog of
// METHODS.md 1.1 and 1.5, then move): each sphere of the cylinder is tied to its place by a
// spring ks = 1e6 N/m, dt = 0.2 sqrt(m/(kn + ks)), v_max dt = 1.8 um (not speed-capped near
// equilibrium). The coupled system settles: mean confinement = p within 1 % (measured 1e-6),
// and the springs carry the applied load: the mean inward displacement matches
// p sum A_band / (N ks) within 3 % (contact forces are 0-11 degrees off radial: cos >= 0.98).
TEST(MembraneCylinder, SpringSupportedSpheresSettleAtConfiningPressure) {
  SpringSample t;
  t.run(800, 0, linear_params());
  const Real p = t.m.settings().pressure;
  EXPECT_NEAR(t.m.mean_confinement(), p, 0.01 * p);
  Real inward = 0, band = 0;
  for (const Vec3& x : t.b.pos) inward += kCylR - Vec3(x.x(), x.y(), 0).norm();
  for (std::size_t k = 0; k < t.m.element_count(); ++k) band += t.m.loaded_area(k);
  const Real expected = p * band / (t.b.pos.size() * SpringSample::ks);
  EXPECT_NEAR(inward / t.b.pos.size(), expected, 0.03 * expected);
}

// "No allocation in the time loop" (HELPERS_COMMON rules): after a warm-up in which the buffers
// reach their size, steps with forced candidate rebuilds every 25 steps allocate nothing.
TEST(MembraneAllocation, StepsAndRebuildsDoNotAllocate) {
  SpringSample t;
  const auto prm = linear_params();
  t.run(300, 25, prm);
  allocations = 0;
  counting = true;
  { std::vector<double> probe(8); EXPECT_EQ(allocations.load(), 1); }  // the counter works
  allocations = 0;
  t.run(300, 25, prm);
  counting = false;
  EXPECT_EQ(allocations.load(), 0);
}
