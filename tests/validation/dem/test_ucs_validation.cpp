// Validation of the UCS test of a bonded-particle sample (issue 2, item 10):
// a small 2D and 3D sample shows a linear elastic stage, a peak, softening and growing crack
// counts (the behaviour of Potyondy & Cundall 2004 Fig. 11 and seed 000 Fig. 12/21), and the
// measured Young's modulus scales linearly with the bond modulus (seed 000 section 5.2:
// "a linear relation between the macroscopic E and pb_emod"; tolerance 10%).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>

#include "ucs_test_support.hpp"

using namespace ff;

namespace {

// R^2 of a straight line through the points between 10% and 50% of the peak, pre-peak.
double linearity(const std::vector<double>& e, const std::vector<double>& s, std::size_t peak) {
  double n = 0, se = 0, ss = 0, see = 0, ses = 0, sss = 0;
  for (std::size_t k = 0; k <= peak; ++k) {
    if (s[k] < 0.1 * s[peak] || s[k] > 0.5 * s[peak]) continue;
    n += 1; se += e[k]; ss += s[k]; see += e[k] * e[k]; ses += e[k] * s[k]; sss += s[k] * s[k];
  }
  const double cov = n * ses - se * ss, ve = n * see - se * se, vs = n * sss - ss * ss;
  return cov * cov / (ve * vs);
}

void check_ucs_curve(int dim) {
  const auto out = test::scratch("ucs" + std::to_string(dim));
  ASSERT_EQ(test::run_scenario(test::small_ucs_scenario(dim), {}, out, 1), RunStatus::Finished);
  const auto r = test::collect(out);
  const auto& e = r.series.column("axial_strain");
  const auto& s = r.series.column("axial_stress_Pa");
  const auto& c = r.series.column("cracks_total");
  std::size_t peak = 0;
  for (std::size_t k = 0; k < s.size(); ++k)
    if (s[k] > s[peak]) peak = k;
  // A peak inside the curve, and softening to 60% of it (the stop criterion) afterwards.
  ASSERT_GT(peak, 5u);
  ASSERT_LT(peak + 1, s.size());
  EXPECT_LT(s.back(), 0.62 * s[peak]);
  EXPECT_NE(r.summary["stop_reason"].get<std::string>().find("fell below"), std::string::npos);
  // Linear elastic stage: R^2 > 0.995 between 10% and 50% of the peak.
  EXPECT_GT(linearity(e, s, peak), 0.995);
  // Cracks: none in the early elastic stage, growing, most of them after the peak.
  for (std::size_t k = 1; k < c.size(); ++k) EXPECT_GE(c[k], c[k - 1]);
  std::size_t quarter = 0;
  while (s[quarter] < 0.25 * s[peak]) ++quarter;
  EXPECT_EQ(c[quarter], 0.0);
  // More cracks form after the peak than up to it in the mean, but not in every packing of these
  // ~200-disk / ~600-sphere samples: over sample.seed 1-5 the 2D sample's final/peak crack counts
  // were 1.8, 11, 8.3, 2.3 and 1.2 (genesis of issue 13 item 7). One packing must keep cracking
  // after its peak.
  EXPECT_GT(c.back(), c[peak]);
  // Plausible elastic constants for these micro-parameters.
  const double E = r.summary["youngs_modulus_Pa"], nu = r.summary["poisson_ratio"], ucs = r.summary["ucs_Pa"];
  EXPECT_GT(E, 0.2e9);
  EXPECT_LT(E, 5e9);
  // Isotropic bounds of Poisson's ratio: 0.5 in 3D, 1 for a 2D (in-plane) medium.
  EXPECT_GT(nu, 0.0);
  EXPECT_LT(nu, dim == 3 ? 0.5 : 1.0);
  EXPECT_GT(ucs, 1e6);
  std::filesystem::remove_all(out);
}

}  // namespace

TEST(UcsValidation, Small2DShowsElasticStagePeakSofteningAndCracks) { check_ucs_curve(2); }

TEST(UcsValidation, Small3DShowsElasticStagePeakSofteningAndCracks) { check_ucs_curve(3); }

TEST(UcsValidation, YoungsModulusScalesLinearlyWithBondModulus) {
  // Doubling both moduli (bond and contact) must double E (seed 000 section 5.2); the
  // strengths are doubled too so the curve keeps its shape. Tolerance 10%.
  const auto out = test::scratch("emod");
  const std::string text = test::small_ucs_scenario(2);
  ASSERT_EQ(test::run_scenario(text, {}, out, 1), RunStatus::Finished);
  const double e1 = test::collect(out).summary["youngs_modulus_Pa"];
  ASSERT_EQ(test::run_scenario(text,
                               {"dem.bond.matrix-matrix.emod=4.18e9", "dem.contact.matrix-matrix.emod=4.18e9",
                                "dem.bond.matrix-matrix.tensile_strength=34.8e6", "dem.bond.matrix-matrix.cohesion=8.7e6"},
                               out, 1),
            RunStatus::Finished);
  const double e2 = test::collect(out).summary["youngs_modulus_Pa"];
  EXPECT_NEAR(e2 / e1, 2.0, 0.2) << "E1 = " << e1 << " Pa, E2 = " << e2 << " Pa";
  std::filesystem::remove_all(out);
}

TEST(UcsValidation, RotationalBondSampleAlsoFailsWithPeakAndCracks) {
  // The second bond law (Wang & Mora 6-DOF rotational bond, METHODS.md 1.8) chosen by name in
  // the scenario runs through the same engine: the 2D sample must still show a peak, softening
  // and cracks.
  const auto out = test::scratch("rot");
  // Table 7's bond table holds parallel-bond keys, which a rotational run refuses (they would
  // be ignored): the rotational bond gets its own keys below.
  std::string text = test::small_ucs_scenario(2);
  const std::string parallel_only = "emod = 2.09e9\nkratio = 14.65\ntensile_strength = 17.4e6\n";
  const auto bond = text.find("[dem.bond.matrix-matrix]\n" + parallel_only);
  ASSERT_NE(bond, std::string::npos);
  text.erase(bond + 25, parallel_only.size());
  ASSERT_EQ(test::run_scenario(text,
                               {"dem.bond_law=rotational", "dem.bond.matrix-matrix.youngs_modulus=2.09e9",
                                "dem.bond.matrix-matrix.poisson_ratio=0.25", "dem.bond.matrix-matrix.cohesion=8e6",
                                "dem.bond.matrix-matrix.friction_angle=30"},
                               out, 1),
            RunStatus::Finished);
  const auto r = test::collect(out);
  EXPECT_NE(r.summary["stop_reason"].get<std::string>().find("fell below"), std::string::npos);
  EXPECT_GT(r.summary["cracks"]["total"].get<long>(), 10);
  EXPECT_GT(r.summary["youngs_modulus_Pa"].get<double>(), 0.1e9);
  std::filesystem::remove_all(out);
}
