// Peng–Robinson with the Peneloux correction (seed 004 Eqs. B10–B17, B21–B22) against tabulated
// densities.
// Water (IAPWS-95, the formulation NIST's webbook tabulates): 998.2 / 988.0 / 971.8 kg/m^3 at 20 / 50 /
// 80 °C and 0.1 MPa (London South Bank University water data table, www1.lsbu.ac.uk/water/data1.html);
// saturated liquid 55.315 mol/dm^3 at 300 K and 54.049 mol/dm^3 at 350 K (Perry's Chemical Engineers'
// Handbook 9th ed., Table 2-135, generated with NIST REFPROP); at 20 °C and 10 MPa 1002.8 kg/m^3 =
// 998.2 exp(kappa_T 9.9 MPa) with kappa_T = 0.4589 /GPa from the same LSBU table.
// Air: ideal gas (M = 28.9586 kg/kmol, Lemmon et al. 2000, J. Phys. Chem. Ref. Data 29:331) divided by
// Z = 1 + B p / (R T) with the second virial coefficient of air B = -7.5 cm^3/mol at 300 K and
// -13 cm^3/mol at 273.15 K: 1.1768 kg/m^3 (300 K, 0.101325 MPa), 1.2927 (273.15 K, 0.101325 MPa),
// 11.644 (300 K, 1 MPa). Written from these formulas, not read from a table (no network here).
// Tolerances: PR + Peneloux for liquid water: 3 % (PR alone is 10–40 % off for polar liquids, seed 004
// after Eq. B16); air at these states: 0.5 %.
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.hpp"
#include "porenet/eos.hpp"

using namespace ff;
using namespace ff::porenet;

TEST(PorenetEos, WaterPengRobinsonPeneloux) {
  struct Ref {
    Real T, p, rho;
  };
  const Ref refs[] = {{293.15, 0.101325e6, 998.2}, {323.15, 0.101325e6, 988.0}, {353.15, 0.101325e6, 971.8},
                      {300.0, 3.537e3, 55.315 * 18.01528}, {350.0, 41.682e3, 54.049 * 18.01528},
                      {293.15, 10e6, 1002.8}};
  Real worst = 0;
  for (const Ref& r : refs) {
    const Eos w = Eos::water_pr(r.T);
    const Real rho = w.density(r.p, true);
    const Real plain = Eos::peng_robinson(r.T, 647.096, 22.064e6, 0.3443, 18.015, 0.0).density(r.p, true);
    const Real err = (rho - r.rho) / r.rho;
    worst = std::max(worst, std::abs(err));
    std::printf("water %.2f K %.4g MPa: PR+Peneloux %.2f, PR %.2f, table %.2f kg/m^3 (error %+.2f %%, PR alone %+.1f %%)\n",
                r.T, r.p / 1e6, rho, plain, r.rho, 100 * err, 100 * (plain - r.rho) / r.rho);
    EXPECT_LT(std::abs(err), 0.03);
    EXPECT_NEAR(w.pressure(rho), r.p, 1e-6 * r.p + 1e-3);  // inverse consistency
  }
  std::printf("water worst %.2f %%\n", 100 * worst);
  // Known limit of the cubic EOS: the liquid is too stiff. PR+Peneloux gives K = rho dp/drho = 7.25 GPa
  // for water at 20 °C against 1 / kappa_T = 2.18 GPa (LSBU/IAPWS-95), so pressure rises from
  // compaction are ~3.3x those of real water (docs/porenet.md); pinned here so a change is noticed.
  const Eos w = Eos::water_pr(293.15);
  const Real K = w.bulk_modulus(w.density(1e5, true));
  std::printf("PR+Peneloux water bulk modulus at 20 °C: %.3f GPa (IAPWS-95: 2.18 GPa)\n", K / 1e9);
  EXPECT_NEAR(K, 7.25e9, 0.05e9);
}

TEST(PorenetEos, AirPengRobinsonAndIdealGas) {
  struct Ref {
    Real T, p, rho;
  };
  const Ref refs[] = {{300.0, 0.101325e6, 1.1768}, {273.15, 0.101325e6, 1.2927}, {300.0, 1e6, 11.644}};
  for (const Ref& r : refs) {
    const Real rho = Eos::air_pr(r.T).density(r.p, false);
    const Real ideal = Eos::ideal_gas(r.T, 28.9586).density(r.p, false);
    std::printf("air %.2f K %.4g MPa: PR %.4f, ideal %.4f, table %.4f kg/m^3 (PR error %+.3f %%)\n", r.T, r.p / 1e6, rho,
                ideal, r.rho, 100 * (rho - r.rho) / r.rho);
    EXPECT_NEAR(rho, r.rho, 5e-3 * r.rho);
    EXPECT_NEAR(ideal, r.rho, 5e-3 * r.rho);
  }
  const Eos g = Eos::ideal_gas(300, 28.9586);
  EXPECT_NEAR(g.bulk_modulus(g.density(2e5, false)), 2e5, 1e-9);  // isothermal ideal gas: K = p
  EXPECT_THROW(g.density(-1.0, false), NumericalError);
}

// density_near (Newton from a pore's last density, used for an absent phase every flow step) finds the
// root density() finds: water's liquid root and air's at 1 kPa - 100 MPa from guesses 10 % off
// (within 1e-13 relative), and the liquid root even from a vapour-like guess (falls back to the cubic).
TEST(PorenetEos, DensityNearFindsTheSameRoot) {
  const Eos water = Eos::water_pr(293.15), air = Eos::air_pr(293.15);
  Real worst = 0;
  for (Real p = 1e3; p <= 1e8; p *= 1.7) {
    for (const Real f : {0.9, 1.0, 1.1}) {
      const Real rq = water.density(p, true), rp = air.density(p, false);
      worst = std::max(worst, std::abs(water.density_near(p, true, f * rq) - rq) / rq);
      worst = std::max(worst, std::abs(air.density_near(p, false, f * rp) - rp) / rp);
    }
    const Real rq = water.density(p, true);
    EXPECT_NEAR(water.density_near(p, true, 0.02), rq, 1e-13 * rq) << "p " << p;  // a vapour-like guess
  }
  EXPECT_LT(worst, 1e-13);
  EXPECT_THROW((void)air.density_near(-1.0, false, 1.2), NumericalError);
}
