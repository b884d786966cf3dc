// Parallel bond after Potyondy & Cundall (2004), Int. J. Rock Mech. Min. Sci. 41:1329-1364,
// in PFC 5/6 `linearpbond` form (METHODS.md 1.4). Fn > 0 is tension.
// Units: emod [Pa], strengths [Pa], stiffnesses kn, ks [Pa/m] (stress per length).
// The bond is stress-free when installed; it breaks in tension when the peripheral normal
// stress reaches `ten`, or in shear when the peripheral shear stress reaches coh - sigma tan(fa).
// After failure it carries nothing; the linear contact (always present) takes over.
//
// Speed: the bond stage is limited by memory traffic, not arithmetic, so each bond stores only
// what evolves (Fn, Mt, Fs, Mb: 64 bytes). The section (R, A, I, J, kn, ks) follows from the
// material and the two radii and is recomputed in registers every step.
#pragma once
#include <algorithm>
#include <cmath>
#include <string>
#include <string_view>

#include "dem/bond/bond_load.hpp"
#include "dem/contact/contact_geometry.hpp"
#include "dem/particle_store.hpp"
#include "io/checkpoint.hpp"
#include "io/params.hpp"

namespace ff::dem {

struct BondEnds;

struct ParallelBond {
  static constexpr std::string_view name = "parallel";
  static constexpr std::string_view checkpoint_key = "dem.pbond";  // its states in a checkpoint
  static constexpr bool installs_bonds = true;
  struct Material {
    Real emod = 1e9;       // bond effective modulus [Pa]
    Real kratio = 1;       // kn/ks [-]
    Real ten = 1e7;        // tensile strength [Pa]
    Real coh = 1e7;        // cohesion [Pa]
    Real fa_deg = 0;       // friction angle [deg]
    Real lambda = 1;       // radius multiplier [-]
    Real beta = 1;         // moment-contribution factor [-]
  };
  // Material in the form the hot loop uses (no tan, no division); see coeffs().
  struct Coeffs {
    Real emod, inv_kratio, ten, coh, tan_fa, lambda, beta;
  };
  static Coeffs coeffs(const Material& m) {
    return {m.emod, 1.0 / m.kratio, m.ten, m.coh, std::tan(m.fa_deg * kPi / 180.0), m.lambda, m.beta};
  }
  // Geometry and stiffness of one bond, and the ratios the peripheral stresses use.
  struct Section {
    Real R, A, I, J;                 // bond radius [m], area [m^2], moments of inertia [m^4]
    Real kn, ks;                     // [Pa/m]
    Real inv_A, R_over_I, R_over_J;  // 1/A, R/I, R/J (0 in 2D)
  };
  // What a bond carries between steps.
  struct State {
    Real Fn = 0, Mt = 0;  // normal force (tension > 0) [N], twisting moment [N m]
    Vec3 Fs = Vec3::Zero(), Mb = Vec3::Zero();
  };
  struct Stress {
    Real sigma, tau;  // peripheral normal and shear stress [Pa]
  };

  // Section: R = lambda min(RA, RB); 3D A = pi R^2, I = pi R^4/4, J = pi R^4/2;
  // 2D (thickness t = 1): A = 2 R, I = 2/3 R^3, J unused (0). kn = E/L with L = RA + RB.
  // One division (the divide/sqrt unit bounds the bond loop): q = 1/(A R L) gives 1/L, 1/A and
  // R/I = cI/(A R), R/J = 2/(A R), where cI = 4 in 3D (I = A R^2/4) and 3 in 2D (A = 2R).
  static Section section(const Coeffs& c, Real rA, Real rB, int dim) {
    Section s;
    const Real L = rA + rB;
    s.R = c.lambda * std::min(rA, rB);
    s.A = dim == 3 ? kPi * s.R * s.R : 2 * s.R;
    const Real q = 1.0 / (s.A * s.R * L);
    s.inv_A = q * s.R * L;
    const Real inv_AR = q * L;
    s.I = dim == 3 ? 0.25 * s.A * s.R * s.R : 2.0 / 3.0 * s.R * s.R * s.R;
    s.J = dim == 3 ? 2 * s.I : 0.0;
    s.R_over_I = (dim == 3 ? 4.0 : 3.0) * inv_AR;
    s.R_over_J = dim == 3 ? 2.0 * inv_AR : 0.0;
    s.kn = c.emod * (q * s.A * s.R);
    s.ks = s.kn * c.inv_kratio;
    return s;
  }
  static Section section(const Material& m, Real rA, Real rB, int dim) { return section(coeffs(m), rA, rB, dim); }
  static State install() { return State{}; }  // stress-free when installed

