// atan2(y, x) for y >= 0 over arrays, vectorised (the 3D network's per-step geometry needs ~1.8 million
// angles on 30,000 spheres; libm's scalar atan2 was a third of a coupled step).
#pragma once

#include "core/types.hpp"

namespace ff::porenet {

// out[i] = atan2(y[i], x[i]) in [0, pi] for y[i] >= 0 (any x[i]; 0 for y = x = 0), within 2 ulp of
// libm's (max |difference| 4.4e-16 on 4 million random arguments). Deterministic: the same bits on
// every thread and vector width (no fused multiply-add). Arrays must not overlap.
void atan2_nonneg(const Real* y, const Real* x, Real* out, int n);

}  // namespace ff::porenet
