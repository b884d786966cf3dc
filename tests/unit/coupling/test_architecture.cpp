// The module tree's one rule that the compiler does not check (docs ARCHITECTURE, "Dependencies
// point one way: core <- geometry <- {dem, lattice, lbm, porenet} <- coupling <- drivers <- apps";
// issue 15, item 1: src/coupling/ is the only code that sees two physics modules): read every
// source file's #include lines and check that
//   - no file outside src/coupling/ includes headers of two physics modules (dem, lattice, lbm,
//     porenet), directly;
//   - a physics module includes no other physics module, and nothing of coupling/, drivers/, batch/
//     or apps/; coupling/ includes nothing of drivers/, batch/ or apps/.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

const std::set<std::string> kPhysics = {"dem", "lattice", "lbm", "porenet"};

// The top folders of the project's own headers that a file includes ("dem" for "dem/x.hpp").
std::set<std::string> included_modules(const fs::path& file) {
  static const std::regex inc(R"re(^\s*#\s*include\s*"([a-z_]+)/)re");
  std::set<std::string> out;
  std::ifstream in(file);
  std::string line;
  std::smatch m;
  while (std::getline(in, line))
    if (std::regex_search(line, m, inc)) out.insert(m[1]);
  return out;
}

struct SourceFile {
  fs::path path;        // relative to the source tree
  std::string module;   // src/<module>/... ; "apps" for apps/
};

std::vector<SourceFile> sources() {
  std::vector<SourceFile> v;
  const fs::path root = FRACFLOW_SOURCE_DIR;
  for (const char* top : {"src", "apps"})
    for (const auto& e : fs::recursive_directory_iterator(root / top)) {
      const auto ext = e.path().extension();
      if (!e.is_regular_file() || (ext != ".cpp" && ext != ".hpp" && ext != ".h")) continue;
      const fs::path rel = fs::relative(e.path(), root);
      auto it = rel.begin();
      const std::string first = (it++)->string();
      v.push_back({rel, first == "apps" ? "apps" : it->string()});
    }
  return v;
}

}  // namespace

TEST(Architecture, OnlyCouplingSeesTwoPhysicsModules) {
  const auto files = sources();
  ASSERT_GT(files.size(), 100u) << "source tree not found at " << FRACFLOW_SOURCE_DIR;
  int checked = 0;
  for (const SourceFile& f : files) {
    const auto mods = included_modules(fs::path(FRACFLOW_SOURCE_DIR) / f.path);
    std::vector<std::string> physics;
    for (const auto& m : mods)
      if (kPhysics.count(m) && m != f.module) physics.push_back(m);
    if (kPhysics.count(f.module)) {
      // A physics module: no other physics module, nothing above it.
      EXPECT_TRUE(physics.empty()) << f.path << " (module " << f.module << ") includes " << physics.front() << "/";
      for (const char* above : {"coupling", "drivers", "batch", "apps"})
        EXPECT_FALSE(mods.count(above)) << f.path << " includes " << above << "/";
    } else if (f.module == "coupling") {
      for (const char* above : {"drivers", "batch", "apps"}) EXPECT_FALSE(mods.count(above)) << f.path << " includes " << above << "/";
    } else {
      EXPECT_LT(physics.size(), 2u) << f.path << " includes two physics modules (" << physics.front() << "/, "
                                    << physics.back() << "/): that belongs in src/coupling/";
    }
    ++checked;
  }
  std::printf("%d source files checked\n", checked);
}
