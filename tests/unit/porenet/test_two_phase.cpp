// Two-phase liquid/gas network flow (seed 004 B3–B7, B18–B23): the stratified channel solution,
// the shared-pressure solve, and the conservation of each phase's mass in a closed network.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include "packings.hpp"
#include "porenet/two_phase.hpp"

using namespace ff;
using namespace ff::porenet;

TEST(PorenetTwoPhase, StratifiedChannelFlow) {
  const Real G = 1e5, h = 1e-4;
  // Equal viscosities: any split gives the single-phase plane Poiseuille rate G h^3 / (12 mu), and
  // each layer carries the integral of the parabola over its part.
  for (const Real a : {0.0, 0.2, 0.5, 0.9, 1.0}) {
    const auto r = stratified_channel_flow(G, a * h, (1 - a) * h, 1e-3, 1e-3);
    EXPECT_NEAR(r.q_liquid + r.q_gas, G * h * h * h / 12e-3, 1e-12 * G * h * h * h / 12e-3);
    // Liquid in y in [0, a h]: integral of G/(2 mu) y (h - y) = G/(2 mu) (h (ah)^2/2 - (ah)^3/3).
    const Real ql = G / 2e-3 * (h * a * h * a * h / 2 - a * h * a * h * a * h / 3);
    EXPECT_NEAR(r.q_liquid, ql, 1e-12 * G * h * h * h / 12e-3);
  }
  // Different viscosities: check the boundary conditions (B5–B7) by rebuilding the profile.
  const Real muq = 1e-3, mup = 1.8e-5, hq = 0.3 * h, hp = 0.7 * h;
  const auto r = stratified_channel_flow(G, hq, hp, muq, mup);
  const Real C = G * hq * hq / (2 * muq) + r.tau_interface * hq / muq;
  auto uq = [&](Real y) { return -G / (2 * muq) * y * y + r.tau_interface / muq * y + C; };
  auto up = [&](Real y) { return -G / (2 * mup) * y * y + r.tau_interface / mup * y + C; };
  EXPECT_NEAR(uq(-hq), 0, 1e-12 * C);  // no slip, lower wall
  EXPECT_NEAR(up(hp), 0, 1e-12 * C);   // no slip, upper wall
  // Flow rates = integrals of the profiles (Simpson is exact for parabolas).
  EXPECT_NEAR(r.q_liquid, hq / 6 * (uq(-hq) + 4 * uq(-hq / 2) + uq(0)), 1e-12 * r.q_gas);
  EXPECT_NEAR(r.q_gas, hp / 6 * (up(0) + 4 * up(hp / 2) + up(hp)), 1e-12 * r.q_gas);
  // The less viscous gas layer carries more per unit thickness.
  EXPECT_GT(r.q_gas / hp, r.q_liquid / hq);
}

TEST(PorenetTwoPhase, SharedPressureRoundTrip) {
  auto s = test_packings::hex_packing(4, 4, 1e-3, 0.45e-3, 0.0, 0.0);
  const Network2D net = build_network_2d(s.view(), {});
  TwoPhaseFlow f(net, {});
  const Real V = 1e-7;
  for (const Real p : {1e5, 1e6, 2e7})
    for (const Real a : {0.05, 0.5, 0.95}) {
      const Real mq = a * V * Eos::water_pr(293.15).density(p, true);
      const Real mp = (1 - a) * V * Eos::air_pr(293.15).density(p, false);
      Real pout;
      const Real aout = f.solve_shared_pressure(mq, mp, V, 0.5, pout);
      EXPECT_NEAR(aout, a, 1e-9);
      EXPECT_NEAR(pout, p, 1e-6 * p);
    }
}

