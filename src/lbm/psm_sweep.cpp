// The fused stream-collide + PSM kernel for bulk spans with covered cells (lbm/psm.hpp has the
// equations and their sources). Per cell: the bulk kernel's collision g* of the pre-collision g
// (collision.hpp, the same operations), then
//   g_new = (1 - B) g* + B g + sum_s B_s Omega^s_q(u_s),
//   Omega^s_q = g_{-q} - g_q + f^eq_q(rho, u_s) - f^eq_{-q}(rho, u),
// with B and the covering particles' velocity sums read from Psm's per-cell arrays, and the cell's
// rho and u written to them (each particle's force follows from those, Psm::reduce). Cells with
// B = 0 get g* unchanged. One pass per covered cell, whatever the number of particles on it. With
// every particle at rest (quasi-static walls: the hydrofrac's default) V and S are zero and not read
// (kMoving false): the pass then reads B alone besides the populations and writes, instead of rho
// and u, the cell's force B (rho u - f_body).
// Compiled like the bulk kernel: one clone per vector width, -ffp-contract=off.
#include "lbm/psm.hpp"
#include "lbm/span_slots.hpp"
#include "lbm/stream_collide.hpp"

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define FF_PSM_SWEEP_CLONES __attribute__((target_clones("default", "arch=x86-64-v3", "arch=x86-64-v4")))
#else
#define FF_PSM_SWEEP_CLONES
#endif

