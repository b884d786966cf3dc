#include "dem/dem_params.hpp"

#include <fmt/format.h>

#include "core/error.hpp"
#include "core/log.hpp"

namespace ff::dem {

void declare_dem_params(ParamTable& t) {
  t.integer("dem.dim", 3, "-", "space dimension: 3 = spheres, 2 = disks of unit thickness in the x-y plane").range(2, 3);
  t.string("dem.contact_law", "linear", "contact law between particles and with walls").one_of({"linear", "hertz_mindlin"});
  t.string("dem.bond_law", "parallel", "bond law: parallel (Potyondy & Cundall 2004), rotational (Wang & Mora 6-DOF), none")
      .one_of({"parallel", "rotational", "none"});
  t.real("dem.local_damping", 0.7, "-", "Cundall local damping coefficient (PFC default 0.7)").range(0, 1).below(1);
  t.real("dem.normal_damping_ratio", 0.0, "-", "viscous normal dashpot as a fraction of critical damping").range(0, 1);
  t.real("dem.time_step", 0.0, "s", "time step; 0 = time_step_safety x critical time step").non_negative();
  t.real("dem.time_step_safety", 0.8, "-", "fraction of the critical time step used (and allowed)").positive().at_most(1);
  t.boolean("dem.mass_scaling", false, "scale inertial masses so that dem.time_step is stable (quasi-static runs only)");
  t.real("dem.skin_ratio", 0.3, "-", "Verlet skin as a fraction of the mean particle radius").positive();
  t.integer("dem.parallel_min", 2048, "-", "loops over fewer particles/contacts/bonds run on one thread (OpenMP fork/join costs more)").non_negative();
  t.real_list("dem.gravity", {0, 0, 0}, "m/s^2", "gravitational acceleration").size(3);
  t.real("dem.group.*.density", 2600, "kg/m^3", "particle density of the group").positive();
  // Linear contact (PFC deformability method).
  t.real("dem.contact.*.emod", 1e9, "Pa", "linear contact effective modulus E* (kn = A E*/L)").positive();
  t.real("dem.contact.*.kratio", 1.0, "-", "linear contact normal-to-shear stiffness ratio kn/ks").positive();
  t.real("dem.contact.*.friction", 0.5, "-", "Coulomb friction coefficient of the contact").non_negative();
  // Hertz-Mindlin contact.
  t.real("dem.contact.*.shear_modulus", 1e9, "Pa", "Hertz-Mindlin particle shear modulus G").positive();
  t.real("dem.contact.*.poisson", 0.25, "-", "Hertz-Mindlin particle Poisson ratio").range(0, 0.5).below(0.5);
  // Parallel bond.
  t.real("dem.bond.*.emod", 1e9, "Pa", "parallel bond effective modulus (kn_bar = E_bar/L)").positive();
  t.real("dem.bond.*.kratio", 1.0, "-", "parallel bond normal-to-shear stiffness ratio").positive();
  t.real("dem.bond.*.tensile_strength", 10e6, "Pa", "parallel bond tensile strength").positive();
  t.real("dem.bond.*.cohesion", 10e6, "Pa", "bond cohesion (parallel and rotational bonds)").positive();
  t.real("dem.bond.*.friction_angle", 0.0, "deg", "bond friction angle (parallel: shear strength c - sigma tan(phi); rotational: > 0)")
      .range(0, 90).below(90);
  t.real("dem.bond.*.radius_multiplier", 1.0, "-", "parallel bond radius multiplier lambda_bar").positive();
  t.real("dem.bond.*.moment_factor", 1.0, "-", "parallel bond moment-contribution factor beta_bar").range(0, 1);
  // Rotational bond (Wang & Mora).
  t.real("dem.bond.*.youngs_modulus", 1e9, "Pa", "rotational bond Young's modulus E (beam of radius L0/2)").positive();
  t.real("dem.bond.*.poisson_ratio", 0.25, "-", "rotational bond Poisson ratio").range(0, 0.5).below(0.5);
  t.real("dem.bond.*.beta1", 1.0, "-", "rotational bond: weight of bending in the tensile criterion").non_negative();
  t.real("dem.bond.*.beta2", 1.0, "-", "rotational bond: weight of twisting in the shear criterion").non_negative();
  t.real("dem.bond.*.truncation", 1.0, "-", "rotational bond: tension cut-off t of the criterion").positive().at_most(1);
}

namespace {
// Pair tables may be written a-b or b-a; both orders name the same pair.
std::string find_pair_table(const Config& cfg, const std::string& section, const std::string& a, const std::string& b) {
  const auto names = cfg.names(section);
  for (auto& n : names)
    if (n == a + "-" + b || n == b + "-" + a) return section + "." + n;
  return "";
}
}  // namespace

Materials build_materials(const Config& cfg) {
  Materials m;
  m.group_names = cfg.names("dem.group");
  if (m.group_names.empty())
    throw InputError(fmt::format("{}: no particle group defined; add e.g. [dem.group.rock] with density = 2600",
                                 cfg.scenario_name()));
  for (auto& g : m.group_names) {
    if (g.find('-') != std::string::npos)
      cfg.fail("dem.group." + g + ".density", "group names may not contain '-' (it separates the two groups of a pair)");
    m.density.push_back(cfg.real("dem.group." + g + ".density"));
  }
  m.contact_law = cfg.string("dem.contact_law") == "linear" ? ContactLaw::Linear : ContactLaw::HertzMindlin;
  const std::string bl = cfg.string("dem.bond_law");
  m.bond_law = bl == "parallel" ? BondLaw::Parallel : bl == "rotational" ? BondLaw::Rotational : BondLaw::None;
  m.normal_damping_ratio = cfg.real("dem.normal_damping_ratio");
  const int ng = m.groups();
  const int dim = static_cast<int>(cfg.integer("dem.dim"));
  m.linear.resize(ng * ng);
  m.hertz.resize(ng * ng);
  m.parallel.resize(ng * ng);
  m.rotational.resize(ng * ng);
  // Pair tables must name declared groups.
  for (const char* section : {"dem.contact", "dem.bond"}) {
    for (auto& n : cfg.names(section)) {
      const auto dash = n.find('-');
      const std::string a = n.substr(0, dash), b = dash == std::string::npos ? "" : n.substr(dash + 1);
      if (dash == std::string::npos || m.group_index(a) < 0 || m.group_index(b) < 0) {
        std::string known;
        for (auto& g : m.group_names) known += (known.empty() ? "" : ", ") + g;
        throw InputError(fmt::format("{}: table [{}.{}] does not name a pair of declared groups 'a-b' (groups: {})",
                                     cfg.scenario_name(), section, n, known));
      }
    }
  }
  for (int a = 0; a < ng; ++a) {
    for (int b = a; b < ng; ++b) {
      const std::string ga = m.group_names[a], gb = m.group_names[b];
      const std::string ct = find_pair_table(cfg, "dem.contact", ga, gb);
      if (ct.empty())
        throw InputError(fmt::format("{}: contact properties of the group pair {}-{} are missing: add a table "
                                     "[dem.contact.{}-{}] (keys emod, kratio, friction, ...)",
                                     cfg.scenario_name(), ga, gb, ga, gb));
      LinearContact::Params lp{cfg.real(ct + ".emod"), cfg.real(ct + ".kratio"), cfg.real(ct + ".friction")};
      HertzMindlinContact::Params hp{cfg.real(ct + ".shear_modulus"), cfg.real(ct + ".poisson"), cfg.real(ct + ".friction")};
      m.linear[m.pair(a, b)] = m.linear[m.pair(b, a)] = lp;
      m.hertz[m.pair(a, b)] = m.hertz[m.pair(b, a)] = hp;
      if (m.bond_law == BondLaw::None) continue;
      const std::string bt = find_pair_table(cfg, "dem.bond", ga, gb);
      if (bt.empty())
        throw InputError(fmt::format("{}: bond properties of the group pair {}-{} are missing: add a table "
                                     "[dem.bond.{}-{}] (or set dem.bond_law = \"none\")",
                                     cfg.scenario_name(), ga, gb, ga, gb));
      ParallelBond::Material pb;
      pb.emod = cfg.real(bt + ".emod");
      pb.kratio = cfg.real(bt + ".kratio");
      pb.ten = cfg.real(bt + ".tensile_strength");
      pb.coh = cfg.real(bt + ".cohesion");
      pb.fa_deg = cfg.real(bt + ".friction_angle");
      pb.lambda = cfg.real(bt + ".radius_multiplier");
      pb.beta = cfg.real(bt + ".moment_factor");
      m.parallel[m.pair(a, b)] = m.parallel[m.pair(b, a)] = pb;
      RotationalBond::Material rb;
      rb.youngs_modulus = cfg.real(bt + ".youngs_modulus");
      rb.poisson_ratio = cfg.real(bt + ".poisson_ratio");
      rb.cohesion = cfg.real(bt + ".cohesion");
      rb.friction_angle_deg = cfg.real(bt + ".friction_angle");
      rb.beta1 = cfg.real(bt + ".beta1");
      rb.beta2 = cfg.real(bt + ".beta2");
      rb.truncation = cfg.real(bt + ".truncation");
      rb.dim = dim;
      if (m.bond_law == BondLaw::Rotational && rb.friction_angle_deg <= 0)
        cfg.fail(bt + ".friction_angle", "the rotational bond needs a friction angle > 0 (its tensile strength is c/tan(phi))");
      m.rotational[m.pair(a, b)] = m.rotational[m.pair(b, a)] = rb;
    }
  }
  return m;
}

DemSettings build_settings(const Config& cfg) {
  DemSettings s;
  s.dim = static_cast<int>(cfg.integer("dem.dim"));
  s.local_damping = cfg.real("dem.local_damping");
  s.parallel_min = static_cast<std::size_t>(cfg.integer("dem.parallel_min"));
  const auto& g = cfg.real_list("dem.gravity");
  s.gravity = Vec3(g[0], g[1], g[2]);
  if (s.dim == 2 && g[2] != 0) cfg.fail("dem.gravity", "a 2D run lies in the x-y plane: the z component must be 0");
  return s;
}

void choose_time_step(const Config& cfg, DemSystem& sys) {
  const Real safety = cfg.real("dem.time_step_safety");
  const Real dt_user = cfg.real("dem.time_step");
  const Real crit = sys.critical_time_step();
  if (dt_user <= 0) {
    sys.settings.dt = safety * crit;
  } else if (cfg.boolean("dem.mass_scaling")) {
    sys.scale_masses_for(dt_user, safety);
    sys.settings.dt = dt_user;
  } else {
    if (dt_user > safety * crit)
      cfg.fail("dem.time_step",
               fmt::format("{:.4g} s is above the stable limit {:.4g} s ({} x critical time step {:.4g} s of this sample); "
                           "set dem.time_step = 0 for automatic, a value <= {:.4g}, or dem.mass_scaling = true",
                           dt_user, safety * crit, safety, crit, safety * crit));
    sys.settings.dt = dt_user;
  }
  log::info("time step {:.4g} s (critical {:.4g} s{})", sys.settings.dt, crit,
            cfg.boolean("dem.mass_scaling") && dt_user > 0 ? ", inertial masses scaled" : "");
}

}  // namespace ff::dem
