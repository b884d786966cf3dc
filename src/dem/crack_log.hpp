// Every bond failure is a crack event (Potyondy & Cundall 2004; seed 000 Table 8): time,
// position, normal, size, mode and the two groups. Events are appended in bond order
// after each step's parallel bond loop, so the log is the same on any thread count.
#pragma once
#include <vector>

#include "core/types.hpp"

namespace ff::dem {

struct CrackEvent {
  Real time;
  Vec3 position;     // contact point of the broken bond [m]
  Vec3 normal;       // bond axis (crack plane normal)
  Real size;         // bond radius [m] (crack disc radius)
  std::uint8_t mode; // 1 tensile, 2 shear
  std::int32_t group_a, group_b;
  std::int64_t i, j; // global ids of the two particles (ParticleStore::id; stable under reordering)
};

struct CrackLog {
  std::vector<CrackEvent> events;
  long tensile = 0, shear = 0;
  void add(const CrackEvent& e) {
    events.push_back(e);
    (e.mode == 1 ? tensile : shear)++;
  }
  long total() const { return tensile + shear; }
  // Count per (ordered-independent) group pair and mode.
  long count(int ga, int gb, int mode) const {
    long c = 0;
    for (auto& e : events)
      if (e.mode == mode && ((e.group_a == ga && e.group_b == gb) || (e.group_a == gb && e.group_b == ga))) ++c;
    return c;
  }
};

}  // namespace ff::dem
