// The command line as a user meets it: bad scenarios stop with exit code 2 and a message that
// names the file, the line, the key, what was wrong and what is allowed; nothing is left
// behind; an existing results folder is never overwritten by accident.
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

namespace fs = std::filesystem;

namespace {
struct Result {
  int code;
  std::string output;
};
Result run(const std::string& args) {
  const std::string cmd = std::string(FRACFLOW_BIN) + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 4096> buf;
  while (std::fgets(buf.data(), buf.size(), p)) out += buf.data();
  const int status = pclose(p);
  return {WEXITSTATUS(status), out};
}
fs::path scratch(const std::string& name) {
  return fs::temp_directory_path() / ("fracflow_cli_" + name + "_" + std::to_string(::getpid()));
}
fs::path write(const std::string& name, const std::string& text) {
  const fs::path p = scratch(name + ".toml");
  std::ofstream(p) << text;
  return p;
}
}  // namespace

TEST(Cli, VersionAndHelp) {
  EXPECT_EQ(run("--version").code, 0);
  EXPECT_NE(run("--version").output.find("fracflow"), std::string::npos);
  const auto h = run("--help");
  EXPECT_EQ(h.code, 0);
  for (const char* sub : {"run", "check", "resume"}) EXPECT_NE(h.output.find(sub), std::string::npos) << sub;
}

TEST(Cli, CheckPrintsEveryResolvedParameterWithUnitAndDefault) {
  const auto r = run("check");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("dem.local_damping"), std::string::npos);
  EXPECT_NE(r.output.find("kg/m^3"), std::string::npos);
  EXPECT_NE(r.output.find("default"), std::string::npos);
  EXPECT_NE(r.output.find("dem.bond.matrix-matrix.tensile_strength"), std::string::npos);
}

TEST(Cli, NegativeRadiusIsRejectedWithFileLineKeyAndAllowedRange) {
  const auto f = write("negr", "driver = \"ucs\"\n[sample]\nradius_min = -1e-3\n");
  const auto out = scratch("negr_out");
  const auto r = run("run " + f.string() + " --out " + out.string());
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find(f.string() + ":3"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("sample.radius_min"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("> 0"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out)) << "no half-written results";
  fs::remove(f);
}

TEST(Cli, FrictionBelowZeroAndPorosityOutsideUnitIntervalAreRejected) {
  const auto f = write("fric", "driver = \"ucs\"\n[dem.group.rock]\n[dem.contact.rock-rock]\nfriction = -0.1\n");
  auto r = run("check " + f.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("dem.contact.rock-rock.friction"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(">= 0"), std::string::npos) << r.output;
  r = run("check --set sample.porosity=1.2");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("(0, 1)"), std::string::npos) << r.output;
  fs::remove(f);
}

TEST(Cli, UnknownKeyGetsASuggestion) {
  const auto f = write("unk", "driver = \"ucs\"\n[ucs]\nplaten_velocty = 0.1\n");
  const auto r = run("check " + f.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find(":3"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("ucs.platen_velocity"), std::string::npos) << r.output;
  fs::remove(f);
}

TEST(Cli, TimeStepAboveTheCriticalOneStopsBeforeRunning) {
  const auto out = scratch("dt_out");
  const auto r = run("run --out " + out.string() + " --set dem.time_step=1e-3 --set sample.diameter=5e-3 --set sample.height=8e-3 --set sample.porosity=0.45 -q");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("dem.time_step"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("critical"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out / "series.csv"));
  fs::remove_all(out);
}

TEST(Cli, ExistingResultsAreNotOverwritten) {
  const auto out = scratch("keep");
  fs::create_directories(out);
  std::ofstream(out / "summary.json") << "{}";
  const auto r = run("run --out " + out.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("--overwrite"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::exists(out / "summary.json"));
  fs::remove_all(out);
}

TEST(Cli, ResumeOfAFolderWithoutCheckpointIsAClearError) {
  const auto r = run("resume /nonexistent/folder");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("not a fracflow results folder"), std::string::npos) << r.output;
}
