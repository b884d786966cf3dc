// The contact and bond laws, registered by name (as LAMMPS "styles", STYLE.md 1): a law is one
// file in src/dem/contact/ or src/dem/bond/ plus one line in a list below. The engine picks
// the active law once per stage (visit_law) and runs a loop templated on it: no per-contact
// virtual call or branch on the law.
//
// A contact law `L` provides (see linear_contact.hpp):
//   L::name; L::Params (with `fric`, the Coulomb friction, read from the common key
//   dem.contact.PAIR.friction); L::State = ContactState;
//   L::declare(ParamTable&)                 its own keys dem.contact.*.KEY (units, defaults, ranges);
//   L::read(cfg, table)                     Params of one pair table ("dem.contact.a-b");
//   L::elastic(E, nu)                       Params of an elastic material (particle membrane), fric 0;
//   L::force(p, g, state, dt, dim, fn)      force on B;
//   L::normal_stiffness_at(p, rA, rB, overlap, dim)   kn at this overlap (dashpot, walls, membrane);
//   L::time_step_stiffness(p, rA, rB, overlap, dim)   max(kn, ks) for the critical time step;
//   L::normal_force(p, rA, rB, overlap, dim)          |Fn| at this overlap (genesis);
//   L::strain_energy(p, rA, rB, overlap, state, dim)  energy stored in the contact [J].
// A bond law `B` provides (see parallel_bond.hpp):
//   B::name; B::checkpoint_key; B::Material; B::State; B::Prepared (what the hot loop reads);
//   B::declare(ParamTable&), B::read(cfg, table, dim), B::elastic(E, nu, strength);
//   B::prepare(material) -> Prepared; B::install(material, ends) -> State (stress-free);
//   B::compute_bond(prepared, state, particles, i, j, dt, dim, load) -> BondFailure;
//   B::time_step_stiffness(material, state, rA, rB, dim, k, krot);
//   B::crack_size(material, rA, rB, dim); B::energy(material, state, rA, rB, dim) [J].
#pragma once
#include <string>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <vector>

#include "dem/bond/cohesive_bond.hpp"
#include "dem/bond/no_bond.hpp"
#include "dem/bond/parallel_bond.hpp"
#include "dem/bond/rotational_bond.hpp"
#include "dem/contact/hertz_mindlin.hpp"
#include "dem/contact/linear_contact.hpp"

namespace ff::dem {

template <class... L> struct LawList {
  static constexpr int size = sizeof...(L);
};

// ---- The registered laws: one line each. ----------------------------------------------------
using ContactLaws = LawList<
    LinearContact,
    HertzMindlinContact,
    CohesiveContact>;
using BondLaws = LawList<
    ParallelBond,
    RotationalBond,
    NoBond,
    CohesiveBond>;
// ---------------------------------------------------------------------------------------------

// Calls f(std::type_identity<Law>{}) for every law of the list, in order.
template <class... L, class F> void for_each_law(LawList<L...>, F&& f) { (f(std::type_identity<L>{}), ...); }

// Calls f(std::type_identity<Law>{}) for the law at `index` of the list (once per stage).
template <class... L, class F> void visit_law(LawList<L...>, int index, F&& f) {
  int k = 0;
  ((k++ == index ? (f(std::type_identity<L>{}), true) : false) || ...);
}

// Index of Law in the list (compile time).
template <class Law, class... L> constexpr int law_index(LawList<L...>) {
  int k = 0, found = -1;
  ((std::is_same_v<Law, L> ? (found = k, ++k) : ++k), ...);
  return found;
}

// Index of the law called `name`, or -1.
template <class... L> int law_index_of(LawList<L...>, std::string_view name) {
  int k = 0, found = -1;
  ((L::name == name ? (found = k, ++k) : ++k), ...);
  return found;
}

// The registered names, e.g. "\"linear\", \"hertz_mindlin\"" (error messages).
template <class... L> std::string law_names(LawList<L...>) {
  std::string s;
  ((s += (s.empty() ? "\"" : ", \"") + std::string(L::name) + "\""), ...);
  return s;
}
template <class... L> std::vector<std::string> law_name_list(LawList<L...>) { return {std::string(L::name)...}; }

template <class... L> std::string_view law_name(LawList<L...>, int index) {
  std::string_view s;
  int k = 0;
  ((k++ == index ? (s = L::name, true) : false) || ...);
  return s;
}

// One per-pair table per law: std::tuple<std::vector<L::Params>...> (contacts) and
// std::tuple<std::vector<B::Material>...> (bonds), std::tuple<std::vector<B::State>...>.
template <class List> struct ContactTablesOf;
template <class... L> struct ContactTablesOf<LawList<L...>> { using type = std::tuple<std::vector<typename L::Params>...>; };
template <class List> struct BondTablesOf;
template <class... L> struct BondTablesOf<LawList<L...>> { using type = std::tuple<std::vector<typename L::Material>...>; };
template <class List> struct BondStatesOf;
template <class... L> struct BondStatesOf<LawList<L...>> { using type = std::tuple<std::vector<typename L::State>...>; };
template <class List> struct BondPreparedOf;
template <class... L> struct BondPreparedOf<LawList<L...>> { using type = std::tuple<std::vector<typename L::Prepared>...>; };

using ContactTables = ContactTablesOf<ContactLaws>::type;
using BondTables = BondTablesOf<BondLaws>::type;
using BondStates = BondStatesOf<BondLaws>::type;
using BondPrepared = BondPreparedOf<BondLaws>::type;

}  // namespace ff::dem
