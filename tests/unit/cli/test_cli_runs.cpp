// Results are never lost, through the fracflow program itself: --overwrite replaces only a run
// of ours and only once the new run has started, protected and unwritable folders are refused,
// one process writes a folder at a time, an edited scenario.toml is refused at resume, and
// SIGINT/SIGTERM leave a checkpoint that `fracflow resume` finishes. Tiny UCS samples (~150
// spheres, well under a second each).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>

#include "io/run_folder.hpp"
#include "../program_runner.hpp"

namespace fs = std::filesystem;

extern char** environ;

namespace {

const std::string kTiny =
    " --set sample.diameter=5e-3 --set sample.height=8e-3 --set sample.porosity=0.45 --set ucs.max_strain=0.004"
    " --set output.vtk=false --set output.plots=false --set output.progress_interval=0 -j1";

using Result = ff::test::ProgramResult;
Result run(const std::string& args) { return ff::test::run_program(args); }
// Same, after `prefix` (e.g. "cd DIR && " or "HOME=DIR ").
Result run_in(const std::string& prefix, const std::string& args) { return ff::test::run_program(args, prefix); }

// Starts fracflow in the background, stdout and stderr into `log`.
pid_t start(const std::vector<std::string>& args, const fs::path& log) {
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, STDOUT_FILENO, STDERR_FILENO);
  std::vector<std::string> store = {FRACFLOW_BIN};
  store.insert(store.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : store) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = -1;
  if (posix_spawn(&pid, FRACFLOW_BIN, &fa, nullptr, argv.data(), environ) != 0) pid = -1;
  posix_spawn_file_actions_destroy(&fa);
  return pid;
}

struct Scratch : ff::test::TestScratch {
  Scratch() : TestScratch("cliruns") {}
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A tiny run stopped by --max-steps: a folder with a checkpoint to resume.
void interrupted_run(const fs::path& dir) {
  const auto r = run("run --out " + dir.string() + kTiny + " --max-steps 300");
  ASSERT_EQ(r.code, 0) << r.output;
  ASSERT_TRUE(fs::exists(dir / "checkpoint")) << r.output;
  ASSERT_FALSE(fs::exists(dir / "summary.json"));
}

}  // namespace

TEST(CliRuns, OverwriteRefusesAFolderThatHoldsNoRun) {
  Scratch s;
  const fs::path dir = s / "thesis";
  fs::create_directories(dir);
  std::ofstream(dir / "chapter1.tex") << "precious";
  const auto r = run("run --out " + dir.string() + " --overwrite" + kTiny);
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("holds no fracflow run"), std::string::npos) << r.output;
  EXPECT_EQ(slurp(dir / "chapter1.tex"), "precious");
}

TEST(CliRuns, OverwriteKeepsTheOldRunWhenTheNewOneFailsItsRunTimeChecks) {
  // The time-step check needs the built sample: before, --overwrite had deleted the old run by then.
  Scratch s;
  const fs::path dir = s / "run";
  ASSERT_EQ(run("run --out " + dir.string() + kTiny).code, 0);
  const std::string summary = slurp(dir / "summary.json");
  const auto r = run("run --out " + dir.string() + " --overwrite" + kTiny + " --set dem.time_step=1e-3");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("dem.time_step"), std::string::npos) << r.output;
  EXPECT_EQ(slurp(dir / "summary.json"), summary) << "the old run is untouched";
  EXPECT_TRUE(ff::is_fracflow_run(dir));
}

TEST(CliRuns, OverwriteReplacesARunOfOursWithoutLeftovers) {
  Scratch s;
  const fs::path dir = s / "run";
  ASSERT_EQ(run("run --out " + dir.string() + kTiny).code, 0);
  std::ofstream(dir / "old_note.txt") << "from the old run";
  const auto r = run("run --out " + dir.string() + " --overwrite" + kTiny + " --set ucs.platen_velocity=0.3");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_FALSE(fs::exists(dir / "old_note.txt"));
  EXPECT_TRUE(fs::exists(dir / "summary.json"));
  EXPECT_NE(slurp(dir / "scenario.toml").find("0.3"), std::string::npos);
  EXPECT_EQ(std::distance(fs::directory_iterator(s.path), fs::directory_iterator()), 1) << "no moved-aside copy left";
}

