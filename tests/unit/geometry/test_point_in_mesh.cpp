// Point-in-mesh against analytic solids, on vertex planes, with cavities, and its speed.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <ctime>
#include <functional>
#include <vector>

#include "core/error.hpp"
#include "core/rng.hpp"
#include "geometry/point_in_mesh.hpp"
#include "geometry/shapes.hpp"

namespace ff::geom {
namespace {

Real longest_edge(const TriangleMesh& m) {
  Real h = 0;
  for (const auto& t : m.triangles) {
    for (int k = 0; k < 3; ++k) h = std::max(h, (m.vertices[t[k]] - m.vertices[t[(k + 1) % 3]]).norm());
  }
  return h;
}

// 100k random points in the (enlarged) box of an ellipsoid: the mesh may only disagree with the
// analytic solid within one triangle size h of the surface, i.e. between the ellipsoids with
// semi-axes a - h and a + h (the polyhedron is inscribed, so its surface lies in that shell).
void check_against_ellipsoid(const Ellipsoid& e, int subdivisions) {
  const MeshRegion mesh(make_ellipsoid_mesh(e.c, e.semi_axes, e.orientation, subdivisions));
  const Real h = longest_edge(mesh.mesh());
  const Ellipsoid outer{e.c, (e.semi_axes.array() + h).matrix(), e.orientation};
  const Ellipsoid inner{e.c, (e.semi_axes.array() - h).matrix(), e.orientation};
  const Aabb box = e.bounds();
  const Vec3 lo = box.lo - 0.2 * box.extent(), hi = box.hi + 0.2 * box.extent();
  Rng rng(11);
  int mismatches = 0, inside = 0;
  for (int k = 0; k < 100000; ++k) {
    const Vec3 p(rng.uniform(lo.x(), hi.x()), rng.uniform(lo.y(), hi.y()), rng.uniform(lo.z(), hi.z()));
    const bool in = mesh.contains(p);
    inside += in;
    if (in != e.contains(p)) {
      ++mismatches;
      ASSERT_TRUE(outer.contains(p) && !inner.contains(p)) << "far from the surface: " << p.transpose();
    }
  }
  EXPECT_GT(inside, 10000);
  EXPECT_LT(mismatches, 2000);  // only the thin shell near the surface
}

TEST(PointInMesh, SphereAgreesWithAnalyticAwayFromTheSurface) {
  check_against_ellipsoid(Ellipsoid{Vec3(0.3, -0.1, 2), Vec3::Constant(1.5), Quat::Identity()}, 4);
}

TEST(PointInMesh, RotatedEllipsoidAgreesWithAnalyticAwayFromTheSurface) {
  const Quat q(Eigen::AngleAxis<Real>(1.1, Vec3(2, 1, -1).normalized()));
  check_against_ellipsoid(Ellipsoid{Vec3(1, 2, 3), Vec3(2.0, 1.0, 0.6), q}, 4);
}

// Points exactly on the z = const planes through the mesh vertices (and on vertex rows in x and y):
// rays from them pass close to vertices and edges, yet every interior point must be inside.
TEST(PointInMesh, BoxMeshIsExactOnVertexPlanes) {
  const Vec3 lo(-1, -2, 0), hi(1, 2, 4);
  const int div = 4;
  const MeshRegion mesh(make_box_mesh(lo, hi, div));
  const Box box{lo, hi};
  int checked = 0;
  for (int kz = 0; kz <= 2 * div; ++kz) {
    const Real z = lo.z() + (hi.z() - lo.z()) * kz / (2.0 * div);
    for (int ky = -2; ky <= 2 * div + 2; ++ky) {
      for (int kx = -2; kx <= 2 * div + 2; ++kx) {
        const Vec3 p(lo.x() + (hi.x() - lo.x()) * kx / (2.0 * div), lo.y() + (hi.y() - lo.y()) * ky / (2.0 * div), z);
        const bool on_surface = box.contains(p) && ((p - lo).minCoeff() == 0 || (hi - p).minCoeff() == 0);
        if (on_surface) continue;  // either answer is acceptable on the surface itself
        ASSERT_EQ(mesh.contains(p), box.contains(p)) << p.transpose();
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 500);
}

// Rays aimed exactly at vertices and edge midpoints (the degenerate cases of ray parity): with
// the watertight test all three rays must still agree for points away from the surface.
void check_rays_through_features(const MeshRegion& region, const std::function<int(const Vec3&)>& truth) {
  const TriangleMesh& m = region.mesh();
  std::vector<Vec3> targets = m.vertices;
  for (const auto& t : m.triangles) targets.push_back(0.5 * (m.vertices[t[0]] + m.vertices[t[1]]));
  const Real size = region.bounds().extent().norm();
  int checked = 0;
  for (const Vec3& d : MeshRegion::ray_directions()) {
    for (const Vec3& v : targets) {
      for (const Real s : {0.05, 0.2, 0.45}) {
        const Vec3 p = v - s * size * d;  // the ray p + t d passes through v at t = s * size
        const int expect = truth(p);      // 1 inside, 0 outside, -1 too close to the surface
        if (expect < 0) continue;
        ASSERT_EQ(region.inside_votes(p), 3 * expect) << p.transpose();
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 100);
}

TEST(PointInMesh, RaysThroughVerticesAndEdgesOfABox) {
  const Vec3 lo(0, 0, 0), hi(2, 1, 3);
  const MeshRegion region(make_box_mesh(lo, hi, 3));
  check_rays_through_features(region, [&](const Vec3& p) {
    const Real depth = std::min((p - lo).minCoeff(), (hi - p).minCoeff());  // > 0 inside
    return std::abs(depth) < 1e-6 ? -1 : (depth > 0 ? 1 : 0);
  });
}

TEST(PointInMesh, RaysThroughVerticesAndEdgesOfASphere) {
  const MeshRegion region(make_ellipsoid_mesh(Vec3(0.1, 0.2, 0.3), Vec3::Constant(1), Quat::Identity(), 2));
  const Real h = longest_edge(region.mesh());
  check_rays_through_features(region, [&](const Vec3& p) {
    const Real r = (p - Vec3(0.1, 0.2, 0.3)).norm();
    return std::abs(r - 1) < h ? -1 : (r < 1 ? 1 : 0);
  });
}

TEST(PointInMesh, CavityIsOutside) {
  // Outer box with an inner box surface: the shell between them is the solid.
  TriangleMesh m = make_box_mesh(Vec3(0, 0, 0), Vec3(4, 4, 4), 2);
  const TriangleMesh hole = make_box_mesh(Vec3(1, 1, 1), Vec3(3, 3, 3), 1);
  const int offset = static_cast<int>(m.vertices.size());
  m.vertices.insert(m.vertices.end(), hole.vertices.begin(), hole.vertices.end());
  for (auto t : hole.triangles) m.triangles.push_back({t[0] + offset, t[2] + offset, t[1] + offset});  // inward
  const MeshRegion shell(m);
  EXPECT_FALSE(shell.contains(Vec3(2, 2, 2)));
  EXPECT_TRUE(shell.contains(Vec3(0.5, 2, 2)));
  EXPECT_TRUE(shell.contains(Vec3(2, 3.5, 2)));
  EXPECT_FALSE(shell.contains(Vec3(5, 2, 2)));
  EXPECT_NEAR(mesh_volume(m), 64 - 8, 1e-12);
}

TEST(PointInMesh, OpenSurfaceIsRefused) {
  TriangleMesh m = make_box_mesh(Vec3::Zero(), Vec3::Ones(), 2);
  m.triangles.pop_back();
  try {
    MeshRegion region(m, "cube.stl");
    FAIL() << "an open surface was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("surface 'cube.stl' is not closed: 3 open edges"), std::string::npos)
        << e.what();
  }
}

TEST(PointInMesh, CopiesShareTheAcceleration) {
  const MeshRegion a(make_ellipsoid_mesh(Vec3::Zero(), Vec3::Ones(), Quat::Identity(), 2), "unit sphere");
  const MeshRegion b = a;
  EXPECT_EQ(&a.mesh(), &b.mesh());
  EXPECT_TRUE(b.contains(Vec3(0.1, 0.2, 0.3)));
  EXPECT_EQ(b.name(), "unit sphere");
}

// Requirement: 100,000 points against a 10,000-triangle mesh in < 1 s (CPU time of this thread,
// so the check is not at the mercy of other jobs on the machine).
TEST(PointInMesh, HundredThousandPointsAgainstTwentyThousandTrianglesUnderOneSecond) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::clock_t c0 = std::clock();
  const MeshRegion mesh(make_ellipsoid_mesh(Vec3::Zero(), Vec3(3, 2, 1), Quat::Identity(), 5));
  ASSERT_EQ(mesh.mesh().triangles.size(), 20480u);
  Rng rng(2);
  int inside = 0;
  for (int k = 0; k < 100000; ++k) inside += mesh.contains(Vec3(rng.uniform(-3, 3), rng.uniform(-2, 2), rng.uniform(-1, 1)));
  const double cpu = double(std::clock() - c0) / CLOCKS_PER_SEC;
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("point-in-mesh: build + 100k queries on 20480 triangles: %.3f s CPU, %.3f s wall\n", cpu, wall);
  // Inside fraction ~ ellipsoid / box = pi / 6.
  EXPECT_NEAR(inside / 1e5, kPi / 6, 0.01);
  EXPECT_LT(cpu, 1.0);
}

}  // namespace
}  // namespace ff::geom
