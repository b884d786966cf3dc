// Real sweeps through the fracflow program on a tiny UCS sample (a few seconds each).
#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "batch/sweep.hpp"
#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "core/log.hpp"

#include "../program_runner.hpp"
namespace fs = std::filesystem;
using namespace ff::batch;

namespace {

// ~150 spheres, run past the peak (~1.2% axial strain; capped at 2%): about a second per case on one thread.
const std::vector<std::string> kTinySample = {
    "sample.diameter=5e-3", "sample.height=8e-3", "sample.porosity=0.45", "ucs.max_strain=0.02",
    "output.vtk=false",     "output.plots=false", "output.progress_interval=0"};

fs::path scratch(const std::string& name) { return ff::test::fresh_out_dir("test_sweep", name); }

using Result = ff::test::ProgramResult;
Result run_cli(const std::string& args) { return ff::test::run_program(args); }

using ff::test::read_json;

}  // namespace

TEST(SweepRuns, TwoTinyUcsCasesAreCollected) {
  ff::log::quiet() = true;
  SweepOptions opt;
  opt.sets = kTinySample;
  opt.axes = {parse_vary("ucs.platen_velocity=0.2,0.3")};
  opt.out_dir = scratch("two");
  opt.executable = FRACFLOW_BIN;
  opt.jobs = 2;
  opt.quiet = true;
  const auto r = run_sweep(opt);
  ASSERT_EQ(r.cases.size(), 2u);
  EXPECT_EQ(r.failed, 0);
  for (auto& c : r.cases) {
    EXPECT_EQ(c.status, "ok") << c.name << ": " << c.error;
    ASSERT_TRUE(c.summary);
    EXPECT_GT(c.summary->ucs_Pa, 0);
    EXPECT_TRUE(fs::exists(c.dir / "scenario.toml"));
  }
  EXPECT_EQ(r.cases[1].values.front().second, "0.3");
  // Both runs at sigma3 = 0: no envelope, and sweep.json says why.
  EXPECT_FALSE(r.fit);
  const auto j = read_json(opt.out_dir / "sweep.json");
  ASSERT_EQ(j["cases"].size(), 2u);
  EXPECT_EQ(j["cases"][0]["values"]["ucs.platen_velocity"], "0.2");
  EXPECT_GT(j["cases"][1]["ucs_Pa"].get<double>(), 0);
  EXPECT_TRUE(j["mohr_coulomb"].is_null());
  EXPECT_TRUE(j.contains("mohr_coulomb_note"));
  std::ifstream csv(opt.out_dir / "sweep.csv");
  std::string header, line;
  std::getline(csv, header);
  EXPECT_EQ(header.rfind("case,ucs.platen_velocity,status,exit_code,sigma3_Pa,", 0), 0u) << header;
  int rows = 0;
  while (std::getline(csv, line)) rows += line.empty() ? 0 : 1;
  EXPECT_EQ(rows, 2);
  fs::remove_all(opt.out_dir);
}

// case_001 asks for a time step far above the critical one: its run stops with exit code 2 and
// names dem.time_step; case_000 still finishes, and the sweep exits with 1.
TEST(SweepRuns, FailingCaseIsReportedWithoutStoppingTheOthers) {
  const auto out = scratch("fail");
  std::string sets;
  for (auto& s : kTinySample) sets += " --set " + s;
  const auto r = run_cli("sweep --vary dem.time_step=0,1e-3 --jobs 2 --out " + out.string() + sets);
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("case_001"), std::string::npos) << r.output;
  const auto j = read_json(out / "sweep.json");
  EXPECT_EQ(j["failed"], 1);
  EXPECT_EQ(j["cases"][0]["status"], "ok");
  EXPECT_EQ(j["cases"][1]["status"], "failed");
  EXPECT_EQ(j["cases"][1]["exit_code"], 2);
  EXPECT_NE(j["cases"][1]["error"].get<std::string>().find("dem.time_step"), std::string::npos) << j.dump(2);
  EXPECT_TRUE(fs::exists(j["cases"][1]["log"].get<std::string>()));
  fs::remove_all(out);
}

TEST(SweepRuns, BadCaseIsRejectedBeforeAnythingIsWritten) {
  const auto out = scratch("bad");
  const auto r = run_cli("sweep --vary sample.porosity=0.4,1.5 --out " + out.string());
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("case_001"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("sample.porosity"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out));
}

