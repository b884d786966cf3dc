#include "geometry/triangle_mesh.hpp"

#include <algorithm>
#include <cstdint>
#include <numeric>

namespace ff::geom {

int open_edge_count(const TriangleMesh& mesh) {
  // Undirected edges as (min, max) keys; sorting makes the count independent of hashing.
  std::vector<std::uint64_t> edges;
  edges.reserve(3 * mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      const auto a = static_cast<std::uint32_t>(t[k]);
      const auto b = static_cast<std::uint32_t>(t[(k + 1) % 3]);
      edges.push_back((std::uint64_t{std::min(a, b)} << 32) | std::max(a, b));
    }
  }
  std::sort(edges.begin(), edges.end());
  int open = 0;
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    if (j - i != 2) ++open;
    i = j;
  }
  return open;
}

bool is_closed(const TriangleMesh& mesh) {
  return !mesh.triangles.empty() && open_edge_count(mesh) == 0;
}

Real mesh_volume(const TriangleMesh& mesh) {
  Real six_v = 0;
  for (const auto& t : mesh.triangles) {
    const Vec3& a = mesh.vertices[t[0]];
    six_v += a.dot(mesh.vertices[t[1]].cross(mesh.vertices[t[2]]));
  }
  return six_v / 6.0;
}

Aabb mesh_bounds(const TriangleMesh& mesh) {
  Aabb box;
  for (const Vec3& v : mesh.vertices) box.expand(v);
  return box;
}

int merge_coincident_vertices(TriangleMesh& mesh) {
  const std::size_t n = mesh.vertices.size();
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  const auto& v = mesh.vertices;
  auto less = [&](int a, int b) {
    if (v[a].x() != v[b].x()) return v[a].x() < v[b].x();
    if (v[a].y() != v[b].y()) return v[a].y() < v[b].y();
    if (v[a].z() != v[b].z()) return v[a].z() < v[b].z();
    return a < b;
  };
  std::sort(order.begin(), order.end(), less);
  // New indices follow the first appearance in the original order, so the result is stable.
  std::vector<int> rep(n);
  for (std::size_t i = 0; i < n;) {
    std::size_t j = i;
    while (j < n && v[order[j]] == v[order[i]]) ++j;
    for (std::size_t k = i; k < j; ++k) rep[order[k]] = order[i];  // order[i] is the smallest index
    i = j;
  }
  std::vector<int> new_index(n, -1);
  std::vector<Vec3> merged;
  merged.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (rep[i] == static_cast<int>(i)) {
      new_index[i] = static_cast<int>(merged.size());
      merged.push_back(v[i]);
    }
  }
  int dropped = 0;
  std::vector<std::array<int, 3>> tris;
  tris.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    const std::array<int, 3> m{new_index[rep[t[0]]], new_index[rep[t[1]]], new_index[rep[t[2]]]};
    if (m[0] == m[1] || m[1] == m[2] || m[0] == m[2]) {
      ++dropped;
      continue;
    }
    tris.push_back(m);
  }
  mesh.vertices = std::move(merged);
  mesh.triangles = std::move(tris);
  return dropped;
}

}  // namespace ff::geom