TEST(PorenetTwoPhase, ClosedNetworkConservesEachPhase) {
  auto s = test_packings::hex_packing(30, 30, 1e-3, 0.45e-3, 0.05, 0.1);
  const Network2D net = build_network_2d(s.view(), {});
  auto run = [&](int threads, bool report) {
    omp_set_num_threads(threads);
    TwoPhaseFlow f(net, {});
    f.init(1e5, 0.5);
    // A high-pressure, wetter left half drives both phases to the right.
    for (Index k = 0; k < net.n_pores(); ++k)
      if (net.pore_cx[k] < 10e-3) f.set_pore_state(k, 3e5, 0.8);
    const Real mq0 = f.total_liquid_mass(), mp0 = f.total_gas_mass(), S0 = f.saturation();
    const Real dt = 0.5 * f.stable_dt();
    for (int n = 0; n < 300; ++n) f.step_explicit(dt);
    const Real eq = std::abs(f.total_liquid_mass() - mq0) / mq0, ep = std::abs(f.total_gas_mass() - mp0) / mp0;
    const auto [lo, hi] = std::minmax_element(f.pressure().begin(), f.pressure().end());
    if (report)
      std::printf("two-phase closed network, dt %.3e s x 300: liquid mass error %.2e, gas %.2e; saturation %.4f -> "
                  "%.4f; p in [%.4e, %.4e] Pa\n", dt, eq, ep, S0, f.saturation(), *lo, *hi);
    EXPECT_LT(eq, 1e-13);
    EXPECT_LT(ep, 1e-13);
    // A pressure front has formed: pores between the two initial levels.
    const auto front = std::count_if(f.pressure().begin(), f.pressure().end(),
                                     [](Real p) { return p > 1.01e5 && p < 2.99e5; });
    if (report) std::printf("pores inside the front: %ld\n", static_cast<long>(front));
    EXPECT_GT(front, 20);
    EXPECT_LE(*hi, 3e5 * (1 + 1e-6));  // PR liquid: K = 7 GPa turns density round-off into ~1e-6 Pa
    EXPECT_GE(*lo, 1e5 * (1 - 1e-6));
    return std::vector<Real>(f.pressure().begin(), f.pressure().end());
  };
  const auto p1 = run(1, true), p2 = run(2, false);
  omp_set_num_threads(omp_get_num_procs());
  EXPECT_EQ(0, std::memcmp(p1.data(), p2.data(), p1.size() * sizeof(Real)));
}

// "Small pores fill first" (a capillary layout: pores below the median void liquid-full, the others
// gas) under a steady compaction, stepped as the DEM coupling does (one stable_dt() per DEM step,
// then equal explicit sub-steps). The gas leaving a gas pore into a liquid-full one must be bounded
// by stable_dt() whichever way the channel's flow points when it is evaluated: this layout drove a
// gas mass negative at dt = 5e-10 s (docs/saturated.md) when the bound used the current upstream
// pore only (the liquid-full one, 55 x less mobile than gas). Each phase's mass stays conserved.
TEST(PorenetTwoPhase, SmallPoresFullLayoutUnderCompaction) {
  auto s = test_packings::hex_packing(20, 20, 1e-3, 0.45e-3, 0.15, 0.15, 11);
  NetworkParams np;  // the apertures of the seed-004 study (docs/saturated.md): B1 h0 1 um, h_inf 0.1 um, B2 gamma 0.01
  np.b1_h0 = 1e-6;
  np.b1_h_inf = 1e-7;
  np.b2_gamma = 0.01;
  Network2D net = build_network_2d(s.view(), {}, np);
  std::vector<Real> v(net.pore_void.begin(), net.pore_void.end());
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  const Real vmed = v[v.size() / 2];
  TwoPhaseFlow f(net, {});
  f.init(1e5, 0.0);
  for (Index k = 0; k < net.n_pores(); ++k)
    if (net.pore_void[k] < vmed) f.set_pore_state(k, 1e5, 1.0);
  const Real mq0 = f.total_liquid_mass(), mp0 = f.total_gas_mass();
  const Real dt_dem = 1e-7, rate = 2e-4;  // volumetric strain per DEM step of the full pores
  long substeps = 0;
  for (int n = 0; n < 60; ++n) {
    for (Index k = 0; k < net.n_pores(); ++k) net.pore_void[k] *= 1 - rate * (k % 3 == 0 ? 1.5 : 0.5);
    const Real h0 = 0.9 * f.stable_dt();
    const long m = static_cast<long>(std::ceil(dt_dem / h0));
    ASSERT_LT(m, 200000);
    for (long j = 0; j < m; ++j) ASSERT_NO_THROW(f.step_explicit(dt_dem / static_cast<Real>(m))) << "DEM step " << n;
    substeps += m;
  }
  const Real eq = std::abs(f.total_liquid_mass() - mq0) / mq0, ep = std::abs(f.total_gas_mass() - mp0) / mp0;
  const auto [lo, hi] = std::minmax_element(f.pressure().begin(), f.pressure().end());
  std::printf("capillary layout, 60 DEM steps of %.1e s, %ld explicit sub-steps: liquid mass error %.2e, gas %.2e; "
              "p in [%.4e, %.4e] Pa\n", dt_dem, substeps, eq, ep, *lo, *hi);
  EXPECT_LT(eq, 1e-13);
  EXPECT_LT(ep, 1e-13);
  EXPECT_GT(*hi, 1.5e5);  // the compaction did load the liquid
}

