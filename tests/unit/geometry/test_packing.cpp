// Dense random packings: target porosity, containment, overlaps, determinism, input checks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.hpp"
#include "geometry/packing.hpp"

namespace ff::geom {
namespace {

// Largest overlap / min radius by brute force over all pairs (independent of the cell grid).
Real brute_force_overlap_ratio(const Packing& p) {
  Real worst = 0;
  for (std::size_t i = 0; i < p.radius.size(); ++i) {
    for (std::size_t j = i + 1; j < p.radius.size(); ++j) {
      const Real overlap = p.radius[i] + p.radius[j] - (p.position[i] - p.position[j]).norm();
      worst = std::max(worst, overlap / std::min(p.radius[i], p.radius[j]));
    }
  }
  return worst;
}

Real solid_measure(const Packing& p, int dim) {
  Real s = 0;
  for (Real r : p.radius) s += dim == 3 ? 4.0 / 3.0 * kPi * r * r * r : kPi * r * r;
  return s;
}

// Checks shared by every case. Tolerances: porosity within 0.01 of the target (task requirement),
// overlaps below 1% of the smaller radius (task requirement; the generator stops at 0.5% of the mean
// radius, i.e. <= 0.625% of the smallest radius), containment to round-off.
void check_packing(const PackingSpec& spec, const Packing& p) {
  ASSERT_FALSE(p.radius.empty());
  ASSERT_EQ(p.position.size(), p.radius.size());
  EXPECT_TRUE(p.converged);
  const Real volume = spec.container == PackingSpec::Container::Cylinder
                          ? kPi * spec.cyl_radius * spec.cyl_radius * (spec.dim == 3 ? spec.cyl_height : 1.0)
                          : (spec.dim == 3 ? (spec.box_hi - spec.box_lo).prod()
                                           : (spec.box_hi - spec.box_lo).head<2>().prod());
  const Real porosity = 1 - solid_measure(p, spec.dim) / volume;
  EXPECT_NEAR(porosity, p.achieved_porosity, 1e-12);
  EXPECT_NEAR(p.achieved_porosity, spec.porosity, 0.01);
  const Real eps = 1e-12 * spec.radius_max;
  for (std::size_t i = 0; i < p.radius.size(); ++i) {
    const Vec3& x = p.position[i];
    const Real r = p.radius[i];
    ASSERT_GE(r, spec.radius_min);
    ASSERT_LE(r, spec.radius_max);
    if (spec.container == PackingSpec::Container::Cylinder) {
      ASSERT_LE(std::hypot(x.x(), x.y()) + r, spec.cyl_radius + eps) << i;
      if (spec.dim == 3) {
        ASSERT_GE(x.z() - r, -eps) << i;
        ASSERT_LE(x.z() + r, spec.cyl_height + eps) << i;
      }
    } else {
      for (int a = 0; a < spec.dim; ++a) {
        ASSERT_GE(x[a] - r, spec.box_lo[a] - eps) << i;
        ASSERT_LE(x[a] + r, spec.box_hi[a] + eps) << i;
      }
    }
    if (spec.dim == 2) {
      ASSERT_EQ(x.z(), 0.0);
    }
  }
  const Real worst = brute_force_overlap_ratio(p);
  EXPECT_NEAR(worst, p.max_overlap_ratio, 1e-12);
  EXPECT_LT(p.max_overlap_ratio, 0.01);
}

TEST(Packing, SpheresInSmallCylinder) {
  PackingSpec spec;  // defaults: radii 0.4-0.6 mm
  spec.cyl_radius = 7.5e-3;
  spec.cyl_height = 15e-3;
  spec.porosity = 0.40;  // a 15-diameter cylinder is loosened by its walls; 0.38 needs the full sample
  const Packing p = dense_random_packing(spec);
  EXPECT_GT(p.radius.size(), 2000u);
  check_packing(spec, p);
}

TEST(Packing, SpheresInBox) {
  PackingSpec spec;
  spec.container = PackingSpec::Container::Box;
  spec.box_lo = Vec3(-5e-3, 0, 1e-3);
  spec.box_hi = Vec3(5e-3, 10e-3, 21e-3);
  spec.porosity = 0.40;
  spec.seed = 7;
  check_packing(spec, dense_random_packing(spec));
}

// PFC-style 2D sample: disks at porosity 0.18 (Potyondy & Cundall 2004 use 0.16-0.18 in 2D).
TEST(Packing, DisksInRectangleReachPorosity018) {
  PackingSpec spec;
  spec.dim = 2;
  spec.container = PackingSpec::Container::Box;
  spec.box_lo = Vec3(0, 0, 0);
  spec.box_hi = Vec3(40e-3, 40e-3, 0);
  spec.porosity = 0.18;
  const Packing p = dense_random_packing(spec);
  EXPECT_GT(p.radius.size(), 1500u);
  check_packing(spec, p);
}

// 2D disc (Brazilian test sample): disks in a circle of diameter 40 mm about the origin.
TEST(Packing, DisksInCircleReachPorosity018) {
  PackingSpec spec;
  spec.dim = 2;
  spec.container = PackingSpec::Container::Cylinder;
  spec.cyl_radius = 20e-3;
  spec.porosity = 0.18;
  const Packing p = dense_random_packing(spec);
  EXPECT_GT(p.radius.size(), 1000u);
  check_packing(spec, p);
}

TEST(Packing, SameSeedSameArraysOtherSeedDifferent) {
  PackingSpec spec;
  spec.dim = 2;
  spec.container = PackingSpec::Container::Box;
  spec.box_hi = Vec3(20e-3, 20e-3, 0);
  spec.porosity = 0.2;
  spec.seed = 42;
  const Packing a = dense_random_packing(spec);
  const Packing b = dense_random_packing(spec);
  EXPECT_EQ(a.radius, b.radius);
  ASSERT_EQ(a.position.size(), b.position.size());
  for (std::size_t i = 0; i < a.position.size(); ++i) ASSERT_EQ(a.position[i], b.position[i]) << i;
  EXPECT_EQ(a.iterations, b.iterations);
  spec.seed = 43;
  const Packing c = dense_random_packing(spec);
  EXPECT_TRUE(c.radius != a.radius || c.position != a.position);
}

template <class F>
std::string input_error(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Packing, UnreachableOrInvalidSpecsAreInputErrors) {
  PackingSpec spec;
  spec.porosity = 0.30;
  const std::string msg = input_error([&] { dense_random_packing(spec); });
  EXPECT_NE(msg.find("achievable range"), std::string::npos) << msg;
  EXPECT_NE(msg.find("0.35"), std::string::npos) << msg;

  PackingSpec flat;
  flat.dim = 2;
  flat.cyl_radius = 1e-3;  // a circle narrower than two diameters
  EXPECT_NE(input_error([&] { dense_random_packing(flat); }).find("circle diameter"), std::string::npos);
  flat.container = PackingSpec::Container::Box;
  flat.box_hi = Vec3(20e-3, 20e-3, 0);
  flat.porosity = 0.12;
  EXPECT_NE(input_error([&] { dense_random_packing(flat); }).find("[0.16, 1)"), std::string::npos);

  PackingSpec radii;
  radii.radius_min = 0.7e-3;  // above radius_max
  EXPECT_NE(input_error([&] { dense_random_packing(radii); }).find("radius_min"), std::string::npos);
  PackingSpec tiny;
  tiny.cyl_radius = 1e-3;
  EXPECT_NE(input_error([&] { dense_random_packing(tiny); }).find("cylinder diameter"), std::string::npos);
}

// A porosity the container cannot hold overlap-free stops early and says so instead of spinning.
TEST(Packing, JammedRequestReportsNotConverged) {
  PackingSpec spec;
  spec.dim = 2;
  spec.container = PackingSpec::Container::Box;
  spec.box_hi = Vec3(12e-3, 12e-3, 0);
  spec.porosity = 0.16;  // allowed, but ~150 disks in a 12 mm box cannot pack this densely
  const Packing p = dense_random_packing(spec);
  EXPECT_FALSE(p.converged);
  EXPECT_GT(p.max_overlap_ratio, 0.01);
  EXPECT_LT(p.iterations, spec.max_iterations);  // stall detection, not the cap
}

}  // namespace
}  // namespace ff::geom
