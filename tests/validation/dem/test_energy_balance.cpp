// Energy bookkeeping closes (issue 13 item 6; src/dem/energy.hpp): over a UCS run that goes past
// the peak with bond breakage,
//   |W_boundaries - (dE_kin + dE_strain + D_damping + D_friction + D_dashpot + D_breakage)| <= 1% W
// with undamped contacts (no dashpot), with Cundall's local damping and without any damping (3D),
// and with a viscous dashpot (2D; then D_dashpot > 0). Reference: the conservation of energy the bookkeeping
// tracks, term by term as in PFC's energy tracking (Itasca PFC 5/6 documentation, "Energy
// tracking"; bond strain energy of Potyondy & Cundall 2004). Tolerance 1% (the issue's).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "ucs_test_support.hpp"

using namespace ff;
using namespace ff::test;

namespace {

void expect_balance_closes(const std::string& name, int dim, const std::vector<std::string>& sets, bool dashpot) {
  const auto out = scratch("energy_" + name);
  ASSERT_EQ(run_scenario(small_ucs_scenario(dim), sets, out, 1), RunStatus::Finished) << name;
  const UcsRun r = collect(out);
  const auto& s = r.series;
  const auto W = s.column("boundary_work_J"), err = s.column("energy_balance_error");
  const auto stress = s.column("axial_stress_Pa"), brk = s.column("bond_break_energy_J");
  const auto damp = s.column("damping_dissipation_J"), fric = s.column("friction_dissipation_J");
  const auto dash = s.column("dashpot_dissipation_J"), cracks = s.column("cracks_total");
  ASSERT_GT(W.size(), 10u);
  const std::size_t peak = static_cast<std::size_t>(std::max_element(stress.begin(), stress.end()) - stress.begin());
  EXPECT_LT(peak + 1, W.size()) << name << ": the run must go past the peak";
  EXPECT_GT(cracks.back(), 10) << name;
  EXPECT_GT(brk.back(), 0) << name << ": broken bonds release their strain energy";
  EXPECT_GT(fric.back(), 0) << name;
  EXPECT_GT(W.back(), 0) << name << ": the platens do work on the sample";
  for (std::size_t k = 0; k < W.size(); ++k) {
    if (W[k] < 0.05 * W.back()) continue;  // the first rows: too little work for a relative figure
    EXPECT_LE(std::abs(err[k]), 0.01) << name << " row " << k << ": W = " << W[k];
  }
  for (std::size_t k = 1; k < W.size(); ++k) {  // dissipations only grow
    EXPECT_GE(damp[k], damp[k - 1]) << name << " row " << k;
    EXPECT_GE(fric[k], fric[k - 1] - 1e-12 * fric.back()) << name << " row " << k;
    EXPECT_GE(brk[k], brk[k - 1]) << name << " row " << k;
  }
  if (dashpot) EXPECT_GT(dash.back(), 0) << name;
  else EXPECT_EQ(dash.back(), 0) << name;
  std::printf("%s: W = %.4g J, final balance error %.2e, D_damp %.3g, D_fric %.3g, D_dash %.3g, D_break %.3g J\n",
              name.c_str(), W.back(), err.back(), damp.back(), fric.back(), dash.back(), brk.back());
  std::filesystem::remove_all(out);
}

}  // namespace

TEST(EnergyBalance, ClosesOverUcsWithLocalDamping) {
  expect_balance_closes("local_damping_3d", 3, {"ucs.stop_fraction=0.85", "ucs.platen_velocity=0.3"}, false);
}

TEST(EnergyBalance, ClosesOverUcsWithoutAnyDamping) {
  expect_balance_closes("undamped_3d", 3, {"ucs.stop_fraction=0.85", "ucs.platen_velocity=0.3", "dem.local_damping=0"}, false);
}

TEST(EnergyBalance, ClosesWithAViscousDashpot) {
  expect_balance_closes("dashpot_2d", 2, {"ucs.stop_fraction=0.85", "ucs.platen_velocity=0.3", "dem.normal_damping_ratio=0.2"}, true);
}
