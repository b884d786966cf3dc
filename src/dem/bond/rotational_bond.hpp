// Six-DOF rotational bond, registry name "rotational": one normal, two shear, one twist and two
// bending springs between two rigid particles, with brittle failure. METHODS.md 1.8.
//
// Sources: Wang, Abe, Latham & Mora (2006) Pure Appl. Geophys. 163:1769 (the six relative motions
// and their springs); Wang (2009) Acta Geotech. 4:117 (total formulation in particle A's body
// frame, relative rotation split into twist and bending with quaternions); ESyS-Particle
// Model/ARotBondedInteraction.cpp and RotBondedInteraction.cpp (stiffness and strength from E, nu,
// c, phi; the "RotBond" failure criterion). Written from the equations, not from that code.
//
// Conventions (the engine must follow them):
//  * A unit quaternion q maps body to world: v_world = q v_body. The engine integrates the
//    orientation of EVERY particle that carries a rotational bond (METHODS 1.1) and keeps it
//    normalised; the bond reads only positions, orientations and radii (total formulation, no
//    history besides State), so restarts need only State.
//  * The bond is not symmetric in A and B (A's frame is the reference), but the loads agree to
//    first order when the ends are swapped. Orient bonds by global id (A = lower id) so every rank
//    computes the same numbers.
//  * Fn > 0 is tension. force_on_B pulls B back towards A in tension; -force_on_B acts on A.
//    Moments are about each particle's own centre and already contain the moment of the force.
//  * Cross-section: beam radius R = L0/2 (ESyS "mean radius" scaling; equals (rA+rB)/2 for
//    touching particles), A = pi R^2, I = pi R^4/4, J = pi R^4/2, length L0 = initial centre
//    distance. dim == 2 (disks 1 m thick) uses a 2R x 1 m rectangle, A = 2R, I = 2R^3/3, as the
//    parallel bond; with in-plane positions and z-only rotations twist and out-of-plane terms vanish.
//  * Bending moment = kb * theta with kb = E I / L0, i.e. an Euler-Bernoulli segment, so that
//    Mb/Mb0 is the peak bending stress over the tensile strength c/tan(phi). ESyS applies
//    kb*theta/2 (LAMMPS bpm/rotational applies kb*theta); for the same E our bonds are twice as
//    stiff in bending as ESyS's and break at half the bending angle.
//  * Rest length r0 = L0 (ESyS uses rA + rB), so an installed bond carries no load even with a gap.
#pragma once
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>

#include "core/error.hpp"
#include "core/types.hpp"
#include "dem/bond/bond_load.hpp"
#include "dem/particle_store.hpp"
#include "io/checkpoint.hpp"
#include "io/params.hpp"

namespace ff::dem {

// The two particles of a bond at the current step (positions, orientations, radii).
struct BondEnds {
  Vec3 xA, xB;
  Quat qA, qB;
  Real rA, rB;
};


struct RotationalBond {
  static constexpr std::string_view name = "rotational";
  static constexpr std::string_view checkpoint_key = "dem.rbond";  // its states in a checkpoint
  static constexpr bool installs_bonds = true;

  struct Material {               // per group pair, from the scenario
    Real youngs_modulus;          // E [Pa]: kr = E A/L0, kb = E I/L0
    Real poisson_ratio;           // nu [-]: G = E/(2(1+nu)), ks = G A/L0, kt = G J/L0
    Real cohesion;                // c [Pa]
    Real friction_angle_deg;      // phi [deg], 0 < phi < 90
    Real beta1 = 1, beta2 = 1;    // moment weights in the failure criterion [-]
    Real truncation = 1;          // t [-]: tension cut-off, 0 < t <= 1
    int dim = 3;                  // 2 or 3; only validated: the same code and section serve both
  };

  struct State {                  // per bond, set by install(), updated by compute()
    Real kr, ks, kt, kb;          // [N/m, N/m, N m/rad, N m/rad]
    Real Fn0, Fs0, Mt0, Mb0;      // [N, N, N m, N m]
    Real r0;                      // rest length = initial centre distance L0 [m]
    Vec3 D0;                      // initial bond vector xB - xA in A's body frame [m]
    Quat q0;                      // initial relative rotation qA^-1 qB
    Real Fn = 0, Fs = 0, Mt = 0, Mb = 0;  // last magnitudes; Fn signed, > 0 tension
  };

