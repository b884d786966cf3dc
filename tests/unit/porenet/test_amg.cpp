// Algebraic-multigrid preconditioned CG for the pore-pressure systems (porenet/amg.hpp, pcg.hpp) on a
// 3D PFV network (~1,800 spheres, ~11,000 pores: several smoother blocks and parallel loops):
//  - the V-cycle is a symmetric operator (CG needs it): x.B y = y.B x to round-off;
//  - single-phase implicit step: the same pressures as DIC-CG to the solver tolerance, in fewer
//    iterations (margin measured: see the assertion), and 1 and 2 threads give identical pressures;
//  - a closed, fully saturated sample (Peng-Robinson water, no gas; the nearly singular case: the
//    compressibility diagonal V/K against the throats' dt G) under a non-uniform compaction, stepped at
//    about the DEM step, converges, conserves the liquid mass to round-off and gives the undrained
//    pressure rise: sum (V/K) dp = sum dV (closed, rigid grains; Biot undrained, to first order).
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "box_network.hpp"
#include "core/error.hpp"
#include "core/rng.hpp"
#include "porenet/flow.hpp"
#include "porenet/two_phase.hpp"

using namespace ff;
using namespace ff::porenet;

namespace {

const Network2D& net3() {
  static const Network2D net = test_packings::box_network_3d(12e-3, 3);
  return net;
}

// A pressure matrix of one implicit step (single phase): storage V/K on the diagonal, the throats'
// dt g (mu 1e-3, dt 1e-6 s), each times factor[c] when given.
void fill_pressure_matrix(PressureSystem& sys, const Network2D& net, const std::vector<Real>* factor = nullptr) {
  auto& A = sys.matrix();
  Real* val = A.valuePtr();
  const auto* outer = A.outerIndexPtr();
  const auto* inner = A.innerIndexPtr();
  for (Index i = 0; i < net.n_pores(); ++i) {
    Real d = net.pore_void[i] / 2.2e9;
    for (Index k = outer[i]; k < outer[i + 1]; ++k)
      if (const Index c = sys.entry_channel()[k]; c >= 0) {
        const Real g = 1e-6 * net.ch_cond[c] / 1e-3 * (factor ? (*factor)[static_cast<std::size_t>(c)] : 1.0);
        val[k] = -g;
        d += g;
      }
    for (Index k = outer[i]; k < outer[i + 1]; ++k)
      if (inner[k] == i) val[k] = d;
  }
}

struct SingleResult {
  std::vector<Real> p;
  int iterations = 0;
};

SingleResult single_phase(Preconditioner pc, int threads, int steps, LinearSolver solver = LinearSolver::ConjugateGradient) {
  omp_set_num_threads(threads);
  const Network2D& net = net3();
  SinglePhaseParams prm;
  prm.fluid = Eos::barotropic(1000, 1e5, 2.2e9);
  prm.preconditioner = pc;
  prm.solver = solver;
  prm.cg_tolerance = 1e-12;
  SinglePhaseFlow f(net, prm);
  for (Index k = 0; k < net.n_pores(); ++k)
    if (net.pore_cx[k] < 1.5e-3) f.set_bc(k, PoreBc::Pressure, 2e5);
  f.init(1e5);
  SingleResult r;
  for (int s = 0; s < steps; ++s) {
    f.step_implicit(1e-6);
    r.iterations += f.last_cg_iterations();
  }
  r.p.assign(f.pressure().begin(), f.pressure().end());
  omp_set_num_threads(omp_get_num_procs());
  return r;
}
}  // namespace

