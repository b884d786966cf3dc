// Runs the fracflow program (FRACFLOW_BIN, set by CMake) as a user would, for the CLI tests:
// its exit code and everything it printed, and per-test scratch folders.
#pragma once
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

namespace ff::test {

struct ProgramResult {
  int code;  // exit status; -1 when the program was killed by a signal
  std::string output;  // stdout and stderr together
};

#ifdef FRACFLOW_BIN
// `prefix` goes before the program (e.g. "cd DIR && ", "HOME=DIR ", "timeout -s KILL 20 ").
inline ProgramResult run_program(const std::string& args, const std::string& prefix = "") {
  const std::string cmd = prefix + std::string(FRACFLOW_BIN) + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 4096> buf;
  while (std::fgets(buf.data(), buf.size(), p)) out += buf.data();
  const int status = pclose(p);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}
#endif

// A fresh folder named after the running test (and `tag`), removed with this object.
struct TestScratch {
  std::filesystem::path path;
  explicit TestScratch(const std::string& tag) {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path = std::filesystem::temp_directory_path() /
           ("fracflow-" + tag + "-" + std::string(info ? info->name() : "none") + "-" + std::to_string(::getpid()));
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
  }
  ~TestScratch() {
    std::error_code ec;
    // A test may have made it read-only (unwritable --out).
    std::filesystem::permissions(path, std::filesystem::perms::owner_all, std::filesystem::perm_options::add, ec);
    std::filesystem::remove_all(path, ec);
  }
  std::filesystem::path operator/(const std::string& n) const { return path / n; }
};

// A results folder path for a test's program run, removed first: TMP/fracflow_<tag>_<name>.
inline std::filesystem::path fresh_out_dir(const std::string& tag, const std::string& name) {
  const auto p = std::filesystem::temp_directory_path() / ("fracflow_" + tag + "_" + name);
  std::filesystem::remove_all(p);
  return p;
}

inline nlohmann::json read_json(const std::filesystem::path& p) {
  std::ifstream f(p);
  return nlohmann::json::parse(f);
}

}  // namespace ff::test
