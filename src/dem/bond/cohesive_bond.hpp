// The cohesive-frictional contact law of seed 004 (Krzaczek, Tejchman & Nitka 2024, Granular
// Matter 26:38, Appendix A, Eqs. A1-A7; the YADE CohFrictMat law of Nitka & Tejchman 2015,
// Granular Matter 17:145), registered as the pair
//   dem.contact_law = "cohesive"  (CohesiveContact: A1-A3, A5: the frictional contact, no tension)
//   dem.bond_law    = "cohesive"  (CohesiveBond: A4, A6: the cohesion of an intact contact)
// and run together: contact + bond reproduce the seed's ONE intact contact, the contact alone the
// broken one (the engine sums contact and bond loads, as for PFC's parallel bond).
//
// Seed 004, Appendix A (Fn > 0 compression here, U the overlap, R = min(R_A, R_B)):
//   A1  Fn = Kn U                               (tension allowed while intact, U < 0)
//   A2  Fs = Fs,prev + Ks dXs                   (incremental, rotated into the contact plane)
//   A3  Kn = Ec 2 RA RB / (RA + RB),  Ks = nu_c Kn
//   A4  |Fs| - C R^2 - Fn tan(mu_c) <= 0        before breakage; exceeded: the contact breaks (shear)
//   A6  Fn >= -T R^2                            below: the contact breaks (tension)
//   A5  |Fs| - Fn tan(mu_c) <= 0                after breakage: Coulomb slip, Fn >= 0 only
//   A7  Cundall's local non-viscous damping: the engine's dem.local_damping (alpha_d), per component.
// Breakage is brittle (no softening; the seed defines none): the cohesion is lost at once.
// Choices the seed leaves open: R in A6 is min(RA, RB) (YADE Ip2_CohFrictMat_CohFrictMat_CohFrictPhys);
// mu_c enters as tan(mu_c) = dem.contact.*.friction; an intact pair installed at a gap g0 > 0 (bonding
// tolerance) is stress-free there: the overlap counts from g0 (U = g0 - gap); 2D discs are 1 m thick
// as everywhere in fracflow, the seed's forces (N) are used unchanged.
//
// The split: the contact carries Kn max(-gap, 0) and its own Coulomb-limited shear spring; the
// bond carries the rest of the seed's intact force: Kn U - Kn max(-gap, 0) normal, and
// Fs_seed - Fs_contact in shear. To know Fs_contact the bond keeps an exact copy of the
// contact's spring (same kinematics, same update, same slip rule), so the sum is the seed's
// single spring Ks whatever the contact does. The bond reads Ec, nu_c and the friction from the
// pair's contact table, so the two halves cannot disagree.
#pragma once
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <string_view>

#include "dem/bond/bond_load.hpp"
#include "dem/bond/rotational_bond.hpp"  // BondEnds
#include "dem/contact/contact_geometry.hpp"
#include "dem/particle_store.hpp"
#include "io/checkpoint.hpp"
#include "io/params.hpp"

