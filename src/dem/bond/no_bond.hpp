// dem.bond_law = "none": no bonds are installed (granular samples); every dem.bond.* key is
// then an error (there is no law to read it).
#pragma once
#include <string>
#include <string_view>

#include "dem/bond/bond_load.hpp"
#include "dem/particle_store.hpp"
#include "io/params.hpp"

namespace ff::dem {

struct BondEnds;

struct NoBond {
  static constexpr std::string_view name = "none";
  static constexpr std::string_view checkpoint_key = "";  // no state
  static constexpr bool installs_bonds = false;
  struct Material {};
  struct State {};
  using Prepared = Material;
  static void declare(ParamTable&) {}
  static Material read(const Config&, const std::string&, int) { return {}; }
  static Material elastic(Real, Real, Real) { return {}; }
  static Prepared prepare(const Material& m) { return m; }
  static State install(const Material&, const BondEnds&) { return {}; }
  static BondFailure compute_bond(const Prepared&, State&, const ParticleStore&, Index, Index, Real, int, BondLoad&) {
    return BondFailure::None;
  }
  static void time_step_stiffness(const Material&, const State&, Real, Real, int, Real& k, Real& krot) { k = krot = 0; }
  static Real crack_size(const Material&, Real, Real, int) { return 0; }
  static Real energy(const Material&, const State&, Real, Real, int) { return 0; }
};

}  // namespace ff::dem
