// Branch-free atan2 that the compiler vectorises: reduce to atan(s), s = min(y, |x|) / max(y, |x|) in
// [0, 1], a degree-39 odd minimax polynomial in s (the coefficients of SLEEF's atan2k, Shibata &
// Petrogalli 2020, IEEE TPDS 31:1316; Boost licence), then the octant. Compiled with
// -fno-trapping-math (CMakeLists.txt), which lets GCC turn the selects into blends; it changes no
// result. AVX2 clone where the CPU has it (same operations, same bits: no FMA).
#include "porenet/atan2_batch.hpp"

#include <cmath>

namespace ff::porenet {

__attribute__((target_clones("avx2", "default"))) void atan2_nonneg(const Real* __restrict y,
                                                                    const Real* __restrict x,
                                                                    Real* __restrict out, int n) {
  constexpr Real kPiHalf = 1.57079632679489661923, kPiFull = 3.14159265358979323846;
#pragma omp simd
  for (int i = 0; i < n; ++i) {
    const Real yy = y[i], ax = std::fabs(x[i]);
    const bool swap = yy > ax;
    const Real num = swap ? ax : yy;
    Real den = swap ? yy : ax;
    den = den > 0 ? den : 1.0;  // y = x = 0: atan2 = 0
    const Real s = num / den, t = s * s;
    Real u = -1.88796008463073496563746e-05;
    u = u * t + 0.000209850076645816976906797;
    u = u * t + -0.00110611831486672482563471;
    u = u * t + 0.00370026744188713119232403;
    u = u * t + -0.00889896195887655491740809;
    u = u * t + 0.016599329773529201970117;
    u = u * t + -0.0254517624932312641616861;
    u = u * t + 0.0337852580001353069993897;
    u = u * t + -0.0407629191276836500001934;
    u = u * t + 0.0466667150077840625632675;
    u = u * t + -0.0523674852303482457616113;
    u = u * t + 0.0587666392926673580854313;
    u = u * t + -0.0666573579361080525984562;
    u = u * t + 0.0769219538311769618355029;
    u = u * t + -0.090908995008245008229153;
    u = u * t + 0.111111105648261418443745;
    u = u * t + -0.14285714266771329383765;
    u = u * t + 0.199999999996591265594148;
    u = u * t + -0.333333333333311110369124;
    Real a = u * t * s + s;             // atan(num / den) in [0, pi/4]
    a = swap ? kPiHalf - a : a;         // atan(y / |x|) in [0, pi/2]
    out[i] = x[i] < 0 ? kPiFull - a : a;
  }
}

}  // namespace ff::porenet
