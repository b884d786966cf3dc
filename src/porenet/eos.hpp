// Equations of state of the pore fluids (seed 004, Appendix B, Eqs. B10–B17, B21–B22).
//
// PengRobinson: Peng & Robinson (1976), Ind. Eng. Chem. Fundam. 15:59, in seed 004's form:
//   p = R T / (V - b) - a / (V^2 + 2 b V - b^2)                         (B10)
//   a = a_c beta(T) [1 + n (1 - sqrt(T/Tc))]^2,  n = 0.37464 + 1.54226 w - 0.26992 w^2   (B11–B13)
//   a_c = 0.457247 R^2 Tc^2 / Pc,  b = 0.07780 R Tc / Pc                 (B14–B15)
//   beta = [1 + c1 (1 - Tr^.5) + c2 (1 - Tr^.5)^2 + c3 (1 - Tr^.5)^3]^2  (B16; c = 0: original PR)
// with the Peneloux volume translation (Peneloux, Rauzy & Freze 1982): V_corr = V + s (B17), i.e.
// the molar volume entered in B10 is V = w / rho - s (B21–B22); s = -0.0034 m^3/kmol for water,
// 0 for gas (seed 004). V in m^3/kmol, R = 8314.4598 J/(kmol K), w the molar mass [kg/kmol].
// IdealGas: p = rho R T / w. Barotropic (single-phase liquid): p = p0 + K ln(rho / rho0), a
// constant bulk modulus K = rho dp/drho (METHODS §5.4).
// An Eos is evaluated at one temperature (isothermal flow; set in the factory functions).
#pragma once
#include "core/types.hpp"

namespace ff::porenet {

inline constexpr Real kGasConstant = 8314.4598;  // J/(kmol K), seed 004 after Eq. B10

enum class EosKind : std::uint8_t { PengRobinson, IdealGas, Barotropic };

struct Eos {
  EosKind kind = EosKind::Barotropic;
  Real T = 293.15;         // temperature [K]
  Real molar_mass = 18.015;  // w [kg/kmol]
  // Peng–Robinson
  Real Tc = 0, Pc = 0, omega = 0, s = 0, c1 = 0, c2 = 0, c3 = 0;
  Real a = 0, b = 0;       // at T
  Real v_spinodal = 0;     // smallest PR molar volume with dp/dV = 0 (liquid spinodal), 0 if none
  // Barotropic
  Real rho0 = 1000, p0 = 0, K = 2.2e9;

  // Water (Tc 647.096 K, Pc 22.064 MPa, acentric 0.3443, w 18.015) with s = -0.0034 m^3/kmol.
  static Eos water_pr(Real T);
  // Dry air as one pseudo-component (Tc 132.53 K, Pc 3.786 MPa, acentric 0.0335, w 28.9586;
  // Lemmon et al. 2000, J. Phys. Chem. Ref. Data 29:331), s = 0.
  static Eos air_pr(Real T);
  static Eos peng_robinson(Real T, Real Tc, Real Pc, Real omega, Real molar_mass, Real s = 0);
  static Eos ideal_gas(Real T, Real molar_mass);
  static Eos barotropic(Real rho0, Real p0, Real K);

  Real pressure(Real rho) const;
  // Density at pressure p. PR: liquid root (smallest Z) if liquid, else the largest (vapour or
  // supercritical) root. Throws NumericalError if p <= 0 for a gas law.
  Real density(Real p, bool liquid) const;
  // The same root found by Newton's method from a nearby density `guess` on the same branch (a pore's
  // last density: a few iterations instead of the cubic's trigonometric roots); falls back to
  // density() when the iteration leaves the branch or does not settle. Agrees with density() to
  // round-off; the result depends on the guess only in the last bits.
  Real density_near(Real p, bool liquid, Real guess) const;
  // Isothermal bulk modulus rho dp/drho [Pa].
  Real bulk_modulus(Real rho) const;
  // pressure(rho) and bulk_modulus(rho) together (the same bits; PR shares its terms).
  Real pressure_and_modulus(Real rho, Real& modulus) const;
  // Largest admissible density (PR: V -> b), +inf for the other laws.
  Real max_density() const;
  // Smallest density on the PR liquid branch (at the liquid spinodal); 0 where there is none.
  Real min_liquid_density() const;
};

}  // namespace ff::porenet
