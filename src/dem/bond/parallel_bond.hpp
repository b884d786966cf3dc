// Parallel bond after Potyondy & Cundall (2004), Int. J. Rock Mech. Min. Sci. 41:1329-1364,
// in PFC 5/6 `linearpbond` form (METHODS.md 1.4). Fn > 0 is tension.
// Units: emod [Pa], strengths [Pa], stiffnesses kn, ks [Pa/m] (stress per length).
// The bond is stress-free when installed; it breaks in tension when the peripheral normal
// stress reaches `ten`, or in shear when the peripheral shear stress reaches coh - sigma tan(fa).
// After failure it carries nothing; the linear contact (always present) takes over.
#pragma once
#include <algorithm>
#include <cmath>
#include <string_view>

#include "dem/bond/bond_load.hpp"
#include "dem/contact/contact_geometry.hpp"

namespace ff::dem {

struct ParallelBond {
  static constexpr std::string_view name = "parallel";
  struct Material {
    Real emod = 1e9;       // bond effective modulus [Pa]
    Real kratio = 1;       // kn/ks [-]
    Real ten = 1e7;        // tensile strength [Pa]
    Real coh = 1e7;        // cohesion [Pa]
    Real fa_deg = 0;       // friction angle [deg]
    Real lambda = 1;       // radius multiplier [-]
    Real beta = 1;         // moment-contribution factor [-]
  };
  struct State {
    Real R = 0, A = 0, I = 0, J = 0;  // bond radius and section properties
    Real kn = 0, ks = 0;              // [Pa/m]
    Real Fn = 0, Mt = 0;              // normal force (tension > 0) [N], twisting moment [N m]
    Vec3 Fs = Vec3::Zero(), Mb = Vec3::Zero();
    Real sigma = 0, tau = 0;          // peripheral stresses at the last evaluation [Pa]
    Real tan_fa = 0;                  // tan(friction angle), cached at installation
    Real inv_A = 0, R_over_I = 0, R_over_J = 0;  // cached so the hot loop multiplies instead of dividing
  };

  // Section: R = lambda min(RA, RB); 3D A = pi R^2, I = pi R^4/4, J = pi R^4/2;
  // 2D (thickness t = 1): A = 2 R, I = 2/3 R^3, J unused. kn = E/L with L = RA + RB.
  static State install(const Material& m, Real rA, Real rB, int dim) {
    State s;
    s.R = m.lambda * std::min(rA, rB);
    if (dim == 3) {
      s.A = kPi * s.R * s.R;
      s.I = 0.25 * kPi * s.R * s.R * s.R * s.R;
      s.J = 2 * s.I;
    } else {
      s.A = 2 * s.R;
      s.I = 2.0 / 3.0 * s.R * s.R * s.R;
      s.J = 0;
    }
    s.kn = m.emod / (rA + rB);
    s.ks = s.kn / m.kratio;
    s.tan_fa = std::tan(m.fa_deg * kPi / 180.0);
    s.inv_A = 1.0 / s.A;
    s.R_over_I = s.R / s.I;
    s.R_over_J = s.J > 0 ? s.R / s.J : 0.0;
    return s;
  }
  // Translational and rotational stiffness the bond adds to each end (time-step estimate).
  static Real translational_stiffness(const State& s) { return std::max(s.kn, s.ks) * s.A; }
  static Real rotational_stiffness(const State& s) { return std::max(s.kn * s.I, s.ks * s.J); }

  static BondFailure compute(const Material& m, State& s, const ContactGeom& g, Real dt, int dim, BondLoad& out) {
    // Stored shear force and bending moment follow the contact plane.
    rotate_into_plane(s.Fs, g, dt);
    rotate_into_plane(s.Mb, g, dt);
    const Real dtheta_t = g.d_theta.dot(g.n);
    const Vec3 dtheta_b = g.d_theta - dtheta_t * g.n;
    s.Fn += s.kn * s.A * g.d_delta_n;
    s.Fs -= s.ks * s.A * g.d_delta_s;
    s.Mb -= s.kn * s.I * dtheta_b;
    if (dim == 3) s.Mt -= s.ks * s.J * dtheta_t;
    // Peripheral stresses (P&C 2004 Eq. 6-7 with the moment-contribution factor).
    const Real mb = s.Mb.norm();
    const Real normal_stress = s.Fn * s.inv_A;
    s.sigma = normal_stress + m.beta * mb * s.R_over_I;
    s.tau = s.Fs.norm() * s.inv_A + m.beta * std::abs(s.Mt) * s.R_over_J;  // Mt = 0 in 2D
    BondFailure fail = BondFailure::None;
    if (s.sigma >= m.ten) {
      fail = BondFailure::Tensile;
    } else {
      const Real tau_c = m.coh - normal_stress * s.tan_fa;
      if (s.tau >= tau_c) fail = BondFailure::Shear;
    }
    // Force on B: tension pulls B back along -n; shear force acts on B as stored.
    out.force_on_B = -s.Fn * g.n + s.Fs;
    // Moments about each centre: the couples plus the lever arm of the force at the
    // contact point (x_c - x_A = (RA + gap/2) n, x_c - x_B = -(RB + gap/2) n).
    const Vec3 mom = s.Mt * g.n + s.Mb;
    const Vec3 n_x_f = g.n.cross(out.force_on_B);
    out.moment_on_B = mom - (g.rB + 0.5 * g.gap) * n_x_f;
    out.moment_on_A = -mom - (g.rA + 0.5 * g.gap) * n_x_f;
    return fail;
  }
};

}  // namespace ff::dem
