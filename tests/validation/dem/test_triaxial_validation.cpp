// Fast checks of the triaxial test (issue 4, items 1-3; seed 000 [S000] Zhao, Konietzky &
// Herbst 2021, sec. 5.1) on a small coal-matrix cylinder (7 x 14 mm, ~600 spheres, seed 000
// Table 7 micro-parameters). The full-size report is docs/validation/triaxial.md.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>

#include "ucs_test_support.hpp"

using namespace ff;

namespace {

void replace(std::string& s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  ASSERT_NE(at, std::string::npos) << from;
  s.replace(at, from.size(), to);
}

std::string small_triaxial(const std::string& lateral, double sigma3) {
  std::string s = test::small_ucs_scenario(3);
  replace(s, "driver = \"ucs\"", "driver = \"triaxial\"");
  replace(s, "[ucs]\n", "[triaxial]\nlateral = \"" + lateral + "\"\nconfining_pressure = " + std::to_string(sigma3) + "\n");
  return s;
}

}  // namespace

TEST(TriaxialValidation, MembraneIsotropicStageAndEquilibrium) {
  // Isotropic stage: platen stress and membrane confinement within the stage tolerance (2%)
  // of sigma3. By equilibrium, the Love-Weber average stress of the whole sample over the
  // volume the membrane encloses equals the boundary stresses (METHODS.md 1.7): tolerance 3%
  // (membrane facets vs the particles' true envelope). The measurement spheres see the core
  // only, which at 7 particles across is denser and stiffer than the wall-affected shell and
  // carries up to ~10% more: their mean pressure is bounded at 15% here. The 5% criterion of
  // the issue is checked at full size (2.6% measured at 20 x 40 mm; docs/validation/triaxial.md).
  const double p = 5e6;
  const auto out = test::scratch("triax_iso");
  ASSERT_EQ(test::run_scenario(small_triaxial("membrane", p), {}, out, 1), RunStatus::Finished);
  const auto r = test::collect(out);
  const auto& iso = r.summary["isotropic_stage"];
  EXPECT_TRUE(iso["converged"].get<bool>());
  EXPECT_NEAR(iso["platen_stress_Pa"].get<double>(), p, 0.02 * p);
  EXPECT_NEAR(iso["confinement_Pa"].get<double>(), p, 0.02 * p);
  EXPECT_NEAR(iso["whole_sample_axial_Pa"].get<double>(), iso["platen_stress_Pa"].get<double>(), 0.03 * p);
  EXPECT_NEAR(iso["whole_sample_lateral_Pa"].get<double>(), iso["confinement_Pa"].get<double>(), 0.03 * p);
  for (const auto& s : iso["measurement_spheres"]) {
    const double mean = (s["axial_Pa"].get<double>() + 2 * s["lateral_Pa"].get<double>()) / 3;
    EXPECT_NEAR(mean, p, 0.15 * p);
    EXPECT_GT(s["particles"].get<int>(), 10);
  }
  // Deviatoric stage: the membrane holds the confinement (mean over the loaded band) within 5%
  // up to the peak, the curve has a peak and softens to the stop fraction.
  const auto& conf = r.series.column("confinement");
  const auto& q = r.series.column("differential_stress");
  std::size_t peak = 0;
  for (std::size_t k = 0; k < q.size(); ++k)
    if (q[k] > q[peak]) peak = k;
  ASSERT_GT(peak, 5u);
  for (std::size_t k = 0; k <= peak; ++k) EXPECT_NEAR(conf[k], p, 0.05 * p) << "row " << k;
  EXPECT_LT(q.back(), 0.62 * q[peak]);
  EXPECT_GT(r.summary["poisson_ratio"].get<double>(), 0.0);
  // The membrane bulged unevenly: its ring radii differ along the axis by more than 1% of R.
  const auto& rings = r.summary["membrane"]["ring_radius_m"];
  double rmin = 1e9, rmax = 0;
  for (std::size_t j = 1; j + 1 < rings.size(); ++j) {
    rmin = std::min(rmin, rings[j].get<double>());
    rmax = std::max(rmax, rings[j].get<double>());
  }
  EXPECT_GT(rmax - rmin, 0.01 * 3.5e-3);
  std::filesystem::remove_all(out);
}

TEST(TriaxialValidation, ConfinementRaisesStrength) {
  // Frictional strength (seed 000 Eq. 1, Fig. 6): the peak differential stress at sigma3 =
  // 5 MPa exceeds the UCS of the same sample, with both lateral boundaries. Rigid cylinder:
  // its confinement is held within 5% up to the peak too.
  const auto out = test::scratch("triax_strength");
  ASSERT_EQ(test::run_scenario(test::small_ucs_scenario(3), {}, out, 1), RunStatus::Finished);
  const double ucs = test::collect(out).summary["ucs_Pa"];
  for (const char* lateral : {"membrane", "rigid_cylinder"}) {
    ASSERT_EQ(test::run_scenario(small_triaxial(lateral, 5e6), {}, out, 1), RunStatus::Finished) << lateral;
    const auto r = test::collect(out);
    const double q = r.summary["peak_differential_stress_Pa"];
    EXPECT_GT(q, 1.05 * ucs) << lateral << ": q_peak " << q << " vs UCS " << ucs;
    EXPECT_NEAR(r.summary["confinement_at_peak_Pa"].get<double>(), 5e6, 0.05 * 5e6) << lateral;
  }
  std::filesystem::remove_all(out);
}

TEST(TriaxialValidation, ResumeContinuesTheRun) {
  // Interrupted in the deviatoric stage and resumed: the rigid-cylinder run (all boundary
  // contacts restored exactly) is bit-identical to an uninterrupted one; the membrane run
  // searches its candidates again on resume, so it matches within 1% in the peak.
  const auto a = test::scratch("triax_full"), b = test::scratch("triax_resumed");
  for (const char* lateral : {"rigid_cylinder", "membrane"}) {
    const std::string text = small_triaxial(lateral, 5e6);
    ASSERT_EQ(test::run_scenario(text, {}, a, 1), RunStatus::Finished);
    const auto full = test::collect(a);
    const long stop = full.summary["steps"].get<long>() / 2;
    ASSERT_EQ(test::run_scenario(text, {}, b, 1, stop), RunStatus::Interrupted);
    ASSERT_EQ(test::run_scenario(text, {}, b, 1, 0, true), RunStatus::Finished);
    const auto res = test::collect(b);
    const double qa = full.summary["peak_differential_stress_Pa"], qb = res.summary["peak_differential_stress_Pa"];
    if (std::string(lateral) == "rigid_cylinder") {
      EXPECT_EQ(full.series_text, res.series_text);
      EXPECT_EQ(qa, qb);
    } else {
      EXPECT_NEAR(qb, qa, 0.01 * qa);
    }
  }
  std::filesystem::remove_all(a);
  std::filesystem::remove_all(b);
}