  // Throws InputError naming the bad parameter; install() calls it, a scenario reader may too.
  static void check(const Material& m);
  static State install(const Material& m, const BondEnds& e);
  // Fills `out` with the load for the current ends and returns the failure mode (None if intact).
  // Needs |xB - xA| > 0. No allocation; one select and the final criterion are the only branches.
  static BondFailure compute(const Material& m, State& s, const BondEnds& e, BondLoad& out);
  // Elastic energy stored in the bond at the last compute() [J], e.g. the energy a crack releases.
  static Real energy(const State& s) {
    return 0.5 * (s.Fn * s.Fn / s.kr + s.Fs * s.Fs / s.ks + s.Mt * s.Mt / s.kt + s.Mb * s.Mb / s.kb);
  }

  // ---- Registry interface (laws.hpp) ----
  using Prepared = Material;
  // Its keys; dem.bond.*.cohesion and dem.bond.*.friction_angle are common to the bond laws.
  static void declare(ParamTable& t) {
    t.real("dem.bond.*.youngs_modulus", 1e9, "Pa", "rotational bond Young's modulus E (beam of radius L0/2)").positive();
    t.real("dem.bond.*.poisson_ratio", 0.25, "-", "rotational bond Poisson ratio").range(0, 0.5).below(0.5);
    t.real("dem.bond.*.beta1", 1.0, "-", "rotational bond: weight of bending in the tensile criterion").non_negative();
    t.real("dem.bond.*.beta2", 1.0, "-", "rotational bond: weight of twisting in the shear criterion").non_negative();
    t.real("dem.bond.*.truncation", 1.0, "-", "rotational bond: tension cut-off t of the criterion").positive().at_most(1);
  }
  static Material read(const Config& cfg, const std::string& bt, int dim) {
    Material rb;
    rb.youngs_modulus = cfg.real(bt + ".youngs_modulus");
    rb.poisson_ratio = cfg.real(bt + ".poisson_ratio");
    rb.cohesion = cfg.real(bt + ".cohesion");
    rb.friction_angle_deg = cfg.real(bt + ".friction_angle");
    rb.beta1 = cfg.real(bt + ".beta1");
    rb.beta2 = cfg.real(bt + ".beta2");
    rb.truncation = cfg.real(bt + ".truncation");
    rb.dim = dim;
    if (rb.friction_angle_deg <= 0)
      cfg.fail(bt + ".friction_angle", "the rotational bond needs a friction angle > 0 (its tensile strength is c/tan(phi))");
    return rb;
  }
  // Elastic bond of cohesion `strength` (particle membrane), friction angle 45 deg.
  static Material elastic(Real E, Real nu, Real strength) {
    Material rb{E, nu, strength, 45.0};
    rb.dim = 3;
    return rb;
  }
  static Prepared prepare(const Material& m) { return m; }
  [[gnu::always_inline]] static BondFailure compute_bond(const Prepared& m, State& st, const ParticleStore& P, Index i, Index j, Real /*dt*/,
                                  int /*dim*/, BondLoad& load) {
    const BondEnds e{P.pos[i], P.pos[j], P.orient[i], P.orient[j], P.radius[i], P.radius[j]};
    return compute(m, st, e, load);
  }
  static void time_step_stiffness(const Material&, const State& s, Real, Real, int, Real& k, Real& krot) {
    k = std::max(s.kr, s.ks);
    krot = std::max(s.kt, s.kb);
  }
  static Real crack_size(const Material&, Real rA, Real rB, int) { return 0.5 * (rA + rB); }
  static Real energy(const Material&, const State& s, Real, Real, int) { return energy(s); }

