// The results-folder rules of io/run_folder.hpp on their own: which folders a run may write or
// replace, the one-writer lock, and the list of keys edited since a run started.
#include "io/run_folder.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <thread>

#include "core/error.hpp"
#include "../program_runner.hpp"

namespace fs = std::filesystem;
using namespace ff;

namespace {

struct Scratch : ff::test::TestScratch {
  Scratch() : TestScratch("runfolder") {}
};

void touch(const fs::path& p, const std::string& text = "x") {
  fs::create_directories(p.parent_path());
  std::ofstream(p) << text;
}

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

// A folder made by NewRunFolder::begin, as a finished run leaves it (plus one result file).
fs::path make_run(const fs::path& dir) {
  NewRunFolder f(dir, false, {});
  f.begin("driver = \"ucs\"\n", "fracflow run");
  touch(dir / "series.csv", "t\n0\n");
  return dir;
}

// The current directory for the life of a test.
struct Chdir {
  fs::path before = fs::current_path();
  explicit Chdir(const fs::path& p) { fs::current_path(p); }
  ~Chdir() { fs::current_path(before); }
};

}  // namespace

TEST(RunFolder, CurrentDirectoryItsParentsRootHomeAndTheScenarioFolderAreRefused) {
  Scratch s;
  const fs::path cwd = s.path / "work" / "here";
  fs::create_directories(cwd);
  Chdir in(cwd);
  EXPECT_NE(message_of([] { refuse_protected_out_dir(".", {}); }).find("the current directory"), std::string::npos);
  EXPECT_NE(message_of([&] { refuse_protected_out_dir(cwd.string() + "/", {}); }).find("the current directory"),
            std::string::npos);
  EXPECT_NE(message_of([] { refuse_protected_out_dir("..", {}); }).find("above the current directory"), std::string::npos);
  EXPECT_NE(message_of([] { refuse_protected_out_dir("/", {}); }).find("root"), std::string::npos);
  const char* old_home = std::getenv("HOME");
  const std::string saved = old_home ? old_home : "";
  ::setenv("HOME", (s.path / "home").c_str(), 1);
  EXPECT_NE(message_of([&] { refuse_protected_out_dir(s.path / "home", {}); }).find("home folder"), std::string::npos);
  if (old_home) ::setenv("HOME", saved.c_str(), 1);
  else ::unsetenv("HOME");
  const fs::path scenario = s.path / "study" / "cases" / "a.toml";
  touch(scenario);
  for (const fs::path& p : {s.path / "study" / "cases", s.path / "study"})
    EXPECT_NE(message_of([&] { refuse_protected_out_dir(p, scenario); }).find("holds the scenario file"), std::string::npos)
        << p;
  // A new folder beside them is fine.
  EXPECT_NO_THROW(refuse_protected_out_dir(s.path / "study" / "runs" / "a", scenario));
  EXPECT_NO_THROW(refuse_protected_out_dir("runs/a", scenario));
}

TEST(RunFolder, AFolderWithoutOurMarkerIsNeverWrittenOrReplaced) {
  Scratch s;
  const fs::path dir = s.path / "thesis";
  touch(dir / "chapter1.tex", "precious");
  for (bool overwrite : {false, true}) {
    const std::string m = message_of([&] { NewRunFolder f(dir, overwrite, {}); });
    EXPECT_NE(m.find("holds no fracflow run"), std::string::npos) << m;
    EXPECT_NE(m.find("with or without --overwrite"), std::string::npos) << m;
  }
  EXPECT_TRUE(fs::exists(dir / "chapter1.tex"));
}

TEST(RunFolder, ARunOfOursNeedsOverwriteAndIsReplacedOnlyAtBegin) {
  Scratch s;
  const fs::path dir = make_run(s.path / "run");
  EXPECT_TRUE(is_fracflow_run(dir));
  const std::string m = message_of([&] { NewRunFolder f(dir, false, {}); });
  for (const char* w : {"--overwrite", "--out", "fracflow resume"}) EXPECT_NE(m.find(w), std::string::npos) << m;
  {
    NewRunFolder f(dir, true, {});
    EXPECT_TRUE(fs::exists(dir / "series.csv")) << "nothing is deleted before the run starts";
  }  // a run that never began (set-up failed) leaves the old one whole
  EXPECT_TRUE(fs::exists(dir / "series.csv"));
  NewRunFolder f(dir, true, {});
  f.begin("driver = \"ucs\"\n# new\n", "fracflow run --overwrite");
  EXPECT_FALSE(fs::exists(dir / "series.csv")) << "the old run is gone";
  EXPECT_TRUE(is_fracflow_run(dir));
  EXPECT_EQ(std::distance(fs::directory_iterator(s.path), fs::directory_iterator()), 1) << "no sibling left behind";
  std::ifstream in(dir / "scenario.toml");
  std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(all.find("# new"), std::string::npos);
}

TEST(RunFolder, ARefusedRunRemovesOnlyTheFolderItMade) {
  Scratch s;
  NewRunFolder f(s.path / "new", false, {});
  EXPECT_FALSE(fs::exists(s.path / "new")) << "nothing is created before the run starts";
  f.begin("", "fracflow run");
  EXPECT_TRUE(fs::exists(s.path / "new" / "scenario.toml"));
  f.discard_if_empty();
  EXPECT_FALSE(fs::exists(s.path / "new"));
}

