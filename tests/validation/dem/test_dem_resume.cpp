// Resume is bit-for-bit for the DEM drivers (issue 12, part 3): a run interrupted at any step
// (inside a stage, across the triaxial stage change, by --max-steps, a stop signal or a damaged
// newest checkpoint) and resumed, also resumed -> interrupted -> resumed, writes the same
// series.csv, cracks.csv and summary.json as the uninterrupted run (timings excepted:
// resume_compare.hpp).
#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <fstream>
#include <thread>

#include "core/interrupt.hpp"
#include "drivers/run_control.hpp"
#include "io/checkpoint.hpp"
#include "resume_compare.hpp"
#include "ucs_test_support.hpp"

using namespace ff;

namespace {

// Runs `text` to the end in `whole`, then in `cut` interrupted at each step of `stops` in turn
// (each a resume of the previous one), and resumed to the end; the two must agree.
void expect_resume_chain_identical(const std::string& text, const std::vector<std::string>& sets,
                                   const std::filesystem::path& whole, const std::filesystem::path& cut,
                                   const std::vector<long>& stops, bool run_whole = true) {
  if (run_whole) {
    ASSERT_EQ(test::run_scenario(text, sets, whole, 1), RunStatus::Finished);
  }
  std::string what = "interrupted at";
  for (std::size_t k = 0; k < stops.size(); ++k) {
    ASSERT_EQ(test::run_scenario(text, sets, cut, 1, stops[k], k > 0), RunStatus::Interrupted) << stops[k];
    what += ' ';
    what += std::to_string(stops[k]);
  }
  ASSERT_EQ(test::run_scenario(text, sets, cut, 1, 0, true), RunStatus::Finished);
  test::expect_same_results(whole, cut, what);
}

std::string small_triaxial(const std::string& lateral) {
  std::string s = test::small_ucs_scenario(3);
  s.replace(s.find("driver = \"ucs\""), 14, "driver = \"triaxial\"");
  s.replace(s.find("[ucs]\n"), 6, "[triaxial]\nlateral = \"" + lateral + "\"\n");
  return s;
}

long steps_of(const std::filesystem::path& dir) {
  return test::collect(dir).summary["steps"].get<long>();
}

}  // namespace

TEST(DemResume, Ucs3dResumedAtSeveralPointsIsBitForBit) {
  // Was: the lateral-strain gauge was re-selected at resume from the platens' current position,
  // so lateral and volumetric strain and Poisson's ratio changed after a resume (with this seed,
  // resumed at n/4: nu 0.38692 instead of 0.38978, final lateral strain -1.1395% vs -1.1346%).
  const std::string text = test::small_ucs_scenario(3);
  const std::vector<std::string> sets = {"sample.seed=3"};
  const auto a = test::scratch("r3_whole"), b = test::scratch("r3_cut");
  ASSERT_EQ(test::run_scenario(text, sets, a, 1), RunStatus::Finished);
  const long n = steps_of(a);
  EXPECT_GT(test::collect(a).summary["cracks"]["total"].get<long>(), 0);
  // Elastic stage, peak, softening: each a resume of the previous interruption.
  expect_resume_chain_identical(text, sets, a, b, {n / 4, n / 2, 3 * n / 4}, false);
  std::filesystem::remove_all(a);
  std::filesystem::remove_all(b);
}

TEST(DemResume, StopRequestWritesACheckpointAndResumesBitForBit) {
  // SIGINT/SIGTERM set the stop flag; the driver checkpoints at its next row and stops.
  const std::string text = test::small_ucs_scenario(2);
  const auto a = test::scratch("sig_whole"), b = test::scratch("sig_cut");
  ASSERT_EQ(test::run_scenario(text, {}, a, 1), RunStatus::Finished);
  request_stop(2);  // before the run: stops at the first row
  EXPECT_EQ(test::run_scenario(text, {}, b, 1), RunStatus::Interrupted);
  clear_stop_request();
  EXPECT_TRUE(std::filesystem::exists(b / "checkpoint" / "state.ffcp"));
  // From another thread while the resumed run is going.
  std::thread stopper([] {
    std::this_thread::sleep_for(std::chrono::milliseconds(150));
    request_stop(15);
  });
  const RunStatus st = test::run_scenario(text, {}, b, 1, 0, true);
  stopper.join();
  clear_stop_request();
  if (st == RunStatus::Interrupted) {
    ASSERT_EQ(test::run_scenario(text, {}, b, 1, 0, true), RunStatus::Finished);
  }
  test::expect_same_results(a, b, "stopped by request");
  std::filesystem::remove_all(a);
  std::filesystem::remove_all(b);
}