TEST(PorenetAmg, VCycleIsSymmetric) {
  const Network2D& net = net3();
  // A pressure matrix from one implicit step (single phase, Dirichlet inlet).
  PressureSystem sys(net);
  fill_pressure_matrix(sys, net);
  const auto& A = sys.matrix();
  const Real* val = A.valuePtr();
  const auto* outer = A.outerIndexPtr();
  const auto* inner = A.innerIndexPtr();
  Amg amg;
  amg.setup({net.n_pores(), outer, inner, val});
  std::printf("AMG on %d pores: %d levels (coarsest %d), operator complexity %.3f\n", net.n_pores(), amg.n_levels(),
              amg.level_size(amg.n_levels() - 1), amg.operator_complexity());
  EXPECT_GE(amg.n_levels(), 3);
  Rng rng(9);
  const auto n = static_cast<std::size_t>(net.n_pores());
  std::vector<Real> x(n), y(n), bx(n), by(n);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = rng.uniform(-1, 1);
    y[i] = rng.uniform(-1, 1);
  }
  amg.apply(x.data(), bx.data());
  amg.apply(y.data(), by.data());
  Real ybx = 0, xby = 0, xbx = 0, scale = 0;
  for (std::size_t i = 0; i < n; ++i) {
    ybx += y[i] * bx[i];
    xby += x[i] * by[i];
    xbx += x[i] * bx[i];
    scale += std::abs(y[i] * bx[i]);
  }
  EXPECT_NEAR(ybx, xby, 1e-12 * scale);
  EXPECT_GT(xbx, 0);  // positive definite (one sample)
}

TEST(PorenetAmg, SinglePhaseSameSolutionFewerIterationsThreadIndependent) {
  const SingleResult ldlt = single_phase(Preconditioner::DIC, 1, 3, LinearSolver::LDLT);  // direct: the reference
  const SingleResult dic = single_phase(Preconditioner::DIC, 1, 3);
  const SingleResult amg1 = single_phase(Preconditioner::AMG, 1, 3);
  const SingleResult amg2 = single_phase(Preconditioner::AMG, 2, 3);
  Real ed = 0, ea = 0;
  for (std::size_t i = 0; i < dic.p.size(); ++i) {
    ed = std::max(ed, std::abs(dic.p[i] - ldlt.p[i]));
    ea = std::max(ea, std::abs(amg1.p[i] - ldlt.p[i]));
  }
  std::printf("3D single phase, %d pores, 3 implicit steps of 1e-6 s (tolerance 1e-12): CG iterations DIC %d, AMG %d; "
              "max |p - p_LDLT|: DIC %.3e Pa, AMG %.3e Pa\n", net3().n_pores(), dic.iterations, amg1.iterations, ed, ea);
  EXPECT_LT(ea, 1.0);  // of a 1e5 Pa jump
  EXPECT_LT(ed, 1.0);
  EXPECT_LT(3 * amg1.iterations, dic.iterations);  // measured: 140 against 636
  EXPECT_EQ(amg1.iterations, amg2.iterations);
  EXPECT_EQ(0, std::memcmp(amg1.p.data(), amg2.p.data(), amg1.p.size() * sizeof(Real)));
}

TEST(PorenetAmg, ClosedSaturatedCompactionConverges) {
  Network2D net = net3();
  auto run = [&](Preconditioner pc, int threads, Real& dp_mean, Real& err, int& its) {
    omp_set_num_threads(threads);
    std::vector<Real> v0(net.pore_void.begin(), net.pore_void.end());
    TwoPhaseParams prm;  // Peng-Robinson water and air; here water only
    prm.preconditioner = pc;
    prm.cg_tolerance = 1e-10;
    TwoPhaseFlow f(net, prm);
    f.init(1e5, 1.0);
    const Real m0 = f.total_liquid_mass();
    // Non-uniform compaction: every third pore loses 1.5e-5 of its void, the others 0.5e-5.
    constexpr int nsteps = 10;
    its = 0;
    for (int s = 0; s < nsteps; ++s) {  // 10 steps of 1e-7 s (about the DEM step of 0.5 mm spheres)
      for (Index k = 0; k < net.n_pores(); ++k) net.pore_void[k] *= 1 - (k % 3 == 0 ? 1.5e-5 : 0.5e-5) / nsteps;
      f.step_implicit(1e-7);
      its += f.last_cg_iterations();
    }
    // Storage-weighted mean pressure rise (closed: sum (V/K) dp = sum dV to first order).
    Real num = 0, den = 0;
    for (Index k = 0; k < net.n_pores(); ++k) {
      const Real c = v0[k] / Eos::water_pr(293.15).bulk_modulus(f.liquid_density()[k]);
      num += c * (f.pressure()[k] - 1e5);
      den += c;
    }
    dp_mean = num / den;
    err = std::abs(f.total_liquid_mass() - m0) / m0;
    std::vector<Real> p(f.pressure().begin(), f.pressure().end());
    std::copy(v0.begin(), v0.end(), net.pore_void.begin());
    omp_set_num_threads(omp_get_num_procs());
    return p;
  };
  Real dpa = 0, ea = 0, dpa2 = 0, ea2 = 0;
  int ita = 0, ita2 = 0;
  const auto pa = run(Preconditioner::AMG, 1, dpa, ea, ita);
  const auto pa2 = run(Preconditioner::AMG, 2, dpa2, ea2, ita2);
  // Undrained estimate (linearised): dp = sum dV / sum (V / K).
  Real dv = 0, vk = 0;
  {
    TwoPhaseFlow f(net, {});
    f.init(1e5, 1.0);
    for (Index k = 0; k < net.n_pores(); ++k) {
      dv += net.pore_void[k] * (k % 3 == 0 ? 1.5e-5 : 0.5e-5);
      vk += net.pore_void[k] / Eos::water_pr(293.15).bulk_modulus(f.liquid_density()[k]);
    }
  }
  const auto [lo, hi] = std::minmax_element(pa.begin(), pa.end());
  std::printf("closed saturated 3D, compaction in 10 steps of 1e-7 s: AMG %d CG iterations; storage-weighted mean dp "
              "%.6e Pa (undrained estimate %.6e), p in [%.6e, %.6e]; liquid mass error %.2e\n", ita, dpa, dv / vk, *lo,
              *hi, ea);
  EXPECT_LT(ea, 1e-13);
  EXPECT_NEAR(dpa, dv / vk, 0.01 * dv / vk);  // 1%: the EOS is linearised, K varies with p
  EXPECT_GT(*lo, 1e5);                        // compressed everywhere, no oscillation
  EXPECT_LT(*hi - 1e5, 2 * dpa);
  EXPECT_EQ(ita, ita2);
  EXPECT_EQ(0, std::memcmp(pa.data(), pa2.data(), pa.size() * sizeof(Real)));
}

