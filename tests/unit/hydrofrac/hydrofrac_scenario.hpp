// Scenario text shared by the hydrofrac tests: the coal-matrix material of examples/ucs_2d.toml
// (the Brazilian tests' material) and an output section without VTK, plots or progress.
#pragma once
#include <fmt/format.h>

#include <string>

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

}  // namespace ff::test
