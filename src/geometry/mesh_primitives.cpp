#include "geometry/mesh_primitives.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <map>
#include <utility>

#include "core/error.hpp"

namespace ff::geom {

TriangleMesh make_ellipsoid_mesh(const Vec3& c, const Vec3& semi_axes, const Quat& orientation, int subdivisions) {
  if (subdivisions < 0 || subdivisions > 8) {
    throw InputError(fmt::format("make_ellipsoid_mesh: subdivisions = {} must be in [0, 8]", subdivisions));
  }
  // Regular icosahedron: cyclic permutations of (0, +-1, +-phi).
  const Real p = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3> v = {{-1, p, 0}, {1, p, 0},  {-1, -p, 0}, {1, -p, 0}, {0, -1, p},  {0, 1, p},
                         {0, -1, -p}, {0, 1, -p}, {p, 0, -1},  {p, 0, 1},  {-p, 0, -1}, {-p, 0, 1}};
  for (Vec3& x : v) x.normalize();
  std::vector<std::array<int, 3>> t = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<int, int>, int> midpoint;  // shared edges get one new vertex
    auto mid = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      const auto it = midpoint.find(key);
      if (it != midpoint.end()) return it->second;
      v.push_back((v[a] + v[b]).normalized());
      const int id = static_cast<int>(v.size()) - 1;
      midpoint.emplace(key, id);
      return id;
    };
    std::vector<std::array<int, 3>> refined;
    refined.reserve(4 * t.size());
    for (const auto& f : t) {
      const int ab = mid(f[0], f[1]), bc = mid(f[1], f[2]), ca = mid(f[2], f[0]);
      refined.push_back({f[0], ab, ca});
      refined.push_back({f[1], bc, ab});
      refined.push_back({f[2], ca, bc});
      refined.push_back({ab, bc, ca});
    }
    t = std::move(refined);
  }
  const Mat3 r = orientation.normalized().toRotationMatrix();
  for (Vec3& x : v) x = c + r * x.cwiseProduct(semi_axes);
  return TriangleMesh{std::move(v), std::move(t)};
}

TriangleMesh make_box_mesh(const Vec3& lo, const Vec3& hi, int divisions) {
  if (divisions < 1) throw InputError(fmt::format("make_box_mesh: divisions = {} must be >= 1", divisions));
  if (!((hi - lo).array() > 0).all()) throw InputError("make_box_mesh: hi must exceed lo in x, y and z");
  TriangleMesh mesh;
  std::map<std::array<std::int64_t, 3>, int> ids;  // lattice index -> vertex (faces share edges)
  const int n = divisions;
  auto vertex = [&](int i, int j, int k) {
    const std::array<std::int64_t, 3> key{i, j, k};
    const auto it = ids.find(key);
    if (it != ids.end()) return it->second;
    const Vec3 f(Real(i) / n, Real(j) / n, Real(k) / n);
    mesh.vertices.push_back(lo + (hi - lo).cwiseProduct(f));
    const int id = static_cast<int>(mesh.vertices.size()) - 1;
    ids.emplace(key, id);
    return id;
  };
  // For each axis `a` and side, the face spans axes b = a+1, c = a+2 (cyclic); (b, c, a) is
  // right-handed, so counter-clockwise in (b, c) points along +a.
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    for (int side = 0; side < 2; ++side) {
      for (int u = 0; u < n; ++u) {
        for (int w = 0; w < n; ++w) {
          auto corner = [&](int du, int dw) {
            int idx[3];
            idx[a] = side * n;
            idx[b] = u + du;
            idx[c] = w + dw;
            return vertex(idx[0], idx[1], idx[2]);
          };
          const int q00 = corner(0, 0), q10 = corner(1, 0), q11 = corner(1, 1), q01 = corner(0, 1);
          if (side == 1) {
            mesh.triangles.push_back({q00, q10, q11});
            mesh.triangles.push_back({q00, q11, q01});
          } else {
            mesh.triangles.push_back({q00, q11, q10});
            mesh.triangles.push_back({q00, q01, q11});
          }
        }
      }
    }
  }
  return mesh;
}

TriangleMesh make_cylinder_mesh(const Vec3& base, const Vec3& axis, Real radius, Real length, int segments,
                                int rings) {
  if (segments < 3 || rings < 1) {
    throw InputError(fmt::format("make_cylinder_mesh: segments = {} (>= 3) and rings = {} (>= 1)", segments, rings));
  }
  const Vec3 a = axis.normalized();
  // Orthonormal (e1, e2, a), right-handed.
  const Vec3 e1 = a.unitOrthogonal();
  const Vec3 e2 = a.cross(e1);
  TriangleMesh mesh;
  for (int r = 0; r <= rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      const Real phi = 2 * kPi * s / segments;
      mesh.vertices.push_back(base + length * Real(r) / rings * a + radius * (std::cos(phi) * e1 + std::sin(phi) * e2));
    }
  }
  const int bottom = static_cast<int>(mesh.vertices.size());
  mesh.vertices.push_back(base);
  mesh.vertices.push_back(base + length * a);
  const int top = bottom + 1;
  auto id = [&](int r, int s) { return r * segments + (s % segments); };
  for (int r = 0; r < rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      mesh.triangles.push_back({id(r, s), id(r, s + 1), id(r + 1, s + 1)});
      mesh.triangles.push_back({id(r, s), id(r + 1, s + 1), id(r + 1, s)});
    }
  }
  for (int s = 0; s < segments; ++s) {
    mesh.triangles.push_back({bottom, id(0, s + 1), id(0, s)});
    mesh.triangles.push_back({top, id(rings, s), id(rings, s + 1)});
  }
  return mesh;
}

}  // namespace ff::geom
