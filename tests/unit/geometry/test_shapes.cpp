// Region primitives, their bounding boxes and group assignment.
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.hpp"
#include "core/rng.hpp"
#include "geometry/packing.hpp"
#include "geometry/shapes.hpp"

namespace ff::geom {
namespace {

Vec3 random_in(Rng& rng, const Aabb& box) {
  return Vec3(rng.uniform(box.lo.x(), box.hi.x()), rng.uniform(box.lo.y(), box.hi.y()),
              rng.uniform(box.lo.z(), box.hi.z()));
}

TEST(Shapes, BoxContainsItsBoundary) {
  const Box b{Vec3(0, 0, 0), Vec3(1, 2, 3)};
  EXPECT_TRUE(b.contains(Vec3(0.5, 1, 1.5)));
  EXPECT_TRUE(b.contains(Vec3(0, 2, 3)));
  EXPECT_FALSE(b.contains(Vec3(1.0001, 1, 1)));
  EXPECT_FALSE(b.contains(Vec3(0.5, -1e-12, 1)));
  EXPECT_EQ(b.bounds().hi, Vec3(1, 2, 3));
}

TEST(Shapes, Sphere) {
  const Sphere s{Vec3(1, 1, 1), 0.5};
  EXPECT_TRUE(s.contains(Vec3(1.5, 1, 1)));
  EXPECT_FALSE(s.contains(Vec3(1.36, 1.36, 1)));  // distance 0.509
  EXPECT_EQ(s.bounds().lo, Vec3(0.5, 0.5, 0.5));
}

TEST(Shapes, TiltedCylinderMatchesDefinitionAndBounds) {
  const Vec3 axis = Vec3(1, 2, 2).normalized();
  const Cylinder c{Vec3(0.1, -0.2, 0.3), axis, 0.4, 1.5};
  const Aabb box = c.bounds();
  Rng rng(3);
  const Aabb wide{box.lo.array() - 0.2, box.hi.array() + 0.2};
  int inside = 0;
  for (int k = 0; k < 20000; ++k) {
    const Vec3 p = random_in(rng, wide);
    const Real s = (p - c.base).dot(axis);
    const Real radial = (p - c.base - s * axis).norm();
    const bool expect = s >= 0 && s <= c.length && radial <= c.radius;
    ASSERT_EQ(c.contains(p), expect) << p.transpose();
    if (expect) {
      ++inside;
      ASSERT_TRUE(box.contains(p));
    }
  }
  EXPECT_GT(inside, 100);
  // Tightness: the rim point furthest along +x touches the box.
  const Vec3 ex = (Vec3::UnitX() - axis.x() * axis).normalized();
  EXPECT_NEAR(box.hi.x(), (c.base + c.length * axis + c.radius * ex).x(), 1e-12);
}

TEST(Shapes, RotatedEllipsoidMatchesBodyFrameTestAndBounds) {
  const Quat q(Eigen::AngleAxis<Real>(0.7, Vec3(1, -1, 2).normalized()));
  const Ellipsoid e{Vec3(1, 2, 3), Vec3(0.9, 0.5, 0.2), q};
  const Aabb box = e.bounds();
  Rng rng(5);
  Real max_x = -1e9;
  for (int k = 0; k < 20000; ++k) {
    // Surface points: body-frame unit sphere scaled and rotated.
    const Vec3 u = Vec3(rng.normal(), rng.normal(), rng.normal()).normalized();
    const Vec3 on = e.c + q * u.cwiseProduct(e.semi_axes);
    ASSERT_TRUE(e.contains(e.c + 0.999 * (on - e.c)));
    ASSERT_FALSE(e.contains(e.c + 1.001 * (on - e.c)));
    ASSERT_TRUE(box.contains(on));
    max_x = std::max(max_x, on.x());
  }
  EXPECT_NEAR(max_x, box.hi.x(), 5e-3 * (box.hi.x() - e.c.x()));
}

TEST(Shapes, RegionVariantDispatches) {
  const std::vector<Region> regions = {Box{Vec3(0, 0, 0), Vec3(1, 1, 1)}, Sphere{Vec3(5, 5, 5), 1},
                                       Cylinder{Vec3(0, 0, 10), Vec3::UnitZ(), 1, 2},
                                       Ellipsoid{Vec3(-5, 0, 0), Vec3(2, 1, 1), Quat::Identity()},
                                       MeshRegion(make_box_mesh(Vec3(20, 20, 20), Vec3(21, 21, 21)))};
  const Vec3 probes[] = {Vec3(0.5, 0.5, 0.5), Vec3(5, 5, 5.9), Vec3(0.5, 0, 11), Vec3(-6.9, 0, 0),
                         Vec3(20.5, 20.5, 20.5)};
  for (std::size_t r = 0; r < regions.size(); ++r) {
    for (std::size_t p = 0; p < regions.size(); ++p) {
      EXPECT_EQ(region_contains(regions[r], probes[p]), r == p) << "region " << r << " probe " << p;
    }
    EXPECT_TRUE(region_bounds(regions[r]).contains(probes[r]));
  }
}

TEST(Shapes, AssignGroupsLastRegionWins) {
  const std::vector<Region> regions = {Box{Vec3(0, 0, 0), Vec3(2, 2, 2)}, Sphere{Vec3(1, 1, 1), 0.5}};
  const std::vector<int> groups = {7, 9};
  const std::vector<Vec3> centres = {Vec3(1, 1, 1), Vec3(0.1, 0.1, 0.1), Vec3(3, 3, 3)};
  EXPECT_EQ(assign_groups(centres, regions, groups, 0), (std::vector<int>{9, 7, 0}));
  const std::vector<int> reversed_groups = {9, 7};
  const std::vector<Region> reversed = {regions[1], regions[0]};
  // How many centres each region gave its group to: the sphere inside the box, listed first, gives
  // none (the sample builder warns about such a region).
  std::vector<std::size_t> assigned;
  EXPECT_EQ(assign_groups(centres, reversed, reversed_groups, -1, &assigned), (std::vector<int>{7, 7, -1}));
  EXPECT_EQ(assigned, (std::vector<std::size_t>{0, 2}));
  assign_groups(centres, regions, groups, 0, &assigned);
  EXPECT_EQ(assigned, (std::vector<std::size_t>{1, 1}));
  const std::vector<int> too_few = {1};
  EXPECT_THROW(assign_groups(centres, regions, too_few, 0), InputError);
}

// Lens volume of two spheres (used for the porosity of PFC-style measurement spheres): the
// closed form against its limits (disjoint, touching, one inside the other, the half-overlap of
// equal spheres: 5 pi R^3 / 12) and against a Monte Carlo estimate with 400,000 points, held to
// 4 standard errors.
TEST(Shapes, SphereOverlapVolume) {
  const Real R = 2.0;
  EXPECT_EQ(sphere_overlap_volume(R, 1.0, 3.5), 0.0);
  EXPECT_NEAR(sphere_overlap_volume(R, 1.0, 3.0), 0.0, 1e-15);
  EXPECT_NEAR(sphere_overlap_volume(R, 1.0, 0.5), 4.0 / 3.0 * kPi, 1e-12);
  EXPECT_NEAR(sphere_overlap_volume(1.0, R, 0.5), 4.0 / 3.0 * kPi, 1e-12);
  EXPECT_NEAR(sphere_overlap_volume(R, 1.0, 1.0 + 1e-12), 4.0 / 3.0 * kPi, 1e-9);  // internally tangent
  EXPECT_NEAR(sphere_overlap_volume(1.0, 1.0, 1.0), 5.0 * kPi / 12.0, 1e-12);
  Rng rng(7);
  for (const Real d : {1.3, 2.0, 2.7}) {
    const Real r = 1.0;
    const Vec3 b(d, 0, 0);
    const long n = 400000;
    long hits = 0;
    for (long k = 0; k < n; ++k) {  // points in the small sphere's bounding box
      const Vec3 p = b + Vec3(rng.uniform(-r, r), rng.uniform(-r, r), rng.uniform(-r, r));
      hits += p.squaredNorm() <= R * R && (p - b).squaredNorm() <= r * r;
    }
    const Real box = 8 * r * r * r, f = static_cast<Real>(hits) / n;
    const Real se = box * std::sqrt(f * (1 - f) / n);
    EXPECT_NEAR(sphere_overlap_volume(R, r, d), box * f, 4 * se) << "d = " << d;
    EXPECT_NEAR(sphere_overlap_volume(r, R, d), sphere_overlap_volume(R, r, d), 1e-12);
  }
}

}  // namespace
}  // namespace ff::geom