namespace ff::dem {

namespace cohesive {
// A3: Kn = Ec 2 RA RB / (RA + RB); against a wall (rB = 0) Kn = Ec 2 RA (the limit RB -> inf).
inline Real normal_stiffness(Real ec, Real rA, Real rB) { return rB > 0 ? ec * 2 * rA * rB / (rA + rB) : ec * 2 * rA; }
// The stiffer of Kn and Ks = nu_c Kn (nu_c > 1: the shear spring), for the critical time step.
inline Real stiffest_spring(Real ec, Real nu_c, Real rA, Real rB) {
  return normal_stiffness(ec, rA, rB) * std::max(Real(1), nu_c);
}

// The frictional spring (A2, A5) shared by the contact and the bond's copy of it: fn >= 0 the
// contact's compressive force. Returns the updated shear force on B.
[[gnu::always_inline]] inline void frictional_shear(Vec3& fs, const ContactGeom& g, Real ks, Real fn, Real fric, Real dt) {
  if (fn == 0) {  // separated: the contact forgets its shear force
    fs.setZero();
    return;
  }
  rotate_into_plane(fs, g, dt);
  fs -= ks * g.d_delta_s;
  const Real limit = fric * fn;
  const Real fs2 = fs.squaredNorm();
  if (fs2 > limit * limit) fs *= limit / std::sqrt(fs2);  // slip
}
}  // namespace cohesive

// A1-A3, A5: linear normal spring (no tension), incremental shear spring, Coulomb slip.
struct CohesiveContact {
  static constexpr std::string_view name = "cohesive";
  struct Params {
    Real ec = 1e9;    // Ec [Pa]
    Real nu_c = 0.3;  // Ks / Kn [-]
    Real fric = 0.5;  // tan(mu_c) [-]
  };
  using State = ContactState;
  static void declare(ParamTable& t) {
    t.real("dem.contact.*.ec", 1e9, "Pa", "cohesive contact (seed 004 A3): modulus Ec, Kn = Ec 2 RA RB/(RA + RB)").positive();
    t.real("dem.contact.*.nu_c", 0.3, "-", "cohesive contact (seed 004 A3): Ks = nu_c Kn").positive();
  }
  static Params read(const Config& cfg, const std::string& table) {
    return {cfg.real(table + ".ec"), cfg.real(table + ".nu_c"), cfg.real(table + ".friction")};
  }
  static Params elastic(Real E, Real nu) { return {E, nu, 0.0}; }
  static Real normal_stiffness_at(const Params& p, Real rA, Real rB, Real, int) {
    return cohesive::normal_stiffness(p.ec, rA, rB);
  }
  static Real time_step_stiffness(const Params& p, Real rA, Real rB, Real, int) {
    return cohesive::stiffest_spring(p.ec, p.nu_c, rA, rB);
  }
  static Real normal_force(const Params& p, Real rA, Real rB, Real overlap, int) {
    return cohesive::normal_stiffness(p.ec, rA, rB) * overlap;
  }
  static Real normal_energy(const Params& p, Real rA, Real rB, Real overlap, int) {
    return 0.5 * cohesive::normal_stiffness(p.ec, rA, rB) * overlap * overlap;
  }
  static Real strain_energy(const Params& p, Real rA, Real rB, Real overlap, const State& s, int) {
    const Real kn = cohesive::normal_stiffness(p.ec, rA, rB);
    return 0.5 * kn * overlap * overlap + 0.5 * s.fs.squaredNorm() / (p.nu_c * kn);
  }
  template <bool kEnergy = false>
  [[gnu::always_inline]] static Vec3 force(const Params& p, const ContactGeom& g, State& s, Real dt, int, Real& fn,
                                           ContactWork* w = nullptr) {
    const Real kn = cohesive::normal_stiffness(p.ec, g.rA, g.rB);
    const Real ks = p.nu_c * kn;
    fn = g.gap < 0 ? -kn * g.gap : 0.0;
    if (fn == 0) {
      if constexpr (kEnergy) {  // what the spring held is lost with it
        w->shear = -0.5 * s.fs.squaredNorm() / ks;
        w->slip = -w->shear;
      }
      s.fs.setZero();
      return Vec3::Zero();
    }
    Vec3 f0;
    if constexpr (kEnergy) {
      f0 = s.fs;
      rotate_into_plane(f0, g, dt);
    }
    cohesive::frictional_shear(s.fs, g, ks, fn, p.fric, dt);
    if constexpr (kEnergy) shear_work(f0, s.fs, ks, g.d_delta_s, *w);
    return fn * g.n + s.fs;
  }
};

// A4, A6: the cohesion of an intact contact, brittle breakage in tension or shear.
struct CohesiveBond {
  static constexpr std::string_view name = "cohesive";
  static constexpr std::string_view checkpoint_key = "dem.cbond";
  static constexpr bool installs_bonds = true;
  struct Material {
    Real ec = 1e9, nu_c = 0.3, fric = 0.5;  // from the pair's contact table (CohesiveContact)
    Real coh = 10e6;                        // C [Pa]: Fs_max = C R^2
    Real ten = 10e6;                        // T [Pa]: Fn_min = T R^2
  };
  struct State {
    Real g0 = 0;                  // reference gap max(gap at install, 0) [m]
    Real fn = 0;                  // the seed's total normal force Kn U of the last step (compression > 0) [N]
    Real fn_b = 0;                // the bond's share of it, Kn U - (contact's Kn max(-gap, 0)) [N]
    Vec3 fs = Vec3::Zero();       // the seed's total shear force on B (A2) [N]
    Vec3 fs_c = Vec3::Zero();     // copy of the frictional contact's shear spring [N]
  };
  using Prepared = Material;

