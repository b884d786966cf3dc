// Lattice descriptors and the collision operator (METHODS §4.1-4.4): isotropy of the
// velocity sets, moments of the equilibrium, conservation by BGK and TRT, Guo forcing.
#include <gtest/gtest.h>

#include <cmath>

#include "lbm/collision.hpp"
#include "lbm/descriptor.hpp"

using namespace ff::lbm;

namespace {

template <class L>
void check_isotropy() {
  // Moments of the weights up to fourth order: sum w c_a c_b = cs2 delta_ab,
  // sum w c_a c_b c_c c_d = cs2^2 (delta_ab delta_cd + delta_ac delta_bd + delta_ad delta_bc).
  for (int a = 0; a < L::D; ++a)
    for (int b = 0; b < L::D; ++b) {
      double m2 = 0;
      for (int q = 0; q < L::Q; ++q) m2 += L::w[q] * L::c[q][a] * L::c[q][b];
      EXPECT_NEAR(m2, a == b ? kCs2 : 0.0, 1e-15);
      for (int c = 0; c < L::D; ++c)
        for (int d = 0; d < L::D; ++d) {
          double m4 = 0;
          for (int q = 0; q < L::Q; ++q) m4 += L::w[q] * L::c[q][a] * L::c[q][b] * L::c[q][c] * L::c[q][d];
          const double e = kCs2 * kCs2 * ((a == b && c == d) + (a == c && b == d) + (a == d && b == c));
          EXPECT_NEAR(m4, e, 1e-15) << a << b << c << d;
        }
    }
  for (int q = 0; q < L::Q; ++q)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(L::c[L::opp[q]][k], -L::c[q][k]);
}

// Moments of shifted populations g = f - w.
template <class L, class T>
void moments(const T* g, double& rho, double* j) {
  rho = 1;
  j[0] = j[1] = j[2] = 0;
  for (int q = 0; q < L::Q; ++q) {
    rho += g[q];
    for (int a = 0; a < 3; ++a) j[a] += L::c[q][a] * double(g[q]);
  }
}

template <class L, class T, CollisionModel M>
void check_collision(double tol) {
  // A non-equilibrium state: equilibrium plus a deterministic perturbation.
  const T u0[3] = {T(0.04), T(-0.03), T(L::D == 3 ? 0.02 : 0.0)};
  T g[L::Q];
  equilibrium<L, T>(T(1.02), u0, g);
  for (int q = 0; q < L::Q; ++q) g[q] += T(1e-3 * std::sin(1.7 * q + 0.3));
  double rho0, j0[3];
  moments<L, T>(g, rho0, j0);
  const double F[3] = {1e-4, -2e-4, L::D == 3 ? 5e-5 : 0.0};
  // Without force: mass and momentum are collision invariants.
  {
    T h[L::Q];
    std::copy(g, g + L::Q, h);
    const double none[3] = {0, 0, 0};
    const Relax<T> r = make_relax<T>(M, 0.7, 3.0 / 16, none);
    T drho, u[3];
    collide<L, T, M, false>(h, r, drho, u);
    double rho1, j1[3];
    moments<L, T>(h, rho1, j1);
    EXPECT_NEAR(rho1, rho0, tol);
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(j1[a], j0[a], tol);
    EXPECT_NEAR(double(drho), rho0 - 1, tol);
    EXPECT_NEAR(double(u[0]), j0[0] / rho0, tol);
  }
  // With Guo forcing the momentum grows by exactly F (Guo, Zheng & Shi 2002), mass unchanged,
  // and the reported velocity is the half-force corrected one.
  {
    T h[L::Q];
    std::copy(g, g + L::Q, h);
    const Relax<T> r = make_relax<T>(M, 0.7, 3.0 / 16, F);
    T drho, u[3];
    collide<L, T, M, true>(h, r, drho, u);
    double rho1, j1[3];
    moments<L, T>(h, rho1, j1);
    EXPECT_NEAR(rho1, rho0, tol);
    for (int a = 0; a < L::D; ++a) EXPECT_NEAR(j1[a], j0[a] + F[a], tol);
    for (int a = 0; a < L::D; ++a) EXPECT_NEAR(double(u[a]), (j0[a] + 0.5 * F[a]) / rho0, tol);
  }
}

}  // namespace

