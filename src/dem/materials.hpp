// Material groups (e.g. matrix, inclusion) and the contact and bond properties of every pair
// of groups (matrix-matrix, inclusion-inclusion, matrix-inclusion), as seed 000 Table 7.
// The laws themselves are registered in laws.hpp; Materials holds which one is active and a
// per-pair table for each (only the active law's table is read by the engine).
#pragma once
#include <string>
#include <vector>

#include "dem/laws.hpp"

namespace ff::dem {

// Every pair of groups has its own contact (and bond) table, n (n + 1) / 2 of them, and the
// pair tables below hold n^2 entries: 64 groups need 2,080 tables, far more phases than a
// segmented rock image has. Scenarios declaring more are refused (dem::build_materials).
inline constexpr int kMaxGroups = 64;

struct Materials {
  std::vector<std::string> group_names;
  std::vector<Real> density;  // [kg/m^3] per group
  int contact_law = law_index<LinearContact>(ContactLaws{});  // index in ContactLaws
  int bond_law = law_index<ParallelBond>(BondLaws{});         // index in BondLaws
  // Per law, per ordered pair index a*n+b (symmetric: both orders hold the same values).
  ContactTables contact;
  BondTables bond;
  Real normal_damping_ratio = 0;  // viscous dashpot, fraction of critical [-]

  int groups() const { return static_cast<int>(group_names.size()); }
  int pair(int a, int b) const { return a * groups() + b; }
  int group_index(const std::string& name) const {
    for (int g = 0; g < groups(); ++g)
      if (group_names[g] == name) return g;
    return -1;
  }

  template <class Law> std::vector<typename Law::Params>& contact_params() {
    return std::get<law_index<Law>(ContactLaws{})>(contact);
  }
  template <class Law> const std::vector<typename Law::Params>& contact_params() const {
    return std::get<law_index<Law>(ContactLaws{})>(contact);
  }
  template <class Law> std::vector<typename Law::Material>& bond_params() {
    return std::get<law_index<Law>(BondLaws{})>(bond);
  }
  template <class Law> const std::vector<typename Law::Material>& bond_params() const {
    return std::get<law_index<Law>(BondLaws{})>(bond);
  }
  template <class Law> void set_contact_law() { contact_law = law_index<Law>(ContactLaws{}); }
  template <class Law> void set_bond_law() { bond_law = law_index<Law>(BondLaws{}); }
  template <class Law> bool contact_is() const { return contact_law == law_index<Law>(ContactLaws{}); }
  template <class Law> bool bond_is() const { return bond_law == law_index<Law>(BondLaws{}); }
  bool has_bonds() const { return !bond_is<NoBond>(); }
  std::string_view contact_law_name() const { return law_name(ContactLaws{}, contact_law); }
  std::string_view bond_law_name() const { return law_name(BondLaws{}, bond_law); }

  // Calls f(std::type_identity<Law>{}) with the active contact (bond) law: once per stage.
  template <class F> void with_contact_law(F&& f) const { visit_law(ContactLaws{}, contact_law, f); }
  template <class F> void with_bond_law(F&& f) const { visit_law(BondLaws{}, bond_law, f); }

  Real friction(int pair_index) const {
    Real mu = 0;
    with_contact_law([&]<class Law>(std::type_identity<Law>) { mu = contact_params<Law>()[pair_index].fric; });
    return mu;
  }
};

}  // namespace ff::dem