TEST(CliRuns, BatchToolsNeverOverwriteAFolderThatHoldsNoResults) {
  Scratch s;
  const fs::path dir = s / "thesis";
  fs::create_directories(dir);
  std::ofstream(dir / "chapter1.tex") << "precious";
  for (const std::string cmd : {"sweep --vary ucs.platen_velocity=0.2,0.3", "calibrate --target-E 2e9 --target-nu 0.3 "
                                "--target-ucs 1e7", "validate-triaxial"}) {
    const auto r = run(cmd + " --out " + dir.string() + " --overwrite");
    EXPECT_EQ(r.code, 2) << cmd << "\n" << r.output;
    EXPECT_NE(r.output.find("holds no fracflow results"), std::string::npos) << cmd << "\n" << r.output;
  }
  EXPECT_EQ(slurp(dir / "chapter1.tex"), "precious");
}

TEST(CliRuns, CurrentDirectoryHomeAndScenarioFolderAreRefusedWhateverTheyHold) {
  Scratch s;
  std::ofstream(s / "notes.txt") << "mine";
  const fs::path scenario = s / "case.toml";
  std::ofstream(scenario) << "driver = \"ucs\"\n";
  const std::string cd = "cd " + s.path.string() + " && ";
  auto r = run_in(cd, "run --out . --overwrite" + kTiny);
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("the current directory"), std::string::npos) << r.output;
  r = run_in(cd, "run case.toml --out " + s.path.string() + " --overwrite" + kTiny);
  EXPECT_EQ(r.code, 2) << r.output;
  r = run_in("HOME=" + s.path.string() + " ", "run --out " + s.path.string() + "/ --overwrite" + kTiny);
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("home folder"), std::string::npos) << r.output;
  r = run("run --out / --overwrite" + kTiny);
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_TRUE(fs::exists(s / "notes.txt"));
  EXPECT_TRUE(fs::exists(scenario));
}

TEST(CliRuns, UnwritableOutIsOneLineAndExitCode2) {
  const auto r = run("run --out /proc/fracflow-test/out" + kTiny);
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("cannot be written"), std::string::npos) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
}

TEST(CliRuns, AFolderInUseIsRefusedToASecondRunOrResume) {
  Scratch s;
  const fs::path dir = s / "run";
  interrupted_run(dir);
  {
    const ff::FolderLock held = ff::FolderLock::acquire(dir);  // as a running fracflow would
    const std::string pid = "process " + std::to_string(::getpid());
    auto r = run("resume " + dir.string() + " -q");
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find("in use by " + pid), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(dir.string()), std::string::npos) << r.output;
    r = run("run --out " + dir.string() + " --overwrite" + kTiny);
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find("in use by " + pid), std::string::npos) << r.output;
    EXPECT_TRUE(fs::exists(dir / "checkpoint"));
  }
  // The lock file stays behind, naming a process that no longer holds it: no obstacle.
  const auto r = run("resume " + dir.string() + " -q");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(fs::exists(dir / "summary.json"));
}

TEST(CliRuns, EditedScenarioIsRefusedAtResumeUnlessAccepted) {
  Scratch s;
  const fs::path dir = s / "run";
  interrupted_run(dir);
  std::string text = slurp(dir / "scenario.toml");
  const auto at = text.find("platen_velocity = ");
  ASSERT_NE(at, std::string::npos) << text;
  const auto eol = text.find('\n', at);
  const std::string old_line = text.substr(at, eol - at);
  text.replace(at, eol - at, "platen_velocity = 0.25");
  std::ofstream(dir / "scenario.toml") << text;
  auto r = run("resume " + dir.string() + " -q");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("ucs.platen_velocity: " + old_line.substr(18) + " -> 0.25"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("--accept-edited-scenario"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "summary.json"));
  r = run("resume " + dir.string() + " -q --accept-edited-scenario");
  EXPECT_EQ(r.code, 0) << r.output;
  const auto summary = nlohmann::json::parse(slurp(dir / "summary.json"));
  ASSERT_TRUE(summary.contains("resumed_with_edited_scenario")) << summary.dump(1);
  EXPECT_EQ(summary["resumed_with_edited_scenario"][0], "ucs.platen_velocity: " + old_line.substr(18) + " -> 0.25");
}

TEST(CliRuns, ResumeWithoutACheckpointSaysHowToStartAgainAndThatWorks) {
  // kill -9 before the first checkpoint: the folder has its marker and scenario.toml only.
  Scratch s;
  const fs::path dir = s / "run";
  interrupted_run(dir);
  fs::remove_all(dir / "checkpoint");
  auto r = run("resume " + dir.string() + " -q");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("--out " + dir.string() + " --overwrite"), std::string::npos) << r.output;
  fs::copy_file(dir / "scenario.toml", s / "again.toml");
  r = run("run " + (s / "again.toml").string() + " --out " + dir.string() + " --overwrite -q");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(fs::exists(dir / "summary.json"));
}

