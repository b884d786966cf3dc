// Fused stream-collide for a contiguous run of plain fluid cells (no branches, no
// boundary logic): the bulk of every step. The caller sets one pointer per direction; the
// kernel itself does not know whether it runs the even or the odd half of the AA pattern
// (docs/lbm.md, "Memory layout and streaming").
#pragma once
#include <cstdint>

#include "lbm/collision.hpp"

namespace ff::lbm {

// Where a span's macroscopic fields go on sampling steps (offset to the span's first cell).
template <class T>
struct MomentOut {
  T* drho = nullptr;
  T* u[3] = {nullptr, nullptr, nullptr};
};

// Software prefetch distance of the bulk kernel, in cache lines per direction: while a line
// of each of the Q streams is being collided, the line this far ahead is requested. One core's
// hardware prefetchers do not keep 19 streams (D3Q19) far enough ahead on their own, and the
// collision then waits for memory instead of overlapping with it (docs/lbm.md, "Speed").
inline constexpr int kPrefetchLines = 4;

// Cells [i0, i1) of a span: g_q = p[q][i] for every q, collide, p[opp q][i] = g*_q.
// Cells never share memory slots (AA pattern), so iterations are independent (hence `ivdep`).
template <class L, class T, CollisionModel M, bool kForce, bool kMoments, bool kIncomp>
FF_LBM_INLINE void stream_collide_cells(T* const* p, std::int64_t i0, std::int64_t i1, const Relax<T>& r,
                                        const MomentOut<T>& m) {
#pragma GCC ivdep
  for (std::int64_t i = i0; i < i1; ++i) {
    T g[L::Q];
    static_for<L::Q>([&](auto q) FF_LBM_LAMBDA_INLINE { g[q] = p[q][i]; });
    T drho, u[3];
    collide<L, T, M, kForce, kIncomp>(g, r, drho, u);
    static_for<L::Q>([&](auto q) FF_LBM_LAMBDA_INLINE { p[L::opp[q]][i] = g[q]; });
    if constexpr (kMoments) {
      m.drho[i] = drho;
      m.u[0][i] = u[0];
      m.u[1][i] = u[1];
      if constexpr (L::D == 3) m.u[2][i] = u[2];
    }
  }
}

// For i in [0, n): g_q = p[q][i] for every q, collide, p[opp q][i] = g*_q.
//
// A cell writes its collided g*_q into the slot it read g_{opp q} from (even step: read
// f[q][x], write f[opp q][x]; odd step: read f[opp q][x - c_q], write f[q][x + c_q], the slot of
// g_{opp q}). So one pointer per direction, to the slot of g_q, serves both reading and
// writing: 19 pointers instead of 38 for D3Q19, which leaves the compiler far fewer spills.
//
// The span is processed one cache line of cells at a time, each line preceded by a prefetch
// of every stream kAhead (= kPrefetchLines; 2-12 were timed, 3-6 were equally good) lines ahead;
// past the span's end that is the start of the next row, which the next span needs. Always inlined, so each target clone of the caller
// vectorises it for its ISA; the arithmetic per cell is that of collide(), whatever the ISA.
template <class L, class T, CollisionModel M, bool kForce, bool kMoments, bool kIncomp, int kAhead = kPrefetchLines>
FF_LBM_INLINE void stream_collide_span(T* const* p_in, std::int64_t n, const Relax<T>& r, const MomentOut<T>& m) {
  constexpr int Q = L::Q;
  constexpr int kLine = 64 / int(sizeof(T));  // cells per cache line
  T* p[Q];
  for (int q = 0; q < Q; ++q) p[q] = p_in[q];
  const Relax<T> rl = r;
  std::int64_t i = 0;
  for (; i + kLine <= n; i += kLine) {
    static_for<Q>([&](auto q) FF_LBM_LAMBDA_INLINE { __builtin_prefetch(p[q] + i + kAhead * kLine, 0, 3); });
    stream_collide_cells<L, T, M, kForce, kMoments, kIncomp>(p, i, i + kLine, rl, m);
  }
  stream_collide_cells<L, T, M, kForce, kMoments, kIncomp>(p, i, n, rl, m);
}

}  // namespace ff::lbm
