// Runs of the flow drivers that are interrupted (wall-clock limit, checkpoint) and resumed give
// bit-identical series, results and final populations, on both lattices and precisions; and
// unstable numerics stop the run with a message that says what to change.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "io/checkpoint.hpp"
#include "flow_driver_runner.hpp"
#include "resume_compare.hpp"

namespace {

std::string slurp(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

const char* kCylinder = R"(
driver = "flow/cylinder"
[channel]
height = 0.04
length = 0.12
[cylinder]
diameter = 0.01
x = 0.03
y = 0.021
[inlet]
velocity = 0.01
[fluid]
viscosity = 1.0e-5
[lbm]
resolution = 6
time_step = 0.01
[run]
end_time = 40
[output]
samples = 40
snapshots = 4
checkpoints = 4
plots = false
)";

void expect_resume_identical(const std::string& name, const std::vector<std::string>& sets) {
  using namespace ff::testing;
  ASSERT_EQ(run_flow_driver_status(name + "_full", kCylinder, sets), ff::RunStatus::Finished);
  // A tiny wall-clock limit stops after the first sample, with a checkpoint.
  ASSERT_EQ(run_flow_driver_status(name + "_cut", kCylinder, sets, false, 1e-9), ff::RunStatus::Interrupted);
  const std::string partial = slurp(flow_test_dir(name + "_cut") / "series.csv");
  EXPECT_GT(partial.size(), 0u);
  ASSERT_EQ(run_flow_driver_status(name + "_cut", kCylinder, sets, true), ff::RunStatus::Finished);
  const std::string a = slurp(flow_test_dir(name + "_full") / "series.csv");
  const std::string b = slurp(flow_test_dir(name + "_cut") / "series.csv");
  EXPECT_GT(std::count(a.begin(), a.end(), '\n'), 30);
  EXPECT_EQ(a, b);
  EXPECT_EQ(read_summary(name + "_full")["results"], read_summary(name + "_cut")["results"]);
  EXPECT_EQ(slurp(flow_test_dir(name + "_full") / "checkpoint" / "state.ffcp"),
            slurp(flow_test_dir(name + "_cut") / "checkpoint" / "state.ffcp"));
  EXPECT_EQ(slurp(flow_test_dir(name + "_full") / "vtk" / "flow.pvd"), slurp(flow_test_dir(name + "_cut") / "vtk" / "flow.pvd"));
}

}  // namespace

TEST(LbmFlowResume, CylinderD2Q9DoubleBouzidi) { expect_resume_identical("resume_d2q9", {}); }

TEST(LbmFlowResume, CylinderD3Q19FloatHalfway) {
  expect_resume_identical("resume_d3q19", {"lbm.lattice=\"D3Q19\"", "lbm.depth_cells=2", "lbm.precision=\"float\"",
                                           "cylinder.wall=\"halfway\""});
}

TEST(LbmFlowResume, UnstableRunStopsWithAFix) {
  // A lattice inflow speed of 0.5 (Mach 0.87) is refused before the run starts, naming a fix.
  try {
    ff::testing::run_flow_driver_status("unstable_refused", kCylinder, {"lbm.time_step=0.05", "fluid.viscosity=1.0e-4"});
    FAIL() << "expected an input error";
  } catch (const ff::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("Mach number"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("lbm.resolution"), std::string::npos) << e.what();
  }
  // The NumericalError a run that must blow up stops with (empty, and a failure, if it does not).
  const auto blow_up_message = [](const std::string& name, const std::vector<std::string>& sets) -> std::string {
    try {
      ff::testing::run_flow_driver_status(name, kCylinder, sets);
    } catch (const ff::NumericalError& e) {
      return e.what();
    }
    ADD_FAILURE() << name << ": expected a numerical error";
    return "";
  };
  // A run that blows up (BGK just above tau = 1/2 at cell Reynolds number ~70) stops with a
  // NumericalError that says what to change, after saving its state.
  const std::string bgk =
      blow_up_message("unstable_run", {"lbm.collision=\"bgk\"", "fluid.viscosity=1.0e-8", "run.inflow_ramp_time=0"});
  EXPECT_NE(bgk.find("lbm.resolution"), std::string::npos) << bgk;
  EXPECT_NE(bgk.find("use lbm.collision = \"trt\""), std::string::npos) << bgk;
  EXPECT_TRUE(std::filesystem::exists(ff::testing::flow_test_dir("unstable_run") / "checkpoint_failed" / "state.ffcp"));
  // With TRT on and its magic parameter near 0 (the antisymmetric rate at 1/2) the advice names
  // lbm.trt_magic; it used to advise switching to the TRT that was running (fuzzed, session 48).
  const std::string trt =
      blow_up_message("unstable_trt", {"lbm.trt_magic=1e-300", "fluid.viscosity=1.0e-8", "run.inflow_ramp_time=0"});
  EXPECT_NE(trt.find("lbm.trt_magic"), std::string::npos) << trt;
  EXPECT_EQ(trt.find("use lbm.collision"), std::string::npos) << trt;
}