TEST(DemResume, DamagedNewestCheckpointFallsBackToThePreviousOne) {
  // Two checkpoints (at 1/3 and 2/3 of the run); the newest is cut short as by a crash while
  // the disk filled up: resume uses the older one, and series.csv, cracks.csv and the VTK series
  // are put back to it, so the results are still those of the uninterrupted run.
  const std::string text = test::small_ucs_scenario(2);
  const auto a = test::scratch("fb_whole"), b = test::scratch("fb_cut");
  ASSERT_EQ(test::run_scenario(text, {"output.vtk=true"}, a, 1), RunStatus::Finished);
  const long n = steps_of(a);
  ASSERT_EQ(test::run_scenario(text, {"output.vtk=true"}, b, 1, n / 3), RunStatus::Interrupted);
  ASSERT_EQ(test::run_scenario(text, {"output.vtk=true"}, b, 1, 2 * n / 3, true), RunStatus::Interrupted);
  const auto newest = b / "checkpoint" / "state.ffcp";
  ASSERT_TRUE(std::filesystem::exists(previous_checkpoint_path(newest)));
  std::filesystem::resize_file(newest, std::filesystem::file_size(newest) / 2);
  ASSERT_EQ(test::run_scenario(text, {"output.vtk=true"}, b, 1, 0, true), RunStatus::Finished);
  test::expect_same_results(a, b, "resumed from the previous checkpoint");
  EXPECT_TRUE(test::slurp(a / "vtk" / "particles.pvd") == test::slurp(b / "vtk" / "particles.pvd"));
  std::filesystem::remove_all(a);
  std::filesystem::remove_all(b);
}

TEST(DemResume, TheCheckpointAtTheStartResumesBitForBit) {
  // Every run checkpoints once set up, so a kill before the first wall-clock checkpoint leaves a
  // resumable folder too. Here the newest checkpoint (at the interruption) is damaged, so resume
  // starts from the one written at step 0.
  const std::vector<std::string> texts = {test::small_ucs_scenario(2), small_triaxial("rigid_cylinder")};
  const std::vector<std::string> sets = {"triaxial.platen_velocity=0.2", "triaxial.stop_fraction=0.85"};
  for (const std::string& text : texts) {
    const auto a = test::scratch("start_whole"), b = test::scratch("start_cut");
    const auto faster = text == texts[0] ? std::vector<std::string>{} : sets;
    ASSERT_EQ(test::run_scenario(text, faster, a, 1), RunStatus::Finished);
    ASSERT_EQ(test::run_scenario(text, faster, b, 1, 200), RunStatus::Interrupted);  // before any stage ends
    const auto newest = b / "checkpoint" / "state.ffcp";
    ASSERT_EQ(CheckpointReader(previous_checkpoint_path(newest)).get_value<long>("dem.step"), 0);
    std::filesystem::remove(newest);
    ASSERT_EQ(test::run_scenario(text, faster, b, 1, 0, true), RunStatus::Finished);
    test::expect_same_results(a, b, "resumed from step 0");
    std::filesystem::remove_all(a);
    std::filesystem::remove_all(b);
  }
}

// Triaxial: interrupted inside the isotropic stage, inside the deviatoric stage, and across the
// stage change (isotropic -> deviatoric -> end), for each lateral boundary, made frictional
// (membrane.friction = -1) so that its contacts' shear history matters. Was: the isotropic
// stage's count of converged rows restarted at 0, and a flexible membrane's contact history
// was dropped at resume.
void triaxial_resume(const std::string& lateral) {
  const std::string text = small_triaxial(lateral);
  const std::vector<std::string> sets = {"triaxial.platen_velocity=0.2", "triaxial.stop_fraction=0.85",
                                         "membrane.friction=-1"};
  const auto a = test::scratch("tx_whole_" + lateral), b = test::scratch("tx_cut_" + lateral);
  ASSERT_EQ(test::run_scenario(text, sets, a, 1), RunStatus::Finished);
  const long n = steps_of(a);
  // The isotropic stage ends one row (50 steps) before the first row of series.csv, once 5 rows
  // in a row have met its criteria: 100 steps before its end is inside that run of rows.
  const long iso_end = static_cast<long>(test::collect(a).series.data[0].front()) - 50;
  ASSERT_LT(iso_end, n);
  const long mid_iso = iso_end / 2 / 50 * 50, mid_dev = (iso_end + n) / 2;
  // Checkpoints by wall clock are 60 s apart: a short run's older checkpoint is the one written
  // at the end of the isotropic stage.
  EXPECT_EQ(CheckpointReader(a / "checkpoint" / "state.prev.ffcp").get_value<long>("dem.step"), iso_end);
  expect_resume_chain_identical(text, sets, a, b, {mid_iso, iso_end - 100, mid_dev}, false);
  EXPECT_TRUE(test::slurp(a / "isotropic.csv") == test::slurp(b / "isotropic.csv"));
  std::filesystem::remove_all(a);
  std::filesystem::remove_all(b);
}

