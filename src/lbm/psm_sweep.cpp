// The fused stream-collide + PSM kernel for bulk spans with cells covered by exactly one particle
// (lbm/psm.hpp has the equations and their sources). Per cell: the bulk kernel's collision g* of
// the pre-collision g (collision.hpp, the same operations), then
//   g_new = (1 - B) g* + B g + B Omega^s(u_s),  Omega^s_q = g_{-q} - g_q + f^eq_q(rho, u_s) - f^eq_{-q}(rho, u),
// with B and u_s read from Psm's per-cell arrays, and the cell's force -B sum_q c_q Omega^s_q
// written to its own slot of the per-cell force arrays (Psm::reduce sums them per particle).
// Cells of the span with B = 0 (uncovered, or covered by several particles: those keep the
// save/apply path of Psm) get g* unchanged. The same update as the batched path (psm.cpp), with
// the solid term arranged by opposite pairs (below; equal to round-off); fused, a covered cell costs
// a bulk cell plus the solid term, instead of the bulk cell, a copy out, a copy back and the term.
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

// Omega^s by opposite pairs (q, o = -q): the (rho - 1) parts of the two equilibria cancel, so with
// cu = c_q.u, cs = c_q.u_s, E = 4.5 (cs^2 - cu^2) - 1.5 (u_s^2 - u^2) and O = 3 (cs + cu),
//   f^eq_q(u_s) - f^eq_o(u) = w rho (E + O),   f^eq_o(u_s) - f^eq_q(u) = w rho (E - O),
// Omega^s_0 = -w_0 rho 1.5 (u_s^2 - u^2) (the rest population: the E parts' balance, so the term
// moves no mass), and -c_q Omega^s_q - c_o Omega^s_o = -c_q (Omega^s_q - Omega^s_o) for the force. rho and u
// are the collision's own moments (Guo's half force included; rho_0 = 1 in the momentum terms
// when incompressible), so the term costs about one more equilibrium per cell.
template <class L, class T, CollisionModel M, bool kForce, bool kMoments, bool kIncomp>
FF_LBM_INLINE void psm_cells(T* const* p, std::int64_t i0, std::int64_t i1, const Relax<T>& r, const MomentOut<T>& m,
                             const T* Bc, const T* const* usc, double* const* Fc) {
  constexpr int Q = L::Q;
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
    const T us[3] = {usc[0][i], usc[1][i], L::D == 3 ? usc[2][i] : T(0)};
    const T dsq15 = T(1.5) * ((us[0] * us[0] + us[1] * us[1] + us[2] * us[2]) - (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]));
    const T B = Bc[i], fluid = T(1) - B;
    const bool covered = B != T(0);
    T F[3] = {0, 0, 0};
    const T om_0 = B * (-(T(L::w[0]) * rho_u) * dsq15);  // Omega^s_0 = f^eq_0(u_s) - f^eq_0(u)
    p[0][i] = covered ? fluid * g[0] + B * pre[0] + om_0 : g[0];
    static_for<P>([&](auto k) FF_LBM_LAMBDA_INLINE {
      constexpr int q = 2 * k + 1, o = q + 1;
      const T cu = cdot<L::c[q][0], L::c[q][1], L::c[q][2]>(u[0], u[1], u[2]);
      const T cs = cdot<L::c[q][0], L::c[q][1], L::c[q][2]>(us[0], us[1], us[2]);
      const T wr = T(L::w[q]) * rho_u;
      const T E = wr * (T(4.5) * (cs * cs - cu * cu) - dsq15), O = wr * (T(3) * (cs + cu));
      const T d = pre[o] - pre[q];
      const T om_q = B * (d + (E + O)), om_o = B * ((E - O) - d);
      p[o][i] = covered ? fluid * g[q] + B * pre[q] + om_q : g[q];
      p[q][i] = covered ? fluid * g[o] + B * pre[o] + om_o : g[o];
      const T f2 = om_q - om_o;  // the pair's -c_q-weighted share: F -= c_q (om_q - om_o)
      static_for<L::D>([&](auto a) FF_LBM_LAMBDA_INLINE {
        if constexpr (L::c[q][a] > 0) F[a] -= f2;
        if constexpr (L::c[q][a] < 0) F[a] += f2;
      });
    });
    static_for<L::D>([&](auto a) FF_LBM_LAMBDA_INLINE { Fc[a][i] = double(F[a]); });
    if constexpr (kMoments) {
      m.drho[i] = drho;
      m.u[0][i] = u[0];
      m.u[1][i] = u[1];
      if constexpr (L::D == 3) m.u[2][i] = u[2];
    }
  }
}

