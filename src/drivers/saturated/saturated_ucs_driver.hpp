#pragma once
#include "drivers/driver.hpp"

namespace ff::drivers {
// Uniaxial compression of a 2D bonded sample with pore fluid (seed 004; src/coupling/porenet).
Driver saturated_ucs_driver();
}  // namespace ff::drivers
