// The PFV-style pore network of a cube of spheres for the 3D pore-network tests.
#pragma once
#include <cstdint>
#include <vector>

#include "geometry/packing.hpp"
#include "porenet/network.hpp"

namespace ff::porenet::test_packings {

// A dense random packing of spheres (radii 0.4-0.6 mm) in the box [0, hi], as coordinate arrays, with
// the porosity the packer reached.
struct Spheres {
  std::vector<Real> x, y, z, r;
  Real porosity = 0;
};
inline Spheres box_spheres(const Vec3& hi, Real porosity, std::uint64_t seed) {
  PackingSpec spec;
  spec.dim = 3;
  spec.container = PackingSpec::Container::Box;
  spec.box_lo = {0, 0, 0};
  spec.box_hi = hi;
  spec.radius_min = 0.4e-3;
  spec.radius_max = 0.6e-3;
  spec.porosity = porosity;
  spec.seed = seed;
  const Packing pk = dense_random_packing(spec);
  Spheres s;
  for (const Vec3& c : pk.position) {
    s.x.push_back(c.x());
    s.y.push_back(c.y());
    s.z.push_back(c.z());
  }
  s.r = pk.radius;
  s.porosity = pk.achieved_porosity;
  return s;
}

// A dense random packing of spheres (radii 0.4-0.6 mm, porosity 0.42) in a cube of the given side,
// and its regular-triangulation network.
inline Network2D box_network_3d(Real side, std::uint64_t seed) {
  PackingSpec spec;
  spec.dim = 3;
  spec.container = PackingSpec::Container::Box;
  spec.box_lo = {0, 0, 0};
  spec.box_hi = {side, side, side};
  spec.radius_min = 0.4e-3;
  spec.radius_max = 0.6e-3;
  spec.porosity = 0.42;
  spec.seed = seed;
  const Packing pk = dense_random_packing(spec);
  std::vector<Real> x, y, z;
  for (const Vec3& c : pk.position) {
    x.push_back(c.x());
    y.push_back(c.y());
    z.push_back(c.z());
  }
  return build_network_3d({x, y, z, pk.radius, {}});
}

}  // namespace ff::porenet::test_packings
