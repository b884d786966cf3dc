// Material groups (e.g. matrix, inclusion) and the contact and bond properties of every pair
// of groups (matrix-matrix, inclusion-inclusion, matrix-inclusion), as seed 000 Table 7.
#pragma once
#include <string>
#include <vector>

#include "dem/bond/parallel_bond.hpp"
#include "dem/bond/rotational_bond.hpp"
#include "dem/contact/hertz_mindlin.hpp"
#include "dem/contact/linear_contact.hpp"

namespace ff::dem {

// Every pair of groups has its own contact (and bond) table, n (n + 1) / 2 of them, and the
// pair tables below hold n^2 entries: 64 groups need 2,080 tables, far more phases than a
// segmented rock image has. Scenarios declaring more are refused (dem::build_materials).
inline constexpr int kMaxGroups = 64;

enum class ContactLaw : std::uint8_t { Linear, HertzMindlin };
enum class BondLaw : std::uint8_t { None, Parallel, Rotational };

struct Materials {
  std::vector<std::string> group_names;
  std::vector<Real> density;  // [kg/m^3] per group
  ContactLaw contact_law = ContactLaw::Linear;
  BondLaw bond_law = BondLaw::Parallel;
  // Per ordered pair index a*n+b (symmetric: both orders hold the same values).
  std::vector<LinearContact::Params> linear;
  std::vector<HertzMindlinContact::Params> hertz;
  std::vector<ParallelBond::Material> parallel;
  std::vector<RotationalBond::Material> rotational;
  Real normal_damping_ratio = 0;  // viscous dashpot, fraction of critical [-]

  int groups() const { return static_cast<int>(group_names.size()); }
  int pair(int a, int b) const { return a * groups() + b; }
  int group_index(const std::string& name) const {
    for (int g = 0; g < groups(); ++g)
      if (group_names[g] == name) return g;
    return -1;
  }
  Real friction(int pair_index) const {
    return contact_law == ContactLaw::Linear ? linear[pair_index].fric : hertz[pair_index].fric;
  }
};

}  // namespace ff::dem
