// Indexed triangle surface (STL inclusions, sample outlines) and its topological checks.
#pragma once
#include <array>
#include <vector>

#include "core/types.hpp"
#include "geometry/aabb.hpp"

namespace ff::geom {

struct TriangleMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;  // vertex indices, counter-clockwise seen from outside
};

// Number of edges not shared by exactly two triangles (0 for a closed surface).
int open_edge_count(const TriangleMesh& mesh);
// Every edge is shared by exactly two triangles.
bool is_closed(const TriangleMesh& mesh);

// Enclosed volume by the divergence theorem, V = 1/6 sum_t v0 . (v1 x v2). Positive when the
// triangles are counter-clockwise seen from outside (outward normals); meaningful for closed meshes.
Real mesh_volume(const TriangleMesh& mesh);

Aabb mesh_bounds(const TriangleMesh& mesh);

// Merges vertices with bit-identical coordinates, renumbers the triangles and drops triangles that
// became degenerate (two equal corners). Returns the number of dropped triangles.
int merge_coincident_vertices(TriangleMesh& mesh);

}  // namespace ff::geom

namespace ff {
using geom::is_closed;
using geom::mesh_volume;
using geom::TriangleMesh;
}  // namespace ff
