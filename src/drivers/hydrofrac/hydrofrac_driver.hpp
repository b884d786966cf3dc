// driver = "hydrofrac": hydraulic fracturing from a borehole in a bonded-particle block
// (docs/hydrofrac.md). 2D disks or 3D spheres, either bond law: the block is built by the
// sample builder, the borehole (and perforations) carved out, natural fractures cut as
// zero-strength bonds, the in-situ stresses applied by servo-controlled walls until
// equilibrium, then the fluid (fluid_load.hpp) pressurises the hole until breakdown.
#pragma once
#include "drivers/driver.hpp"

namespace ff::drivers {
Driver hydrofrac_driver();
}
