// Fast checks of the triaxial test (issue 4, items 1-3; seed 000 [S000] Zhao, Konietzky &
// Herbst 2021, sec. 5.1) on a small coal-matrix cylinder (7 x 14 mm, ~600 spheres, seed 000
// Table 7 micro-parameters). The full-size report is docs/validation/triaxial.md.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "io/checkpoint.hpp"
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

// Bit-for-bit equality of two checkpointed particle states.
void expect_same_state(const std::filesystem::path& a, const std::filesystem::path& b) {
  CheckpointReader ra(a / "checkpoint" / "state.ffcp"), rb(b / "checkpoint" / "state.ffcp");
  for (const char* tag : {"dem.pos", "dem.vel", "dem.omega"}) {
    std::vector<Vec3> va, vb;
    ra.get(tag, va);
    rb.get(tag, vb);
    ASSERT_EQ(va.size(), vb.size()) << tag;
    EXPECT_EQ(std::memcmp(va.data(), vb.data(), va.size() * sizeof(Vec3)), 0) << tag;
  }
}

}  // namespace

TEST(TriaxialValidation, MembraneIsotropicStageAndEquilibrium) {
  // Isotropic stage: platen stress and membrane confinement within the stage tolerance (2%)
  // of sigma3. By equilibrium, the Love-Weber average stress of the whole sample over the
  // volume the membrane encloses equals the boundary stresses (METHODS.md 1.7): tolerance 3%
  // (membrane facets vs the particles' true envelope). The measurement spheres (each with its
  // own porosity) see the core only, which at 7 particles across is denser and stiffer than the
  // wall-affected shell and holds a few dozen particles: their mean pressures read +1.7%, +4.5%
  // and +17% here, bounded at 20%. The 5% criterion holds at seed 000's resolution:
  // test_triaxial_spheres_long (make test-long) and docs/validation/triaxial.md.
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
    EXPECT_NEAR(mean, p, 0.20 * p);
    EXPECT_GT(s["particles"].get<int>(), 10);
  }
  // Deviatoric stage: the membrane holds the confinement (mean over the loaded band) within 5%
  // up to the peak, the curve has a peak and softens to the stop fraction.
  const auto& conf = r.series.column("confinement_Pa");
  const auto& q = r.series.column("differential_stress_Pa");
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
  // Interrupted in the deviatoric stage and resumed: bit-identical to an uninterrupted run, with
  // a rigid cylinder and with a flexible membrane (its contacts get their history back).
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
    EXPECT_EQ(full.series_text, res.series_text) << lateral;
    EXPECT_EQ(qa, qb) << lateral;
  }
  std::filesystem::remove_all(a);
  std::filesystem::remove_all(b);
}

TEST(TriaxialValidation, ParticleMembraneConfinesTheSampleLikeTheFlexibleMembrane) {
  // Particle membrane ([S000] sec. 6 and Fig. 15; de Bono et al. 2012; METHODS.md 3): bonded
  // spheres, each pushed towards the axis by a force of constant magnitude p A_i fixed when it is
  // built. Isotropic stage: platen stress within the stage tolerance (2%) of sigma3; by
  // equilibrium the lateral stress the sample carries (Love-Weber average over the volume inside
  // the membrane, METHODS.md 1.7) and the reported confinement (total force / current inner
  // surface) within 10% of sigma3 (spheres nestling in the sample's surface hollows make the inner
  // surface uneven; measured +2% and +7%). Peak: [S000] Fig. 15 finds a clearly lower strength
  // than with its flexible wall. Not reproduced here, so not asserted: the membrane's mean radius
  // hardly grows before the peak while the platens close, so the constant forces act on a
  // slightly smaller area and the applied confinement rises (+8% at the peak). Measured peaks,
  // particle vs flexible membrane: 15.26 vs 15.31 MPa in this run, 14.95 vs 15.12 MPa at the
  // default 0.1 m/s, 14.50 vs 14.43 MPa for examples/triaxial_c1.toml. Asserted: within 10%.
  const double p = 5e6;
  const auto out = test::scratch("triax_particle_membrane");
  const std::vector<std::string> faster = {"triaxial.platen_velocity=0.2", "triaxial.stop_fraction=0.85"};
  ASSERT_EQ(test::run_scenario(small_triaxial("particle_membrane", p), faster, out, 1), RunStatus::Finished);
  const auto r = test::collect(out);
  const auto& iso = r.summary["isotropic_stage"];
  EXPECT_TRUE(iso["converged"].get<bool>());
  EXPECT_NEAR(iso["platen_stress_Pa"].get<double>(), p, 0.02 * p);
  EXPECT_NEAR(iso["whole_sample_lateral_Pa"].get<double>(), p, 0.10 * p);
  EXPECT_NEAR(iso["confinement_Pa"].get<double>(), p, 0.10 * p);
  const auto& pm = r.summary["particle_membrane"];
  EXPECT_EQ(pm["bonds"].get<long>(), pm["n_theta"].get<long>() * (2 * pm["n_z"].get<long>() - 1));
  // No crack involves the membrane: its bonds never break and it is bonded to nothing else.
  EXPECT_EQ(r.cracks_text.find("membrane"), std::string::npos);
  const double q_pm = r.summary["peak_differential_stress_Pa"];
  ASSERT_EQ(test::run_scenario(small_triaxial("membrane", p), faster, out, 1), RunStatus::Finished);
  const auto fw = test::collect(out);
  const double q_fw = fw.summary["peak_differential_stress_Pa"];
  // The same sample; its figures leave the membrane's spheres and bonds out.
  EXPECT_EQ(r.summary["sample"]["particles"], fw.summary["sample"]["particles"]);
  EXPECT_EQ(r.series.column("intact_bonds")[0] + r.series.column("cracks_total")[0],
            r.summary["sample"]["bonds"].get<double>());
  EXPECT_NEAR(q_pm, q_fw, 0.10 * q_fw) << "particle membrane " << q_pm << " Pa, flexible membrane " << q_fw << " Pa";
  std::filesystem::remove_all(out);
}

