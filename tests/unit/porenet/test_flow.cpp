// Single-phase compressible flow on the pore network (seed 004 B8–B9; METHODS.md §5.4):
// steady-state mass balance, explicit vs implicit, the stable step, mass conservation,
// thread-count independence, the undrained pressure jump and Terzaghi's 1D consolidation.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "core/error.hpp"
#include "packings.hpp"
#include "porenet/flow.hpp"

using namespace ff;
using namespace ff::porenet;

namespace {

// Pores whose centroid lies within band of the lowest / highest coordinate (x if !vertical).
std::vector<Index> band(const Network2D& net, bool vertical, bool high, Real width) {
  const auto& c = vertical ? net.pore_cy : net.pore_cx;
  const Real lo = *std::min_element(c.begin(), c.end()), hi = *std::max_element(c.begin(), c.end());
  std::vector<Index> out;
  for (Index k = 0; k < net.n_pores(); ++k)
    if (high ? c[k] > hi - width : c[k] < lo + width) out.push_back(k);
  return out;
}

SinglePhaseParams water() {
  SinglePhaseParams p;
  p.mu = 1e-3;
  p.fluid = Eos::barotropic(1000, 1e5, 2.2e9);
  return p;
}

}  // namespace

TEST(PorenetFlow, SteadyStateInflowEqualsOutflow) {
  auto s = test_packings::hex_packing(30, 20, 1e-3, 0.45e-3, 0.05, 0.1);
  const Network2D net = build_network_2d(s.view(), {});
  SinglePhaseFlow f(net, water());
  for (Index k : band(net, false, false, 0.5e-3)) f.set_bc(k, PoreBc::Pressure, 2e5);
  for (Index k : band(net, false, true, 0.5e-3)) f.set_bc(k, PoreBc::Pressure, 1e5);
  f.init(1e5);
  for (int n = 0; n < 40; ++n) f.step_implicit(1.0);  // >> diffusion time of the sample
  const Real in = f.pressure_pores_inflow_rate(true), out = -f.pressure_pores_inflow_rate(false);
  ASSERT_GT(in, 0);
  std::printf("steady state: inflow %.9e kg/s, outflow %.9e kg/s, relative difference %.2e\n", in, out,
              std::abs(in - out) / in);
  EXPECT_LT(std::abs(in - out) / in, 1e-9);
}

TEST(PorenetFlow, ExplicitAndImplicitAgreeAndStableStep) {
  auto s = test_packings::hex_packing(12, 8, 1e-3, 0.45e-3, 0.05, 0.1);
  const Network2D net = build_network_2d(s.view(), {});
  auto run = [&](bool implicit, Real dt, int steps, LinearSolver solver = LinearSolver::ConjugateGradient) {
    auto prm = water();
    prm.solver = solver;
    SinglePhaseFlow f(net, prm);
    for (Index k : band(net, false, false, 0.5e-3)) f.set_bc(k, PoreBc::Pressure, 1.1e5);
    f.init(1e5);
    for (int n = 0; n < steps; ++n) implicit ? f.step_implicit(dt) : f.step_explicit(dt);
    return std::vector<Real>(f.pressure().begin(), f.pressure().end());
  };
  SinglePhaseFlow probe(net, water());
  for (Index k : band(net, false, false, 0.5e-3)) probe.set_bc(k, PoreBc::Pressure, 1.1e5);
  probe.init(1e5);
  const Real dts = probe.stable_dt();
  std::printf("stable explicit step %.4e s\n", dts);
  const Real T = 1000 * dts;
  const auto pe = run(false, 0.5 * dts, 2000);
  const auto pi = run(true, 0.5 * dts, 2000);
  const auto pl = run(true, 0.5 * dts, 2000, LinearSolver::LDLT);
  Real emax = 0, lmax = 0, rise = 0;
  for (std::size_t k = 0; k < pe.size(); ++k) {
    emax = std::max(emax, std::abs(pe[k] - pi[k]));
    lmax = std::max(lmax, std::abs(pl[k] - pi[k]));
    rise = std::max(rise, pe[k] - 1e5);
  }
  std::printf("t = %.3e s: max |p_explicit - p_implicit| = %.3e Pa of a 1e4 Pa step; CG vs LDLT %.3e Pa\n", T, emax,
              lmax);
  EXPECT_LT(emax, 1e-2 * 1e4);  // first-order schemes, dt = dt_s / 2
  EXPECT_LT(lmax, 1e-6);
  // Below dt_s the explicit update is a convex combination (bounded); well above 2 dt_s it diverges.
  auto bounded = [&](Real dt) {
    std::vector<Real> p;
    try {
      p = run(false, dt, 400);
    } catch (const NumericalError&) {  // a pore emptied: diverged
      return false;
    }
    const auto [lo, hi] = std::minmax_element(p.begin(), p.end());
    std::printf("explicit dt = %.2f dt_s: p in [%.6f, %.6f] Pa\n", dt / dts, *lo, *hi);
    for (Real v : p)
      if (!(v >= 1e5 - 1e-6 && v <= 1.1e5 + 1e-6)) return false;
    return true;
  };
  EXPECT_TRUE(bounded(0.99 * dts));
  EXPECT_FALSE(bounded(4.0 * dts));   // the true limit 2/lambda_max lies in [dt_s, 2 dt_s]
}

TEST(PorenetFlow, ClosedNetworkConservesMassAndThreadsAgree) {
  auto s = test_packings::hex_packing(40, 40, 1e-3, 0.45e-3, 0.05, 0.1);
  const Network2D net = build_network_2d(s.view(), {});
  auto run = [&](int threads) {
    omp_set_num_threads(threads);
    SinglePhaseFlow f(net, water());
    const auto inj = band(net, false, false, 1e-3);
    for (Index k : inj) f.set_bc(k, PoreBc::Flux, 1e-3);  // injection [kg/s]
    f.init(1e5);
    const Real m0 = f.total_mass();
    const Real dt = 0.5 * f.stable_dt();
    for (int n = 0; n < 50; ++n) f.step_explicit(dt);
    for (int n = 0; n < 10; ++n) f.step_implicit(1e-5);  // raises the pressure by ~0.03 MPa
    const Real err = std::abs(f.total_mass() - m0 - f.injected_mass()) / m0;
    std::printf("%d thread(s): relative mass error after 60 steps %.2e (injected %.3e of %.3e kg), CG iterations %d\n",
                threads, err, f.injected_mass(), m0, f.last_cg_iterations());
    EXPECT_LT(err, 1e-14);
    EXPECT_GT(*std::max_element(f.pressure().begin(), f.pressure().end()), 1.1e5);
    return std::vector<Real>(f.pressure().begin(), f.pressure().end());
  };
  const auto p1 = run(1), p2 = run(2);
  omp_set_num_threads(omp_get_num_procs());
  ASSERT_EQ(p1.size(), p2.size());
  EXPECT_EQ(0, std::memcmp(p1.data(), p2.data(), p1.size() * sizeof(Real)));
}
