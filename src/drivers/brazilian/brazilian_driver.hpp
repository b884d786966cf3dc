// Tensile strength of a bonded-particle sample, by the two tests rock mechanics uses:
// - brazilian: the indirect tensile test (ISRM 1978 suggested method; Potyondy & Cundall 2004
//   section 3.3): a disc (2D) or a cylinder lying on its side (3D) pressed across a diameter
//   between two rigid platens; sigma_t = 2 P / (pi D t) from the peak load P.
// - direct_tension: the sample's end slabs are glued to rigid grips pulled apart at a constant
//   speed; sigma_t = peak pulling force / cross-section.
// Both run on the shared DEM loop (dem_run_loop.hpp).
#pragma once
#include "drivers/driver.hpp"

namespace ff::drivers {
Driver brazilian_driver();
Driver direct_tension_driver();
}  // namespace ff::drivers
