// Performance and quality of the PFC-size sample: ~28k spheres, radii 0.4-0.6 mm, in a 25 mm x
// 50 mm cylinder at porosity 0.38 (Potyondy & Cundall 2004 use porosity ~0.35-0.38 for such samples).
// Requirement: a 25k-sphere genesis in under 5 s on 2 cores (issue 13), of which the single-threaded
// packer is most: under 10 s of CPU here (3.0 s measured, 6.5 s before issue 13); measured as this
// process's CPU time so that other jobs on a shared machine cannot make it fail (wall time printed).
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>

#include "geometry/packing.hpp"

namespace ff::geom {
namespace {

TEST(Packing30k, CylinderAtPorosity038) {
  PackingSpec spec;  // defaults are the 25 x 50 mm cylinder at porosity 0.38
  const auto t0 = std::chrono::steady_clock::now();
  const std::clock_t c0 = std::clock();
  const Packing p = dense_random_packing(spec);
  const double cpu = double(std::clock() - c0) / CLOCKS_PER_SEC;
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("30k packing: N = %zu, porosity %.4f, max overlap/r_min %.4f, %d steps (%d thermal), %.2f s CPU, %.2f s wall\n",
              p.radius.size(), p.achieved_porosity, p.max_overlap_ratio, p.iterations, p.thermal_steps, cpu, wall);
  EXPECT_GT(p.radius.size(), 27000u);
  EXPECT_TRUE(p.converged);
  EXPECT_NEAR(p.achieved_porosity, 0.38, 0.01);  // task tolerance
  EXPECT_LT(p.max_overlap_ratio, 0.01);          // task tolerance
  for (std::size_t i = 0; i < p.radius.size(); ++i) {
    const Vec3& x = p.position[i];
    ASSERT_LE(std::hypot(x.x(), x.y()) + p.radius[i], spec.cyl_radius * (1 + 1e-12)) << i;
    ASSERT_GE(x.z() - p.radius[i], -1e-15) << i;
    ASSERT_LE(x.z() + p.radius[i], spec.cyl_height * (1 + 1e-12)) << i;
  }
  EXPECT_LT(cpu, 10.0);
}

}  // namespace
}  // namespace ff::geom
