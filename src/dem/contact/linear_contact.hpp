// Linear contact with Coulomb friction, PFC 5/6 "linear" model with the deformability method
// (Itasca PFC documentation, linear model; METHODS.md 1.3). Also the frictional contact that
// takes over after a parallel bond breaks (Potyondy & Cundall 2004).
// Units: emod [Pa], kratio [-], fric [-]. No tension; dashpots off (as P&C 2004).
#pragma once
#include <algorithm>
#include <string>
#include <string_view>

#include "dem/contact/contact_geometry.hpp"
#include "io/params.hpp"

namespace ff::dem {

struct LinearContact {
  static constexpr std::string_view name = "linear";
  struct Params {
    Real emod = 1e9;  // effective modulus E* [Pa]
    Real kratio = 1;  // kn / ks [-]
    Real fric = 0.5;  // Coulomb friction coefficient [-]
  };
  using State = ContactState;
  // Its keys (the friction, dem.contact.*.friction, is common to every contact law).
  static void declare(ParamTable& t) {
    t.real("dem.contact.*.emod", 1e9, "Pa", "linear contact effective modulus E* (kn = A E*/L)").positive();
    t.real("dem.contact.*.kratio", 1.0, "-", "linear contact normal-to-shear stiffness ratio kn/ks").positive();
  }
  static Params read(const Config& cfg, const std::string& table) {
    return {cfg.real(table + ".emod"), cfg.real(table + ".kratio"), cfg.real(table + ".friction")};
  }
  static Params elastic(Real E, Real /*nu*/) { return {E, 1.0, 0.0}; }
  // kn = A E*/L, A = pi r^2 (3D) or 2 r t (2D, t = 1 m), r = min(RA, RB), L = RA + RB;
  // against a wall (rB = 0): r = L = RA.
  static Real normal_stiffness(const Params& p, Real rA, Real rB, int dim) {
    const Real r = rB > 0 ? std::min(rA, rB) : rA;
    const Real L = rB > 0 ? rA + rB : rA;
    const Real A = dim == 3 ? kPi * r * r : 2.0 * r;
    return A * p.emod / L;
  }
  static Real normal_stiffness_at(const Params& p, Real rA, Real rB, Real /*overlap*/, int dim) {
    return normal_stiffness(p, rA, rB, dim);
  }
  // The stiffer of the two springs: kratio < 1 makes ks = kn / kratio the larger one.
  static Real time_step_stiffness(const Params& p, Real rA, Real rB, Real /*overlap*/, int dim) {
    return normal_stiffness(p, rA, rB, dim) * std::max(Real(1), 1 / p.kratio);
  }
  static Real normal_force(const Params& p, Real rA, Real rB, Real overlap, int dim) {
    return normal_stiffness(p, rA, rB, dim) * overlap;
  }
  // 1/2 kn delta^2 + 1/2 |Fs|^2 / ks (PFC linear model, strain energy of the springs).
  static Real normal_energy(const Params& p, Real rA, Real rB, Real overlap, int dim) {
    return 0.5 * normal_stiffness(p, rA, rB, dim) * overlap * overlap;
  }
  static Real strain_energy(const Params& p, Real rA, Real rB, Real overlap, const State& s, int dim) {
    const Real kn = normal_stiffness(p, rA, rB, dim);
    const Real ks = kn / p.kratio;
    return 0.5 * kn * overlap * overlap + 0.5 * s.fs.squaredNorm() / ks;
  }
  // Force on B. `fn` returns the compressive normal force magnitude [N].
  // With kEnergy, `w` receives the shear spring's work and the slip dissipation (shear_work()).
  template <bool kEnergy = false>
  [[gnu::always_inline]] static Vec3 force(const Params& p, const ContactGeom& g, State& s, Real dt, int dim, Real& fn,
                    ContactWork* w = nullptr) {
    const Real kn = normal_stiffness(p, g.rA, g.rB, dim);
    const Real ks = kn / p.kratio;
    fn = g.gap < 0 ? -kn * g.gap : 0.0;
    if (fn == 0) {  // separated: the contact forgets its shear force
      if constexpr (kEnergy) {  // what the spring held is lost with it
        w->shear = -0.5 * s.fs.squaredNorm() / ks;
        w->slip = -w->shear;
      }
      s.fs.setZero();
      return Vec3::Zero();
    }
    rotate_into_plane(s.fs, g, dt);
    Vec3 f0;
    if constexpr (kEnergy) f0 = s.fs;
    s.fs -= ks * g.d_delta_s;
    const Real limit = p.fric * fn;
    const Real fs2 = s.fs.squaredNorm();
    if (fs2 > limit * limit) s.fs *= limit / std::sqrt(fs2);  // slip
    if constexpr (kEnergy) shear_work(f0, s.fs, ks, g.d_delta_s, *w);
    return fn * g.n + s.fs;
  }
};

}  // namespace ff::dem
