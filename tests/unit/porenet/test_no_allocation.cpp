// No heap allocation in the flow steps (explicit and implicit-CG single phase, explicit two-phase),
// the geometry update and the force kernels, after a warm-up. The global operator new of this
// program counts allocations while `counting` is set (as tests/unit/dem/test_no_allocation.cpp).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "packings.hpp"
#include "porenet/flow.hpp"
#include "porenet/forces.hpp"
#include "porenet/two_phase.hpp"

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
using namespace ff::porenet;

TEST(PorenetNoAllocation, FlowStepsUpdateAndForces) {
  auto s = test_packings::hex_packing(20, 20, 1e-3, 0.45e-3, 0.05, 0.1);
  PairList pairs;
  pairs.add(0, 1, PairState::Bond, 1e6, 0);
  Network2D net = build_network_2d(s.view(), pairs);
  SinglePhaseParams prm;
  prm.fluid = Eos::barotropic(1000, 1e5, 2.2e9);
  SinglePhaseFlow f(net, prm);
  for (Index k = 0; k < net.n_pores(); ++k)
    if (net.pore_cx[k] < 2e-3) f.set_bc(k, PoreBc::Pressure, 2e5);
  f.init(1e5);
  TwoPhaseFlow tp(net, {});
  tp.init(1e5, 0.5);
  for (Index k = 0; k < net.n_pores(); ++k)
    if (net.pore_cx[k] < 5e-3) tp.set_pore_state(k, 2e5, 0.8);
  std::vector<Real> fx(s.x.size()), fy(s.x.size());
  const Real dt = 0.5 * f.stable_dt(), dt2 = 0.5 * tp.stable_dt();
  auto step = [&] {
    update_network_2d(net, s.view(), pairs);
    f.step_explicit(dt);
    f.step_implicit(10 * dt);
    tp.step_explicit(dt2);
    add_pressure_forces(net, s.view(), f.pressure(), fx, fy);
    add_shear_forces(net, s.view(), f.pressure(), fx, fy);
  };
  for (int n = 0; n < 3; ++n) step();  // warm-up (OpenMP runtime, thread pools)
  allocations = 0;
  counting = true;
  for (int n = 0; n < 10; ++n) step();
  counting = false;
  EXPECT_EQ(allocations.load(), 0);
}
