// kill -9 at any moment leaves a resumable folder (issue 12, part 2): the real fracflow binary,
// checkpointing by wall clock every 0.2 s, is killed with SIGKILL at several moments after its
// first checkpoint; `fracflow resume DIR` then finishes it with the same series.csv, cracks.csv
// and summary.json (timings excepted) as an uninterrupted run.
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fcntl.h>

#include <chrono>
#include <cstdlib>
#include <thread>

#include "resume_compare.hpp"
#include "ucs_test_support.hpp"

extern char** environ;

namespace {

namespace fs = std::filesystem;

int fracflow(const std::string& args) {
  const std::string cmd = std::string(FRACFLOW_BIN) + " " + args + " > /dev/null 2>&1";
  const int rc = std::system(cmd.c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

// Starts `fracflow run` in the background; returns its pid.
pid_t spawn_run(const fs::path& scenario, const fs::path& out, const std::string& wall_interval) {
  std::vector<std::string> args = {FRACFLOW_BIN, "run", scenario.string(), "--out", out.string(), "--quiet",
                                   "--set", "output.checkpoint_wall_interval=" + wall_interval};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, FRACFLOW_BIN, &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  return rc == 0 ? pid : -1;
}

}  // namespace

TEST(KillResume, SigkillAtAnyMomentLeavesAResumableFolder) {
  // A 2D UCS run of a few seconds (slow platens) with checkpoints every 0.2 s of wall time.
  const fs::path dir = ff::test::scratch("kill");
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::string text = ff::test::small_ucs_scenario(2);
  text.replace(text.find("platen_velocity = 0.1"), 21, "platen_velocity = 0.03");
  const fs::path scenario = dir / "slow.toml";
  std::ofstream(scenario) << text;
  ASSERT_EQ(fracflow("run " + scenario.string() + " --out " + (dir / "whole").string() +
                     " --quiet --set output.checkpoint_wall_interval=0.2"),
            0);
  int killed = 0;
  for (const double delay : {0.0, 0.3, 0.9}) {
    const std::string what = "killed " + std::to_string(delay) + " s after the first checkpoint";
    const fs::path out = dir / ("killed_" + std::to_string(int(delay * 100)));
    const pid_t pid = spawn_run(scenario, out, "0.2");
    ASSERT_GT(pid, 0);
    // Wait for the first checkpoint, then `delay`, then SIGKILL (no chance to clean up).
    const auto t0 = std::chrono::steady_clock::now();
    int status = 0;
    bool exited = false;
    while (!fs::exists(out / "checkpoint" / "state.ffcp") && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(60)) {
      if (waitpid(pid, &status, WNOHANG) == pid) {
        exited = true;
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    std::this_thread::sleep_for(std::chrono::duration<double>(delay));
    if (!exited) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      if (WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) ++killed;
    }
    ASSERT_EQ(fracflow("resume " + out.string() + " --quiet"), 0) << what;
    ff::test::expect_same_results(dir / "whole", out, what);
  }
  EXPECT_GE(killed, 2) << "the run ended before most kills; make it longer";
  fs::remove_all(dir);
}