  static void declare(ParamTable& t) {
    t.real("dem.bond.*.tension", 10e6, "Pa", "cohesive bond (seed 004 A6): tensile strength T, Fn_min = T min(RA,RB)^2")
        .positive();
  }
  // The pair's contact table is "dem.contact.a-b" or "dem.contact.b-a".
  static std::string contact_table(const Config& cfg, const std::string& bt) {
    const std::string pair = bt.substr(std::string("dem.bond.").size());
    const auto dash = pair.find('-');
    const std::string swapped = pair.substr(dash + 1) + "-" + pair.substr(0, dash);
    const std::string p = "dem.contact." + pair + ".";
    const auto it = cfg.values().lower_bound(p);
    const bool has = it != cfg.values().end() && it->first.compare(0, p.size(), p) == 0;
    return "dem.contact." + (has ? pair : swapped);
  }
  static Material read(const Config& cfg, const std::string& bt, int) {
    if (cfg.string("dem.contact_law") != CohesiveContact::name)
      cfg.fail("dem.bond_law", fmt::format("the cohesive bond (seed 004 A4, A6) completes the cohesive contact law (A1-A3, "
                                           "A5): set dem.contact_law = \"cohesive\" (now \"{}\")",
                                           cfg.string("dem.contact_law")));
    const std::string ct = contact_table(cfg, bt);
    Material m;
    m.ec = cfg.real(ct + ".ec");
    m.nu_c = cfg.real(ct + ".nu_c");
    m.fric = cfg.real(ct + ".friction");
    m.coh = cfg.real(bt + ".cohesion");
    m.ten = cfg.real(bt + ".tension");
    if (cfg.real(bt + ".friction_angle") != 0)
      cfg.fail(bt + ".friction_angle", "the cohesive bond takes mu_c from the contact: tan(mu_c) = dem.contact.*.friction; "
                                       "remove friction_angle");
    return m;
  }
  static Material elastic(Real E, Real nu, Real strength) { return {E, nu, 0.0, strength, strength}; }
  static Prepared prepare(const Material& m) { return m; }
  static State install(const Material&, const BondEnds& e) {
    return install_at_gap((e.xB - e.xA).norm() - e.rA - e.rB);
  }
  static State install_at_gap(Real gap) {
    State s;
    s.g0 = std::max(gap, 0.0);
    return s;
  }

  [[gnu::always_inline]] static BondFailure compute_bond(const Prepared& m, State& st, const ParticleStore& P, Index i,
                                                         Index j, Real dt, int dim, BondLoad& load) {
    ContactGeom g;
    sphere_sphere(g, P.pos[i], P.radius[i], P.pos[j], P.radius[j]);
    contact_kinematics(g, P.pos[i], P.vel[i], P.omega[i], P.pos[j], P.vel[j], P.omega[j], dt);
    return compute(m, st, g, dt, dim, load);
  }

  // One step: the seed's intact force (A1, A2), the breakage test (A4, A6), and the part of that
  // force the frictional contact does not carry, as the bond's load.
  [[gnu::always_inline]] static BondFailure compute(const Material& m, State& s, const ContactGeom& g, Real dt, int,
                                                    BondLoad& out) {
    const Real kn = cohesive::normal_stiffness(m.ec, g.rA, g.rB);
    const Real ks = m.nu_c * kn;
    const Real R = std::min(g.rA, g.rB);
    // The contact's half (CohesiveContact::force, step for step).
    const Real fn_c = g.gap < 0 ? -kn * g.gap : 0.0;
    cohesive::frictional_shear(s.fs_c, g, ks, fn_c, m.fric, dt);
    // The seed's intact contact.
    s.fn = kn * (s.g0 - g.gap);  // A1
    rotate_into_plane(s.fs, g, dt);
    s.fs -= ks * g.d_delta_s;  // A2
    BondFailure fail = BondFailure::None;
    if (s.fn < -m.ten * R * R) {
      fail = BondFailure::Tensile;  // A6
    } else {
      const Real cap = m.coh * R * R + s.fn * m.fric;  // A4
      if (cap <= 0 || s.fs.squaredNorm() > cap * cap) fail = BondFailure::Shear;
    }
    s.fn_b = s.fn - fn_c;
    out.force_on_B = s.fn_b * g.n + (s.fs - s.fs_c);
    // At the contact point: moments of the force about each centre (the seed has no couples).
    const Vec3 n_x_f = g.n.cross(out.force_on_B);
    out.moment_on_B = -(g.rB + 0.5 * g.gap) * n_x_f;
    out.moment_on_A = -(g.rA + 0.5 * g.gap) * n_x_f;
    return fail;
  }
  // The bond adds at most Kn (tension, when the contact is open) or Ks to a pair.
  static void time_step_stiffness(const Material& m, const State&, Real rA, Real rB, int, Real& k, Real& krot) {
    k = cohesive::stiffest_spring(m.ec, m.nu_c, rA, rB);
    krot = 0;
  }
  static Real crack_size(const Material&, Real rA, Real rB, int) { return std::min(rA, rB); }
  // Energy of the bond's share of the springs (what is lost when it breaks).
  static Real energy(const Material& m, const State& s, Real rA, Real rB, int) {
    const Real kn = cohesive::normal_stiffness(m.ec, rA, rB);
    const Vec3 fs_b = s.fs - s.fs_c;
    return 0.5 * s.fn_b * s.fn_b / kn + 0.5 * fs_b.squaredNorm() / (m.nu_c * kn);
  }
};

}  // namespace ff::dem

namespace ff {
template <> struct is_checkpoint_pod<dem::CohesiveBond::State> : std::true_type {};
}  // namespace ff
