#include "porenet/eos.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>

#include "core/error.hpp"

namespace ff::porenet {
namespace {

Real pr_p(const Eos& e, Real V) { return kGasConstant * e.T / (V - e.b) - e.a / (V * V + 2 * e.b * V - e.b * e.b); }
Real pr_dpdV(const Eos& e, Real V) {
  const Real d = V * V + 2 * e.b * V - e.b * e.b;
  return -kGasConstant * e.T / ((V - e.b) * (V - e.b)) + e.a * (2 * V + 2 * e.b) / (d * d);
}

// Real roots of z^3 + a2 z^2 + a1 z + a0 (ascending), each polished by Newton steps.
int cubic_roots(Real a2, Real a1, Real a0, Real r[3]) {
  const Real q = (a2 * a2 - 3 * a1) / 9;
  const Real rr = (2 * a2 * a2 * a2 - 9 * a2 * a1 + 27 * a0) / 54;
  int n;
  if (rr * rr < q * q * q) {
    const Real th = std::acos(std::clamp(rr / std::sqrt(q * q * q), Real(-1), Real(1)));
    const Real sq = -2 * std::sqrt(q);
    r[0] = sq * std::cos(th / 3) - a2 / 3;
    r[1] = sq * std::cos((th + 2 * kPi) / 3) - a2 / 3;
    r[2] = sq * std::cos((th - 2 * kPi) / 3) - a2 / 3;
    n = 3;
  } else {
    const Real A = -std::copysign(std::cbrt(std::abs(rr) + std::sqrt(rr * rr - q * q * q)), rr);
    const Real B = A != 0 ? q / A : 0;
    r[0] = A + B - a2 / 3;
    n = 1;
  }
  for (int k = 0; k < n; ++k)
    for (int it = 0; it < 3; ++it) {
      const Real z = r[k];
      const Real f = ((z + a2) * z + a1) * z + a0, df = (3 * z + 2 * a2) * z + a1;
      if (df != 0) r[k] = z - f / df;
    }
  std::sort(r, r + n);
  return n;
}

}  // namespace

Eos Eos::peng_robinson(Real T, Real Tc, Real Pc, Real omega, Real molar_mass, Real s) {
  if (!(T > 0 && Tc > 0 && Pc > 0 && molar_mass > 0))
    throw InputError(fmt::format("porenet: Peng-Robinson needs T, Tc, Pc and molar mass > 0 (got {}, {}, {}, {})",
                                 T, Tc, Pc, molar_mass));
  Eos e;
  e.kind = EosKind::PengRobinson;
  e.T = T;
  e.Tc = Tc;
  e.Pc = Pc;
  e.omega = omega;
  e.molar_mass = molar_mass;
  e.s = s;
  const Real R = kGasConstant;
  const Real n = 0.37464 + 1.54226 * omega - 0.26992 * omega * omega;  // B12
  const Real x = 1 - std::sqrt(T / Tc);
  const Real beta = std::pow(1 + e.c1 * x + e.c2 * x * x + e.c3 * x * x * x, 2);  // B16
  const Real ac = 0.457247 * R * R * Tc * Tc / Pc;                                   // B14
  e.a = ac * beta * (1 + n * x) * (1 + n * x);                                       // B11, B13
  e.b = 0.07780 * R * Tc / Pc;                                                       // B15
  // Liquid spinodal: first V > b where dp/dV turns non-negative (none above Tc).
  e.v_spinodal = 0;
  Real lo = e.b * (1 + 1e-9), hi = lo;
  while (hi < 1e4 * e.b) {
    hi = lo * 1.01;
    if (pr_dpdV(e, hi) >= 0) break;
    lo = hi;
  }
  if (pr_dpdV(e, hi) >= 0) {
    for (int it = 0; it < 200; ++it) {
      const Real mid = 0.5 * (lo + hi);
      (pr_dpdV(e, mid) >= 0 ? hi : lo) = mid;
    }
    e.v_spinodal = lo;
  }
  return e;
}

Eos Eos::water_pr(Real T) { return peng_robinson(T, 647.096, 22.064e6, 0.3443, 18.015, -0.0034); }
Eos Eos::air_pr(Real T) { return peng_robinson(T, 132.53, 3.786e6, 0.0335, 28.9586, 0.0); }

Eos Eos::ideal_gas(Real T, Real molar_mass) {
  if (!(T > 0 && molar_mass > 0)) throw InputError("porenet: ideal gas needs T > 0 and molar mass > 0");
  Eos e;
  e.kind = EosKind::IdealGas;
  e.T = T;
  e.molar_mass = molar_mass;
  return e;
}

Eos Eos::barotropic(Real rho0, Real p0, Real K) {
  if (!(rho0 > 0 && K > 0)) throw InputError(fmt::format("porenet: barotropic fluid needs rho0 > 0 and K > 0 "
                                                          "(got {}, {})", rho0, K));
  Eos e;
  e.kind = EosKind::Barotropic;
  e.rho0 = rho0;
  e.p0 = p0;
  e.K = K;
  return e;
}

Real Eos::pressure(Real rho) const {
  switch (kind) {
    case EosKind::PengRobinson: return pr_p(*this, molar_mass / rho - s);  // B10 with B21/B22
    case EosKind::IdealGas: return rho * kGasConstant * T / molar_mass;
    case EosKind::Barotropic: return p0 + K * std::log(rho / rho0);
  }
  return 0;
}

Real Eos::density(Real p, bool liquid) const {
  switch (kind) {
    case EosKind::PengRobinson: {
      if (!(p > 0)) throw NumericalError(fmt::format("porenet: Peng-Robinson density asked at p = {} Pa (> 0 needed)", p));
      const Real RT = kGasConstant * T;
      const Real A = a * p / (RT * RT), B = b * p / RT;
      Real z[3];
      const int n = cubic_roots(-(1 - B), A - 3 * B * B - 2 * B, -(A * B - B * B - B * B * B), z);
      Real Z = liquid ? std::numeric_limits<Real>::infinity() : 0;
      for (int k = 0; k < n; ++k)
        if (z[k] > B) Z = liquid ? std::min(Z, z[k]) : std::max(Z, z[k]);
      return molar_mass / (Z * RT / p + s);  // B17: V_corr = V + s
    }
    case EosKind::IdealGas:
      if (!(p > 0)) throw NumericalError(fmt::format("porenet: ideal-gas density asked at p = {} Pa (> 0 needed)", p));
      return p * molar_mass / (kGasConstant * T);
    case EosKind::Barotropic: return rho0 * std::exp((p - p0) / K);
  }
  return 0;
}

Real Eos::density_near(Real p, bool liquid, Real guess) const {
  if (kind != EosKind::PengRobinson || !(p > 0) || !(guess > 0) || !std::isfinite(guess)) return density(p, liquid);
  // Newton on p(V) = p in the molar volume V (uncorrected, B10): on the liquid branch p(V) falls and is
  // convex, on the gas branch it falls; a step that leaves (b, spinodal) or a rising p(V) means the
  // guess was on another branch.
  Real V = molar_mass / guess - s;
  const Real vmax = liquid && v_spinodal > 0 ? v_spinodal : std::numeric_limits<Real>::infinity();
  for (int it = 0; it < 8; ++it) {
    if (!(V > b && V < vmax)) break;
    const Real d = pr_dpdV(*this, V);
    if (!(d < 0)) break;
    const Real dV = (pr_p(*this, V) - p) / d;
    V -= dV;
    if (std::abs(dV) <= 1e-14 * V) {
      if (!(V > b && V < vmax) || !(pr_dpdV(*this, V) < 0)) break;
      return molar_mass / (V + s);  // B17: V_corr = V + s
    }
  }
  return density(p, liquid);
}

Real Eos::bulk_modulus(Real rho) const {
  switch (kind) {
    case EosKind::PengRobinson: return -(molar_mass / rho) * pr_dpdV(*this, molar_mass / rho - s);
    case EosKind::IdealGas: return pressure(rho);
    case EosKind::Barotropic: return K;
  }
  return 0;
}

Real Eos::pressure_and_modulus(Real rho, Real& modulus) const {
  if (kind != EosKind::PengRobinson) {
    modulus = bulk_modulus(rho);
    return pressure(rho);
  }
  // pressure() and bulk_modulus() at one molar volume: the same expressions, their common terms
  // evaluated once by the compiler (pr_p and pr_dpdV are inline here).
  const Real V = molar_mass / rho - s;
  modulus = -(molar_mass / rho) * pr_dpdV(*this, V);
  return pr_p(*this, V);
}

Real Eos::max_density() const {
  return kind == EosKind::PengRobinson ? molar_mass / (b + s) : std::numeric_limits<Real>::infinity();
}

Real Eos::min_liquid_density() const {
  return kind == EosKind::PengRobinson && v_spinodal > 0 ? molar_mass / (v_spinodal + s) : 0;
}

}  // namespace ff::porenet
