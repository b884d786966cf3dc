// Small deterministic 2D packings for the pore-network tests.
#pragma once
#include <cmath>
#include <vector>

#include "core/rng.hpp"
#include "porenet/network.hpp"

namespace ff::porenet::test_packings {

struct Discs {
  std::vector<Real> x, y, r;
  std::vector<std::int64_t> gid;
  Particles2D view() const { return {x, y, r, gid}; }
};

// Triangular lattice nx by ny of spacing d, radii r0 (1 +- rjit), positions jittered by pjit d.
inline Discs hex_packing(int nx, int ny, Real d, Real r0, Real rjit, Real pjit, std::uint64_t seed = 7) {
  Discs s;
  Rng rng(seed);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      s.x.push_back((i + 0.5 * (j % 2)) * d + pjit * d * rng.uniform(-1, 1));
      s.y.push_back(j * d * std::sqrt(3.0) / 2 + pjit * d * rng.uniform(-1, 1));
      s.r.push_back(r0 * (1 + rjit * rng.uniform(-1, 1)));
      s.gid.push_back(static_cast<std::int64_t>(s.x.size()) - 1);
    }
  return s;
}

}  // namespace ff::porenet::test_packings