// LiquidPlacement::SmallestPoresFirst (capillary equilibrium of a wetting liquid: Blunt 2017,
// ch. 4): the whole void holds the asked saturation to round-off, every liquid-full pore is no
// larger than every gas pore and at most one pore is partly filled. (That layout under compaction:
// SmallPoresFullLayoutUnderCompaction above.)
TEST(PorenetTwoPhase, SmallestPoresFirstPlacement) {
  auto s = test_packings::hex_packing(20, 20, 1e-3, 0.45e-3, 0.15, 0.15, 11);
  const Network2D net = build_network_2d(s.view(), {});
  for (const Real S : {0.1, 0.5, 0.9}) {
    TwoPhaseFlow f(net, {});
    f.init(1e5, S, LiquidPlacement::SmallestPoresFirst);
    EXPECT_NEAR(f.saturation(), S, 1e-13) << "S " << S;
    Real largest_full = 0, smallest_gas = 1e300;
    int partial = 0;
    for (Index k = 0; k < net.n_pores(); ++k) {
      const Real a = f.liquid_fraction()[k];
      EXPECT_EQ(f.pressure()[k], 1e5);
      if (a == 1) largest_full = std::max(largest_full, net.pore_void[k]);
      else if (a == 0) smallest_gas = std::min(smallest_gas, net.pore_void[k]);
      else ++partial;
    }
    EXPECT_LE(partial, 1);
    EXPECT_LE(largest_full, smallest_gas);
    EXPECT_GT(largest_full, 0);
  }
  // Uniform (the default) and the limits S = 0, 1 are unchanged.
  TwoPhaseFlow u(net, {});
  u.init(1e5, 0.3);
  for (Index k = 0; k < net.n_pores(); ++k) EXPECT_EQ(u.liquid_fraction()[k], 0.3);
  TwoPhaseFlow w(net, {});
  w.init(1e5, 1.0, LiquidPlacement::SmallestPoresFirst);
  for (Index k = 0; k < net.n_pores(); ++k) EXPECT_EQ(w.liquid_fraction()[k], 1.0);
  EXPECT_THROW(w.init(1e5, 1.5, LiquidPlacement::SmallestPoresFirst), InputError);
}

