// Fused stream-collide for a contiguous run of plain fluid cells (no branches, no
// boundary logic): the bulk of every step. The caller sets one source and one destination
// pointer per direction; the kernel itself does not know whether it runs the even or the
// odd half of the AA pattern (docs/lbm.md, "Memory layout and streaming").
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

// For i in [0, n): g_q = src[q][i] for every q, collide, dst[q][i] = g*_q.
// src/dst of different cells never overlap (AA pattern), so iterations are independent
// (hence `ivdep`). Always inlined, so each target clone of the caller vectorises it for its ISA.
template <class L, class T, CollisionModel M, bool kForce, bool kMoments>
FF_LBM_INLINE void stream_collide_span(T* const* src_in, T* const* dst_in, std::int64_t n, const Relax<T>& r,
                         const MomentOut<T>& m) {
  constexpr int Q = L::Q;
  const T* src[Q];
  T* dst[Q];
  for (int q = 0; q < Q; ++q) {
    src[q] = src_in[q];
    dst[q] = dst_in[q];
  }
  const Relax<T> rl = r;
#pragma GCC ivdep
  for (std::int64_t i = 0; i < n; ++i) {
    T g[Q];
    static_for<Q>([&](auto q) FF_LBM_LAMBDA_INLINE { g[q] = src[q][i]; });
    T drho, u[3];
    collide<L, T, M, kForce>(g, rl, drho, u);
    static_for<Q>([&](auto q) FF_LBM_LAMBDA_INLINE { dst[q][i] = g[q]; });
    if constexpr (kMoments) {
      m.drho[i] = drho;
      m.u[0][i] = u[0];
      m.u[1][i] = u[1];
      if constexpr (L::D == 3) m.u[2][i] = u[2];
    }
  }
}

}  // namespace ff::lbm
