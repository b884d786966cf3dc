// The DEM step of a coupled run (DEM-only: drivers that see the fluid through an interface use it
// too). Defined in dem_lbm_coupler.cpp.
#pragma once
#include "dem/dem_system.hpp"

namespace ff::coupling {

// A DEM step for a coupled run: safety x the smaller of the engine's critical step (contacts and
// bonds now) and the step of a contact that may form later (each particle against one like it,
// overlap 1% of its radius) [s].
double coupled_dem_time_step(const dem::DemSystem& dem, double safety);

}  // namespace ff::coupling
