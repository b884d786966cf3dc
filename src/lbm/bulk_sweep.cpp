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

#include <omp.h>

#include "lbm/span_slots.hpp"
#include "lbm/stream_collide.hpp"

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define FF_LBM_CLONES __attribute__((target_clones("default", "arch=x86-64-v3", "arch=x86-64-v4")))
#else
#define FF_LBM_CLONES
#endif

namespace ff::lbm {

namespace {

// One span of plain fluid cells (span_slots.hpp: the AA pattern's pointers and the periodic seam).
template <class L, class T, CollisionModel M, bool kForce, bool kMoments, bool kIncomp>
FF_LBM_CLONES void sweep_span(const Grid& g, T* f, CellIndex N, int x0, int y, int z, int n, bool odd,
                              const Relax<T>& r, T* drho, T* const* u) {
  with_span_slots<L, T>(g, f, N, x0, y, z, n, odd, [&](T* const* p, CellIndex base) FF_LBM_LAMBDA_INLINE {
    MomentOut<T> m;
    if constexpr (kMoments) {
      m.drho = drho + base;
      for (int a = 0; a < 3; ++a) m.u[a] = u[a] + base;
    }
    stream_collide_span<L, T, M, kForce, kMoments, kIncomp>(p, n, r, m);
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
  // Cells covered by particles (lbm/psm.hpp): their spans run the fused PSM kernel.
  Psm<L, T>* psm = psm_ && psm_->active() ? psm_.get() : nullptr;
  const PsmSpanFn<T> fn_psm =
      psm ? psm_span_kernel<L, T>(settings_.collision, force, sample, settings_.incompressible, psm->moving()) : nullptr;
  const PsmCells<T> cells = psm ? psm->bulk_cells() : PsmCells<T>{};
  mb_inline_rows_.clear();
  MovingBoundary<L, T>* mb = !psm && mb_ && mb_->rows_ready() ? mb_.get() : nullptr;
  if (mb) {
    // Particle links inside the sweep (moving_boundary.hpp, "Links inside the bulk sweep"): each
    // thread sweeps its own block of rows and applies the links of row r - lag after row r; the
    // first and last lag rows of each block wait for MovingBoundary::apply().
    mb->prepare_rows();
    const std::int64_t nrows = std::int64_t(row_span_.size()) - 1, lag = mb->row_lag();
    const bool par = num_bulk_cells_ > kParallelMinCells;
    const int nt = par ? omp_get_max_threads() : 1;
    mb_inline_rows_.assign(std::size_t(nt), {0, 0});
    const std::int64_t* rs = row_span_.data();
#pragma omp parallel num_threads(nt) if (par)
    {
      const std::int64_t t = omp_get_thread_num(), nth = omp_get_num_threads();
      const std::int64_t r0 = nrows * t / nth, r1 = nrows * (t + 1) / nth;
      for (std::int64_t row = r0; row < r1; ++row) {
        for (std::int64_t s = rs[row]; s < rs[row + 1]; ++s) {
          const Span& sp = spans[s];
          fn(g, f, N, sp.x0, sp.y, sp.z, sp.n, odd, r, drho, u);
        }
        if (row - lag >= r0 + lag) mb->apply_rows(f, odd, row - lag, row - lag + 1);
      }
      if (r1 - lag > r0 + lag) mb_inline_rows_[std::size_t(t)] = {r0 + lag, r1 - lag};
    }
    return;
  }
  // Small lattices run serially: a parallel region costs more than it saves there.
#pragma omp parallel for schedule(static) if (num_bulk_cells_ > kParallelMinCells)
  for (std::int64_t s = 0; s < ns; ++s) {
    const Span& sp = spans[s];
    if (psm && psm->span_covered(s)) fn_psm(g, f, N, sp.x0, sp.y, sp.z, sp.n, odd, r, drho, u, cells);
    else fn(g, f, N, sp.x0, sp.y, sp.z, sp.n, odd, r, drho, u);
  }
}

template void Solver<D2Q9, double>::bulk_sweep(bool, bool);
template void Solver<D2Q9, float>::bulk_sweep(bool, bool);
template void Solver<D3Q19, double>::bulk_sweep(bool, bool);
template void Solver<D3Q19, float>::bulk_sweep(bool, bool);

}  // namespace ff::lbm
