// sedimentation: particles settling under gravity in a closed box of fluid, through the DEM-LBM
// coupling (src/coupling, partially saturated cells). 2D (D2Q9, disks of unit thickness):
// drafting, kissing and tumbling of two disks in a channel (Fortes, Joseph & Lundgren 1987;
// Feng, Hu & Joseph 1994; Glowinski et al. 2001); 3D (D3Q19, spheres): a sphere settling in a
// box (ten Cate et al. 2002). Writes series.csv (positions, velocities, hydrodynamic forces),
// summary.json, VTK of the fluid (pressure, velocity, solid fraction) and the particles, plots,
// checkpoints; resumes bit for bit.
#pragma once
#include "drivers/driver.hpp"

namespace ff::drivers {
Driver sedimentation_driver();
}  // namespace ff::drivers