// Every flow driver, interrupted at several points (during the inflow ramp, mid-run, and
// resume -> interrupt -> resume) by --max-steps, gives the same series.csv, summary.json
// (timings excepted: resume_compare.hpp) and VTK series as the uninterrupted run.
namespace {

const char* kPoiseuille = R"(
driver = "flow/poiseuille"
[channel]
height = 1.0e-3
length = 1.0e-3
[lbm]
resolution = 10
[run]
end_time = 2.0
steady_tolerance = 1.0e-7
[output]
samples = 40
snapshots = 4
plots = false
)";

const char* kCavity = R"(
driver = "flow/cavity"
[cavity]
size = 0.1
lid_velocity = 1.0e-3
[fluid]
viscosity = 1.0e-6
[lbm]
resolution = 12
tau = 0.55
[run]
end_time = 2000
[output]
samples = 40
snapshots = 4
plots = false
)";

void expect_every_resume_identical(const std::string& name, const std::string& text, const std::vector<std::string>& sets) {
  using namespace ff::testing;
  const auto whole = flow_test_dir(name + "_whole"), cut = flow_test_dir(name + "_cut");
  ASSERT_EQ(run_flow_driver_status(name + "_whole", text, sets), ff::RunStatus::Finished);
  const long n = read_summary(name + "_whole")["steps"];
  for (const std::vector<long>& stops : {std::vector<long>{n / 4}, std::vector<long>{n / 2, 3 * n / 4}}) {
    std::string what = name + " interrupted at";
    for (std::size_t k = 0; k < stops.size(); ++k) {
      ASSERT_EQ(run_flow_driver_status(name + "_cut", text, sets, k > 0, 0, stops[k]), ff::RunStatus::Interrupted);
      what += fmt::format(" {}", stops[k]);  // (" " + std::to_string trips GCC 12's -Wrestrict)
    }
    ASSERT_EQ(run_flow_driver_status(name + "_cut", text, sets, true), ff::RunStatus::Finished) << what;
    ff::test::expect_same_results(whole, cut, what);
    EXPECT_EQ(slurp(whole / "vtk" / "flow.pvd"), slurp(cut / "vtk" / "flow.pvd")) << what;
  }
}

}  // namespace

TEST(LbmFlowResume, PoiseuilleResumedAtSeveralPointsIsBitForBit) {
  expect_every_resume_identical("every_poiseuille", kPoiseuille, {});
}
TEST(LbmFlowResume, PoiseuilleVelocityInletD3Q19ResumedAtSeveralPointsIsBitForBit) {
  expect_every_resume_identical("every_poiseuille_v", kPoiseuille,
                                {"channel.drive=\"velocity\"", "lbm.lattice=\"D3Q19\"", "lbm.depth_cells=2"});
}
TEST(LbmFlowResume, CavityResumedAtSeveralPointsIsBitForBit) { expect_every_resume_identical("every_cavity", kCavity, {}); }
TEST(LbmFlowResume, CylinderResumedInTheRampAndAfterIsBitForBit) {
  // The inflow ramp (20 domain lengths at the sound speed, ~2500 steps) covers the first stop.
  expect_every_resume_identical("every_cylinder", kCylinder, {"output.checkpoints=0"});
}

