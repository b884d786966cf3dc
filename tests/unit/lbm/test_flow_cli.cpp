// The flow drivers through the real program (issue 14 bugs): `fracflow resume` continues a run
// set up with lbm.time_step; --max-steps stops a flow run with a checkpoint, and the resumed
// run ends bit for bit as the uninterrupted one (also when resumed with a --max-steps already
// passed); `check` prints the derived dt, tau, Mach number and expected error, and refuses
// what `run` refuses.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "../program_runner.hpp"
#include "../../validation/resume_compare.hpp"

namespace fs = std::filesystem;

namespace {

const char* kCylinder = R"(driver = "flow/cylinder"
channel.height = 0.04
channel.length = 0.12
cylinder.diameter = 0.01
cylinder.x = 0.03
cylinder.y = 0.021
inlet.velocity = 0.01
fluid.viscosity = 1.0e-5
lbm.resolution = 6
lbm.time_step = 0.01
run.end_time = 60
output.samples = 60
output.snapshots = 0
output.plots = false
probes.names = ["fore", "aft"]
probes.x = [0.025, 0.035]
probes.y = [0.021, 0.021]
probes.delta_p = ["fore", "aft"]
)";

// A D3Q19 duct (channel.depth > 0): its depth comes from channel.depth, and lbm.depth_cells is
// refused there; the saved scenario must not set it, or resume refuses its own run.
const char* kDuct = R"(driver = "flow/cylinder"
channel.height = 0.04
channel.length = 0.08
channel.depth = 0.02
cylinder.diameter = 0.01
cylinder.x = 0.03
cylinder.y = 0.021
inlet.velocity = 0.01
inlet.profile = "parabolic"
fluid.viscosity = 1.0e-5
lbm.lattice = "D3Q19"
lbm.resolution = 4
lbm.time_step = 0.04
run.end_time = 20
output.samples = 20
output.snapshots = 0
output.plots = false
)";

using ff::test::run_program;

// Writes `text` to s.path/file and runs it twice through the program: whole, and cut by
// --max-steps (no summary yet). Returns the cut run's output.
std::string run_whole_and_cut(const ff::test::TestScratch& s, const std::string& file, const char* text,
                              long max_steps, const fs::path& whole, const fs::path& cut) {
  const fs::path scen = s.path / file;
  std::ofstream(scen) << text;
  auto r = run_program("run " + scen.string() + " --out " + whole.string() + " --quiet");
  EXPECT_EQ(r.code, 0) << r.output;
  r = run_program("run " + scen.string() + " --out " + cut.string() + " --quiet --max-steps " + std::to_string(max_steps));
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_FALSE(fs::exists(cut / "summary.json")) << "stopped before the end";
  return r.output;
}

}  // namespace

TEST(FlowCli, ADuctRunResumesFromItsSavedScenario) {
  const ff::test::TestScratch s("flowcli");
  const fs::path whole = s.path / "whole", cut = s.path / "cut";
  run_whole_and_cut(s, "duct.toml", kDuct, 250, whole, cut);
  ASSERT_FALSE(::testing::Test::HasFailure());
  EXPECT_NE(ff::test::read_bytes(cut / "scenario.toml").find("# (default, not set) lbm.depth_cells"), std::string::npos);
  const auto r = run_program("resume " + cut.string() + " --quiet");
  ASSERT_EQ(r.code, 0) << r.output;
  ff::test::expect_same_results(whole, cut, "duct interrupted by --max-steps 250 and resumed through the program");
}

TEST(FlowCli, MaxStepsStopsAndATimeStepRunResumesBitForBit) {
  const ff::test::TestScratch s("flowcli");
  const fs::path whole = s.path / "whole", cut = s.path / "cut";
  const std::string out = run_whole_and_cut(s, "cyl.toml", kCylinder, 2345, whole, cut);
  ASSERT_FALSE(::testing::Test::HasFailure());
  EXPECT_NE(out.find("--max-steps 2345"), std::string::npos) << out;
  // Resumed with a --max-steps it has already passed: stops at once, nothing advances.
  const std::string before = ff::test::read_bytes(cut / "series.csv");
  auto r = run_program("resume " + cut.string() + " --quiet --max-steps 1000");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(ff::test::read_bytes(cut / "series.csv"), before);
  // The saved scenario holds lbm.time_step and lbm.tau's default as a comment: resume accepts it.
  EXPECT_NE(ff::test::read_bytes(cut / "scenario.toml").find("# (default, not set) lbm.tau"), std::string::npos);
  r = run_program("resume " + cut.string() + " --quiet");
  ASSERT_EQ(r.code, 0) << r.output;
  ff::test::expect_same_results(whole, cut, "interrupted by --max-steps 2345 and resumed through the program");
}

TEST(FlowCli, CheckPrintsTheDerivedUnitsAndRefusesWhatRunRefuses) {
  const ff::test::TestScratch s("flowcli");
  const fs::path scen = s.path / "cyl.toml";
  std::ofstream(scen) << kCylinder;
  auto c = run_program("check " + scen.string());
  ASSERT_EQ(c.code, 0) << c.output;
  // dt = 0.01 s, dx = 1/600 m, nu = 1e-5: tau = 1/2 + 3 nu dt / dx^2 = 0.608; Ma = sqrt(3) 0.01 dt / dx.
  for (const char* want : {"time step dt = 0.01 s", "relaxation time tau = 0.608", "from lbm.time_step; lbm.tau is not used",
                           "Mach number 0.104",
                           "expected relative compressibility error 0.0011 (0.1 Ma^2: incompressible equilibrium, steady flow)",
                           "2 probe(s) checked"})
    EXPECT_NE(c.output.find(want), std::string::npos) << want << " missing in:\n" << c.output;
  c = run_program("check " + scen.string() + " --set lbm.time_step=0 --set lbm.mach=0.05");
  ASSERT_EQ(c.code, 0) << c.output;
  EXPECT_NE(c.output.find("Mach number 0.05 "), std::string::npos) << c.output;
  EXPECT_NE(c.output.find("from lbm.mach"), std::string::npos) << c.output;
  for (const std::string& bad : {std::string("--set lbm.mach=0.05"), std::string("--set lbm.tau=0.6"),
                                 std::string("--set 'probes.x=[0.03, 0.035]'")}) {
    const auto chk = run_program("check " + scen.string() + " " + bad);
    const auto run = run_program("run " + scen.string() + " " + bad + " --out " + (s.path / "bad").string() + " --quiet");
    EXPECT_EQ(chk.code, 2) << bad << ":\n" << chk.output;
    EXPECT_EQ(run.code, 2) << bad << ":\n" << run.output;
    EXPECT_FALSE(fs::exists(s.path / "bad")) << bad;
    const std::string key = bad.find("probes") != std::string::npos ? "probes.names" : "are both set";
    EXPECT_NE(chk.output.find(key), std::string::npos) << chk.output;
    EXPECT_NE(run.output.find(key), std::string::npos) << run.output;
  }
}
