// Sums whose result does not depend on the number of OpenMP threads: fixed blocks of
// kReduceBlock terms are summed in order (blocks in parallel), then the block sums in order.
#pragma once
#include <algorithm>
#include <vector>

#include "core/types.hpp"

namespace ff::porenet {

inline constexpr Index kReduceBlock = 2048;
// Loops over fewer items run on one thread: on a busy machine an OpenMP fork/join (and its spinning
// workers) costs more than a few thousand pores' work.
inline constexpr Index kParallelMin = 4096;


inline Index reduce_blocks(Index n) { return (n + kReduceBlock - 1) / kReduceBlock; }

// scratch must hold reduce_blocks(n) values (sized once, outside the time loop).
template <class F>
Real fixed_order_sum(Index n, F&& term, std::vector<Real>& scratch) {
  const Index nb = reduce_blocks(n);
  // Few blocks: no parallel region (idle, spinning workers slow a busy machine down).
#pragma omp parallel for schedule(static) if (n > kParallelMin)
  for (Index b = 0; b < nb; ++b) {
    const Index end = std::min(n, (b + 1) * kReduceBlock);
    Real s = 0;
    for (Index i = b * kReduceBlock; i < end; ++i) s += term(i);
    scratch[b] = s;
  }
  Real s = 0;
  for (Index b = 0; b < nb; ++b) s += scratch[b];
  return s;
}

}  // namespace ff::porenet
