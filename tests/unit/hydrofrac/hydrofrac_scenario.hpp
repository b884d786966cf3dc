// Shared by the hydrofrac tests: the coal-matrix material of examples/ucs_2d.toml (the Brazilian
// tests' material), an output section without VTK, plots or progress, where the first cracks lie,
// and the stop-and-resume check.
#pragma once
#include <fmt/format.h>

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "io/csv.hpp"
#include "../program_runner.hpp"
#include "../../validation/resume_compare.hpp"  // read_bytes

namespace ff::test {

// 2D parallel bonds with the coal matrix's micro-parameters; bond strength [Pa] as given.
inline std::string coal_matrix_2d(double strength) {
  return fmt::format(R"(
[dem]
dim = 2
bond_law = "parallel"
[dem.group.matrix]
density = 1390
[dem.contact.matrix-matrix]
emod = 2.09e9
kratio = 14.65
friction = 0.4
[dem.bond.matrix-matrix]
emod = 2.09e9
kratio = 14.65
tensile_strength = {0}
cohesion = {0}
friction_angle = 4.0
)",
                     strength);
}

inline const std::string kQuietOutput = R"(
[output]
vtk = false
plots = false
progress_interval = 0
)";

// Distances from the hole's axis of the first `n` cracks of cracks.csv (x_m, y_m columns).
inline std::vector<double> first_crack_distances(const std::filesystem::path& csv, double cx, double cy,
                                                 std::size_t n) {
  const auto t = ff::read_csv(csv);
  const auto& x = t.column("x_m");
  const auto& y = t.column("y_m");
  std::vector<double> d;
  for (std::size_t r = 0; r < t.rows() && d.size() < n; ++r) d.push_back(std::hypot(x[r] - cx, y[r] - cy));
  return d;
}

// `file` run into `parts`, stopped after `stop` steps and resumed by `fracflow resume` (one thread,
// `sets` as the whole run had them): series.csv and cracks.csv byte for byte those of the whole run
// in `whole`.
inline void expect_resume_identical(const std::filesystem::path& file, const std::filesystem::path& whole,
                                    const std::filesystem::path& parts, long stop, const std::string& sets = "") {
  auto r = run_program("run " + file.string() + " --out " + parts.string() + " -q -j1 --max-steps " +
                       std::to_string(stop) + sets);
  ASSERT_EQ(r.code, 0) << r.output;
  ASSERT_FALSE(std::filesystem::exists(parts / "summary.json"));
  r = run_program("resume " + parts.string() + " -q -j1");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(read_bytes(whole / "series.csv"), read_bytes(parts / "series.csv"));
  EXPECT_EQ(read_bytes(whole / "cracks.csv"), read_bytes(parts / "cracks.csv"));
}

}  // namespace ff::test
