// The per-direction slot pointers of one bulk span in the AA pattern, with the periodic-x seam, for
// the fused kernels (bulk_sweep.cpp: plain fluid; psm_sweep.cpp: cells covered by one particle).
#pragma once
#include "lbm/collision.hpp"
#include "lbm/grid.hpp"

namespace ff::lbm {

// Sets p[q], the slot the span's first cell reads g_q from (the kernel writes g*_{opp q} back into
// it), and runs `kernel(p, base)` with base the first cell's index:
//   even step: p[q] = f[q][x]             (g*_q goes to f[opp q][x])
//   odd step:  p[q] = f[opp q][x - c_q]   (g*_q goes to f[q][x + c_q] = p[opp q])
//
// Periodic x: the odd-step pointers are not wrapped in x, so the first cell of a row (x = 0)
// reads and writes its slots of the directions with c_x = +1 in the ghost column x = -1, and
// the last cell (x = nx - 1) those with c_x = -1 in the ghost column x = nx. Each such slot
// belongs to that one cell alone (AA pattern), so the span copies the wrapped slot into the
// ghost before the kernel, copies it back after, and restores the ghost's own value (the
// populations array, checkpoints included, is the same as with wrapped indices). Whole rows
// thus stay one span, vectorised from x = 0 with no scalar cells at the seam: the split into
// three spans per row (x = 0, 1..nx-2, nx-1) made the odd step 20-30% slower.
template <class L, class T, class Kernel>
FF_LBM_INLINE void with_span_slots(const Grid& g, T* f, CellIndex N, int x0, int y, int z, int n, bool odd,
                                   Kernel&& kernel) {
  T* p[L::Q];
  const CellIndex base = g.index(x0, y, z);
  for (int q = 0; q < L::Q; ++q) {
    const auto& c = L::c[q];
    if (odd) p[q] = f + L::opp[q] * N + g.index(x0 - c[0], g.step(y, -c[1], 1), g.step(z, -c[2], 2));
    else p[q] = f + q * N + base;
  }
  // Seam cells of a periodic x axis: p[q][klo] (c_x > 0) and p[q][khi] (c_x < 0) are ghost
  // slots; p[q][klo + nx] and p[q][khi - nx] the wrapped slots they stand for.
  const bool lo = odd && g.periodic[0] && x0 == 0;
  const bool hi = odd && g.periodic[0] && x0 + n == g.nx;
  const std::int64_t klo = 0, khi = std::int64_t(n) - 1;
  const std::int64_t nx = g.nx;
  T saved[L::Q] = {};
  static_for<L::Q>([&](auto q) FF_LBM_LAMBDA_INLINE {
    if constexpr (L::c[q][0] > 0) {
      if (lo) {
        saved[q] = p[q][klo];
        p[q][klo] = p[q][klo + nx];
      }
    } else if constexpr (L::c[q][0] < 0) {
      if (hi) {
        saved[q] = p[q][khi];
        p[q][khi] = p[q][khi - nx];
      }
    }
  });
  kernel(static_cast<T* const*>(p), base);
  static_for<L::Q>([&](auto q) FF_LBM_LAMBDA_INLINE {
    if constexpr (L::c[q][0] > 0) {
      if (lo) {
        p[q][klo + nx] = p[q][klo];
        p[q][klo] = saved[q];
      }
    } else if constexpr (L::c[q][0] < 0) {
      if (hi) {
        p[q][khi - nx] = p[q][khi];
        p[q][khi] = saved[q];
      }
    }
  });
}

}  // namespace ff::lbm
