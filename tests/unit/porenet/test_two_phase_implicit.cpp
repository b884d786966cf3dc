// Implicit two-phase step (IMPES: backward-Euler pressure with the EOS linearised per pore, then a
// conservative phase update; porenet/two_phase.hpp). Checks:
//  - each phase's mass is conserved to round-off in a closed sample, partially and fully saturated
//    (Peng–Robinson water + air, seed 004 B10–B23), at 100 x the explicit stable step, and the pressure
//    ends inside its initial range (backward Euler's discrete maximum principle; the symmetric
//    linearisation can overshoot for a few steps where the gas density jumps 3:1 across a channel);
//  - on a soft fluid the implicit and explicit steps agree: backward Euler is first-order accurate,
//    |p_impl - p_expl| = O(dt) (the tolerance below is for dt = 4 explicit stable steps);
//  - a 3D network (PFV throats) conserves each phase; 1 and 2 threads give identical pressures.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fmt/format.h>
#include <string>

#include "core/error.hpp"
#include "geometry/packing.hpp"
#include "box_network.hpp"
#include "packings.hpp"
#include "porenet/flow.hpp"
#include "porenet/two_phase.hpp"

using namespace ff;
using namespace ff::porenet;

namespace {

struct Result {
  std::vector<Real> p, alpha;
  Real eq = 0, ep = 0, lo = 0, hi = 0;
};

// Left part at p_hi / S_hi, the rest at p_lo / S_lo; n steps of dt_factor x the explicit stable step.
Result run(const Network2D& net, const TwoPhaseParams& prm, Real S_lo, Real S_hi, bool implicit, Real dt, int n,
           int threads, Real x_split) {
  omp_set_num_threads(threads);
  TwoPhaseFlow f(net, prm);
  f.init(1e5, S_lo);
  for (Index k = 0; k < net.n_pores(); ++k)
    if (net.pore_cx[k] < x_split) f.set_pore_state(k, 3e5, S_hi);
  const Real mq0 = f.total_liquid_mass(), mp0 = f.total_gas_mass();
  for (int s = 0; s < n; ++s) implicit ? f.step_implicit(dt) : f.step_explicit(dt);
  Result r;
  r.p.assign(f.pressure().begin(), f.pressure().end());
  r.alpha.assign(f.liquid_fraction().begin(), f.liquid_fraction().end());
  r.eq = std::abs(f.total_liquid_mass() - mq0) / mq0;
  r.ep = mp0 > 0 ? std::abs(f.total_gas_mass() - mp0) / mp0 : std::abs(f.total_gas_mass());
  const auto [lo, hi] = std::minmax_element(r.p.begin(), r.p.end());
  r.lo = *lo;
  r.hi = *hi;
  omp_set_num_threads(omp_get_num_procs());
  return r;
}

Real explicit_dt(const Network2D& net, const TwoPhaseParams& prm, Real S_lo, Real S_hi, Real x_split) {
  TwoPhaseFlow f(net, prm);
  f.init(1e5, S_lo);
  for (Index k = 0; k < net.n_pores(); ++k)
    if (net.pore_cx[k] < x_split) f.set_pore_state(k, 3e5, S_hi);
  return f.stable_dt();
}


}  // namespace

TEST(PorenetTwoPhaseImplicit, ClosedSampleConservesEachPhaseAt100xExplicitStep) {
  auto s = test_packings::hex_packing(30, 30, 1e-3, 0.45e-3, 0.05, 0.1);
  const Network2D net = build_network_2d(s.view(), {});
  const TwoPhaseParams prm;  // PR water and air
  for (const auto& [S_lo, S_hi] : {std::pair{0.5, 0.8}, std::pair{1.0, 1.0}}) {
    const Real dte = explicit_dt(net, prm, S_lo, S_hi, 10e-3);
    const Result r1 = run(net, prm, S_lo, S_hi, true, 100 * dte, 100, 1, 10e-3);
    const Result r2 = run(net, prm, S_lo, S_hi, true, 100 * dte, 100, 2, 10e-3);
    std::printf("implicit, S %.1f/%.1f, dt = 100 x explicit %.3e s, 100 steps: liquid mass error %.2e, gas %.2e; "
                "p in [%.6e, %.6e] Pa\n", S_lo, S_hi, dte, r1.eq, r1.ep, r1.lo, r1.hi);
    EXPECT_LT(r1.eq, 1e-13);
    EXPECT_LT(r1.ep, 1e-13);
    EXPECT_GE(r1.lo, 1e5 * (1 - 1e-6));
    EXPECT_LE(r1.hi, 3e5 * (1 + 1e-6));
    // The jump has diffused: pores between the two initial levels.
    const auto front = std::count_if(r1.p.begin(), r1.p.end(), [](Real p) { return p > 1.01e5 && p < 2.99e5; });
    std::printf("  pores inside the front: %ld\n", static_cast<long>(front));
    EXPECT_GT(front, 20);
    EXPECT_EQ(0, std::memcmp(r1.p.data(), r2.p.data(), r1.p.size() * sizeof(Real)));
  }
}

