// One cell's collision: moments, equilibrium, BGK or TRT relaxation and Guo forcing.
// The same inline function serves the vectorised bulk kernel and the boundary-cell path,
// so both give bit-identical results for the same populations.
//
// Populations are stored shifted by their rest weight, g_q = f_q - w_q (as in FluidX3D's
// "DDF shifting"): the O(1) part cancels and single precision keeps ~7 significant digits
// of the O(Ma^2) deviations that carry the physics.
//
// Equations (METHODS §4.2–4.4):
//   f^eq_q = w_q rho [1 + 3 c.u + 9/2 (c.u)^2 - 3/2 u^2]                 ([S003] Eq. 2)
//   BGK: f*_q = f_q - (f_q - f^eq_q)/tau                                 ([S003] Eq. 1)
//   TRT (Ginzburg et al. 2008): symmetric / antisymmetric parts relax with
//        w+ = 1/tau and w- from the magic parameter (1/w+ - 1/2)(1/w- - 1/2) = Lambda
//   Incompressible variant (He & Luo 1997, J. Stat. Phys. 88:927; Zou et al. 1995): the momentum
//        terms use rho_0 = 1, f^eq_q = w_q [rho + 3 c.u + 9/2 (c.u)^2 - 3/2 u^2], u = sum f c.
//        rho is then a pressure variable only: a steady flow no longer carries the O(Ma^2) error of
//        a density (and so a dynamic viscosity rho nu) that rises with the pressure drop, which is
//        what put the DFG cylinder's drag ~Ma^2 above its interval (docs/lbm.md, "Accuracy").
//   Guo, Zheng & Shi (2002): rho u = sum f c + F/2,
//        S_q = (1 - w/2) w_q [3 (c - u) + 9 (c.u) c] . F, split into its even part (relaxed
//        with w+) and odd part (with w-) for TRT.
#pragma once
#include <type_traits>
#include <utility>

#include "lbm/descriptor.hpp"

// The kernels are written with compile-time loops over lambdas; GCC must inline all of them
// (D3Q19 bodies are large enough that it otherwise declines, and the loop no longer vectorises).
#define FF_LBM_INLINE inline __attribute__((always_inline))
#define FF_LBM_LAMBDA_INLINE __attribute__((always_inline))

