// Four frictionless plane walls around a DEM sample at the spheres' extent on the two axes other than
// the loading one: with the platens, an oedometer or the box of a network with walls (3D tests).
#pragma once
#include <algorithm>

#include "dem/dem_system.hpp"

namespace ff::test {

inline void add_side_walls(dem::DemSystem& sys, int loading_axis) {
  const auto& P = sys.particles;
  for (int a = 0; a < 3; ++a) {
    if (a == loading_axis) continue;
    Real lo = 1e9, hi = -1e9;
    for (std::size_t i = 0; i < P.size(); ++i) {
      lo = std::min(lo, P.pos[i][a] - P.radius[i]);
      hi = std::max(hi, P.pos[i][a] + P.radius[i]);
    }
    for (int side = 0; side < 2; ++side) {
      dem::Wall w;
      w.name = "side";
      w.normal = Vec3::Zero();
      w.normal[a] = side == 0 ? 1 : -1;
      w.point = Vec3::Zero();
      w.point[a] = side == 0 ? lo : hi;
      w.friction = 0;
      sys.walls.push_back(w);
    }
  }
}

}  // namespace ff::test
