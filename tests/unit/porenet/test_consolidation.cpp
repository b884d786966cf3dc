// Poromechanical checks of the single-phase network flow with a prescribed compressible matrix
// (standalone: no DEM; METHODS.md §5.7, the checks YADE runs for its PFV engine):
//  - undrained loading: pore-pressure jump = load step x (V_cell/M) / (V/K_f + V_cell/M);
//  - Terzaghi's 1D consolidation (Terzaghi 1943, Theoretical Soil Mechanics, Wiley, ch. XIII):
//    drained top, impermeable bottom and sides, mean excess pressure
//    1 - U(T_v) = sum_m 2/M^2 exp(-M^2 T_v), M = (2m+1) pi/2, T_v = c_v t / H^2, c_v = k / (mu S),
//    with k measured on the same network by a steady vertical flow and S = (sum V/K_f + sum V_cell/M) / sum V_cell.
// Model: V_i = V0_i - V_cell,i (sigma - p_i - sigma'_0)/M (oedometric, grains incompressible).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "packings.hpp"
#include "terzaghi.hpp"
#include "porenet/flow.hpp"

using namespace ff;
using namespace ff::porenet;

using ff::test::terzaghi_mean_excess;

TEST(PorenetConsolidation, UndrainedJumpAndTerzaghi) {
  const Real d = 1e-3;
  auto s = test_packings::hex_packing(16, 160, d, 0.45e-3, 0.05, 0.1);
  const Network2D net = build_network_2d(s.view(), {});
  const Index np = net.n_pores();
  const Real ytop = *std::max_element(net.pore_cy.begin(), net.pore_cy.end());
  const Real ybot = *std::min_element(s.y.begin(), s.y.end());
  std::vector<Index> top, bottom;
  for (Index k = 0; k < np; ++k) {
    if (net.pore_cy[k] > ytop - 0.5 * d) top.push_back(k);
    if (net.pore_cy[k] < ybot + 0.5 * d) bottom.push_back(k);
  }
  auto mean_y = [&](const std::vector<Index>& v) {
    Real m = 0;
    for (Index k : v) m += net.pore_cy[k];
    return m / static_cast<Real>(v.size());
  };
  const Real mu = 1e-3, K = 2.2e9, M = 1e7, pref = 1e5, dsig = 1e4, depth = net.params.thickness;
  SinglePhaseParams prm;
  prm.mu = mu;
  prm.fluid = Eos::barotropic(1000, pref, K);
  prm.matrix_modulus = M;
  prm.solver = LinearSolver::LDLT;

  // 1. Permeability of the column: steady vertical flow (Darcy, k = Q mu H / (W t dp)).
  Real k_perm;
  {
    SinglePhaseFlow f(net, prm);
    for (Index k : top) f.set_bc(k, PoreBc::Pressure, pref + 1e3);
    for (Index k : bottom) f.set_bc(k, PoreBc::Pressure, pref);
    f.init(pref);
    for (int n = 0; n < 5; ++n) f.step_implicit(1e3);
    const Real Q = f.pressure_pores_inflow_rate(true) / 1000.0;  // m^3/s
    const Real W = *std::max_element(s.x.begin(), s.x.end()) - *std::min_element(s.x.begin(), s.x.end());
    k_perm = Q * mu * (mean_y(top) - mean_y(bottom)) / (W * depth * 1e3);
    std::printf("column permeability k = %.4e m^2 (in %.6e, out %.6e kg/s)\n", k_perm,
                f.pressure_pores_inflow_rate(true), -f.pressure_pores_inflow_rate(false));
  }
  // 2. Undrained jump, incompressible-like water and a compressible fluid.
  for (const Real Kf : {K, 2e6}) {
    SinglePhaseParams q = prm;
    q.fluid = Eos::barotropic(1000, pref, Kf);
    SinglePhaseFlow f(net, q);
    f.init(pref);
    f.set_total_stress(dsig);
    f.step_implicit(0.0);
    Real emax = 0, Bmin = 1;
    for (Index k = 0; k < np; ++k) {
      const Real a = net.pore_cell[k] / M, b = net.pore_void[k] / Kf;
      const Real B = a / (a + b);
      Bmin = std::min(Bmin, B);
      emax = std::max(emax, std::abs((f.pressure()[k] - pref) / dsig - B));
    }
    std::printf("undrained, K_f = %.1e Pa: jump / load step vs (V_cell/M)/(V/K_f + V_cell/M): max error %.2e "
                "(smallest ratio %.4f)\n", Kf, emax, Bmin);
    EXPECT_LT(emax, 2e-3);
  }
  // 3. Consolidation under the load step, drained at the top.
  SinglePhaseFlow f(net, prm);
  for (Index k : top) f.set_bc(k, PoreBc::Pressure, pref);
  f.init(pref);
  f.set_total_stress(dsig);
  f.step_implicit(0.0);  // undrained response
  Real Vc = 0, S = 0;
  for (Index k = 0; k < np; ++k) {
    Vc += net.pore_cell[k];
    S += net.pore_void[k] / K + net.pore_cell[k] / M;
  }
  S /= Vc;
  const Real H = mean_y(top) - ybot;
  const Real cv = k_perm / (mu * S);
  auto mean_excess = [&]() {
    Real num = 0, den = 0;
    for (Index k = 0; k < np; ++k) {
      if (net.pore_cy[k] > ytop - 0.5 * d) continue;
      num += net.pore_cell[k] * (f.pressure()[k] - pref);
      den += net.pore_cell[k];
    }
    return num / den;
  };
  const Real p0 = mean_excess();
  const int steps_per_unit = 1000;
  const Real dt = H * H / cv / steps_per_unit;
  Real worst = 0;
  int n = 0;
  for (const Real Tv : {0.02, 0.05, 0.1, 0.2, 0.4, 0.8}) {
    while (n < Tv * steps_per_unit - 0.5) {
      f.step_implicit(dt);
      ++n;
    }
    const Real num = mean_excess() / p0, ref = terzaghi_mean_excess(Tv);
    worst = std::max(worst, std::abs(num - ref));
    std::printf("T_v = %.2f: mean excess pressure %.4f, Terzaghi %.4f, difference %+.4f\n", Tv, num, ref, num - ref);
  }
  std::printf("H = %.4e m, c_v = %.4e m^2/s, undrained mean jump %.1f Pa of %.0f\n", H, cv, p0, dsig);
  EXPECT_LT(worst, 0.01);  // 0.021 on an 8 x 80 column, 0.005 on this 16 x 160 one (discretisation of H and k)
}
