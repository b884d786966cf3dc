// Linear contact with Coulomb friction, PFC 5/6 "linear" model with the deformability method
// (Itasca PFC documentation, linear model; METHODS.md 1.3). Also the frictional contact that
// takes over after a parallel bond breaks (Potyondy & Cundall 2004).
// Units: emod [Pa], kratio [-], fric [-]. No tension; dashpots off (as P&C 2004).
#pragma once
#include <algorithm>
#include <string_view>

#include "dem/contact/contact_geometry.hpp"

namespace ff::dem {

struct LinearContact {
  static constexpr std::string_view name = "linear";
  struct Params {
    Real emod = 1e9;  // effective modulus E* [Pa]
    Real kratio = 1;  // kn / ks [-]
    Real fric = 0.5;  // Coulomb friction coefficient [-]
  };
  using State = ContactState;
  // kn = A E*/L, A = pi r^2 (3D) or 2 r t (2D, t = 1 m), r = min(RA, RB), L = RA + RB;
  // against a wall (rB = 0): r = L = RA.
  static Real normal_stiffness(const Params& p, Real rA, Real rB, int dim) {
    const Real r = rB > 0 ? std::min(rA, rB) : rA;
    const Real L = rB > 0 ? rA + rB : rA;
    const Real A = dim == 3 ? kPi * r * r : 2.0 * r;
    return A * p.emod / L;
  }
  // Force on B. `fn` returns the compressive normal force magnitude [N].
  static Vec3 force(const Params& p, const ContactGeom& g, State& s, Real dt, int dim, Real& fn) {
    const Real kn = normal_stiffness(p, g.rA, g.rB, dim);
    const Real ks = kn / p.kratio;
    fn = g.gap < 0 ? -kn * g.gap : 0.0;
    if (fn == 0) {  // separated: the contact forgets its shear force
      s.fs.setZero();
      return Vec3::Zero();
    }
    rotate_into_plane(s.fs, g, dt);
    s.fs -= ks * g.d_delta_s;
    const Real limit = p.fric * fn;
    const Real fs2 = s.fs.squaredNorm();
    if (fs2 > limit * limit) s.fs *= limit / std::sqrt(fs2);  // slip
    return fn * g.n + s.fs;
  }
};

}  // namespace ff::dem