TEST(CliRuns, ResumeOfARunWithoutMarkerStillWorks) {
  // Runs made before results folders carried .fracflow/ resume as before, and lose nothing.
  Scratch s;
  const fs::path dir = s / "run";
  interrupted_run(dir);
  fs::remove_all(dir / ".fracflow");
  const auto r = run("resume " + dir.string() + " -q");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(fs::exists(dir / "summary.json"));
  EXPECT_TRUE(fs::exists(dir / "scenario.toml"));
}

namespace {

// Starts a tiny run that lasts a few seconds, sends `sig` once the sample is built, and checks
// that the run stops at once with a checkpoint, exit code 0 and a message naming the signal
// and `fracflow resume DIR` (also with --quiet).
void stop_with_signal(const fs::path& dir, int sig, const std::string& name, bool quiet) {
  std::vector<std::string> args = {"run", "--out", dir.string()};
  if (quiet) args.push_back("-q");  // the way to continue is printed all the same
  std::istringstream tiny(kTiny);
  for (std::string w; tiny >> w;) args.push_back(w);
  for (const char* a : {"--set", "ucs.platen_velocity=0.004"}) args.push_back(a);  // ~3 s
  const fs::path log = dir.string() + ".log";
  const pid_t pid = start(args, log);
  ASSERT_GT(pid, 0);
  const auto t0 = std::chrono::steady_clock::now();
  while (!fs::exists(ff::run_marker_file(dir)) && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(20))
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  ::kill(pid, sig);
  int status = 0;
  ::waitpid(pid, &status, 0);
  const std::string out = slurp(log);
  ASSERT_TRUE(WIFEXITED(status)) << "killed by the signal instead of stopping cleanly\n" << out;
  EXPECT_EQ(WEXITSTATUS(status), 0) << out;
  EXPECT_NE(out.find("stopped by " + name), std::string::npos) << out;
  EXPECT_NE(out.find("fracflow resume " + dir.string()), std::string::npos) << out;
  EXPECT_TRUE(fs::exists(dir / "checkpoint")) << out;
  EXPECT_FALSE(fs::exists(dir / "summary.json")) << "the run should have been stopped before its end\n" << out;
}

}  // namespace

TEST(CliRuns, SigintWritesACheckpointAndResumeFinishesTheRun) {
  Scratch s;
  const fs::path dir = s / "run";
  stop_with_signal(dir, SIGINT, "SIGINT", false);
  const auto r = run("resume " + dir.string() + " -q");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(fs::exists(dir / "summary.json"));
}

TEST(CliRuns, SigtermWritesACheckpoint) {
  Scratch s;
  stop_with_signal(s / "run", SIGTERM, "SIGTERM", true);
}

TEST(CliRuns, SignalDuringSetUpEndsAtOnceAndLeavesTheOldRun) {
  // Nothing is written while the sample is built, so there is nothing to save: the default
  // scenario's genesis (about a second) is stopped at once and the run it would replace stays.
  Scratch s;
  const fs::path dir = s / "run";
  ASSERT_EQ(run("run --out " + dir.string() + kTiny).code, 0);
  const std::string summary = slurp(dir / "summary.json");
  const pid_t pid = start({"run", "--out", dir.string(), "--overwrite", "-j1"}, s / "log");
  ASSERT_GT(pid, 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  ::kill(pid, SIGTERM);
  const auto t0 = std::chrono::steady_clock::now();
  int status = 0;
  ::waitpid(pid, &status, 0);
  const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM) << slurp(s / "log");
  EXPECT_LT(waited, 1.0);
  EXPECT_EQ(slurp(dir / "summary.json"), summary);
  EXPECT_EQ(std::distance(fs::directory_iterator(s.path), fs::directory_iterator()), 2) << "only the run and the log";
}