TEST(PorenetTwoPhaseImplicit, MatchesExplicitOnSoftFluid) {
  auto s = test_packings::hex_packing(30, 20, 1e-3, 0.45e-3, 0.05, 0.1);
  const Network2D net = build_network_2d(s.view(), {});
  TwoPhaseParams prm;
  prm.liquid = Eos::barotropic(1000, 1e5, 2e6);  // soft liquid: K = 2 MPa
  prm.gas = Eos::ideal_gas(293.15, 28.9586);
  const Real dte = explicit_dt(net, prm, 0.5, 0.8, 10e-3);
  const int n = 400;  // T = 200 explicit stable steps
  const Result re = run(net, prm, 0.5, 0.8, false, 0.5 * dte, n, 1, 10e-3);
  for (const int k : {1, 4, 20}) {
    const Result ri = run(net, prm, 0.5, 0.8, true, 0.5 * dte * k, n / k, 1, 10e-3);
    Real ep = 0, ea = 0;
    for (std::size_t i = 0; i < re.p.size(); ++i) {
      ep = std::max(ep, std::abs(ri.p[i] - re.p[i]));
      ea = std::max(ea, std::abs(ri.alpha[i] - re.alpha[i]));
    }
    std::printf("soft fluid, T = %.3e s: implicit dt = %.1f x explicit stable step: max |dp| = %.3e Pa (of a 2e5 Pa "
                "jump), max |d alpha| = %.3e; mass errors %.1e %.1e\n", n * 0.5 * dte, 0.5 * k, ep, ea, ri.eq, ri.ep);
    if (k == 4) {
      EXPECT_LT(ep, 0.02 * 2e5);
      EXPECT_LT(ea, 0.02);
    }
    EXPECT_LT(ri.eq, 1e-13);
    EXPECT_LT(ri.ep, 1e-13);
  }
}

TEST(PorenetTwoPhaseImplicit, Network3DConservesEachPhase) {
  const Network2D net = test_packings::box_network_3d(8e-3, 3);
  const TwoPhaseParams prm;
  const Real dte = explicit_dt(net, prm, 0.5, 0.8, 3e-3);
  const Result r1 = run(net, prm, 0.5, 0.8, true, 100 * dte, 30, 1, 3e-3);
  const Result r2 = run(net, prm, 0.5, 0.8, true, 100 * dte, 30, 2, 3e-3);
  std::printf("3D: %d pores: implicit dt = 100 x %.3e s x 30: liquid mass error %.2e, gas %.2e; p in "
              "[%.6e, %.6e] Pa\n", net.n_pores(), dte, r1.eq, r1.ep, r1.lo, r1.hi);
  EXPECT_LT(r1.eq, 1e-13);
  EXPECT_LT(r1.ep, 1e-13);
  EXPECT_GE(r1.lo, 1e5 * (1 - 1e-6));
  EXPECT_LE(r1.hi, 3e5 * (1 + 1e-6));
  EXPECT_EQ(0, std::memcmp(r1.p.data(), r2.p.data(), r1.p.size() * sizeof(Real)));
}

