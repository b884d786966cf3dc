// The built-in default scenario (`fracflow run` with no file): a small 3D UCS test of a
// coal-like bonded sample with seed 000's coal-matrix micro-parameters (Table 7). It finishes
// in well under a minute on 2 cores. The same text is examples/ucs_default.toml.
#include "drivers/driver.hpp"

namespace ff {
std::string_view default_scenario_text() {
  return R"toml(# fracflow built-in default: uniaxial compression of a small bonded coal-like cylinder.
driver = "ucs"
title = "default: 10 mm x 20 mm coal-matrix cylinder, parallel bonds (seed 000 Table 7)"

[dem]
dim = 3
contact_law = "linear"
bond_law = "parallel"
local_damping = 0.7

[dem.group.matrix]
density = 1390            # kg/m^3

[dem.contact.matrix-matrix]
emod = 2.09e9             # Pa
kratio = 14.65
friction = 0.4

[dem.bond.matrix-matrix]
emod = 2.09e9             # Pa
kratio = 14.65
tensile_strength = 17.4e6 # Pa
cohesion = 4.35e6         # Pa
friction_angle = 4.0      # deg

[sample]
shape = "cylinder"
diameter = 10e-3          # m
height = 20e-3            # m
radius_min = 0.4e-3
radius_max = 0.6e-3
porosity = 0.40           # 0.39 or less is denser than this small cylinder packs (warning)
seed = 1
bond_gap = 0.05e-3

[ucs]
platen_velocity = 0.2     # m/s each (inertial number ~2e-4 < 1e-3: quasi-static)
platen_friction = 0.1
stop_fraction = 0.6
)toml";
}
}  // namespace ff