TEST(RunFolder, UnwritableOutFolderIsAnInputError) {
  // /proc takes no new folders, even from root.
  EXPECT_NE(message_of([] { probe_writable("/proc/fracflow-test/out"); }).find("cannot be written"), std::string::npos);
  if (::geteuid() == 0) GTEST_SKIP() << "root ignores folder permissions; /proc covered the rule";
  Scratch s;
  const fs::path ro = s.path / "ro";
  fs::create_directories(ro);
  fs::permissions(ro, fs::perms::owner_read | fs::perms::owner_exec);
  const std::string m = message_of([&] { NewRunFolder f(ro / "out", false, {}); });
  EXPECT_NE(m.find("cannot be written"), std::string::npos) << m;
}

TEST(RunFolder, SecondWriterIsRefusedWithTheHoldersPid) {
  Scratch s;
  const fs::path dir = make_run(s.path / "run");
  FolderLock held = FolderLock::acquire(dir);
  const std::string m = message_of([&] { FolderLock::acquire(dir); });
  EXPECT_NE(m.find("in use by process " + std::to_string(::getpid())), std::string::npos) << m;
  EXPECT_NE(m.find(dir.string()), std::string::npos) << m;
  // --overwrite of a run that is being written is refused before anything is built.
  EXPECT_NE(message_of([&] { NewRunFolder f(dir, true, {}); }).find("in use"), std::string::npos);
  held.release();
  EXPECT_NO_THROW(FolderLock::acquire(dir));
}

TEST(RunFolder, LockOfAKilledProcessDoesNotBlock) {
  Scratch s;
  const fs::path dir = make_run(s.path / "run");
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    FolderLock l = FolderLock::acquire(dir);
    ::kill(::getpid(), SIGKILL);  // dies holding it, as kill -9 would
    ::_exit(1);
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status));
  std::ifstream lock(dir / ".fracflow" / "lock");
  long pid = 0;
  lock >> pid;
  EXPECT_EQ(pid, child) << "the lock file is still there, naming the dead process";
  EXPECT_NO_THROW(FolderLock::acquire(dir));
}

TEST(RunFolder, ScenarioChangesNameEveryEditedKeyWithOldAndNewValue) {
  const std::vector<std::pair<std::string, ParamValue>> a = {
      {"driver", std::string("ucs")}, {"ucs.platen_velocity", 0.2}, {"sample.seed", 1L}, {"output.vtk", true}};
  const std::vector<std::pair<std::string, ParamValue>> b = {
      {"driver", std::string("ucs")}, {"ucs.platen_velocity", 0.3}, {"sample.seed", 1L}, {"ucs.extra", 1.0}};
  const auto c = scenario_changes(a, b);
  ASSERT_EQ(c.size(), 3u);
  EXPECT_EQ(to_string(c[0]), "ucs.platen_velocity: 0.2 -> 0.3");
  EXPECT_EQ(c[1].key, "ucs.extra");
  EXPECT_EQ(c[1].before, "(absent)");
  EXPECT_EQ(c[2].key, "output.vtk");
  EXPECT_EQ(c[2].after, "(absent)");
  EXPECT_TRUE(scenario_changes(a, a).empty());
}

TEST(RunFolder, BatchFolderReplacesOnlyAFolderOfOurs) {
  Scratch s;
  const fs::path foreign = s.path / "mine";
  touch(foreign / "data.csv", "precious");
  for (bool overwrite : {false, true})
    EXPECT_NE(message_of([&] { prepare_batch_folder(foreign, overwrite, "sweep folder"); }).find("holds no fracflow results"),
              std::string::npos);
  EXPECT_TRUE(fs::exists(foreign / "data.csv"));
  const fs::path dir = s.path / "sweep";
  {
    FolderLock l = prepare_batch_folder(dir, false, "sweep folder");
    EXPECT_TRUE(is_fracflow_run(dir));
    touch(dir / "case_000" / "series.csv");
    EXPECT_NE(message_of([&] { prepare_batch_folder(dir, true, "sweep folder"); }).find("in use"), std::string::npos)
        << "a sweep still writing its folder keeps it";
  }
  EXPECT_NE(message_of([&] { prepare_batch_folder(dir, false, "sweep folder"); }).find("--overwrite"), std::string::npos);
  FolderLock l = prepare_batch_folder(dir, true, "sweep folder");
  EXPECT_FALSE(fs::exists(dir / "case_000"));
  EXPECT_TRUE(is_fracflow_run(dir));
  EXPECT_NE(message_of([&] { prepare_batch_folder(".", true, "sweep folder"); }).find("current directory"),
            std::string::npos);
}

TEST(RunFolder, ThreadsOfOneProcessProbeTheSameFolderAtOnce) {
  // `fracflow calibrate` starts a UCS run beside its triaxial sweep in one process: both probe
  // the calibration folder at the same moment, and neither may be refused for the other's probe.
  Scratch s;
  std::atomic<int> failures{0};
  auto probe_many = [&] {
    for (int i = 0; i < 2000; ++i) try {
        probe_writable(s.path);
      } catch (const InputError&) {
        ++failures;
      }
  };
  std::thread a(probe_many), b(probe_many);
  a.join();
  b.join();
  EXPECT_EQ(failures.load(), 0);
  EXPECT_TRUE(fs::is_empty(s.path)) << "every probe folder is removed again";
}
