// Real sweeps through the fracflow program on a tiny UCS sample (a few seconds each).
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "batch/sweep.hpp"
#include "core/error.hpp"
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