TEST(LbmLattice, D2Q9IsIsotropic) { check_isotropy<D2Q9>(); }
TEST(LbmLattice, D3Q19IsIsotropic) { check_isotropy<D3Q19>(); }

TEST(LbmLattice, EquilibriumMoments) {
  // sum f^eq = rho, sum f^eq c = rho u, sum f^eq c c = rho (cs2 I + u u) (METHODS §4.2).
  const double u[3] = {0.05, -0.02, 0.01};
  double geq[D3Q19::Q];
  equilibrium<D3Q19, double>(1.1, u, geq);
  double rho = 0, j[3] = {0, 0, 0}, P[3][3] = {};
  for (int q = 0; q < D3Q19::Q; ++q) {
    const double f = geq[q] + D3Q19::w[q];
    rho += f;
    for (int a = 0; a < 3; ++a) {
      j[a] += f * D3Q19::c[q][a];
      for (int b = 0; b < 3; ++b) P[a][b] += f * D3Q19::c[q][a] * D3Q19::c[q][b];
    }
  }
  EXPECT_NEAR(rho, 1.1, 1e-14);
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(j[a], 1.1 * u[a], 1e-14);
    for (int b = 0; b < 3; ++b) EXPECT_NEAR(P[a][b], 1.1 * ((a == b) * kCs2 + u[a] * u[b]), 1e-14);
  }
}

TEST(LbmCollision, ConservesMassAndMomentumD2Q9) {
  check_collision<D2Q9, double, CollisionModel::Bgk>(1e-15);
  check_collision<D2Q9, double, CollisionModel::Trt>(1e-15);
  check_collision<D2Q9, float, CollisionModel::Trt>(2e-7);
}
TEST(LbmCollision, ConservesMassAndMomentumD3Q19) {
  check_collision<D3Q19, double, CollisionModel::Bgk>(1e-15);
  check_collision<D3Q19, double, CollisionModel::Trt>(1e-15);
  check_collision<D3Q19, float, CollisionModel::Bgk>(2e-7);
}

TEST(LbmCollision, TrtWithEqualRatesIsBgk) {
  // Lambda = (tau - 1/2)^2 gives tau- = tau+: TRT must then reproduce BGK.
  const double tau = 0.9, none[3] = {0, 0, 0};
  const Relax<double> rt = make_relax<double>(CollisionModel::Trt, tau, (tau - 0.5) * (tau - 0.5), none);
  const Relax<double> rb = make_relax<double>(CollisionModel::Bgk, tau, 3.0 / 16, none);
  const double u0[3] = {0.03, 0.01, 0};
  double a[D2Q9::Q], b[D2Q9::Q];
  equilibrium<D2Q9, double>(0.98, u0, a);
  for (int q = 0; q < D2Q9::Q; ++q) a[q] += 1e-3 * std::cos(0.9 * q);
  std::copy(a, a + D2Q9::Q, b);
  double dr, u[3];
  collide<D2Q9, double, CollisionModel::Trt, false>(a, rt, dr, u);
  collide<D2Q9, double, CollisionModel::Bgk, false>(b, rb, dr, u);
  for (int q = 0; q < D2Q9::Q; ++q) EXPECT_NEAR(a[q], b[q], 1e-16);
}

TEST(LbmCollision, TrtMagicParameter) {
  // Lambda = (tau+ - 1/2)(tau- - 1/2) (Ginzburg et al. 2008).
  EXPECT_NEAR((0.8 - 0.5) * (trt_tau_minus(0.8, 3.0 / 16) - 0.5), 3.0 / 16, 1e-15);
  EXPECT_NEAR((2.0 - 0.5) * (trt_tau_minus(2.0, 0.25) - 0.5), 0.25, 1e-15);
}
