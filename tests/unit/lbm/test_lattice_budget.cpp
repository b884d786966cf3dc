// Guards on a lattice's size (lbm/lattice_budget.hpp): the errors name the keys to change, and a
// lattice that fits passes.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/error.hpp"
#include "lbm/lattice_budget.hpp"

namespace ff::lbm {
namespace {

std::string message_of(auto&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(LatticeBudget, SidesOutsideAnIntAreRefusedWithTheKey) {
  EXPECT_EQ(lattice_side(255.6, "channel.length", "hint"), 256);
  EXPECT_EQ(lattice_side(1.2, "channel.length", "hint"), 1);
  for (double bad : {2e12, 1073741824.0, 0.2, -5.0, std::nan("")}) {
    const std::string m = message_of([&] { lattice_side(bad, "channel.height", "lower lbm.resolution"); });
    EXPECT_NE(m.find("channel.height"), std::string::npos) << bad << ": " << m;
    EXPECT_NE(m.find("lower lbm.resolution"), std::string::npos) << m;
  }
}

TEST(LatticeBudget, LatticesBeyondTheMemoryAreRefusedWithTheirSize) {
  // 1000 x 1000 cells of D2Q9 in double: 9 x 8 + 4 x 8 + 8 = 112 bytes a cell, 112 MB.
  EXPECT_DOUBLE_EQ(lattice_bytes(1000, 1000, 1, 9, 8), 112e6);
  EXPECT_NO_THROW(check_lattice_memory(1000, 1000, 1, 9, 8, "hint", 113e6));
  const std::string m = message_of([] { check_lattice_memory(1000, 1000, 1, 9, 8, "a coarser lbm.dx", 111e6); });
  EXPECT_NE(m.find("1000 x 1000 x 1"), std::string::npos) << m;
  EXPECT_NE(m.find("a coarser lbm.dx"), std::string::npos) << m;
  // This machine's memory: a million cubed cells never fit, a small lattice always does.
  EXPECT_THROW(check_lattice_memory(1e6, 1e6, 1e6, 19, 8, "hint"), InputError);
  EXPECT_NO_THROW(check_lattice_memory(64, 64, 64, 19, 8, "hint"));
}

}  // namespace
}  // namespace ff::lbm
