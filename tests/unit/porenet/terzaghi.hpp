// Terzaghi's 1D consolidation (Terzaghi 1943, Theoretical Soil Mechanics, Wiley, ch. XIII): the mean
// excess pore pressure of a layer drained at the top and impermeable at the bottom, over its value just
// after a total-stress step, at time factor T_v = c_v t / H^2:
//   1 - U(T_v) = sum_m 2 / M^2 exp(-M^2 T_v), M = (2m + 1) pi / 2.
#pragma once
#include <cmath>

#include "core/types.hpp"

namespace ff::test {

inline Real terzaghi_mean_excess(Real Tv) {
  Real s = 0;
  for (int m = 0; m < 200; ++m) {
    const Real M = (2 * m + 1) * kPi / 2;
    s += 2 / (M * M) * std::exp(-M * M * Tv);
  }
  return s;
}

}  // namespace ff::test