template <class L, class T, CollisionModel M, bool kForce, bool kMoments, bool kIncomp>
FF_PSM_SWEEP_CLONES void psm_span(const Grid& g, T* f, CellIndex N, int x0, int y, int z, int n, bool odd,
                                  const Relax<T>& r, T* drho, T* const* u, const PsmCells<T>& d) {
  with_span_slots<L, T>(g, f, N, x0, y, z, n, odd, [&](T* const* p, CellIndex base) FF_LBM_LAMBDA_INLINE {
    MomentOut<T> m;
    if constexpr (kMoments) {
      m.drho = drho + base;
      for (int a = 0; a < 3; ++a) m.u[a] = u[a] + base;
    }
    const T* us[3] = {d.us[0] + base, d.us[1] + base, L::D == 3 ? d.us[2] + base : nullptr};
    double* F[3] = {d.F[0] + base, d.F[1] + base, L::D == 3 ? d.F[2] + base : nullptr};
    const T* B = d.B + base;
    constexpr int kLine = 64 / int(sizeof(T));
    const Relax<T> rl = r;
    std::int64_t i = 0;
    for (; i + kLine <= n; i += kLine) {
      static_for<L::Q>([&](auto q) FF_LBM_LAMBDA_INLINE { __builtin_prefetch(p[q] + i + kPrefetchLines * kLine, 0, 3); });
      psm_cells<L, T, M, kForce, kMoments, kIncomp>(p, i, i + kLine, rl, m, B, us, F);
    }
    psm_cells<L, T, M, kForce, kMoments, kIncomp>(p, i, n, rl, m, B, us, F);
  });
}

template <class L, class T, CollisionModel M, bool kIncomp>
PsmSpanFn<T> pick_forcing(bool force, bool moments) {
  if (force) return moments ? &psm_span<L, T, M, true, true, kIncomp> : &psm_span<L, T, M, true, false, kIncomp>;
  return moments ? &psm_span<L, T, M, false, true, kIncomp> : &psm_span<L, T, M, false, false, kIncomp>;
}

}  // namespace

template <class L, class T>
PsmSpanFn<T> psm_span_kernel(CollisionModel model, bool force, bool moments, bool incomp) {
  const bool trt = model == CollisionModel::Trt;
  if (incomp)
    return trt ? pick_forcing<L, T, CollisionModel::Trt, true>(force, moments)
               : pick_forcing<L, T, CollisionModel::Bgk, true>(force, moments);
  return trt ? pick_forcing<L, T, CollisionModel::Trt, false>(force, moments)
             : pick_forcing<L, T, CollisionModel::Bgk, false>(force, moments);
}

template PsmSpanFn<double> psm_span_kernel<D2Q9, double>(CollisionModel, bool, bool, bool);
template PsmSpanFn<float> psm_span_kernel<D2Q9, float>(CollisionModel, bool, bool, bool);
template PsmSpanFn<double> psm_span_kernel<D3Q19, double>(CollisionModel, bool, bool, bool);
template PsmSpanFn<float> psm_span_kernel<D3Q19, float>(CollisionModel, bool, bool, bool);

}  // namespace ff::lbm
