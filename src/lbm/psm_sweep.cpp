// The fused stream-collide + PSM kernel for bulk spans with cells covered by exactly one particle
// (lbm/psm.hpp has the equations and their sources). Per cell: the bulk kernel's collision g* of
// the pre-collision g (collision.hpp, the same operations), then
//   g_new = (1 - B) g* + B g + B Omega^s(u_s),  Omega^s_q = g_{-q} - g_q + f^eq_q(rho, u_s) - f^eq_{-q}(rho, u),
// with B and u_s read from Psm's per-cell arrays, and the cell's force -B sum_q c_q Omega^s_q
// written to its own slot of the per-cell force arrays (Psm::reduce sums them per particle).
// Cells of the span with B = 0 (uncovered, or covered by several particles: those keep the
// save/apply path of Psm) get g* unchanged. The arithmetic per cell is that of the batched path
// (psm.cpp, psm_batch_solid and psm_batch_combine) in the same order, so either path gives the
// same bits; fused, the covered cells cost a bulk cell plus the solid term, instead of the bulk
// cell, a copy out, a copy back and the term (the coupled benchmark: c/L from 24 down, docs/coupling.md).
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

template <class L, class T, CollisionModel M, bool kForce, bool kMoments, bool kIncomp>
FF_LBM_INLINE void psm_cells(T* const* p, std::int64_t i0, std::int64_t i1, const Relax<T>& r, const MomentOut<T>& m,
                             const T* Bc, const T* const* usc, double* const* Fc) {
  constexpr int Q = L::Q;
#pragma GCC ivdep
  for (std::int64_t i = i0; i < i1; ++i) {
    T g[Q], pre[Q];
    static_for<Q>([&](auto q) FF_LBM_LAMBDA_INLINE {
      g[q] = p[q][i];
      pre[q] = g[q];
    });
    // Fluid moments of the pre-collision state (Guo's half force), f^eq(rho, u) and f^eq(rho, u_s).
    T drho_s = 0, j[3] = {0, 0, 0};
    static_for<Q>([&](auto q) FF_LBM_LAMBDA_INLINE {
      drho_s += pre[q];
      static_for<L::D>([&](auto a) FF_LBM_LAMBDA_INLINE {
        if constexpr (L::c[q][a] > 0) j[a] += pre[q];
        if constexpr (L::c[q][a] < 0) j[a] -= pre[q];
      });
    });
    if constexpr (kForce)
      static_for<L::D>([&](auto a) FF_LBM_LAMBDA_INLINE { j[a] += T(0.5) * r.force[a]; });
    const T rho = T(1) + drho_s;
    const T rho_u = kIncomp ? T(1) : rho;
    const T inv = kIncomp ? T(1) : T(1) / rho;
    const T u[3] = {j[0] * inv, j[1] * inv, j[2] * inv};
    const T usq15 = T(1.5) * (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    const T us[3] = {usc[0][i], usc[1][i], L::D == 3 ? usc[2][i] : T(0)};
    const T ssq15 = T(1.5) * (us[0] * us[0] + us[1] * us[1] + us[2] * us[2]);
    T geqf[Q], geqs[Q];
    static_for<Q>([&](auto q) FF_LBM_LAMBDA_INLINE {
      const T cu = cdot<L::c[q][0], L::c[q][1], L::c[q][2]>(u[0], u[1], u[2]);
      geqf[q] = T(L::w[q]) * ((rho - T(1)) + rho_u * (T(3) * cu + T(4.5) * cu * cu - usq15));
      const T cs = cdot<L::c[q][0], L::c[q][1], L::c[q][2]>(us[0], us[1], us[2]);
      geqs[q] = T(L::w[q]) * ((rho - T(1)) + rho_u * (T(3) * cs + T(4.5) * cs * cs - ssq15));
    });
    T drho, uo[3];
    collide<L, T, M, kForce, kIncomp>(g, r, drho, uo);  // g = g*
    const T B = Bc[i], fluid = T(1) - B;
    const bool covered = B != T(0);
    double F[3] = {0, 0, 0};
    static_for<Q>([&](auto q) FF_LBM_LAMBDA_INLINE {
      constexpr int o = L::opp[q];
      const T om = B * ((pre[o] - pre[q]) + (geqs[q] - geqf[o]));
      static_for<L::D>([&](auto a) FF_LBM_LAMBDA_INLINE {
        if constexpr (L::c[q][a] > 0) F[a] -= double(om);
        if constexpr (L::c[q][a] < 0) F[a] += double(om);
      });
      const T out = fluid * g[q] + B * pre[q] + (T(0) + om);
      p[o][i] = covered ? out : g[q];
    });
    static_for<L::D>([&](auto a) FF_LBM_LAMBDA_INLINE { Fc[a][i] = F[a]; });
    if constexpr (kMoments) {
      m.drho[i] = drho;
      m.u[0][i] = uo[0];
      m.u[1][i] = uo[1];
      if constexpr (L::D == 3) m.u[2][i] = uo[2];
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