  // Bond vector r = qA^-1 (xB - xA), its length L and the relative rotation p = qA^-1 qB, all in
  // A's body frame. Deliberately not inlined: install() and compute() must run the same machine
  // code, so that an unmoved bond gives bit-identical r, L, p (two inlined copies may be
  // FMA-contracted differently under -march=native and round differently).
  struct Kinematics {
    Vec3 r;
    Real L;
    Quat p;
  };
  [[gnu::noinline]] static Kinematics kinematics(const BondEnds& e) {
    const Quat qAc = e.qA.conjugate();
    Kinematics k;
    k.r = qAc * (e.xB - e.xA);
    k.L = k.r.norm();
    k.p = qAc * e.qB;
    return k;
  }
};

// ---------------------------------------------------------------------------------------------

inline void RotationalBond::check(const Material& m) {
  auto bad = [](std::string_view key, Real v, std::string_view allowed) {
    throw InputError(fmt::format("rotational bond: {} = {} is invalid; use {}", key, v, allowed));
  };
  if (!(m.youngs_modulus > 0)) bad("youngs_modulus", m.youngs_modulus, "a value > 0 [Pa]");
  if (!(m.poisson_ratio > -1 && m.poisson_ratio <= 0.5))
    bad("poisson_ratio", m.poisson_ratio, "a value in (-1, 0.5]");
  if (!(m.cohesion > 0)) bad("cohesion", m.cohesion, "a value > 0 [Pa]");
  if (!(m.friction_angle_deg > 0 && m.friction_angle_deg < 90))
    bad("friction_angle", m.friction_angle_deg, "a value in (0, 90) degrees (the tensile strength is c/tan(phi))");
  if (!(m.beta1 >= 0)) bad("beta1", m.beta1, "a value >= 0");
  if (!(m.beta2 >= 0)) bad("beta2", m.beta2, "a value >= 0");
  // With t > 1 the envelope S <= 1 - N already breaks every bond with N > 1, so t would be ignored.
  if (!(m.truncation > 0 && m.truncation <= 1)) bad("truncation", m.truncation, "a value in (0, 1]");
  if (m.dim != 2 && m.dim != 3) bad("dim", m.dim, "2 or 3");
}

inline RotationalBond::State RotationalBond::install(const Material& m, const BondEnds& e) {
  check(m);
  State s{};
  const Kinematics k = kinematics(e);
  s.D0 = k.r;
  s.r0 = k.L;
  s.q0 = k.p;
  if (!(s.r0 > 0))
    throw InputError("rotational bond: the two particles have the same centre; remove duplicate particles");

  // ESyS brittle-beam scaling (METHODS 1.8): beam of radius R = L0/2 and length L0. In 2D the
  // disks are 1 m thick (as everywhere in fracflow's 2D), so the beam is a 2R x 1 m rectangle
  // (A = 2R, I = 2R^3/3, the same section as the parallel bond's 2D form); J only enters
  // through twist, which vanishes in the plane.
  const Real R = 0.5 * s.r0;
  const bool planar = m.dim == 2;
  const Real area = planar ? 2 * R : kPi * R * R;
  const Real I = planar ? 2.0 / 3.0 * R * R * R : 0.25 * kPi * R * R * R * R;
  const Real J = 2 * I;
  const Real E = m.youngs_modulus, G = E / (2 * (1 + m.poisson_ratio));
  s.kr = E * area / s.r0;
  s.ks = G * area / s.r0;
  s.kb = E * I / s.r0;
  s.kt = G * J / s.r0;
  // Strengths: cohesion c is the shear strength, c/tan(phi) the tensile strength; moments give
  // those peak stresses at the rim (Mb0 = sigma_t I/R, Mt0 = c J/R).
  const Real c = m.cohesion, tan_phi = std::tan(m.friction_angle_deg * kPi / 180);
  s.Fn0 = area * c / tan_phi;
  s.Fs0 = area * c;
  s.Mb0 = I * c / (R * tan_phi);
  s.Mt0 = J * c / R;
  return s;
}

inline BondFailure RotationalBond::compute(const Material& m, State& s, const BondEnds& e, BondLoad& out) {
  const Kinematics k = kinematics(e);
  const Vec3& r = k.r;
  const Real L = k.L;
  const Vec3 n = r / L;

  // Rotation of B relative to A since install, in A's body frame: Delta = (qA^-1 qB) q0^-1.
  // (The brief's q0^-1 (qA^-1 qB) is the same rotation with its axis in B's frame.) Writing
  // qA^-1 qB = q0 + dq gives Delta = 1 + dq q0^-1, whose vector part is exactly zero when nothing
  // moved, whatever the rounding of q0 q0^-1.
  const Quat& p = k.p;
  const Real dw = p.w() - s.q0.w();
  const Vec3 dv = p.vec() - s.q0.vec();
  Vec3 v = s.q0.w() * dv - dw * s.q0.vec() - dv.cross(s.q0.vec());
  Real w = p.coeffs().dot(s.q0.coeffs());
  const Real sgn = std::copysign(Real(1), w);  // shortest rotation: angles in [-pi, pi]
  v *= sgn;
  w *= sgn;

  // Swing-twist split about the current bond axis n (Wang 2009): twist psi about n, bending by
  // theta about an axis normal to n. We take that axis along the in-plane part of
  // Delta's vector, i.e. in the frame halfway through the twist; Wang's "swing after twist"
  // axis differs from it by psi/2 about n, a second-order difference that keeps A and B symmetric.
  const Real vn = v.dot(n);
  const Vec3 v_perp = v - vn * n;
  const Real sb = v_perp.norm(), cb = std::sqrt(w * w + vn * vn);
  const Real theta = 2 * std::atan2(sb, cb);
  const Real psi = 2 * std::atan2(vn, w);
  const Vec3 bend = (sb > 0 ? theta / sb : 2 / cb) * v_perp;  // bending rotation vector, |bend| = theta

  // Shear: relative displacement of the two material points that sat at the contact point
  // x_c = xA + lamA (xB - xA) at install, lamA = rA/(rA + rB). A's point stays at lamA D0 in
  // A's frame; B's point is at r - lamB Delta(D0). So u = (r - D0) - lamB (Delta(D0) - D0),
  // which to first order is Wang's two shear terms: k_s r0 gamma from the rotation gamma of the
  // bond vector away from D0, plus k_s r0 theta/2 from the relative rotation (our lamB = 1/2 for
  // equal radii). Wang's arc r0 gamma becomes our chord: equal to first order.
  // Using the same lamA as lever arm for the moments below makes the bond work-conjugate: its
  // tangent stiffness is symmetric, and rigid motions give no load.
  const Real lamA = e.rA / (e.rA + e.rB), lamB = 1 - lamA;
  const Vec3 vxD = v.cross(s.D0);
  const Vec3 rotD0 = 2 * (w * vxD + v.cross(vxD));  // Delta(D0) - D0 for the unit quaternion (w, v)
  const Vec3 u = (r - s.D0) - lamB * rotD0;
  const Vec3 us = u - u.dot(n) * n;

  s.Fn = s.kr * (L - s.r0);                            // tension > 0
  s.Fs = s.ks * us.norm();
  s.Mt = s.kt * std::abs(psi);
  s.Mb = s.kb * theta;
  const Vec3 force_B = -s.Fn * n - s.ks * us;          // on B, A's frame
  const Vec3 couple_A = s.kt * psi * n + s.kb * bend;  // restores B's relative rotation; -couple_A on B

  // Back to the world frame. The force acts at x_c on the current line of centres, so
  // M_A + M_B + (xB - xA) x F_B = 0 up to rounding (angular momentum is conserved).
  out.force_on_B = e.qA * force_B;
  const Vec3 couple = e.qA * couple_A;
  const Vec3 dxF = (e.xB - e.xA).cross(out.force_on_B);
  out.moment_on_A = couple - lamA * dxF;
  out.moment_on_B = -couple - lamB * dxF;

  // ESyS RotBond criterion ("direct Mohr-Coulomb"): N uses the signed Fn, so compression
  // raises the shear capacity 1 - N; there is no compressive failure.
  const Real N = s.Fn / s.Fn0 + m.beta1 * s.Mb / s.Mb0;
  const Real S = s.Fs / s.Fs0 + m.beta2 * s.Mt / s.Mt0;
  if (N > m.truncation) return BondFailure::Tensile;
  if (S > 1 - N) return BondFailure::Shear;
  return BondFailure::None;
}

}  // namespace ff::dem

namespace ff {
template <> struct is_checkpoint_pod<dem::RotationalBond::State> : std::true_type {};
}  // namespace ff
