// Building the lateral boundary a triaxial scenario asks for (triaxial.lateral): the flexible
// membrane's settings, the servo-controlled rigid cylinder, the particle membrane, and the
// friction of their contacts (membrane.friction). Controlling and measuring them is
// triaxial_boundary.hpp's job.
#pragma once
#include "dem/dem_system.hpp"
#include "dem/membrane/flexible_membrane.hpp"
#include "dem/membrane/particle_membrane.hpp"
#include "dem/sample_builder.hpp"
#include "io/params.hpp"

namespace ff::drivers {

// membrane.friction as the contacts take it: -1 is kGroupFriction, otherwise >= 0.
Real membrane_friction(const Config& cfg);
// The membrane around a sample of radius R between the platens: a sleeve `length_factor`
// times the sample height, centred on it, its facets `clearance` R outside the sample.
dem::MembraneSettings membrane_settings(const Config& cfg, const dem::DemSystem& sys, const dem::SampleInfo& info);
// A rigid cylinder wall around the sample (appended after the platens).
void add_rigid_cylinder(dem::DemSystem& sys, const dem::SampleInfo& info, Real friction);
// The particle membrane's material from particle_membrane.* and membrane.friction.
dem::ParticleMembraneMaterial particle_membrane_material(const Config& cfg);
// The particle membrane around the sample between the platens, after the time step is chosen:
// its spheres' inertial masses are scaled so that they do not lower it.
dem::ParticleMembraneLayout add_particle_membrane(const Config& cfg, dem::DemSystem& sys, const dem::SampleInfo& info);

}  // namespace ff::drivers
