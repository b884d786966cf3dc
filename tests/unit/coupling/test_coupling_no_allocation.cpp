// "No allocation in the time loop" for the coupled step (src/coupling): after a warm-up in which
// the work buffers reach their size (PSM cell lists, DEM neighbour lists), DemLbmCoupler::step()
// makes no heap allocation while two spheres settle side by side, collide with each other (DEM
// contact) and one touches dry rock (the pressure-load path). The global operator new of this
// test program counts allocations while `counting` is set.
#include <gtest/gtest.h>
#include <omp.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "coupling_fixture.hpp"

namespace {
std::atomic<bool> counting{false};
std::atomic<long> allocations{0};
}  // namespace

void* operator new(std::size_t n) {
  if (counting.load(std::memory_order_relaxed)) allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
#pragma GCC diagnostic pop

using namespace ff;
using namespace ff::coupling;
using namespace ff::coupling::test;

TEST(CouplerNoAllocation, StepAllocatesNothing) {
  omp_set_num_threads(1);
  FluidSpec fs;
  fs.density = 1000;
  fs.viscosity = 1e-3;
  fs.dx = 1e-3;
  fs.tau = 0.7;
  fs.background_pressure = 1e6;
  const FluidScales sc = derive_scales(fs);
  auto fluid = make_fluid<lbm::D3Q19>(sc, 24, 24, 24, {true, true, false});
  fluid.set_face(4, lbm::FaceCondition{});
  fluid.set_face(5, lbm::FaceCondition{});
  const int obj = fluid.add_object("dry", lbm::WallScheme::HalfwayBounceBack, Vec3::Zero());
  for (int z = 0; z < 24; ++z)
    for (int y = 0; y < 24; ++y) fluid.set_solid(21, y, z, obj);
  start_at_rest(fluid);
  auto dem = free_particles(3, 3000);
  dem.settings.gravity = Vec3(0, 0, -30);
  add_particle(dem, Vec3(8.5e-3, 12e-3, 14e-3), 4e-3, Vec3(0.3, 0, 0));
  add_particle(dem, Vec3(17.6e-3, 12.2e-3, 14e-3), 4e-3, Vec3(-0.3, 0, 0));
  dem.settings.dt = 0.25 * sc.dt();
  dem.initialise();
  CouplerSettings cs;
  cs.origin = Vec3::Constant(0.5e-3);
  DemLbmCoupler<lbm::D3Q19, double> c(dem, fluid, sc, cs);
  for (int t = 0; t < 20; ++t) c.step(t % 5 == 0);  // warm-up
  allocations = 0;
  counting = true;
  for (int t = 0; t < 40; ++t) c.step(t % 5 == 0);
  counting = false;
  EXPECT_EQ(allocations.load(), 0);
  double dry = 0;
  for (auto& f : c.pressure_force()) dry += f.norm();
  EXPECT_GT(dry, 0);  // the dry-side path ran
}