// The CLI's begin_output hook (it replaces an old run only once the new one is known to start)
// is called once on a fresh run, after set-up and before any file is written into out_dir, and
// never on resume.
void expect_begin_output_first(const std::string& text, long max_steps) {
  const Driver& d = find_driver(peek_driver(text, "test"));
  const ParamTable table = parameter_table(d);
  const Config cfg = load_scenario(table, "test.toml", text, {});
  const auto out = test::scratch("begin_output");
  std::filesystem::remove_all(out);
  std::filesystem::create_directories(out);
  RunOptions opt;
  opt.out_dir = out;
  opt.max_steps = max_steps;
  opt.progress_interval_s = 0;
  int calls = 0;
  bool empty = false;
  opt.begin_output = [&] {
    ++calls;
    empty = std::filesystem::is_empty(out);
  };
  ASSERT_EQ(d.run(cfg, opt), RunStatus::Interrupted);
  EXPECT_EQ(calls, 1);
  EXPECT_TRUE(empty) << "files were written before begin_output";
  opt.resume = true;
  opt.max_steps = 2 * max_steps;
  calls = 0;
  d.run(cfg, opt);
  EXPECT_EQ(calls, 0);
  std::filesystem::remove_all(out);
}

TEST(DemResume, BeginOutputComesAfterSetUpAndBeforeAnyFile) {
  expect_begin_output_first(test::small_ucs_scenario(2), 200);
  expect_begin_output_first(small_triaxial("rigid_cylinder"), 200);
  expect_begin_output_first(small_triaxial("particle_membrane"), 200);
}

TEST(DemResume, TriaxialRigidCylinderBothStages) { triaxial_resume("rigid_cylinder"); }
TEST(DemResume, TriaxialParticleMembraneBothStages) { triaxial_resume("particle_membrane"); }
TEST(DemResume, TriaxialFlexibleMembraneBothStages) { triaxial_resume("membrane"); }

TEST(DemResume, RunControlNamesWhyARunStopsAndWhenToCheckpoint) {
  const Driver& d = find_driver("ucs");
  const ParamTable table = parameter_table(d);
  const Config cfg = load_scenario(table, "test.toml", "driver = \"ucs\"\n", {"output.checkpoint_wall_interval=0.05"});
  const auto dir = test::scratch("run_control");
  std::filesystem::create_directories(dir);
  RunOptions opt;
  opt.max_steps = 100;
  opt.abort_file = dir / "ABORT";
  drivers::RunControl c(cfg, opt);
  EXPECT_EQ(c.stop_reason(50), "");
  EXPECT_NE(c.stop_reason(100).find("--max-steps"), std::string::npos);
  request_stop(SIGINT);
  EXPECT_NE(c.stop_reason(50).find("SIGINT"), std::string::npos);
  clear_stop_request();
  request_stop(SIGTERM);
  EXPECT_NE(c.stop_reason(50).find("SIGTERM"), std::string::npos);
  clear_stop_request();
  std::ofstream(opt.abort_file) << "";
  EXPECT_NE(c.stop_reason(50).find("ABORT"), std::string::npos);
  std::filesystem::remove(opt.abort_file);
  // Wall-clock checkpoints: due once the interval has passed since the last one.
  EXPECT_FALSE(c.checkpoint_due());
  std::this_thread::sleep_for(std::chrono::milliseconds(60));
  EXPECT_TRUE(c.checkpoint_due());
  c.checkpoint_written();
  EXPECT_FALSE(c.checkpoint_due());
  RunOptions walled;
  walled.max_wall_s = 1e-9;
  EXPECT_NE(drivers::RunControl(cfg, walled).stop_reason(0).find("--max-wall"), std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST(DemResume, WallTimeCountsEverySession) {
  // Was: summary.json's wall_time_s counted only the last session of a resumed run. Now each
  // checkpoint records the run's wall time so far, and the resumed run adds its own.
  const std::string text = test::small_ucs_scenario(2);
  const auto a = test::scratch("wall_whole"), b = test::scratch("wall_cut");
  ASSERT_EQ(test::run_scenario(text, {}, a, 1), RunStatus::Finished);
  const long n = steps_of(a);
  ASSERT_EQ(test::run_scenario(text, {}, b, 1, 9 * n / 10), RunStatus::Interrupted);
  CheckpointReader r(b / "checkpoint" / "state.ffcp");
  ASSERT_TRUE(r.has(drivers::RunControl::kWallTag));
  const double first = r.get_value<double>(drivers::RunControl::kWallTag);
  EXPECT_GT(first, 0);
  ASSERT_EQ(test::run_scenario(text, {}, b, 1, 0, true), RunStatus::Finished);
  const double whole = test::collect(a).summary["wall_time_s"].get<double>();
  const double resumed = test::collect(b).summary["wall_time_s"].get<double>();
  std::printf("wall time: uninterrupted %.3f s; first session %.3f s (to 9/10 of the steps), whole resumed run %.3f s\n",
              whole, first, resumed);
  EXPECT_GE(resumed, first);
  test::expect_same_results(a, b, "resumed for the wall time");
  std::filesystem::remove_all(a);
  std::filesystem::remove_all(b);
}
