// Saving and restoring the complete state of a DemSystem (particles, bonds and their
// history, contact history, the neighbour list with its reference positions, walls, cracks),
// so that a resumed run is bit-identical to an uninterrupted one.
#pragma once
#include "dem/dem_system.hpp"
#include "io/checkpoint.hpp"

namespace ff::dem {

void save_dem(CheckpointWriter& w, const DemSystem& sys);
// `sys` must already hold settings and materials built from the same scenario.
void load_dem(CheckpointReader& r, DemSystem& sys);

}  // namespace ff::dem
