// The sedimentation driver (src/drivers/sedimentation) through the code path of `fracflow run`:
// an interrupted and resumed run is bit-for-bit the uninterrupted one (series.csv, summary.json
// without timings), 1 and 2 threads give the same series, and bad input is refused naming the key.
#include <gtest/gtest.h>
#include <omp.h>

#include <cstdio>

#include "core/error.hpp"
#include "lbm/flow_driver_runner.hpp"
#include "resume_compare.hpp"

namespace {

const char* kTwoDisks = R"(
driver = "sedimentation"
[lbm]
lattice = "D2Q9"
dx = 2.5e-4
[box]
size = [0.01, 0.02]
[fluid]
density = 1000.0
viscosity = 1.0e-5
sound_speed = 0.5
[particles]
x = [0.0049, 0.005]
y = [0.016, 0.012]
radius = [0.001]
density = 1200.0
[run]
end_time = 0.08
[output]
samples = 40
snapshots = 2
plots = false
)";

const char* kSphere = R"(
driver = "sedimentation"
[lbm]
lattice = "D3Q19"
dx = 5e-4
[box]
size = [0.01, 0.01, 0.014]
[fluid]
density = 1000.0
viscosity = 1.0e-5
sound_speed = 2.0
[particles]
x = [0.005]
y = [0.0051]
z = [0.01]
radius = [0.002]
density = 1200.0
[run]
end_time = 0.02
[output]
samples = 10
snapshots = 1
plots = false
)";

}  // namespace

using namespace ff::testing;

TEST(SedimentationDriver, ResumeIsBitForBit2D) {
  ASSERT_EQ(run_flow_driver_status("sed_full", kTwoDisks, {}), ff::RunStatus::Finished);
  ASSERT_EQ(run_flow_driver_status("sed_cut", kTwoDisks, {}, false, 0, 130), ff::RunStatus::Interrupted);
  ASSERT_EQ(run_flow_driver_status("sed_cut", kTwoDisks, {}, true), ff::RunStatus::Finished);
  ff::test::expect_same_results(flow_test_dir("sed_full"), flow_test_dir("sed_cut"), "2D disks resumed at step 130");
  const auto j = read_summary("sed_full");
  // The disks fall: the largest settling speed is positive and the Mach number small.
  EXPECT_GT(j["results"]["particles"][0]["max_settling_speed_m_per_s"].get<double>(), 0);
  EXPECT_LT(j["results"]["max_mach"].get<double>(), 0.3);
  EXPECT_GE(j["units"]["dem_sub_steps"].get<long>(), 1);
}

// lbm.psm_refresh: the fractions stay while the disks move less than 0.05 cells, so a resumed run
// must start from the geometry they came from (checkpointed), not from the positions at the cut.
TEST(SedimentationDriver, ResumeWithPsmRefreshIsBitForBit) {
  const std::vector<std::string> sets = {"lbm.psm_refresh=0.05"};
  ASSERT_EQ(run_flow_driver_status("sedr_full", kTwoDisks, sets), ff::RunStatus::Finished);
  ASSERT_EQ(run_flow_driver_status("sedr_cut", kTwoDisks, sets, false, 0, 130), ff::RunStatus::Interrupted);
  ASSERT_EQ(run_flow_driver_status("sedr_cut", kTwoDisks, sets, true), ff::RunStatus::Finished);
  ff::test::expect_same_results(flow_test_dir("sedr_full"), flow_test_dir("sedr_cut"), "psm_refresh 0.05, resumed at step 130");
  // The same physics as rebuilding every step: the settling speed within 1% (measured below).
  ASSERT_EQ(run_flow_driver_status("sedr_every", kTwoDisks, {}), ff::RunStatus::Finished);
  const double v0 = read_summary("sedr_every")["results"]["particles"][0]["max_settling_speed_m_per_s"].get<double>();
  const double v1 = read_summary("sedr_full")["results"]["particles"][0]["max_settling_speed_m_per_s"].get<double>();
  std::printf("max settling speed: rebuilt every step %.6g m/s, psm_refresh 0.05 %.6g m/s\n", v0, v1);
  EXPECT_NEAR(v1, v0, 0.01 * v0);
}

TEST(SedimentationDriver, ResumeIsBitForBit3D) {
  ASSERT_EQ(run_flow_driver_status("sed3_full", kSphere, {}), ff::RunStatus::Finished);
  ASSERT_EQ(run_flow_driver_status("sed3_cut", kSphere, {}, false, 0, 20), ff::RunStatus::Interrupted);
  ASSERT_EQ(run_flow_driver_status("sed3_cut", kSphere, {}, true), ff::RunStatus::Finished);
  ff::test::expect_same_results(flow_test_dir("sed3_full"), flow_test_dir("sed3_cut"), "3D sphere resumed at step 20");
}

TEST(SedimentationDriver, OneAndTwoThreadsIdentical) {
  const int n = omp_get_max_threads();
  omp_set_num_threads(1);
  ASSERT_EQ(run_flow_driver_status("sed_t1", kTwoDisks, {}), ff::RunStatus::Finished);
  omp_set_num_threads(2);
  ASSERT_EQ(run_flow_driver_status("sed_t2", kTwoDisks, {}), ff::RunStatus::Finished);
  omp_set_num_threads(n);
  EXPECT_TRUE(ff::test::read_bytes(flow_test_dir("sed_t1") / "series.csv") ==
              ff::test::read_bytes(flow_test_dir("sed_t2") / "series.csv"));
}

TEST(SedimentationDriver, BadInputNamesTheKey) {
  auto message = [](const std::vector<std::string>& sets) {
    try {
      run_flow_driver_status("sed_bad", kTwoDisks, sets);
    } catch (const ff::InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(message({"box.size=[0.01, 0.02, 0.03]"}).find("box.size"), std::string::npos);
  EXPECT_NE(message({"particles.y=[0.016, 0.0155]"}).find("overlap"), std::string::npos);
  // Two keys fixing the step; tau too close to 1/2 (real water's sound speed at this dx).
  EXPECT_NE(message({"fluid.tau=0.8"}).find("fluid.tau"), std::string::npos);
  EXPECT_NE(message({"fluid.sound_speed=0", "fluid.bulk_modulus=2.2e9"}).find("too close to 1/2"), std::string::npos);
  EXPECT_NE(message({"lbm.dx=7e-4"}).find("lbm.dx"), std::string::npos);
  EXPECT_NE(message({"dem.time_step=1e-3"}).find("dem.time_step"), std::string::npos);  // above the contact limit
}

// A grain driven far past the fluid's Mach limit stops the run, naming the keys. Before, a gravity
// of 1e300 m/s^2 (the fluid's Mach check sampled the fluid, which the grain had left) ran to the
// end with the grain at -1e298 m/s. Here the disks reach 10 m/s (g = 1e5, free fall over 1 ms),
// 0.5 m/s sound speed: Mach ~35 within the first rows.
TEST(SedimentationDriver, GrainPastTheMachLimitStopsTheRun) {
  std::string what;
  try {
    run_flow_driver_status("sed_mach", kTwoDisks, {"box.gravity=1e5", "fluid.reference_velocity=0.1"});
  } catch (const ff::NumericalError& e) {
    what = e.what();
  }
  EXPECT_NE(what.find("Mach number"), std::string::npos) << what;
  EXPECT_NE(what.find("box.gravity"), std::string::npos) << what;
  EXPECT_TRUE(std::filesystem::exists(flow_test_dir("sed_mach") / "checkpoint_failed"));
}