// A checkpoint's AMG state (PressureSystem::amg_state: the matrix values the aggregates were built from,
// and the rebuild rule's counters) restored into a new system on the same pattern gives the same solve,
// bit for bit, as the system that kept its aggregates; a system that builds them from its current matrix
// instead (what a resume did before 2026-11-30) does not: the conductances changed by orders between.
TEST(PorenetAmg, RestoredStateGivesTheSameSolves) {
  const Network2D& net = net3();
  Rng rng(17);
  std::vector<Real> factor(static_cast<std::size_t>(net.n_channels()));
  for (auto& f : factor) f = std::pow(10.0, rng.uniform(-3, 3));
  auto fill = [&](PressureSystem& sys, bool varied) { fill_pressure_matrix(sys, net, varied ? &factor : nullptr); };
  const auto n = static_cast<std::size_t>(net.n_pores());
  std::vector<Real> b(n);
  for (auto& v : b) v = rng.uniform(-1e-12, 1e-12);
  auto solve = [&](PressureSystem& sys, std::vector<Real>& x) {
    std::fill(x.begin(), x.end(), 0.0);
    return sys.solve(b, x, Preconditioner::AMG, 1e-10, 2000);
  };
  std::vector<Real> x(n), x_kept(n), x_restored(n), x_rebuilt(n);
  PressureSystem kept(net);
  fill(kept, false);
  solve(kept, x);  // the aggregates from the uniform conductances
  const std::vector<Real> state = kept.amg_state();
  ASSERT_FALSE(state.empty());
  fill(kept, true);
  const int it_kept = solve(kept, x_kept);

  PressureSystem restored(net);
  fill(restored, true);
  restored.restore_amg_state(state);
  const int it_restored = solve(restored, x_restored);

  PressureSystem rebuilt(net);
  fill(rebuilt, true);
  const int it_rebuilt = solve(rebuilt, x_rebuilt);
  long differ = 0;
  for (std::size_t i = 0; i < n; ++i) differ += x_rebuilt[i] != x_kept[i];
  std::printf("AMG state: kept %d iterations, restored %d, rebuilt from the current matrix %d (%ld of %zu values "
              "differ from the kept one's)\n", it_kept, it_restored, it_rebuilt, differ, n);
  EXPECT_EQ(it_restored, it_kept);
  EXPECT_EQ(0, std::memcmp(x_restored.data(), x_kept.data(), n * sizeof(Real)));
  EXPECT_GT(differ, 0);  // the test can tell
  EXPECT_THROW(restored.restore_amg_state(std::vector<Real>(5, 0.0)), InputError);
}
