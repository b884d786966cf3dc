// What a bond law returns each step, shared by every bond law.
#pragma once
#include <cstdint>

#include "core/types.hpp"

namespace ff::dem {

// Force on B (minus it acts on A) and the TOTAL moments about each particle's own centre
// (couples plus the lever arm of the force), so the engine adds them as they are.
struct BondLoad {
  Vec3 force_on_B = Vec3::Zero();
  Vec3 moment_on_A = Vec3::Zero(), moment_on_B = Vec3::Zero();
};
enum class BondFailure : std::uint8_t { None = 0, Tensile = 1, Shear = 2 };

}  // namespace ff::dem
