// Uniaxial compressive strength (UCS) test of a bonded-particle sample (seed 000 sections
// 4-5; Potyondy & Cundall 2004 section 3): platens approach at constant velocity until the
// axial stress has fallen to a set fraction of its peak.
#pragma once
#include "drivers/driver.hpp"

namespace ff::drivers {
Driver ucs_driver();
// Declares the ucs.* keys and the DEM and sample keys they need.
void declare_ucs_params(ParamTable& t);
}