TEST(LbmFlowResume, StopBetweenTwoSamplesResumesBitForBit) {
  // Stops are polled between samples too (every 256 steps and at --max-steps), so a run whose
  // samples lie minutes apart still stops within seconds; such a checkpoint resumes bit for bit.
  using namespace ff::testing;
  const auto whole = flow_test_dir("between_whole"), cut = flow_test_dir("between_cut");
  ASSERT_EQ(run_flow_driver_status("between_whole", kCavity, {}), ff::RunStatus::Finished);
  const long n = read_summary("between_whole")["steps"];
  const long every = n / 40;  // output.samples = 40
  ASSERT_GT(every, 8);
  const long stop = 3 * every + every / 2;
  ASSERT_EQ(run_flow_driver_status("between_cut", kCavity, {}, false, 0, stop), ff::RunStatus::Interrupted);
  const std::string partial = slurp(cut / "series.csv");
  EXPECT_EQ(std::count(partial.begin(), partial.end(), '\n'), 1 + 3) << "header and three samples before the stop";
  ff::CheckpointReader r(cut / "checkpoint" / "state.ffcp");
  struct RunnerState {  // as flow_runner.cpp stores it
    std::int64_t step, vtk_index, finished, columns;
  };
  EXPECT_EQ(r.get_value<RunnerState>("flow.state").step, stop) << "the checkpoint lies between two samples";
  ASSERT_EQ(run_flow_driver_status("between_cut", kCavity, {}, true), ff::RunStatus::Finished);
  ff::test::expect_same_results(whole, cut, "stopped between two samples");
}

TEST(LbmFlowResume, StopRequestWritesACheckpointAndResumes) {
  using namespace ff::testing;
  ASSERT_EQ(run_flow_driver_status("sig_whole", kCavity, {}), ff::RunStatus::Finished);
  ff::request_stop(15);  // SIGTERM before the run: stops at the first sample
  const auto st = run_flow_driver_status("sig_cut", kCavity, {});
  ff::clear_stop_request();
  ASSERT_EQ(st, ff::RunStatus::Interrupted);
  EXPECT_TRUE(std::filesystem::exists(flow_test_dir("sig_cut") / "checkpoint" / "state.ffcp"));
  EXPECT_FALSE(std::filesystem::exists(flow_test_dir("sig_cut") / "summary.json"));
  ASSERT_EQ(run_flow_driver_status("sig_cut", kCavity, {}, true), ff::RunStatus::Finished);
  ff::test::expect_same_results(flow_test_dir("sig_whole"), flow_test_dir("sig_cut"), "stopped by SIGTERM");
}

TEST(LbmFlowResume, BeginOutputComesAfterSetUpAndBeforeAnyFile) {
  // Called once on a fresh run before any file is written into out_dir; never on resume.
  for (const char* text : {kPoiseuille, kCavity, kCylinder}) {
    const ff::Driver& d = ff::find_driver(ff::peek_driver(text, "test"));
    const ff::ParamTable table = ff::parameter_table(d);
    const ff::Config cfg = ff::load_scenario(table, "test.toml", text, {});
    ff::RunOptions opt;
    opt.out_dir = ff::testing::flow_test_dir("begin_output");
    std::filesystem::remove_all(opt.out_dir);
    std::filesystem::create_directories(opt.out_dir);
    opt.max_steps = 50;
    opt.progress_interval_s = 0;
    int calls = 0;
    bool empty = false;
    opt.begin_output = [&] {
      ++calls;
      empty = std::filesystem::is_empty(opt.out_dir);
    };
    ASSERT_EQ(d.run(cfg, opt), ff::RunStatus::Interrupted) << text;
    EXPECT_EQ(calls, 1) << text;
    EXPECT_TRUE(empty) << text;
    opt.resume = true;
    opt.max_steps = 100;
    d.run(cfg, opt);
    EXPECT_EQ(calls, 1) << text;
  }
}

TEST(LbmFlowResume, TheCheckpointAtTheStartResumesBitForBit) {
  // The run checkpoints once set up (a kill before the first wall-clock checkpoint leaves a
  // resumable folder); with the newest checkpoint gone, resume starts from that one.
  using namespace ff::testing;
  ASSERT_EQ(run_flow_driver_status("start_whole", kCylinder, {}), ff::RunStatus::Finished);
  ASSERT_EQ(run_flow_driver_status("start_cut", kCylinder, {"output.checkpoints=0"}, false, 0, 2000), ff::RunStatus::Interrupted);
  std::filesystem::remove(flow_test_dir("start_cut") / "checkpoint" / "state.ffcp");
  ASSERT_EQ(run_flow_driver_status("start_cut", kCylinder, {"output.checkpoints=0"}, true), ff::RunStatus::Finished);
  EXPECT_EQ(slurp(flow_test_dir("start_whole") / "series.csv"), slurp(flow_test_dir("start_cut") / "series.csv"));
  EXPECT_EQ(read_summary("start_whole")["results"], read_summary("start_cut")["results"]);
  EXPECT_EQ(slurp(flow_test_dir("start_whole") / "vtk" / "flow.pvd"), slurp(flow_test_dir("start_cut") / "vtk" / "flow.pvd"));
}
