// Boundary conditions on small channels with known steady solutions (METHODS §4.5-4.7):
// moving-wall bounce-back ([S003] Eq. 8) and the interpolated schemes of Bouzidi et al. (2001)
// and Yu et al. (2003, [S002] Eq. 7) on Couette flow (exact for a linear profile), Zou-He
// velocity and pressure faces, and the momentum-exchange force ([S003] Eq. 11) against the
// momentum balance of a body-force driven flow.
#include <gtest/gtest.h>

#include <cmath>

#include "lbm/solver.hpp"

using namespace ff;
using namespace ff::lbm;

namespace {

template <class S>
void run_steps(S& s, int n) {
  for (int i = 0; i < n; ++i) s.step(i == n - 1);
}

// Couette flow between a wall at y = y0 and a wall at y = y0 + W moving at U: u = U (y - y0) / W.
// Interpolated schemes with Box walls at arbitrary positions; half-way with the grid walls.
template <class L>
double couette_error(WallScheme scheme, double y0, double W) {
  // Half-way: the grid's own walls at y = -1/2 and ny - 1/2; otherwise Box walls inside.
  const int ny = scheme == WallScheme::HalfwayBounceBack ? int(W) : int(std::ceil(y0 + W)) + 1;
  Grid g(L::D, 3, ny, 2, {true, false, true});
  SolverSettings st;
  st.tau = 0.9;
  Solver<L, double> s(g, st);
  const double U = 0.02;
  int top = -1;
  if (scheme == WallScheme::HalfwayBounceBack) {
    FaceCondition lid;
    lid.velocity = Vec3(U, 0, 0);
    s.set_face(3, lid);
  } else {
    const int bottom = s.add_object("bottom", scheme, Vec3::Zero());
    top = s.add_object("top", scheme, Vec3::Zero());
    s.add_shape(bottom, Box{Vec3(-9, -9, -9), Vec3(99, y0, 99)});
    s.add_shape(top, Box{Vec3(-9, y0 + W, -9), Vec3(99, 99, 99)});
  }
  s.finalize();
  if (top >= 0) s.set_object_motion(top, Vec3(U, 0, 0), Vec3::Zero());
  s.initialize([](int, int, int, double&, Vec3&) {});
  run_steps(s, 6000);
  double err = 0;
  for (int y = 0; y < ny; ++y) {
    if (s.is_solid(1, y, 0)) continue;
    err = std::max(err, std::abs(s.velocity(1, y, 0)[0] - U * (y - y0) / W) / U);
  }
  return err;
}

// Poiseuille flow between walls at y0 and y0 + W driven by a body force.
double poiseuille_offset_error(WallScheme scheme, double y0, double W) {
  const int ny = int(std::ceil(y0 + W)) + 1;
  Grid g(2, 3, ny, 1, {true, false, true});
  SolverSettings st;
  st.tau = 0.8;
  const double F = 1e-6;
  st.body_force = Vec3(F, 0, 0);
  Solver<D2Q9, double> s(g, st);
  const int lo = s.add_object("lo", scheme, Vec3::Zero()), hi = s.add_object("hi", scheme, Vec3::Zero());
  s.add_shape(lo, Box{Vec3(-9, -9, -9), Vec3(99, y0, 9)});
  s.add_shape(hi, Box{Vec3(-9, y0 + W, -9), Vec3(99, 99, 9)});
  s.finalize();
  s.initialize([](int, int, int, double&, Vec3&) {});
  run_steps(s, 12000);
  const double nu = (0.8 - 0.5) / 3, umax = F * W * W / (8 * nu);
  double err2 = 0;
  int n = 0;
  for (int y = 0; y < ny; ++y) {
    if (s.is_solid(1, y, 0)) continue;
    const double yy = y - y0, ua = F / (2 * nu) * yy * (W - yy);
    err2 += (s.velocity(1, y, 0)[0] - ua) * (s.velocity(1, y, 0)[0] - ua);
    ++n;
  }
  return std::sqrt(err2 / n) / umax;
}

}  // namespace

TEST(LbmBoundary, MovingWallCouetteIsExact) {
  // Half-way bounce-back with the moving-wall term reproduces the linear profile exactly.
  EXPECT_LT(couette_error<D2Q9>(WallScheme::HalfwayBounceBack, -0.5, 8.0), 1e-9);
  EXPECT_LT(couette_error<D3Q19>(WallScheme::HalfwayBounceBack, -0.5, 8.0), 1e-9);
}