TEST(TriaxialValidation, FrictionalFlexibleMembraneCarriesAxialLoad) {
  // What seed 000's Fig. 15 difference takes in this model (docs/dem.md, docs/validation/
  // triaxial.md): with frictional element contacts (membrane.friction = -1: each particle's own
  // contact friction, 0.4) the flexible membrane's elements, which move only along their normals,
  // hold the sample's surface where it slides along them. The sleeve then carries axial load: the
  // peak rises (measured +32% on this small sample, +7% on validate-triaxial's C1 at 2.5 MPa;
  // asserted > +10%), and in the isotropic stage the whole sample's axial stress (Love-Weber, over
  // the enclosed volume) no longer equals the platens' (measured +21%; frictionless within 3%, see
  // MembraneIsotropicStageAndEquilibrium; asserted > +5%).
  const double p = 5e6;
  const auto out = test::scratch("triax_friction");
  const std::vector<std::string> faster = {"triaxial.platen_velocity=0.2", "triaxial.stop_fraction=0.85"};
  ASSERT_EQ(test::run_scenario(small_triaxial("membrane", p), faster, out, 1), RunStatus::Finished);
  const double q0 = test::collect(out).summary["peak_differential_stress_Pa"];
  std::vector<std::string> frictional = faster;
  frictional.push_back("membrane.friction=-1");
  ASSERT_EQ(test::run_scenario(small_triaxial("membrane", p), frictional, out, 1), RunStatus::Finished);
  const auto r = test::collect(out);
  const double q1 = r.summary["peak_differential_stress_Pa"];
  EXPECT_GT(q1, 1.10 * q0) << "frictional " << q1 << " Pa, frictionless " << q0 << " Pa";
  const auto& iso = r.summary["isotropic_stage"];
  EXPECT_GT(iso["whole_sample_axial_Pa"].get<double>(), 1.05 * iso["platen_stress_Pa"].get<double>());
  std::filesystem::remove_all(out);
}

TEST(TriaxialValidation, ParticleMembraneRunResumesAndIgnoresTheThreadCount) {
  // Everything the particle membrane needs is in the DEM state (spheres, bonds, inward loads) and
  // the checkpointed layout. A run on 2 threads with every loop parallel (dem.parallel_min = 0),
  // interrupted in the isotropic stage and resumed on 1 thread into the deviatoric stage, is
  // bit-identical to an uninterrupted run on 1 thread: same files, same particle state.
  const std::string text = small_triaxial("particle_membrane", 5e6);
  const std::vector<std::string> sets = {"dem.parallel_min=0"};
  const auto a = test::scratch("pm_whole"), b = test::scratch("pm_resumed");
  const long stop = 7000;  // the isotropic stage ends after ~6400 steps
  ASSERT_EQ(test::run_scenario(text, sets, a, 1, stop), RunStatus::Interrupted);
  ASSERT_EQ(test::run_scenario(text, sets, b, 2, 3000), RunStatus::Interrupted);
  ASSERT_EQ(test::run_scenario(text, sets, b, 1, stop, true), RunStatus::Interrupted);
  const std::string series = test::slurp(a / "series.csv");
  EXPECT_GT(std::count(series.begin(), series.end(), '\n'), 5) << "the deviatoric stage must have started";
  EXPECT_TRUE(test::slurp(a / "isotropic.csv") == test::slurp(b / "isotropic.csv"));
  EXPECT_TRUE(series == test::slurp(b / "series.csv"));
  expect_same_state(a, b);
  std::filesystem::remove_all(a);
  std::filesystem::remove_all(b);
}
