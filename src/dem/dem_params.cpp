#include "dem/dem_params.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string_view>

#include "core/error.hpp"
#include "core/log.hpp"
#include "dem/diagnostics.hpp"

namespace ff::dem {

void declare_dem_params(ParamTable& t) {
  t.integer("dem.dim", 3, "-", "space dimension: 3 = spheres, 2 = disks of unit thickness in the x-y plane").range(2, 3);
  // The laws' names come from their registry (laws.hpp); each law declares its own keys below.
  t.string("dem.contact_law", "linear", "contact law between particles and with walls").one_of(law_name_list(ContactLaws{}));
  t.string("dem.bond_law", "parallel", "bond law: parallel (Potyondy & Cundall 2004), rotational (Wang & Mora 6-DOF), cohesive (seed 004's A1-A7, with "
           "dem.contact_law = \"cohesive\"), none")
      .one_of(law_name_list(BondLaws{}));
  t.real("dem.local_damping", 0.7, "-", "Cundall local damping coefficient (PFC default 0.7)").range(0, 1).below(1);
  t.real("dem.normal_damping_ratio", 0.0, "-", "viscous normal dashpot as a fraction of critical damping").range(0, 1);
  t.real("dem.time_step", 0.0, "s", "time step; 0 = time_step_safety x critical time step").non_negative();
  t.real("dem.time_step_safety", 0.8, "-", "fraction of the critical time step used (and allowed)").positive().at_most(1);
  t.boolean("dem.mass_scaling", false, "scale inertial masses so that dem.time_step is stable (quasi-static runs only)");
  t.real("dem.skin_ratio", 0.3, "-",
         "Verlet skin as a fraction of the mean particle radius (above a few radii every near particle is a neighbour "
         "and the contact search costs more than it saves)")
      .positive()
      .at_most(10);
  t.integer("dem.parallel_min", 2048, "-", "loops over fewer particles/contacts/bonds run on one thread (OpenMP fork/join costs more)").non_negative();
  t.boolean("dem.energy_tracking", true,
            "energy bookkeeping: boundary work, kinetic and strain energy, damping, friction, dashpot and bond-breakage "
            "dissipation in series.csv (docs/dem.md)");
  t.real_list("dem.gravity", {0, 0, 0}, "m/s^2", "gravitational acceleration").size(3);
  t.real("dem.group.*.density", 2600, "kg/m^3", "particle density of the group").positive();
  // Keys common to the contact laws (each law reads them), then each law's own.
  t.real("dem.contact.*.friction", 0.5, "-", "Coulomb friction coefficient of the contact").non_negative();
  for_each_law(ContactLaws{}, [&]<class Law>(std::type_identity<Law>) { Law::declare(t); });
  // Keys common to the bond laws that install bonds, then each law's own.
  t.real("dem.bond.*.cohesion", 10e6, "Pa", "bond cohesion (parallel and rotational bonds)").positive();
  t.real("dem.bond.*.friction_angle", 0.0, "deg", "bond friction angle (parallel: shear strength c - sigma tan(phi); rotational: > 0)")
      .range(0, 90).below(90);
  for_each_law(BondLaws{}, [&]<class Law>(std::type_identity<Law>) { Law::declare(t); });
}

namespace {

// The registered law that declares `key` ("" when it is common to every law of its section).
template <class List> std::string law_of_key(List list, const std::string& key) {
  std::string owner;
  for_each_law(list, [&]<class Law>(std::type_identity<Law>) {
    ParamTable own;
    Law::declare(own);
    if (owner.empty() && own.find(key)) owner = Law::name;
  });
  return owner;
}

// A pair-table key of a law that is not the active one would be silently ignored: refused,
// unless it holds its default (a resolved scenario.toml writes every key of every law).
void check_law_keys(const Config& cfg) {
  for (const char* section : {"dem.contact", "dem.bond"}) {
    const std::string law_key = std::string(section) == "dem.contact" ? "dem.contact_law" : "dem.bond_law";
    const std::string& active = cfg.string(law_key);
    const std::string p = std::string(section) + ".";
    const auto& values = cfg.values();
    for (auto it = values.lower_bound(p); it != values.end() && it->first.compare(0, p.size(), p) == 0; ++it) {
      const std::string& key = it->first;
      const std::string leaf = key.substr(key.rfind('.') + 1);
      const std::string law = std::string(section) == "dem.contact" ? law_of_key(ContactLaws{}, key) : law_of_key(BondLaws{}, key);
      const bool unused = active == NoBond::name || (!law.empty() && active != law);
      if (!unused) continue;
      const ParamSpec* spec = cfg.table().find(key);
      if (spec && spec->default_value && *spec->default_value == it->second.first) continue;
      if (active == NoBond::name)
        cfg.fail(key, fmt::format("dem.bond_law = \"none\" installs no bonds, so this bond key would be ignored; remove "
                                  "the [{}] table or choose a bond law (dem.bond_law, registered: {})",
                                  key.substr(0, key.rfind('.')), law_names(BondLaws{})));
      cfg.fail(key, fmt::format("'{}' belongs to the {} law, but {} = \"{}\", which does not read it (it would be "
                                "ignored); remove it, or set {} = \"{}\"",
                                leaf, law, law_key, active, law_key, law));
    }
  }
}

}  // namespace

Materials build_materials(const Config& cfg) {
  check_law_keys(cfg);
  Materials m;
  m.group_names = cfg.names("dem.group");
  if (m.group_names.empty())
    throw InputError(fmt::format("{}: no particle group defined; add e.g. [dem.group.rock] with density = 2600",
                                 cfg.scenario_name()));
  if (m.groups() > kMaxGroups)
    throw InputError(fmt::format("{}: the scenario declares {} particle groups ([dem.group.NAME]); the limit is {} (every "
                                 "pair of groups needs its own contact and bond table)",
                                 cfg.scenario_name(), m.group_names.size(), kMaxGroups));
  for (auto& g : m.group_names) {
    if (g.find('-') != std::string::npos)
      cfg.fail("dem.group." + g + ".density", "group names may not contain '-' (it separates the two groups of a pair)");
    m.density.push_back(cfg.real("dem.group." + g + ".density"));
  }
  m.contact_law = law_index_of(ContactLaws{}, cfg.string("dem.contact_law"));
  m.bond_law = law_index_of(BondLaws{}, cfg.string("dem.bond_law"));
  if (m.contact_law < 0)
    cfg.fail("dem.contact_law", fmt::format("unknown contact law; registered: {}", law_names(ContactLaws{})));
  if (m.bond_law < 0) cfg.fail("dem.bond_law", fmt::format("unknown bond law; registered: {}", law_names(BondLaws{})));
  m.normal_damping_ratio = cfg.real("dem.normal_damping_ratio");
  const int ng = m.groups();
  const int dim = static_cast<int>(cfg.integer("dem.dim"));
  // Only the active laws' tables are filled.
  m.with_contact_law([&]<class Law>(std::type_identity<Law>) { m.contact_params<Law>().resize(ng * ng); });
  m.with_bond_law([&]<class Law>(std::type_identity<Law>) { m.bond_params<Law>().resize(ng * ng); });
  // Pair tables must name declared groups, each pair once (a-b or b-a: both name the same pair).
  std::vector<std::string> contact_table(ng * ng), bond_table(ng * ng);
  for (const char* section : {"dem.contact", "dem.bond"}) {
    auto& table = std::string(section) == "dem.contact" ? contact_table : bond_table;
    for (auto& n : cfg.names(section)) {
      const auto dash = n.find('-');
      const std::string a = n.substr(0, dash), b = dash == std::string::npos ? "" : n.substr(dash + 1);
      const int ia = m.group_index(a), ib = dash == std::string::npos ? -1 : m.group_index(b);
      const std::string key = std::string(section) + "." + n;
      if (ia < 0 || ib < 0) {
        std::string known;
        for (auto& g : m.group_names) known += (known.empty() ? "" : ", ") + g;
        const std::string what = fmt::format("table [{}] does not name a pair of declared groups 'a-b' (groups: {}; "
                                             "declare a group with [dem.group.NAME])",
                                             key, known);
        const auto first = cfg.values().lower_bound(key + ".");  // one of its keys, for file and line
        if (first != cfg.values().end() && first->first.rfind(key + ".", 0) == 0) cfg.fail(first->first, what);
        throw InputError(fmt::format("{}: {}", cfg.scenario_name(), what));
      }
      auto& slot = table[m.pair(std::min(ia, ib), std::max(ia, ib))];
      if (!slot.empty())
        throw InputError(fmt::format("{}: tables [{}] and [{}] describe the same pair of groups; keep one",
                                     cfg.scenario_name(), slot, key));
      slot = key;
    }
  }
  for (int a = 0; a < ng; ++a) {
    for (int b = a; b < ng; ++b) {
      const std::string ga = m.group_names[a], gb = m.group_names[b];
      const std::string& ct = contact_table[m.pair(a, b)];
      if (ct.empty())
        throw InputError(fmt::format("{}: contact properties of the group pair {}-{} are missing: add a table "
                                     "[dem.contact.{}-{}] (keys emod, kratio, friction, ...)",
                                     cfg.scenario_name(), ga, gb, ga, gb));
      m.with_contact_law([&]<class Law>(std::type_identity<Law>) {
        auto& table = m.contact_params<Law>();
        table[m.pair(a, b)] = table[m.pair(b, a)] = Law::read(cfg, ct);
      });
      if (!m.has_bonds()) continue;
      const std::string& bt = bond_table[m.pair(a, b)];
      if (bt.empty())
        throw InputError(fmt::format("{}: bond properties of the group pair {}-{} are missing: add a table "
                                     "[dem.bond.{}-{}] (or set dem.bond_law = \"none\")",
                                     cfg.scenario_name(), ga, gb, ga, gb));
      m.with_bond_law([&]<class Law>(std::type_identity<Law>) {
        auto& table = m.bond_params<Law>();
        table[m.pair(a, b)] = table[m.pair(b, a)] = Law::read(cfg, bt, dim);
      });
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

Real checked_critical_time_step(const Config& cfg, const DemSystem& sys, std::string_view what,
                                std::span<const Real> extra_stiffness) {
  const Real crit = critical_time_step(sys, extra_stiffness);
  if (!(crit > 0))
    throw InputError(fmt::format(
        "{}: the {} is 0: the sample's contact or bond stiffness is not finite (a modulus, or a parallel bond's "
        "section, so large that k = E A / L overflows, or a normal-to-shear ratio kn/ks so small that ks does) or a "
        "particle's mass is 0; check dem.contact.*.emod, dem.contact.*.kratio, dem.contact.*.nu_c, dem.bond.*.emod, "
        "dem.bond.*.kratio, dem.bond.*.radius_multiplier, dem.bond.*.youngs_modulus and dem.group.*.density{}",
        cfg.scenario_name(), what, extra_stiffness.empty() ? "" : ", and the coupled fluid's stiffness"));
  return crit;
}

// The critical step counts the contacts that touch now; a bonded sample with a bond gap has few, and a
// pair of groups may have none yet. A contact of such a pair that would be unstable alone at the chosen
// step makes the run blow up when the first one forms, with advice about the safety factor: say so
// now. Checked per pair of groups present, between each group's lightest particles (the shortest
// period), with the same bound as critical_time_step.
namespace {

void check_contacts_to_come(const Config& cfg, DemSystem& sys) {
  const auto& P = sys.particles;
  const auto& M = sys.materials;
  const int ng = M.groups();
  std::vector<Index> lightest(static_cast<std::size_t>(ng), -1);
  for (std::size_t i = 0; i < P.size(); ++i) {  // the largest inverse mass (masses may be scaled)
    Index& l = lightest[static_cast<std::size_t>(P.group[i])];
    if (l < 0 || P.inv_mass[i] > P.inv_mass[l]) l = static_cast<Index>(i);
  }
  const Real dt = sys.settings.dt;
  sys.untouched_unstable_contacts.clear();
  for (int a = 0; a < ng; ++a) {
    for (int b = a; b < ng; ++b) {
      const Index i = lightest[static_cast<std::size_t>(a)], j = lightest[static_cast<std::size_t>(b)];
      if (i < 0 || j < 0) continue;
      const Real ri = P.radius[i], rj = P.radius[j];
      const Real k = pair_stiffness(sys, M.pair(a, b), ri, rj, 0.01 * std::min(ri, rj));
      Real bound = std::numeric_limits<Real>::infinity();
      for (const Index p : {i, j})
        bound = std::min({bound, std::sqrt(1 / (P.inv_mass[p] * k)),
                          std::sqrt(1 / (P.inv_inertia[p] * k * P.radius[p] * P.radius[p]))});
      const std::string &ga = M.group_names[a], &gb = M.group_names[b];
      std::string table = fmt::format("dem.contact.{}-{}", ga, gb);  // as the scenario spells it
      for (const auto& n : cfg.names("dem.contact"))
        if (n == gb + "-" + ga) table = "dem.contact." + n;
      if (!std::isfinite(k) || !(bound > 0))
        throw InputError(fmt::format(
            "{}: a contact of the group pair {}-{} allows no time step: its stiffness overflows (table [{}]: check "
            "its modulus, emod, ec or shear_modulus, and its kratio or nu_c)",
            cfg.scenario_name(), ga, gb, table));
      if (dt > bound) {
        log::warn("{}: one contact between the lightest particles of groups {} and {} is stable only below {:.3g} s "
                  "and the time step is {:.3g} s; none touches now (the critical step counts the contacts that do), "
                  "so the run will go unstable once one forms: lower the stiffness in [{}], or set dem.time_step "
                  "below {:.3g} s",
                  cfg.scenario_name(), ga, gb, bound, dt, table, bound);
        sys.untouched_unstable_contacts.push_back(fmt::format(
            "groups {} and {}, stable only below {:.3g} s: lower the stiffness in [{}] or set dem.time_step below {:.3g} s",
            ga, gb, bound, table, bound));
      }
    }
  }
}

}  // namespace

void choose_time_step(const Config& cfg, DemSystem& sys, std::span<const Real> extra_stiffness) {
  const Real safety = cfg.real("dem.time_step_safety");
  const Real dt_user = cfg.real("dem.time_step");
  const Real crit = checked_critical_time_step(cfg, sys, "critical time step", extra_stiffness);
  const char* with = extra_stiffness.empty() ? "" : " with the coupled fluid's stiffness";
  if (dt_user <= 0) {
    sys.settings.dt = safety * crit;
  } else if (cfg.boolean("dem.mass_scaling")) {
    scale_masses_for(sys, dt_user, safety, extra_stiffness);
    sys.settings.dt = dt_user;
  } else {
    if (dt_user > safety * crit)
      cfg.fail("dem.time_step",
               fmt::format("{:.4g} s is above the stable limit {:.4g} s ({} x critical time step {:.4g} s of this "
                           "sample{}); set dem.time_step = 0 for automatic, a value <= {:.4g}, or dem.mass_scaling = true",
                           dt_user, safety * crit, safety, crit, with, safety * crit));
    sys.settings.dt = dt_user;
  }
  log::info("time step {:.4g} s (critical {:.4g} s{}{})", sys.settings.dt, crit, with,
            cfg.boolean("dem.mass_scaling") && dt_user > 0 ? ", inertial masses scaled" : "");
  check_contacts_to_come(cfg, sys);
  refuse_gravity_jump(cfg, sys);
}

void refuse_wall_jump(const Config& cfg, const std::string& key, const DemSystem& sys, std::string_view wall,
                      std::string_view usual) {
  const auto& r = sys.particles.radius;
  if (r.empty()) return;
  const Real v = cfg.real(key), dt = sys.settings.dt, r_min = *std::min_element(r.begin(), r.end());
  if (v * dt > kMaxWallStep * r_min)
    cfg.fail(key, fmt::format("{:.4g} m/s moves the {} {:.3g} m in one time step ({:.4g} s), {:.3g} of the smallest "
                              "particle radius ({:.4g} m); the limit is {}: {} (the step is the grains' own, ~sqrt(m/k): "
                              "a density far too high or a stiffness far too low lengthens it; see the time step line "
                              "above)",
                              v, wall, v * dt, dt, v * dt / r_min, r_min, kMaxWallStep, usual));
}

void refuse_gravity_jump(const Config& cfg, const DemSystem& sys) {
  const auto& r = sys.particles.radius;
  if (r.empty()) return;
  const Real g = sys.settings.gravity.stableNorm(), dt = sys.settings.dt, r_min = *std::min_element(r.begin(), r.end());
  if (g * dt * dt > kMaxWallStep * r_min)
    cfg.fail("dem.gravity", fmt::format("|g| = {:.4g} m/s^2 moves a grain at rest {:.3g} m in one time step ({:.4g} s), "
                                        "{:.3g} of the smallest particle radius ({:.4g} m); the limit is {}: the grains "
                                        "would fall through each other (Earth: 9.81; a centrifuge: a few hundred g)",
                                        g, g * dt * dt, dt, g * dt * dt / r_min, r_min, kMaxWallStep));
}

}  // namespace ff::dem