TEST(LbmBoundary, InterpolatedWallsAreExactForCouette) {
  // Both linear interpolation schemes are exact for a linear profile at any wall distance,
  // which also checks the placement of the moving-wall term (METHODS §4.6, "verify").
  for (double y0 : {0.2, 0.5, 0.85})
    for (double W : {6.3, 7.0}) {
      EXPECT_LT(couette_error<D2Q9>(WallScheme::Bouzidi, y0, W), 1e-8) << "Bouzidi y0 " << y0 << " W " << W;
      EXPECT_LT(couette_error<D2Q9>(WallScheme::Yu, y0, W), 1e-8) << "Yu y0 " << y0 << " W " << W;
    }
  EXPECT_LT(couette_error<D3Q19>(WallScheme::Bouzidi, 0.3, 6.6), 1e-8);
}

TEST(LbmBoundary, InterpolatedWallsBeatStairsInPoiseuille) {
  // Walls 0.3 cell off the half-way position: stair-wise walls err by O(dx), the
  // interpolated ones by O(dx^2) (Bouzidi et al. 2001).
  const double stair = poiseuille_offset_error(WallScheme::HalfwayBounceBack, 0.8, 19.3);
  const double bouzidi = poiseuille_offset_error(WallScheme::Bouzidi, 0.8, 19.3);
  const double yu = poiseuille_offset_error(WallScheme::Yu, 0.8, 19.3);
  EXPECT_GT(stair, 0.03);
  EXPECT_LT(bouzidi, 0.006);
  EXPECT_LT(yu, 0.007);
}

TEST(LbmBoundary, ZouHeVelocityAndPressureFaces) {
  // Parabolic inflow (Zou-He velocity) and a Zou-He pressure outlet on both lattices: the
  // open nodes carry the prescribed velocity and density.
  auto check = [](auto tag) {
    using L = decltype(tag);
    const int H = 12, Lx = 30;
    Grid g(L::D, Lx, H, 2, {false, false, true});
    SolverSettings st;
    st.tau = 0.8;
    Solver<L, double> s(g, st);
    const double umax = 0.01;
    auto prof = [&](int, int y, int) { const double yy = y + 0.5; return Vec3(4 * umax * yy * (H - yy) / (H * H), 0, 0); };
    FaceCondition in, out;
    in.kind = FaceCondition::Kind::Velocity;
    in.profile = prof;
    out.kind = FaceCondition::Kind::Pressure;
    out.density = 1.001;
    s.set_face(0, in);
    s.set_face(1, out);
    s.finalize();
    s.initialize([&](int x, int y, int z, double& r, Vec3& u) { r = 1.001; u = prof(x, y, z); });
    run_steps(s, 4000);
    for (int y = 0; y < H; ++y) {
      EXPECT_NEAR(s.velocity(0, y, 0)[0], prof(0, y, 0)[0], 1e-12) << L::name;
      EXPECT_NEAR(s.velocity(0, y, 0)[1], 0.0, 1e-12) << L::name;
      EXPECT_NEAR(s.density(Lx - 1, y, 0), 1.001, 1e-12) << L::name;
      // Fully developed: the profile is still the parabola in the middle, up to the weak
      // compressibility of the LBM (mass flux conserved, u ~ 1/rho along the channel: 0.3%).
      EXPECT_NEAR(s.velocity(Lx / 2, y, 0)[0], prof(0, y, 0)[0], 5e-3 * umax) << L::name;
    }
  };
  check(D2Q9{});
  check(D3Q19{});
}

TEST(LbmBoundary, MomentumExchangeBalancesBodyForce) {
  // Periodic array of cylinders pushed by a body force: at steady state the force on each
  // cylinder equals the body force on the fluid around it ([S003] Eq. 11); by symmetry the
  // lift and torque vanish.
  for (WallScheme sch : {WallScheme::HalfwayBounceBack, WallScheme::Bouzidi, WallScheme::Yu}) {
    Grid g(2, 20, 16, 1, {true, true, true});
    SolverSettings st;
    st.tau = 1.0;
    st.body_force = Vec3(2e-6, 0, 0);
    Solver<D2Q9, double> s(g, st);
    const Vec3 c(9.5, 7.5, 0);
    const int id = s.add_object("cylinder", sch, c);
    s.add_shape(id, Circle{c, 3.3});
    s.finalize();
    s.initialize([](int, int, int, double&, Vec3&) {});
    run_steps(s, 3000);
    const auto& o = s.objects()[id];
    const double total = 2e-6 * double(s.num_fluid_cells());
    EXPECT_NEAR(o.force[0], total, 1e-6 * total) << int(sch);
    EXPECT_NEAR(o.force[1], 0.0, 1e-6 * total) << int(sch);
    EXPECT_NEAR(o.torque[2], 0.0, 1e-5 * total) << int(sch);
    EXPECT_GT(o.links, 20);
  }
}
