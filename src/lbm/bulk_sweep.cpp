// Solver::bulk_sweep(): the fused stream-collide kernel over all bulk spans of one step.
//
// Speed: the kernel is compiled three times through GCC's target_clones (x86-64 baseline SSE2,
// x86-64-v3 = AVX2+FMA, x86-64-v4 = AVX-512 with 512-bit vectors), and the loader picks the best
// the CPU supports. The binary stays portable (no -march=native). With one pointer per direction
// (stream_collide.hpp) the AVX-512 clone, with its 32 vector registers, spills far less than the
// AVX2 one and is the fastest on Zen 4 (docs/lbm.md, "Speed"). All clones do the same IEEE
// operations per cell (the project builds with -ffp-contract=off), and within one run every
// cell always goes through the same code path: results do not depend on the thread count.
#include "lbm/solver.hpp"
#include "lbm/stream_collide.hpp"

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define FF_LBM_CLONES __attribute__((target_clones("default", "arch=x86-64-v3", "arch=x86-64-v4")))
#else
#define FF_LBM_CLONES
#endif

namespace ff::lbm {

namespace {

// One span: sets the per-direction pointers of the AA pattern and runs the kernel. p[q] is
// the slot the cell reads g_q from; the kernel writes g*_{opp q} back into it.
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
template <class L, class T, CollisionModel M, bool kForce, bool kMoments, bool kIncomp>
FF_LBM_CLONES void sweep_span(const Grid& g, T* f, CellIndex N, int x0, int y, int z, int n, bool odd,
                              const Relax<T>& r, T* drho, T* const* u) {
  T* p[L::Q];
  const CellIndex base = g.index(x0, y, z);
  for (int q = 0; q < L::Q; ++q) {
    const auto& c = L::c[q];
    if (odd) p[q] = f + L::opp[q] * N + g.index(x0 - c[0], g.step(y, -c[1], 1), g.step(z, -c[2], 2));
    else p[q] = f + q * N + base;
  }
  MomentOut<T> m;
  if constexpr (kMoments) {
    m.drho = drho + base;
    for (int a = 0; a < 3; ++a) m.u[a] = u[a] + base;
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
  stream_collide_span<L, T, M, kForce, kMoments, kIncomp>(p, n, r, m);
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

}  // namespace

template <class L, class T>
void Solver<L, T>::bulk_sweep(bool odd, bool sample) {
  const bool force = settings_.body_force.squaredNorm() > 0;
  const bool trt = settings_.collision == CollisionModel::Trt;
  // Pick the instantiation once per step; the loop below has no further branches.
  using Fn = void (*)(const Grid&, T*, CellIndex, int, int, int, int, bool, const Relax<T>&, T*, T* const*);
  auto pick = [&]<CollisionModel M, bool kIncomp>() -> Fn {
    if (force) return sample ? &sweep_span<L, T, M, true, true, kIncomp> : &sweep_span<L, T, M, true, false, kIncomp>;
    return sample ? &sweep_span<L, T, M, false, true, kIncomp> : &sweep_span<L, T, M, false, false, kIncomp>;
  };
  Fn fn;
  if (settings_.incompressible)
    fn = trt ? pick.template operator()<CollisionModel::Trt, true>() : pick.template operator()<CollisionModel::Bgk, true>();
  else
    fn = trt ? pick.template operator()<CollisionModel::Trt, false>() : pick.template operator()<CollisionModel::Bgk, false>();
  T* f = f_.data();
  const CellIndex N = n_();
  T* u[3] = {u_[0].data(), u_[1].data(), u_[2].data()};
  T* drho = drho_.data();
  const Relax<T> r = relax_;
  const std::int64_t ns = std::int64_t(spans_.size());
  const Span* spans = spans_.data();
  const Grid& g = grid_;
  // Cells covered by particles (lbm/psm.hpp): the PSM update wraps the kernel of their span.
  Psm<L, T>* psm = psm_ && psm_->active() ? psm_.get() : nullptr;
  const bool force_psm = force;
  const bool incomp = settings_.incompressible;
  // Small lattices run serially: a parallel region costs more than it saves there.
#pragma omp parallel for schedule(static) if (num_bulk_cells_ > kParallelMinCells)
  for (std::int64_t s = 0; s < ns; ++s) {
    const Span& sp = spans[s];
    const bool covered = psm && psm->span_covered(s);
    if (covered) psm->save_span(s, f, odd);
    fn(g, f, N, sp.x0, sp.y, sp.z, sp.n, odd, r, drho, u);
    if (covered) psm->apply_span(s, f, odd, r, force_psm, incomp);
  }
}

template void Solver<D2Q9, double>::bulk_sweep(bool, bool);
template void Solver<D2Q9, float>::bulk_sweep(bool, bool);
template void Solver<D3Q19, double>::bulk_sweep(bool, bool);
template void Solver<D3Q19, float>::bulk_sweep(bool, bool);

}  // namespace ff::lbm