TEST(CliRuns, ARunThatBlowsUpStopsWithAdviceAndKeepsItsCheckpoints) {
  // A rock-inclusion contact 1e200 times too stiff in a sample where no such contact touches at the
  // start: the set-up can only warn (the critical step counts the contacts that touch), and the run
  // blows up when the first one forms (NaN at step 463). It must stop with advice and keep its last good
  // checkpoint and the failing state. (Until session 48 this test used a body force of 1e300 m/s^2,
  // which overflowed the energies before any position became NaN; the set-up now refuses such a
  // gravity, test CheckEqualsRun.)
  Scratch s;
  const fs::path scenario = s / "two_groups.toml";
  std::ofstream(scenario) << "driver = \"ucs\"\noutput.vtk = false\noutput.plots = false\noutput.progress_interval = 0\n"
                             "dem.dim = 2\ndem.group.rock.density = 2600\ndem.group.incl.density = 2600\n"
                             "dem.contact.rock-rock.friction = 0.5\ndem.contact.incl-incl.friction = 0.5\n"
                             "dem.contact.rock-incl.friction = 0.5\ndem.contact.rock-incl.emod = 1e200\n"
                             "dem.bond.rock-rock.cohesion = 5e6\ndem.bond.incl-incl.cohesion = 5e6\n"
                             "dem.bond.rock-incl.cohesion = 5e6\nsample.shape = \"box\"\nsample.width = 6e-3\n"
                             "sample.height = 12e-3\nsample.porosity = 0.25\nsample.default_group = \"rock\"\n"
                             "sample.region.core.group = \"incl\"\nsample.region.core.center = [3e-3, 6e-3, 0]\n"
                             "sample.region.core.radius = 2e-3\n";
  const fs::path dir = s / "run";
  const auto r = run("run " + scenario.string() + " --out " + dir.string() + " -j1");
  EXPECT_EQ(r.code, 3) << r.output;
  EXPECT_NE(r.output.find("[dem.contact.rock-incl]"), std::string::npos) << r.output;  // the set-up's warning
  const auto stop = r.output.find("became NaN/inf");
  ASSERT_NE(stop, std::string::npos) << r.output;
  // The stop names the particle that went first and the contact table that the set-up warned about
  // (until session 49 it blamed the safety factor alone).
  const std::string tail = r.output.substr(stop);
  EXPECT_NE(tail.find("first particle: id "), std::string::npos) << r.output;
  EXPECT_NE(tail.find("[dem.contact.rock-incl]"), std::string::npos) << r.output;
  EXPECT_NE(tail.find("dem.time_step_safety"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::exists(dir / "checkpoint" / "state.ffcp")) << "the last good checkpoint stays";
  EXPECT_TRUE(fs::exists(dir / "checkpoint_failed" / "state.ffcp")) << "the failing state is kept for inspection";
  EXPECT_FALSE(fs::exists(dir / "summary.json")) << "no result from a broken run";
}

// `resume --max-steps N` of a run whose checkpoint is already at or past step N ran on to its next
// row and saved a checkpoint there ("step 2000 reached: checkpoint written at step 2100"; the kill
// and resume sweep of session 50). Now it stops before stepping and the folder is unchanged, for
// the DEM drivers' loop (ucs), the hydrofrac's and the sedimentation's (the flow drivers':
// FlowCli.MaxStepsStopsAndATimeStepRunResumesBitForBit).
TEST(CliRuns, AResumeAlreadyAtMaxStepsChangesNothing) {
  Scratch s;
  const std::string quiet = " --set output.vtk=false --set output.plots=false --set output.progress_interval=0 -j1";
  const fs::path hydrofrac = s / "hydrofrac.toml";
  std::ofstream(hydrofrac) << "driver = \"hydrofrac\"\ndem.dim = 2\ndem.group.rock.density = 2600\n"
                              "dem.contact.rock-rock.friction = 0.5\ndem.bond.rock-rock.cohesion = 5e6\n"
                              "sample.shape = \"box\"\nsample.width = 12e-3\nsample.height = 12e-3\n"
                              "sample.porosity = 0.25\nborehole.radius = 1.5e-3\n";
  struct Case {
    std::string name, run_args;
    long steps;
  };
  const std::vector<Case> cases = {
      {"ucs", kTiny, 300},
      {"hydrofrac", hydrofrac.string() + quiet, 400},
      {"sedimentation", std::string(FRACFLOW_SOURCE_DIR) + "/examples/sedimentation_dkt.toml" + quiet, 64}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path dir = s / c.name;
    const auto first = run("run --out " + dir.string() + " " + c.run_args + " --max-steps " + std::to_string(c.steps));
    ASSERT_EQ(first.code, 0) << first.output;
    ASSERT_TRUE(fs::exists(dir / "checkpoint")) << first.output;
    ASSERT_FALSE(fs::exists(dir / "summary.json")) << first.output;
    const std::string series = slurp(dir / "series.csv"), state = slurp(dir / "checkpoint" / "state.ffcp");
    ASSERT_FALSE(state.empty());
    for (const long n : {c.steps, c.steps / 2}) {  // at, and past, the asked step
      const auto again = run("resume " + dir.string() + " -j1 --max-steps " + std::to_string(n));
      EXPECT_EQ(again.code, 0) << again.output;
      EXPECT_NE(again.output.find("nothing to do"), std::string::npos) << again.output;
      EXPECT_NE(again.output.find("fracflow resume " + dir.string()), std::string::npos) << again.output;
      EXPECT_EQ(slurp(dir / "series.csv"), series) << "resume --max-steps " << n << " advanced the run";
      EXPECT_EQ(slurp(dir / "checkpoint" / "state.ffcp"), state) << "resume --max-steps " << n << " rewrote the checkpoint";
    }
  }
}

