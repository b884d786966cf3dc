// Hertz-Mindlin contact with Coulomb friction (no-slip Mindlin tangential stiffness,
// incremental form), as PFC "hertz" / YADE / LIGGGHTS granular/hertz/history:
//   Fn = 4/3 E* sqrt(R*) delta^(3/2),  kt = 8 G* sqrt(R* delta)
// with, for two bodies of one material (shear modulus G, Poisson ratio nu),
//   E* = E / (2 (1 - nu^2)),  G* = G / (2 (2 - nu)),  R* = RA RB / (RA + RB)
// (Johnson 1985, Contact Mechanics, ch. 4 and 7). Against a wall, R* = RA and the wall is rigid
// (E* = E/(1-nu^2), G* = G/(2-nu)). In 2D the same formulas are used per unit thickness, which
// is a common approximation (Hertz has no exact 2D law for cylinders).
#pragma once
#include <algorithm>
#include <cmath>
#include <string>
#include <string_view>

#include "dem/contact/contact_geometry.hpp"
#include "io/params.hpp"

namespace ff::dem {

struct HertzMindlinContact {
  static constexpr std::string_view name = "hertz_mindlin";
  struct Params {
    Real shear_modulus = 1e9;  // G [Pa]
    Real poisson = 0.25;       // nu [-]
    Real fric = 0.5;           // [-]
  };
  using State = ContactState;
  // Its keys (the friction, dem.contact.*.friction, is common to every contact law).
  static void declare(ParamTable& t) {
    t.real("dem.contact.*.shear_modulus", 1e9, "Pa", "Hertz-Mindlin particle shear modulus G").positive();
    t.real("dem.contact.*.poisson", 0.25, "-", "Hertz-Mindlin particle Poisson ratio").range(0, 0.5).below(0.5);
  }
  static Params read(const Config& cfg, const std::string& table) {
    return {cfg.real(table + ".shear_modulus"), cfg.real(table + ".poisson"), cfg.real(table + ".friction")};
  }
  static Params elastic(Real E, Real nu) { return {E / (2 * (1 + nu)), nu, 0.0}; }
  static void moduli(const Params& p, bool wall, Real& e_star, Real& g_star) {
    const Real E = 2 * p.shear_modulus * (1 + p.poisson);
    e_star = E / ((wall ? 1.0 : 2.0) * (1 - p.poisson * p.poisson));
    g_star = p.shear_modulus / ((wall ? 1.0 : 2.0) * (2 - p.poisson));
  }
  static Real reduced_radius(Real rA, Real rB) { return rB > 0 ? rA * rB / (rA + rB) : rA; }
  // Tangent normal stiffness dFn/d(delta) = 2 E* sqrt(R* delta), for the time-step estimate.
  static Real normal_stiffness(const Params& p, Real rA, Real rB, Real overlap) {
    Real es, gs;
    moduli(p, rB <= 0, es, gs);
    return 2 * es * std::sqrt(reduced_radius(rA, rB) * std::max(overlap, 0.0));
  }
  static Real normal_stiffness_at(const Params& p, Real rA, Real rB, Real overlap, int /*dim*/) {
    return normal_stiffness(p, rA, rB, overlap);
  }
  // At least 1% of the smaller radius: a contact just closing must still bound the step.
  static Real time_step_stiffness(const Params& p, Real rA, Real rB, Real overlap, int /*dim*/) {
    return normal_stiffness(p, rA, rB, std::max(overlap, 0.01 * std::min(rA, rB > 0 ? rB : rA)));
  }
  // Fn = 4/3 E* sqrt(R*) delta^(3/2) = 2/3 (dFn/d delta) delta.
  static Real normal_force(const Params& p, Real rA, Real rB, Real overlap, int /*dim*/) {
    return 2.0 / 3.0 * normal_stiffness(p, rA, rB, overlap) * overlap;
  }
  // Normal: integral of Fn = 8/15 E* sqrt(R*) delta^(5/2) (Johnson 1985, ch. 4).
  static Real normal_energy(const Params& p, Real rA, Real rB, Real overlap, int /*dim*/) {
    Real es, gs;
    moduli(p, rB <= 0, es, gs);
    return 8.0 / 15.0 * es * std::sqrt(reduced_radius(rA, rB)) * std::pow(overlap, 2.5);
  }
  // Normal energy plus the shear spring's |Fs|^2/(2 kt) at the current kt = 8 G* sqrt(R* delta)
  // (Mindlin's no-slip stiffness; since kt varies with delta this is not path independent: the
  // energy balance instead sums the work of the shear force increments, shear_work()).
  static Real strain_energy(const Params& p, Real rA, Real rB, Real overlap, const State& s, int dim) {
    Real es, gs;
    moduli(p, rB <= 0, es, gs);
    const Real kt = 8 * gs * std::sqrt(reduced_radius(rA, rB) * overlap);
    return normal_energy(p, rA, rB, overlap, dim) + (kt > 0 ? 0.5 * s.fs.squaredNorm() / kt : 0.0);
  }
  // With kEnergy, `w` receives the shear spring's work and the slip dissipation (shear_work()).
  template <bool kEnergy = false>
  [[gnu::always_inline]] static Vec3 force(const Params& p, const ContactGeom& g, State& s, Real dt, int /*dim*/, Real& fn,
                    ContactWork* w = nullptr) {
    if (g.gap >= 0) {
      fn = 0;
      s.fs.setZero();  // |Fs| <= mu Fn ~ delta^(3/2) and kt ~ delta^(1/2): nothing left to lose
      if constexpr (kEnergy) *w = ContactWork{};
      return Vec3::Zero();
    }
    Real es, gs;
    moduli(p, g.rB <= 0, es, gs);
    const Real delta = -g.gap;
    const Real a = std::sqrt(reduced_radius(g.rA, g.rB) * delta);  // contact radius
    fn = 4.0 / 3.0 * es * a * delta;
    const Real kt = 8 * gs * a;
    rotate_into_plane(s.fs, g, dt);
    Vec3 f0;
    if constexpr (kEnergy) f0 = s.fs;
    s.fs -= kt * g.d_delta_s;
    const Real limit = p.fric * fn;
    const Real fs2 = s.fs.squaredNorm();
    if (fs2 > limit * limit) s.fs *= limit / std::sqrt(fs2);
    if constexpr (kEnergy) shear_work(f0, s.fs, kt, g.d_delta_s, *w);
    return fn * g.n + s.fs;
  }
};

}  // namespace ff::dem