namespace ff::lbm {

enum class CollisionModel { Bgk, Trt };

// Relaxation constants in the storage precision.
template <class T>
struct Relax {
  T omega_plus = 1, omega_minus = 1;  // 1/tau+, 1/tau-
  T force[3] = {0, 0, 0};             // body-force density (lattice units), uniform
  T src_plus = 0, src_minus = 0;      // 1 - omega/2 (Guo source prefactors)
};

// tau- from tau+ and the TRT magic parameter Lambda = (tau+ - 1/2)(tau- - 1/2).
inline double trt_tau_minus(double tau, double magic) { return 0.5 + magic / (tau - 0.5); }

template <class T>
Relax<T> make_relax(CollisionModel m, double tau, double magic, const double force[3]) {
  Relax<T> r;
  const double tm = m == CollisionModel::Trt ? trt_tau_minus(tau, magic) : tau;
  r.omega_plus = T(1.0 / tau);
  r.omega_minus = T(1.0 / tm);
  for (int a = 0; a < 3; ++a) r.force[a] = T(force[a]);
  r.src_plus = T(1.0 - 0.5 / tau);
  r.src_minus = T(1.0 - 0.5 / tm);
  return r;
}

// Compile-time loop: f(std::integral_constant<int, I>) for I = 0..N-1.
template <int N, class F>
FF_LBM_INLINE void static_for(F&& f) {
  [&]<int... I>(std::integer_sequence<int, I...>) FF_LBM_LAMBDA_INLINE {
    (f(std::integral_constant<int, I>{}), ...);
  }(std::make_integer_sequence<int, N>{});
}

// c . v for a compile-time c with entries in {-1, 0, 1}, without multiplying by zero
// (x*0 cannot be folded away without -ffast-math).
template <int cx, int cy, int cz, class T>
FF_LBM_INLINE T cdot(T x, T y, T z) {
  if constexpr (cx != 0) {
    T r = cx > 0 ? x : -x;
    if constexpr (cy != 0) r = cy > 0 ? r + y : r - y;
    if constexpr (cz != 0) r = cz > 0 ? r + z : r - z;
    return r;
  } else if constexpr (cy != 0) {
    T r = cy > 0 ? y : -y;
    if constexpr (cz != 0) r = cz > 0 ? r + z : r - z;
    return r;
  } else if constexpr (cz != 0) {
    return cz > 0 ? z : -z;
  } else {
    return T(0);
  }
}

// Collides the shifted populations g[] of one cell in place. Returns the density deviation
// (rho - 1) and the velocity (Guo's half-force corrected), used for output and checks.
// kIncomp: the incompressible equilibrium of He & Luo (1997) (rho_0 = 1 in the momentum terms).
template <class L, class T, CollisionModel M, bool kForce, bool kIncomp = false>
FF_LBM_INLINE void collide(T* g, const Relax<T>& r, T& drho_out, T* u_out) {
  constexpr int P = (L::Q - 1) / 2;  // opposite pairs (2p+1, 2p+2)
  // Moments: sums and differences over opposite pairs.
  T gp[P], gm[P];
  static_for<P>([&](auto p) FF_LBM_LAMBDA_INLINE {
    constexpr int q = 2 * p + 1;
    gp[p] = g[q] + g[q + 1];
    gm[p] = g[q] - g[q + 1];
  });
  T drho = g[0];
  static_for<P>([&](auto p) FF_LBM_LAMBDA_INLINE { drho += gp[p]; });
  T j[3] = {0, 0, 0};
  static_for<P>([&](auto p) FF_LBM_LAMBDA_INLINE {
    constexpr int q = 2 * p + 1;
    static_for<L::D>([&](auto a) FF_LBM_LAMBDA_INLINE {
      constexpr int c = L::c[q][a];
      if constexpr (c > 0) j[a] += gm[p];
      if constexpr (c < 0) j[a] -= gm[p];
    });
  });
  if constexpr (kForce) {
    static_for<L::D>([&](auto a) FF_LBM_LAMBDA_INLINE { j[a] += T(0.5) * r.force[a]; });
  }
  // rho multiplies the momentum terms: the density (compressible) or rho_0 = 1 (incompressible).
  const T rho = kIncomp ? T(1) : T(1) + drho;
  const T inv_rho = kIncomp ? T(1) : T(1) / rho;
  const T ux = j[0] * inv_rho, uy = j[1] * inv_rho;
  const T uz = L::D == 3 ? j[2] * inv_rho : T(0);
  T usq = ux * ux + uy * uy;
  if constexpr (L::D == 3) usq += uz * uz;
  const T usq15 = T(1.5) * usq;
  const T wp = r.omega_plus;
  const T wm = M == CollisionModel::Trt ? r.omega_minus : r.omega_plus;
  const T base = drho - rho * usq15;  // g^eq_q / w_q = base + 4.5 rho (c.u)^2 + 3 rho c.u

  T uF = 0;
  if constexpr (kForce) {
    uF = ux * r.force[0] + uy * r.force[1];
    if constexpr (L::D == 3) uF += uz * r.force[2];
  }
  // Rest population.
  {
    constexpr T w0 = T(L::w[0]);
    g[0] -= wp * (g[0] - w0 * base);
    if constexpr (kForce) g[0] += r.src_plus * w0 * (T(-3) * uF);
  }
  // Moving populations, pair by pair. The weight-dependent factors are hoisted per pair
  // (they are shared by all pairs of one weight class, and the compiler merges them).
  const T omw = T(1) - wp;
  const T hwp = T(0.5) * wp, hwm = T(0.5) * wm;
  static_for<P>([&](auto p) FF_LBM_LAMBDA_INLINE {
    constexpr int q = 2 * p + 1, o = q + 1;
    constexpr T w = T(L::w[q]);
    const T wpA = (wp * w) * base;   // w+ w (rho-1 - 1.5 rho u^2)
    const T wpB = (wp * w) * (T(4.5) * rho);
    const T cu = cdot<L::c[q][0], L::c[q][1], L::c[q][2]>(ux, uy, uz);
    const T even = wpA + wpB * (cu * cu);  // w+ g^eq,even
    if constexpr (M == CollisionModel::Trt) {
      const T wmC = (wm * w) * (T(3) * rho);
      const T a = hwp * gp[p] - even;             // w+ (g^+ - g^eq,+)
      const T b = hwm * gm[p] - wmC * cu;         // w- (g^- - g^eq,-)
      g[q] -= a + b;
      g[o] -= a - b;
    } else {
      const T odd = ((wp * w) * (T(3) * rho)) * cu;
      g[q] = omw * g[q] + even + odd;
      g[o] = omw * g[o] + even - odd;
    }
    if constexpr (kForce) {
      const T cF = cdot<L::c[q][0], L::c[q][1], L::c[q][2]>(r.force[0], r.force[1], r.force[2]);
      const T s_even = r.src_plus * w * (T(9) * cu * cF - T(3) * uF);
      const T s_odd = (M == CollisionModel::Trt ? r.src_minus : r.src_plus) * w * (T(3) * cF);
      g[q] += s_even + s_odd;
      g[o] += s_even - s_odd;
    }
  });
  drho_out = drho;
  u_out[0] = ux;
  u_out[1] = uy;
  u_out[2] = uz;
}

// Shifted equilibrium g^eq_q = f^eq_q - w_q for density rho and velocity u (incompressible:
// rho_0 = 1 in the momentum terms, as in collide()).
template <class L, class T>
inline void equilibrium(T rho, const T* u, T* geq, bool incompressible = false) {
  const T usq15 = T(1.5) * (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
  const T rho_u = incompressible ? T(1) : rho;
  for (int q = 0; q < L::Q; ++q) {
    const T cu = L::c[q][0] * u[0] + L::c[q][1] * u[1] + L::c[q][2] * u[2];
    geq[q] = T(L::w[q]) * ((rho - T(1)) + rho_u * (T(3) * cu + T(4.5) * cu * cu - usq15));
  }
}

}  // namespace ff::lbm
