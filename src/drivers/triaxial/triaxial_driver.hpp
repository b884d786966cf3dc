// Triaxial compression of a bonded-particle cylinder (seed 000 [S000] sec. 5: Zhao, Konietzky &
// Herbst 2021): an isotropic stage brings platens and lateral confinement to the confining
// pressure, then the platens approach at constant velocity under constant confinement until the
// differential stress has fallen to a set fraction of its peak. The lateral confinement is a
// flexible membrane of servo-controlled triangles (default), or a rigid cylinder whose radius
// is servo-controlled (for comparison, [S000] Fig. 15).
#pragma once
#include "drivers/driver.hpp"

namespace ff::drivers {
Driver triaxial_driver();
}