// Traces: a gas pore that received 1e-25 kg of liquid (and a liquid pore 1e-25 kg of gas) from a
// neighbour. Reference: B23 as a volume balance, m_q / rho_q(p) + m_p / rho_p(p) = V, solved for p
// by bisection here. The absolute bracket width of the first version stopped at alpha ~ 3e-17 for a
// liquid trace (its density 1e-8 of water's, p = -4e10 Pa) or, from the previous alpha 0, at 3e-61
// (p = -1.6e11 Pa). A gas trace below ~1e-16 of the void cannot be carried by alpha next to 1: the
// liquid's pressure is then off by K x 1e-16. Barotropic and Peng-Robinson water, ideal-gas air.
TEST(PorenetTwoPhase, SharedPressureWithATraceOfOnePhase) {
  auto s = test_packings::hex_packing(4, 4, 1e-3, 0.45e-3, 0.0, 0.0);
  const Network2D net = build_network_2d(s.view(), {});
  const Real V = 8.6e-8, p0 = 1e5;
  for (const bool pr : {false, true}) {
    TwoPhaseParams prm;
    prm.liquid = pr ? Eos::water_pr(293.15) : Eos::barotropic(1000, p0, 2.2e9);
    prm.gas = Eos::ideal_gas(293.15, 28.9586);
    TwoPhaseFlow f(net, prm);
    auto reference = [&](Real mq, Real mp) {
      Real lo = 0.5 * p0, hi = 4 * p0;
      for (int it = 0; it < 200; ++it) {
        const Real pm = 0.5 * (lo + hi);
        (mq / prm.liquid.density(pm, true) + mp / prm.gas.density(pm, false) > V ? lo : hi) = pm;
      }
      return 0.5 * (lo + hi);
    };
    const Real rho_g = prm.gas.density(p0, false), rho_q = prm.liquid.density(p0, true);
    for (const Real trace : {1e-25, 1e-18, 1e-12}) {
      for (const Real a0 : {0.0, 0.5, 1e-9}) {
        Real p;
        const Real mp = V * rho_g, a = f.solve_shared_pressure(trace, mp, V, a0, p);  // gas pore, liquid trace
        const Real pref = reference(trace, mp);
        EXPECT_NEAR(p, pref, 1e-9 * pref) << "liquid trace " << trace << " from alpha " << a0 << (pr ? " PR" : "");
        EXPECT_NEAR(a, trace / (prm.liquid.density(pref, true) * V), 1e-9 * a);
      }
      for (const Real a0 : {1.0, 0.5, 1 - 1e-9}) {
        Real p;
        const Real mq = V * rho_q, a = f.solve_shared_pressure(mq, trace, V, a0, p);  // liquid pore, gas trace
        const Real pref = reference(mq, trace);
        EXPECT_NEAR(p, pref, 1e-9 * pref + 3e-16 * 7e9) << "gas trace " << trace << " from alpha " << a0 << (pr ? " PR" : "");
        EXPECT_GT(a, 0.99);
      }
    }
  }
}

// Barotropic water (K 2.2 GPa) and ideal-gas air: the study's fluids, for single-pore B23 checks.
namespace {
TwoPhaseParams water_air() {
  TwoPhaseParams prm;
  prm.liquid = Eos::barotropic(1000, 1e5, 2.2e9);
  prm.gas = Eos::ideal_gas(293.15, 28.9586);
  return prm;
}
}  // namespace

// Newton converged on the end of its bracket (every pore whose last alpha is already the root)
// must stop there: it went to a bisection and back, 128 iterations per pore for the pores of a
// partly saturated specimen with a gas fraction ~1e-6 (80 % of its step). A pore of that run
// (m_q 1e-4 kg, m_p 5.3e-12 kg, alpha 1 - 1.3e-6) and a half-full one; barotropic water, ideal air.
TEST(PorenetTwoPhase, SharedPressureFromItsOwnRootStopsAtOnce) {
  auto s = test_packings::hex_packing(4, 4, 1e-3, 0.45e-3, 0.0, 0.0);
  const Network2D net = build_network_2d(s.view(), {});
  const TwoPhaseParams prm = water_air();
  TwoPhaseFlow f(net, prm);
  // The pore's masses, void and last alpha as the run's checkpoint held them.
  const std::array<Real, 4> cases[] = {{9.979970897626098e-05, 5.260836026557399e-12, 9.964939981297731e-08, 0.9999987002693413},
                                       {5e-5, 5.9e-8, 1e-7, 0.5}};
  for (const auto& [mq, mp, V, last] : cases) {
    Real p1, p2;
    int n1 = 0, n2 = 0;
    const Real a1 = f.solve_shared_pressure(mq, mp, V, 0.5, p1, &n1);
    const Real a2 = f.solve_shared_pressure(mq, mp, V, last, p2, &n2);
    std::printf("m_q %.3g, m_p %.3g: alpha %.15f, p %.6e Pa; %d iterations from 0.5, %d from its last alpha\n", mq, mp,
                a1, p1, n1, n2);
    EXPECT_LE(n1, 40);
    EXPECT_LE(n2, 4);
    EXPECT_NEAR(a2, a1, 1e-15);
    EXPECT_NEAR(p2, p1, 1e-9 * p1);
  }
}

