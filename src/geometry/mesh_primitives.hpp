// Closed triangle meshes of simple solids (outward, counter-clockwise triangles). Used by tests and
// by sample generators that write STL inclusions.
#pragma once
#include "core/types.hpp"
#include "geometry/triangle_mesh.hpp"

namespace ff::geom {

// Icosphere: an icosahedron refined `subdivisions` times (20 * 4^s triangles), projected on the
// unit sphere, scaled by the semi-axes and rotated by `orientation` (body -> world).
TriangleMesh make_ellipsoid_mesh(const Vec3& c, const Vec3& semi_axes, const Quat& orientation, int subdivisions);

// Box [lo, hi] with every face split into divisions x divisions squares (2 triangles each).
TriangleMesh make_box_mesh(const Vec3& lo, const Vec3& hi, int divisions = 1);

// Cylinder from `base` along unit `axis`: `segments` facets around, `rings` bands along the axis,
// end caps as fans around their centre.
TriangleMesh make_cylinder_mesh(const Vec3& base, const Vec3& axis, Real radius, Real length, int segments,
                                int rings = 1);

}  // namespace ff::geom

namespace ff {
using geom::make_box_mesh;
using geom::make_cylinder_mesh;
using geom::make_ellipsoid_mesh;
}  // namespace ff