// A liquid-full pore stretched past the Peng–Robinson spinodal (dp/drho <= 0: what an unstable coupled
// step produces, the pressures oscillating and growing until pores are torn open) makes the storage
// term, and so the pressure matrix, indefinite: CG then ran to its iteration cap and advised raising
// it. The step must stop at once and say why (the benchmark's saturated 3D sample at 11.6 x the DEM's
// critical step with the fluid's stiffness ended that way; benchmarks/porenet.cpp).
TEST(PorenetTwoPhaseImplicit, LiquidPastTheSpinodalStopsWithTheCause) {
  auto s = test_packings::hex_packing(12, 12, 1e-3, 0.45e-3, 0.05, 0.1);
  Network2D net = build_network_2d(s.view(), {});
  const TwoPhaseParams prm;  // PR water and air
  ASSERT_GT(prm.liquid.min_liquid_density(), 0);
  Index k = 0;  // the pore nearest the centre
  Real best = 1e300;
  for (Index i = 0; i < net.n_pores(); ++i) {
    const Real d = std::hypot(net.pore_cx[i] - 6e-3, net.pore_cy[i] - 5e-3);
    if (d < best) best = d, k = i;
  }
  for (const bool single_phase : {false, true}) {
    Network2D n2 = net;
    std::string what;
    try {
      if (single_phase) {
        SinglePhaseParams sp;
        sp.fluid = prm.liquid;
        SinglePhaseFlow f(n2, sp);
        f.init(1e5);
        const Real rho = f.density()[k];
        n2.pore_void[k] *= 1.2 * rho / prm.liquid.min_liquid_density();  // torn open: density below the spinodal's
        f.step_implicit(1e-12);  // too short for the neighbours to refill it
        f.step_implicit(1e-12);
      } else {
        TwoPhaseFlow f(n2, prm);
        f.init(1e5, 1.0);
        const Real rho = f.liquid_density()[k];
        n2.pore_void[k] *= 1.2 * rho / prm.liquid.min_liquid_density();
        f.step_implicit(1e-12);
        f.step_implicit(1e-12);
      }
    } catch (const NumericalError& e) {
      what = e.what();
    }
    std::printf("%s: %s\n", single_phase ? "single phase" : "two phase", what.c_str());
    EXPECT_NE(what.find("unstable region"), std::string::npos) << what;
    EXPECT_NE(what.find(fmt::format("pore {}", k)), std::string::npos) << what;
    EXPECT_NE(what.find("dem.time_step"), std::string::npos) << what;
  }
}

// A closed, liquid-full 3D sample compacted pore by pore (+-50 % about the UCS platen rate), one
// implicit step per 1e-7 s with AMG-CG at a loose relative tolerance (1e-8, what benchmarks/porenet
// uses). The conductances dwarf the water's storage (C_i / a_ii down to ~1e-9), so a residual that
// the global test accepts is a pressure mismatch of up to tol (a_ii / C_i) ||b|| once the pore's
// state is taken from its mass; carried into the next step's b, it grew ~6x per step on the
// benchmark's sample until pores were torn past the spinodal (or, sub-cycled, p oscillated over
// -2e5..7e5 Pa). The solve's state check (pcg.hpp) bounds each pore's mismatch. Reference: undrained
// compression of the pore water, mean p - p0 = K ln(V0 / V) (K of PR water at the mean pressure;
// the same closed-form check as test_saturated_ucs's undrained case, Wang 2000 with B = 1).
TEST(PorenetTwoPhaseImplicit, ClosedSaturated3DStaysSmoothAtALooseTolerance) {
  Network2D net = test_packings::box_network_3d(8e-3, 5);
  TwoPhaseParams prm;  // PR water
  prm.preconditioner = Preconditioner::AMG;
  prm.cg_tolerance = 1e-8;
  TwoPhaseFlow f(net, prm);
  f.init(1e5, 1.0);
  const std::vector<Real> void0(net.pore_void.begin(), net.pore_void.end());
  Real v0 = 0;
  for (const Real v : void0) v0 += v;
  std::uint64_t st = 12345;
  std::vector<Real> w(void0.size());
  for (auto& wi : w) {
    st = st * 6364136223846793005ULL + 1442695040888963407ULL;
    wi = 0.5 + static_cast<Real>(st >> 11) * (1.0 / 9007199254740992.0);
  }
  const Real deps = 2 * 0.05 * 1e-7 / 8e-3;  // volumetric strain per step
  const int steps = 30;
  for (int s = 0; s < steps; ++s) {
    for (Index i = 0; i < net.n_pores(); ++i) net.pore_void[i] -= void0[i] * deps * w[i];
    f.step_implicit(1e-7);
  }
  Real v1 = 0, pv = 0;
  for (Index i = 0; i < net.n_pores(); ++i) {
    v1 += net.pore_void[i];
    pv += f.pressure()[i] * net.pore_void[i];
  }
  const Real p_mean = pv / v1;
  const auto [lo, hi] = std::minmax_element(f.pressure().begin(), f.pressure().end());
  Real rho = 0;
  for (Index i = 0; i < net.n_pores(); ++i) rho += f.liquid_density()[i] * net.pore_void[i] / v1;
  const Real expected = prm.liquid.bulk_modulus(rho) * std::log(v0 / v1);
  std::printf("closed S 1, %d pores, %d steps, AMG tol 1e-8: mean p - p0 %.6e Pa (K ln(V0/V) %.6e), p in [%.6e, "
              "%.6e] Pa\n", net.n_pores(), steps, p_mean - 1e5, expected, *lo, *hi);
  EXPECT_NEAR(p_mean - 1e5, expected, 0.02 * expected);
  EXPECT_GT(*lo, 1e5);
  EXPECT_LT(*hi - *lo, 0.05 * expected);  // the pores even out: a closed sample's spread stays small
}

