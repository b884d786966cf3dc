// Solver::bulk_sweep(): the fused stream-collide kernel over all bulk spans of one step.
//
// Speed: the kernel is compiled twice (x86-64 baseline SSE2, and x86-64-v3 = AVX2+FMA)
// through GCC's target_clones, and the loader picks the one the CPU supports. The binary stays
// portable (no -march=native). An AVX-512 clone was measured too and was 5-20% slower on the
// Zen 4 development machine (the odd AA half reads and writes one cell off alignment for 10 of
// 19 directions, and every misaligned 64-byte store splits two cache lines). Within one run
// every cell always goes through the same code path: results do not depend on the thread count.
#include "lbm/solver.hpp"
#include "lbm/stream_collide.hpp"

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define FF_LBM_CLONES __attribute__((target_clones("default", "arch=x86-64-v3")))
#else
#define FF_LBM_CLONES
#endif

namespace ff::lbm {

namespace {

// One span: sets the per-direction pointers of the AA pattern and runs the kernel.
//   even step: read f[q][x],            write f[opp q][x]
//   odd step:  read f[opp q][x - c_q],  write f[q][x + c_q]
template <class L, class T, CollisionModel M, bool kForce, bool kMoments>
FF_LBM_CLONES void sweep_span(const Grid& g, T* f, CellIndex N, int x0, int y, int z, int n, bool odd,
                              const Relax<T>& r, T* drho, T* const* u) {
  T* src[L::Q];
  T* dst[L::Q];
  const CellIndex base = g.index(x0, y, z);
  for (int q = 0; q < L::Q; ++q) {
    const int o = L::opp[q];
    const auto& c = L::c[q];
    if (odd) {
      src[q] = f + o * N + g.neighbour(x0, y, z, -c[0], -c[1], -c[2]);
      dst[q] = f + q * N + g.neighbour(x0, y, z, c[0], c[1], c[2]);
    } else {
      src[q] = f + q * N + base;
      dst[q] = f + o * N + base;
    }
  }
  MomentOut<T> m;
  if constexpr (kMoments) {
    m.drho = drho + base;
    for (int a = 0; a < 3; ++a) m.u[a] = u[a] + base;
  }
  stream_collide_span<L, T, M, kForce, kMoments>(src, dst, n, r, m);
}

}  // namespace

template <class L, class T>
void Solver<L, T>::bulk_sweep(bool odd, bool sample) {
  const bool force = settings_.body_force.squaredNorm() > 0;
  const bool trt = settings_.collision == CollisionModel::Trt;
  // Pick the instantiation once per step; the loop below has no further branches.
  using Fn = void (*)(const Grid&, T*, CellIndex, int, int, int, int, bool, const Relax<T>&, T*, T* const*);
  Fn fn;
  if (trt) {
    if (force) fn = sample ? &sweep_span<L, T, CollisionModel::Trt, true, true> : &sweep_span<L, T, CollisionModel::Trt, true, false>;
    else fn = sample ? &sweep_span<L, T, CollisionModel::Trt, false, true> : &sweep_span<L, T, CollisionModel::Trt, false, false>;
  } else {
    if (force) fn = sample ? &sweep_span<L, T, CollisionModel::Bgk, true, true> : &sweep_span<L, T, CollisionModel::Bgk, true, false>;
    else fn = sample ? &sweep_span<L, T, CollisionModel::Bgk, false, true> : &sweep_span<L, T, CollisionModel::Bgk, false, false>;
  }
  T* f = f_.data();
  const CellIndex N = n_();
  T* u[3] = {u_[0].data(), u_[1].data(), u_[2].data()};
  T* drho = drho_.data();
  const Relax<T> r = relax_;
  const std::int64_t ns = std::int64_t(spans_.size());
  const Span* spans = spans_.data();
  const Grid& g = grid_;
  // Small lattices run serially: a parallel region costs more than it saves there.
  if (!odd) {
    const std::int64_t ne = std::int64_t(even_spans_.size());
    const Span* es = even_spans_.data();
#pragma omp parallel for schedule(static) if (num_bulk_cells_ > kParallelMinCells)
    for (std::int64_t s = 0; s < ne; ++s) fn(g, f, N, es[s].x0, es[s].y, es[s].z, es[s].n, odd, r, drho, u);
    return;
  }
#pragma omp parallel for schedule(static) if (num_bulk_cells_ > kParallelMinCells)
  for (std::int64_t s = 0; s < ns; ++s) {
    const Span& sp = spans[s];
    fn(g, f, N, sp.x0, sp.y, sp.z, sp.n, odd, r, drho, u);
  }
}

template void Solver<D2Q9, double>::bulk_sweep(bool, bool);
template void Solver<D2Q9, float>::bulk_sweep(bool, bool);
template void Solver<D3Q19, double>::bulk_sweep(bool, bool);
template void Solver<D3Q19, float>::bulk_sweep(bool, bool);

}  // namespace ff::lbm