namespace ff::lbm {

namespace {

// sum_s B_s Omega^s by opposite pairs (q, o = -q). f^eq is quadratic in the velocity, so with the
// cell's V = sum_s B_s u_s and S = sum_s B_s u_s u_s^T (Psm::bulk_cells) and cu = c_q.u, cV = c_q.V,
// cSc = c_q.S.c_q, the (rho - 1) parts of the equilibria cancelling,
//   sum_s B_s (f^eq_q(u_s) - f^eq_o(u)) = w rho (E + O),  sum_s B_s (f^eq_o(u_s) - f^eq_q(u)) = w rho (E - O),
//   E = 4.5 (cSc - B cu^2) - 1.5 (tr S - B u^2),  O = 3 (cV + B cu),
// and the rest population's term is -w_0 rho 1.5 (tr S - B u^2) (the E parts' balance: no mass
// moves). One particle: V = B u_s, S = B u_s u_s^T. rho and u are the collision's own moments (Guo's
// half force included; rho_0 = 1 in the momentum terms when incompressible), written out for the
// particles' forces (Psm::reduce). The term costs about one more equilibrium per cell.
template <class L, class T, CollisionModel M, bool kForce, bool kMoments, bool kIncomp, bool kMoving>
FF_LBM_INLINE void psm_cells(T* const* p, std::int64_t i0, std::int64_t i1, const Relax<T>& r, const MomentOut<T>& m,
                             const PsmCells<T>& d) {
  constexpr int Q = L::Q, D = L::D;
  constexpr int P = (Q - 1) / 2;  // opposite pairs (2p+1, 2p+2), as in collide()
#pragma GCC ivdep
  for (std::int64_t i = i0; i < i1; ++i) {
    T g[Q], pre[Q];
    static_for<Q>([&](auto q) FF_LBM_LAMBDA_INLINE {
      g[q] = p[q][i];
      pre[q] = g[q];
    });
    T drho, u[3];
    collide<L, T, M, kForce, kIncomp>(g, r, drho, u);  // g = g*
    const T rho_u = kIncomp ? T(1) : T(1) + drho;
    const T B = d.B[i], fluid = T(1) - B;
    const bool covered = B != T(0);
    const T V[3] = {kMoving ? d.V[0][i] : T(0), kMoving ? d.V[1][i] : T(0), kMoving && D == 3 ? d.V[2][i] : T(0)};
    // S: xx, xy, yy (2D); xx, xy, xz, yy, yz, zz (3D)
    const T Sxx = kMoving ? d.S[0][i] : T(0), Sxy = kMoving ? d.S[1][i] : T(0);
    const T Syy = !kMoving ? T(0) : D == 3 ? d.S[3][i] : d.S[2][i];
    const T Sxz = kMoving && D == 3 ? d.S[2][i] : T(0), Syz = kMoving && D == 3 ? d.S[4][i] : T(0);
    const T Szz = kMoving && D == 3 ? d.S[5][i] : T(0);
    const T uu = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
    const T dsq15 = T(1.5) * (((Sxx + Syy) + Szz) - B * uu);
    const T om_0 = -(T(L::w[0]) * rho_u) * dsq15;
    p[0][i] = covered ? fluid * g[0] + B * pre[0] + om_0 : g[0];
    static_for<P>([&](auto k) FF_LBM_LAMBDA_INLINE {
      constexpr int q = 2 * k + 1, o = q + 1;
      constexpr int cx = L::c[q][0], cy = L::c[q][1], cz = L::c[q][2];
      const T cu = cdot<cx, cy, cz>(u[0], u[1], u[2]);
      const T cV = cdot<cx, cy, cz>(V[0], V[1], V[2]);
      T cSc = T(0);
      if constexpr (cx != 0) cSc += Sxx;
      if constexpr (cy != 0) cSc += Syy;
      if constexpr (cz != 0) cSc += Szz;
      if constexpr (cx * cy > 0) cSc += T(2) * Sxy;
      if constexpr (cx * cy < 0) cSc -= T(2) * Sxy;
      if constexpr (cx * cz > 0) cSc += T(2) * Sxz;
      if constexpr (cx * cz < 0) cSc -= T(2) * Sxz;
      if constexpr (cy * cz > 0) cSc += T(2) * Syz;
      if constexpr (cy * cz < 0) cSc -= T(2) * Syz;
      const T wr = T(L::w[q]) * rho_u;
      const T E = wr * (T(4.5) * (cSc - B * (cu * cu)) - dsq15), O = wr * (T(3) * (cV + B * cu));
      const T dq = pre[o] - pre[q];
      const T om_q = B * dq + (E + O), om_o = (E - O) - B * dq;
      p[o][i] = covered ? fluid * g[q] + B * pre[q] + om_q : g[q];
      p[q][i] = covered ? fluid * g[o] + B * pre[o] + om_o : g[o];
    });
    if constexpr (kMoving) {
      d.rho[i] = rho_u;
      static_for<D>([&](auto a) FF_LBM_LAMBDA_INLINE { d.u[a][i] = u[a]; });
    } else {  // every particle at rest: the cell's force B (rho u - f_body) (Psm::reduce), one array less
      static_for<D>([&](auto a) FF_LBM_LAMBDA_INLINE {
        d.u[a][i] = B * (rho_u * u[a] - (kForce ? r.force[a] : T(0)));
      });
    }
    if constexpr (kMoments) {
      m.drho[i] = drho;
      m.u[0][i] = u[0];
      m.u[1][i] = u[1];
      if constexpr (D == 3) m.u[2][i] = u[2];
    }
  }
}

template <class L, class T, CollisionModel M, bool kForce, bool kMoments, bool kIncomp, bool kMoving>
FF_PSM_SWEEP_CLONES void psm_span(const Grid& g, T* f, CellIndex N, int x0, int y, int z, int n, bool odd,
                                  const Relax<T>& r, T* drho, T* const* u, const PsmCells<T>& d) {
  with_span_slots<L, T>(g, f, N, x0, y, z, n, odd, [&](T* const* p, CellIndex base) FF_LBM_LAMBDA_INLINE {
    MomentOut<T> m;
    if constexpr (kMoments) {
      m.drho = drho + base;
      for (int a = 0; a < 3; ++a) m.u[a] = u[a] + base;
    }
    PsmCells<T> c;  // the span's cells
    c.B = d.B + base;
    c.rho = d.rho + base;
    for (int a = 0; a < L::D; ++a) {
      c.V[a] = d.V[a] + base;
      c.u[a] = d.u[a] + base;
    }
    for (int k = 0; k < (L::D == 3 ? 6 : 3); ++k) c.S[k] = d.S[k] + base;
    constexpr int kLine = 64 / int(sizeof(T));
    const Relax<T> rl = r;
    std::int64_t i = 0;
    for (; i + kLine <= n; i += kLine) {
      static_for<L::Q>(
          [&](auto q) FF_LBM_LAMBDA_INLINE { __builtin_prefetch(p[q] + i + kPrefetchLines * kLine, 0, 3); });
      psm_cells<L, T, M, kForce, kMoments, kIncomp, kMoving>(p, i, i + kLine, rl, m, c);
    }
    psm_cells<L, T, M, kForce, kMoments, kIncomp, kMoving>(p, i, n, rl, m, c);
  });
}

template <class L, class T, CollisionModel M, bool kIncomp, bool kMoving>
PsmSpanFn<T> pick_forcing(bool force, bool moments) {
  if (force)
    return moments ? &psm_span<L, T, M, true, true, kIncomp, kMoving> : &psm_span<L, T, M, true, false, kIncomp, kMoving>;
  return moments ? &psm_span<L, T, M, false, true, kIncomp, kMoving> : &psm_span<L, T, M, false, false, kIncomp, kMoving>;
}

template <class L, class T, CollisionModel M, bool kIncomp>
PsmSpanFn<T> pick_motion(bool force, bool moments, bool moving) {
  return moving ? pick_forcing<L, T, M, kIncomp, true>(force, moments) : pick_forcing<L, T, M, kIncomp, false>(force, moments);
}

}  // namespace

template <class L, class T>
PsmSpanFn<T> psm_span_kernel(CollisionModel model, bool force, bool moments, bool incomp, bool moving) {
  const bool trt = model == CollisionModel::Trt;
  if (incomp)
    return trt ? pick_motion<L, T, CollisionModel::Trt, true>(force, moments, moving)
               : pick_motion<L, T, CollisionModel::Bgk, true>(force, moments, moving);
  return trt ? pick_motion<L, T, CollisionModel::Trt, false>(force, moments, moving)
             : pick_motion<L, T, CollisionModel::Bgk, false>(force, moments, moving);
}

template PsmSpanFn<double> psm_span_kernel<D2Q9, double>(CollisionModel, bool, bool, bool, bool);
template PsmSpanFn<float> psm_span_kernel<D2Q9, float>(CollisionModel, bool, bool, bool, bool);
template PsmSpanFn<double> psm_span_kernel<D3Q19, double>(CollisionModel, bool, bool, bool, bool);
template PsmSpanFn<float> psm_span_kernel<D3Q19, float>(CollisionModel, bool, bool, bool, bool);

}  // namespace ff::lbm
