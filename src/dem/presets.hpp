// Scenario fragments used by benchmarks and tests: seed 000 Table 7 coal-matrix micro-parameters
// (Zhao, Konietzky & Herbst 2021, PFC3D linear parallel-bond model).
#pragma once
#include <string_view>

namespace ff::dem {
inline constexpr std::string_view kCoalMatrixTable7Toml = R"(
[dem.group.matrix]
density = 1390
[dem.contact.matrix-matrix]
emod = 2.09e9
kratio = 14.65
friction = 0.4
[dem.bond.matrix-matrix]
emod = 2.09e9
kratio = 14.65
tensile_strength = 17.4e6
cohesion = 4.35e6
friction_angle = 4.0
)";
}  // namespace ff::dem