// A gas trace below alpha's resolution: 2e-24 kg of gas beside 9.5e-5 kg of water (a pore of a
// saturated specimen's run, session 33: the trace came with the flow), so 1 - alpha ~ 2e-17, under
// the ulp of alpha next to 1. The root lies past the largest alpha below 1; from that alpha (its
// last result) the solve took 31-200 bisections per pore and step (the S 1 study run: 40 % of its
// solves past 40 iterations). It must take one evaluation and give the liquid-alone pressure (to
// K ulp ~ 1e-6 Pa).
TEST(PorenetTwoPhase, GasTraceBelowAlphaResolutionStopsAtOnce) {
  auto s = test_packings::hex_packing(4, 4, 1e-3, 0.45e-3, 0.0, 0.0);
  const Network2D net = build_network_2d(s.view(), {});
  const TwoPhaseParams prm = water_air();
  TwoPhaseFlow f(net, prm);
  const Real below_one = std::nextafter(1.0, 0.0);
  const std::array<Real, 4> cases[] = {{9.4655341008404519e-05, 2.0208994896592586e-24, 9.4659176850600283e-08, below_one},
                                       {1.2494269830952843e-04, 2.229681822018718e-25, 1.2494824353574728e-07, 0.99999978380760768},
                                       {5.4445822338767344e-05, 8.6526306996779833e-26, 5.444823040194265e-08, 0.99999973169099343}};
  for (const auto& [mq, mp, V, last] : cases) {
    Real p = 0;
    int n = 0;
    const Real a = f.solve_shared_pressure(mq, mp, V, last, p, &n);
    EXPECT_LE(n, 2) << "m_p " << mp;
    EXPECT_EQ(a, below_one);
    EXPECT_NEAR(p, prm.liquid.pressure(mq / V), 1e-5) << "m_p " << mp;
  }
  // A trace that alpha does resolve (1 - alpha ~ 1e-12) still converges to its own root from there.
  const Real V = 1e-7, mq = (1 - 1e-12) * V * prm.liquid.density(1e5, true), mp = 1.0001e-12 * V * prm.gas.density(1e5, false);
  Real p = 0;
  int n = 0;
  const Real a = f.solve_shared_pressure(mq, mp, V, below_one, p, &n);
  EXPECT_LE(n, 4);
  EXPECT_NEAR(1 - a, mp / (V * prm.gas.density(p, false)), 1e-3 * (1 - a));
}

// A phase under 1e-30 of the other's mass takes no part in B23: a liquid trace of 5e-324 kg (what
// the outflow limiter left of one, step by step, in a 3D run) gave alpha 1e-316 and a liquid
// density m / (alpha V) of inf, and the implicit step's matrix inf (CG failed). It must give the gas
// pore's pressure and alpha 0 (and the mirror case alpha 1, the liquid's pressure).
TEST(PorenetTwoPhase, DenormalTraceTakesNoPart) {
  auto s = test_packings::hex_packing(4, 4, 1e-3, 0.45e-3, 0.0, 0.0);
  const Network2D net = build_network_2d(s.view(), {});
  TwoPhaseParams prm;  // PR water and air
  TwoPhaseFlow f(net, prm);
  const Real V = 6.19202e-11, mp = 7.36129e-11, mq = 5.80589e-08;
  Real p = 0;
  EXPECT_EQ(f.solve_shared_pressure(4.94066e-324, mp, V, 9.8499318432636783e-317, p), 0.0);
  EXPECT_DOUBLE_EQ(p, prm.gas.pressure(mp / V));
  EXPECT_EQ(f.solve_shared_pressure(mq, 1e-45, V, 1 - 1e-16, p), 1.0);
  EXPECT_DOUBLE_EQ(p, prm.liquid.pressure(mq / V));
}
