// Point-in-solid test for closed triangle surfaces (STL inclusions, sample outlines).
//
// Method: ray parity (Jordan) along three fixed directions with irrational components, majority
// vote. Per direction the vertices are projected once onto the plane normal to the ray and the
// triangles are binned into a uniform 2D grid of that plane, so a query visits only the triangles
// whose shadow covers its cell. The 2D point-in-triangle test is watertight: edge functions are
// cross products of the corners' offsets from the query point (Woop, Benthin & Wald 2013, JCGT
// 2(1)), exactly antisymmetric for the two triangles of an edge, and exact ties are broken by the
// top-left fill rule (Pineda 1988), so a ray through a shared edge or vertex counts once. The
// majority over three rays guards against the remaining round-off (depth comparison,
// near-collinear corners). Points on the surface may be classified either way. Requires a closed
// surface (every edge shared by two triangles); triangle orientation does not matter. Copies
// share the immutable acceleration data.
#pragma once
#include <array>
#include <filesystem>
#include <memory>
#include <string>

#include "core/types.hpp"
#include "geometry/aabb.hpp"
#include "geometry/mesh_primitives.hpp"  // convenience: make_*_mesh are used together with MeshRegion
#include "geometry/triangle_mesh.hpp"

namespace ff::geom {

class MeshRegion {
 public:
  // `name` (usually the file name) is used in error messages. Throws ff::InputError
  // "surface '<name>' is not closed: N open edges" for an open or empty mesh.
  explicit MeshRegion(TriangleMesh mesh, std::string name = "triangle mesh");

  bool contains(const Vec3& p) const;
  // Diagnostics: how many of the three rays see an odd number of crossings (0..3). Away from the
  // surface a watertight test gives 0 or 3.
  int inside_votes(const Vec3& p) const;
  // The three ray directions (unit vectors).
  static std::array<Vec3, 3> ray_directions();
  Aabb bounds() const;
  const TriangleMesh& mesh() const;
  const std::string& name() const;

  struct Data;

 private:
  std::shared_ptr<const Data> data_;
};

// read_stl + MeshRegion, naming the file in every error.
MeshRegion load_mesh_region(const std::filesystem::path& stl_path);

}  // namespace ff::geom

namespace ff {
using geom::load_mesh_region;
using geom::MeshRegion;
}  // namespace ff
