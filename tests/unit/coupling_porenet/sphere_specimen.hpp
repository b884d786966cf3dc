// The 3D coupling tests' specimen: a 6 mm cube of bonded spheres (radii 0.4-0.6 mm, the UCS driver's
// sample builder and parallel-bond law).
#pragma once
#include <string>

namespace ff::test {

inline const std::string kSphereSpecimen =
    "[dem]\ndim = 3\nbond_law = \"parallel\"\n[dem.group.matrix]\ndensity = 2400\n"
    "[dem.contact.matrix-matrix]\nemod = 2.0e9\nkratio = 2.5\nfriction = 0.4\n"
    "[dem.bond.matrix-matrix]\nemod = 2.0e9\nkratio = 2.5\ntensile_strength = 17.4e6\ncohesion = 4.35e6\n"
    "[sample]\nshape = \"box\"\nwidth = 6e-3\ndepth = 6e-3\nheight = 6e-3\nradius_min = 0.4e-3\nradius_max = 0.6e-3\n"
    "porosity = 0.45\nseed = 5\n";

}  // namespace ff::test