  // ---- Registry interface (laws.hpp) ----
  using Prepared = Coeffs;
  // Its keys; dem.bond.*.cohesion and dem.bond.*.friction_angle are common to the bond laws.
  static void declare(ParamTable& t) {
    t.real("dem.bond.*.emod", 1e9, "Pa", "parallel bond effective modulus (kn_bar = E_bar/L)").positive();
    t.real("dem.bond.*.kratio", 1.0, "-", "parallel bond normal-to-shear stiffness ratio").positive();
    t.real("dem.bond.*.tensile_strength", 10e6, "Pa", "parallel bond tensile strength").positive();
    t.real("dem.bond.*.radius_multiplier", 1.0, "-", "parallel bond radius multiplier lambda_bar").positive();
    t.real("dem.bond.*.moment_factor", 1.0, "-", "parallel bond moment-contribution factor beta_bar").range(0, 1);
  }
  static Material read(const Config& cfg, const std::string& bt, int /*dim*/) {
    Material pb;
    pb.emod = cfg.real(bt + ".emod");
    pb.kratio = cfg.real(bt + ".kratio");
    pb.ten = cfg.real(bt + ".tensile_strength");
    pb.coh = cfg.real(bt + ".cohesion");
    pb.fa_deg = cfg.real(bt + ".friction_angle");
    pb.lambda = cfg.real(bt + ".radius_multiplier");
    pb.beta = cfg.real(bt + ".moment_factor");
    return pb;
  }
  // Soft elastic bond of strength `strength` (particle membrane).
  static Material elastic(Real E, Real /*nu*/, Real strength) {
    Material pb;
    pb.emod = E;
    pb.kratio = 1;
    pb.ten = pb.coh = strength;
    pb.fa_deg = 0;
    return pb;
  }
  static Prepared prepare(const Material& m) { return coeffs(m); }
  static State install(const Material&, const BondEnds&) { return install(); }
  [[gnu::always_inline]] static BondFailure compute_bond(const Prepared& c, State& st, const ParticleStore& P, Index i, Index j, Real dt,
                                  int dim, BondLoad& load) {
    ContactGeom g;
    sphere_sphere(g, P.pos[i], P.radius[i], P.pos[j], P.radius[j]);
    contact_kinematics(g, P.pos[i], P.vel[i], P.omega[i], P.pos[j], P.vel[j], P.omega[j], dt);
    return compute(c, st, g, dt, dim, load);
  }
  static void time_step_stiffness(const Material& m, const State&, Real rA, Real rB, int dim, Real& k, Real& krot) {
    const auto sec = section(m, rA, rB, dim);
    k = translational_stiffness(sec);
    krot = rotational_stiffness(sec);
  }
  static Real crack_size(const Material& m, Real rA, Real rB, int dim) { return section(m, rA, rB, dim).R; }
  // Energy of the four springs: Fn^2/(2 kn A) + |Fs|^2/(2 ks A) + |Mb|^2/(2 kn I) + Mt^2/(2 ks J)
  // (Potyondy & Cundall 2004, strain energy of the parallel bond; PFC's "bond strain energy").
  static Real energy(const Material& m, const State& s, Real rA, Real rB, int dim) {
    const auto c = section(m, rA, rB, dim);
    return 0.5 * s.Fn * s.Fn / (c.kn * c.A) + 0.5 * s.Fs.squaredNorm() / (c.ks * c.A) +
           0.5 * s.Mb.squaredNorm() / (c.kn * c.I) + (c.J > 0 ? 0.5 * s.Mt * s.Mt / (c.ks * c.J) : 0.0);
  }

  // Translational and rotational stiffness the bond adds to each end (time-step estimate).
  static Real translational_stiffness(const Section& s) { return std::max(s.kn, s.ks) * s.A; }
  static Real rotational_stiffness(const Section& s) { return std::max(s.kn * s.I, s.ks * s.J); }

  // Peripheral stresses (P&C 2004 Eq. 6-7 with the moment-contribution factor); Mt = 0 in 2D.
  static Stress stress(const Coeffs& c, const Section& sec, const State& s) {
    return {s.Fn * sec.inv_A + c.beta * s.Mb.norm() * sec.R_over_I,
            s.Fs.norm() * sec.inv_A + c.beta * std::abs(s.Mt) * sec.R_over_J};
  }

  // One step: update the stored loads from the increments in g, check failure, and return the
  // loads on both ends. Failure is judged on the loads after this step's increment.
  [[gnu::always_inline]] static BondFailure compute(const Coeffs& c, State& s, const ContactGeom& g, Real dt, int dim, BondLoad& out,
                             Stress* stress_out = nullptr) {
    const Section sec = section(c, g.rA, g.rB, dim);
    // Stored shear force and bending moment follow the contact plane.
    rotate_into_plane(s.Fs, g, dt);
    rotate_into_plane(s.Mb, g, dt);
    const Real dtheta_t = g.d_theta.dot(g.n);
    const Vec3 dtheta_b = g.d_theta - dtheta_t * g.n;
    s.Fn += sec.kn * sec.A * g.d_delta_n;
    s.Fs -= sec.ks * sec.A * g.d_delta_s;
    s.Mb -= sec.kn * sec.I * dtheta_b;
    if (dim == 3) s.Mt -= sec.ks * sec.J * dtheta_t;
    // Failure (P&C 2004 Eq. 6-7): sigma = Fn/A + beta |Mb| R/I >= ten, else
    // tau = |Fs|/A + beta |Mt| R/J >= coh - (Fn/A) tan(fa). Compared on squares, no sqrt.
    const Real normal_stress = s.Fn * sec.inv_A;
    const Real bend_room = c.ten - normal_stress;  // what the bending term may add before failure
    const Real bend_k = c.beta * sec.R_over_I;
    BondFailure fail = BondFailure::None;
    if (bend_room <= 0 || bend_k * bend_k * s.Mb.squaredNorm() >= bend_room * bend_room) {
      fail = BondFailure::Tensile;
    } else {
      const Real shear_room = c.coh - normal_stress * c.tan_fa - c.beta * std::abs(s.Mt) * sec.R_over_J;
      if (shear_room <= 0 || s.Fs.squaredNorm() * sec.inv_A * sec.inv_A >= shear_room * shear_room)
        fail = BondFailure::Shear;
    }
    if (stress_out) *stress_out = stress(c, sec, s);
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

namespace ff {
template <> struct is_checkpoint_pod<dem::ParallelBond::State> : std::true_type {};
}  // namespace ff