// Liquid flowing through liquid-full pores: at a step where pores pass many times the liquid they hold
// (steady throughflow between an inlet and an outlet band, water, dt = 1 s: the largest ratio is ~1e10,
// in pores at the void floor), the implicit step needs no halving (one solve per step: a liquid-full pore
// taking in no gas is bounded by its net loss, not its gross outflow) and reaches the single-phase
// solver's steady pressures: void-weighted mean difference 5.0e-4 of the drop (measured 2026-11-30;
// asserted below 2e-3). Single pores are off by more (the largest 1.6 x the drop, in a pore at the void
// floor: its pressure comes from its mass, and the pressure solve's residual, times dt K / V, moves it).
// Before 2026-11-30 the gross bound halved such steps to its limit (2^12 solves per step: this test did
// not finish in 11 minutes).
TEST(PorenetTwoPhaseImplicit, ThroughflowOfLiquidFullPoresNeedsNoHalving) {
  const Network2D net = test_packings::box_network_3d(6e-3, 4);
  TwoPhaseParams prm;
  prm.liquid = Eos::barotropic(1000, 1e5, 2.2e9);
  prm.mu_liquid = 1e-3;
  TwoPhaseFlow f(net, prm);
  f.init(1e5, 1.0);
  SinglePhaseParams sp;
  sp.fluid = Eos::barotropic(1000, 1e5, 2.2e9);
  sp.mu = 1e-3;
  sp.solver = LinearSolver::ConjugateGradient;
  SinglePhaseFlow ref(net, sp);
  for (Index k = 0; k < net.n_pores(); ++k) {
    if (net.pore_cx[k] < 1e-3) {
      f.set_bc(k, PoreBc::Pressure, 1e5 + 1e4);
      ref.set_bc(k, PoreBc::Pressure, 1e5 + 1e4);
    } else if (net.pore_cx[k] > 5e-3) {
      f.set_bc(k, PoreBc::Pressure, 1e5);
      ref.set_bc(k, PoreBc::Pressure, 1e5);
    }
  }
  ref.init(1e5);
  for (int s = 0; s < 30; ++s) ref.step_implicit(1.0);
  int most_substeps = 0;
  for (int s = 0; s < 40; ++s) {
    f.step_implicit(1.0);
    most_substeps = std::max(most_substeps, f.last_substeps());
  }
  Real weighted = 0, volume = 0, worst = 0;
  for (Index k = 0; k < net.n_pores(); ++k) {
    const Real e = std::abs(f.pressure()[k] - ref.pressure()[k]) / 1e4;
    weighted += e * net.pore_void[k];
    volume += net.pore_void[k];
    worst = std::max(worst, e);
  }
  // Throughflow per pore and step against its liquid: the largest ratio.
  Real ratio = 0;
  for (Index k = 0; k < net.n_pores(); ++k) {
    if (f.bc(k) == PoreBc::Pressure) continue;
    Real out = 0;
    for (Index e = net.pc_start[k]; e < net.pc_start[k + 1]; ++e) {
      const Index c = net.pc_ch[e];
      const Index o = net.ch_pore[2 * c] == k ? net.ch_pore[2 * c + 1] : net.ch_pore[2 * c];
      out += std::max(net.ch_cond[c] / prm.mu_liquid * (f.pressure()[k] - f.pressure()[o]), 0.0);
    }
    ratio = std::max(ratio, out * 1.0 / net.pore_void[k]);
  }
  std::printf("throughflow: %d pores, the largest passes %.3g x its liquid per step; substeps per step at most %d; "
              "pressures vs the single-phase solver's: void-weighted mean %.2e, largest %.2e of the drop\n",
              net.n_pores(), ratio, most_substeps, weighted / volume, worst);
  EXPECT_GT(ratio, 10.0);
  EXPECT_EQ(most_substeps, 1);
  EXPECT_LT(weighted / volume, 2e-3);
}