TEST(SweepRuns, VaryIsRequired) {
  const auto r = run_cli("sweep");
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.output.find("--vary"), std::string::npos) << r.output;
}

TEST(SweepRuns, EnvelopePlotIsDrawn) {
  const auto out = scratch("plot");
  const std::vector<StrengthPoint> pts = {{0, 14e6}, {2.5e6, 24e6}, {5e6, 33e6}};
  const auto fit = fit_mohr_coulomb(pts);
  const bool drawn = plot_peak_vs_confinement(out, pts, fit);
  EXPECT_TRUE(fs::exists(out / "plots" / "peak_vs_confinement.csv"));
  if (!drawn) GTEST_SKIP() << "python3 with matplotlib is not available here";
  EXPECT_GT(fs::file_size(out / "plots" / "peak_vs_confinement.png"), 1000u);
  fs::remove_all(out);
}

// SIGTERM to the sweep (what a batch scheduler sends at its wall-time limit): the running cases
// checkpoint and stop (the request passed on as their ABORT file), no new case starts, sweep.json
// says which, and --resume finishes the sweep. Before, the signal ended the sweep process at once
// and left its children running to their ends (this test process died of it).
TEST(SweepRuns, SigtermStopsTheCasesWithCheckpointsAndResumeFinishesThem) {
  ff::log::quiet() = true;
  SweepOptions opt;
  opt.sets = kTinySample;
  opt.axes = {parse_vary("ucs.platen_velocity=0.05,0.06,0.07")};  // ~5 s per case
  opt.out_dir = scratch("stop");
  opt.executable = FRACFLOW_BIN;
  opt.jobs = 2;
  opt.quiet = true;
  std::thread killer([&] {  // the signal once case_000 has begun its folder
    const fs::path marker = opt.out_dir / "case_000" / ".fracflow" / "run.json";
    for (int k = 0; k < 1200 && !fs::exists(marker); ++k) std::this_thread::sleep_for(std::chrono::milliseconds(25));
    std::raise(SIGTERM);
  });
  const auto r = run_sweep(opt);
  killer.join();
  ASSERT_TRUE(ff::stop_requested());
  ASSERT_EQ(r.cases.size(), 3u);
  EXPECT_EQ(r.cases[0].status, "interrupted") << r.cases[0].error;
  EXPECT_TRUE(fs::exists(r.cases[0].dir / "checkpoint"));
  EXPECT_FALSE(fs::exists(r.cases[0].dir / "summary.json"));
  EXPECT_EQ(r.cases[2].status, "not started");
  EXPECT_FALSE(fs::exists(r.cases[2].dir));
  EXPECT_EQ(r.failed, 0);
  std::ifstream log0(r.cases[0].log);
  const std::string log_text((std::istreambuf_iterator<char>(log0)), std::istreambuf_iterator<char>());
  EXPECT_NE(log_text.find("ABORT"), std::string::npos) << log_text;
  const auto j = read_json(opt.out_dir / "sweep.json");
  EXPECT_EQ(j["cases"][0]["status"], "interrupted");
  EXPECT_EQ(j["cases"][2]["status"], "not started");
  EXPECT_EQ(j["not_started"].get<int>() + j["interrupted"].get<int>(), 3 - (r.cases[1].status == "ok" ? 1 : 0));
  ff::clear_stop_request();

  // --resume with other --vary values: refused, nothing run.
  SweepOptions other = opt;
  other.resume = true;
  other.axes = {parse_vary("ucs.platen_velocity=0.05,0.06")};
  EXPECT_THROW(run_sweep(other), ff::InputError);
  EXPECT_FALSE(fs::exists(r.cases[2].dir));
  // --resume: case_000 continues from its checkpoint, case_002 runs; every case finishes.
  opt.resume = true;
  const auto again = run_sweep(opt);
  EXPECT_EQ(again.failed + again.interrupted + again.not_started, 0);
  for (auto& c : again.cases) EXPECT_EQ(c.status, "ok") << c.name << ": " << c.error;
  EXPECT_GE(again.continued, 1);
  EXPECT_TRUE(fs::exists(r.cases[0].dir / "summary.json"));
  EXPECT_EQ(read_json(opt.out_dir / "sweep.json")["interrupted"], 0);
  fs::remove_all(opt.out_dir);
}
