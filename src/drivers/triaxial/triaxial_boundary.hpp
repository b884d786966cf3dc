// Boundary control and measurement of the triaxial test: the lateral confinement (flexible
// membrane, servo-controlled rigid cylinder or particle membrane), the platen servo of the
// isotropic stage, and the measurement spheres that check the stress inside the sample against
// the boundary. Rock-mechanics signs here: compression positive.
#pragma once
#include <limits>
#include <string>
#include <vector>

#include "dem/dem_system.hpp"
#include "dem/membrane/particle_membrane.hpp"
#include "dem/sample_builder.hpp"

namespace ff::drivers {

enum class LateralKind : std::uint8_t { Membrane = 0, RigidCylinder = 1, ParticleMembrane = 2 };

// The lateral boundary of a run.
struct Lateral {
  LateralKind kind = LateralKind::Membrane;
  std::size_t cylinder_wall = 2;              // RigidCylinder: the wall after the platens
  dem::ParticleMembraneLayout particles;      // ParticleMembrane: its spheres follow the sample's
  // Particles of the sample proper (the membrane's spheres are appended after them).
  std::size_t sample_particles(const dem::DemSystem& sys) const {
    return kind == LateralKind::ParticleMembrane ? static_cast<std::size_t>(particles.first) : sys.particles.size();
  }
};

// Servo gains shared by the platens and the rigid cylinder (PFC wall servo, METHODS.md 3):
// v = G (F_target - F), G = alpha / (k dt), |v| <= v_max; v_max towards the sample when k = 0.
struct ServoSettings {
  Real v_max = 0.01;     // [m/s]
  Real relaxation = 0.8; // alpha [-]
};

// Compressive forces on the bottom and top platens (walls 0 and 1) from the particles with
// index < sample_particles [N]: the walls' totals when that is all of them. A particle membrane's
// spheres also touch the platens; their soft column's share is not the sample's stress.
void platen_forces(const dem::DemSystem& sys, std::size_t sample_particles, Real& bottom, Real& top);
// Mean axial stress on the two platens over the area `area` [Pa].
Real platen_stress(const dem::DemSystem& sys, Real area,
                   std::size_t sample_particles = std::numeric_limits<std::size_t>::max());
// Sets both platens' velocities so their stress approaches `target` [Pa] (isotropic stage).
void servo_platens(dem::DemSystem& sys, Real target, Real area, const ServoSettings& s,
                   std::size_t sample_particles = std::numeric_limits<std::size_t>::max());

// Radial force of the particles on the rigid cylinder wall `w`, outward positive [N].
Real cylinder_radial_force(dem::DemSystem& sys, std::size_t w);
// Sets the cylinder's radial velocity so the pressure on its band between the platens
// approaches `target` [Pa].
void servo_cylinder(dem::DemSystem& sys, std::size_t w, Real target, const ServoSettings& s);

// Lateral confinement actually applied [Pa]: the membrane's mean (-sum F^c / loaded area), the
// cylinder's radial force over its band area, or the particle membrane's constant total force
// over its current inner surface between the platens.
Real applied_confinement(dem::DemSystem& sys, const Lateral& lateral);
// Volume enclosed between the platens by the lateral boundary [m^3].
Real enclosed_volume(const dem::DemSystem& sys, const Lateral& lateral);

// Measurement spheres on the sample axis ([S000] sec. 5.1 checks the isotropic state with
// PFC measurement spheres). Average stress over the particles whose centres lie in a sphere,
// with PFC's porosity correction sigma = -(1 - n)/sum(V_p) sum_p sum_c (x_c - x_p) f_c
// (Itasca PFC 5 "measure" logic; METHODS.md 1.7), n = the porosity inside the sphere, from the
// exact volume of every particle's part in it (the core of a walled sample is denser than the
// sample's mean, so the sample porosity would understate the core's stress).
struct SphereStress {
  Vec3 centre;
  Real radius;
  int particles;
  Real porosity;
  Real axial, lateral;  // -sigma_zz and -(sigma_xx + sigma_yy)/2 [Pa]
};
// Only particles with index < sample_particles count (a particle membrane's do not).
std::vector<SphereStress> measure_spheres(const dem::DemSystem& sys, const dem::SampleInfo& info, Real z_bottom,
                                          Real z_top, Real radius_fraction,
                                          std::size_t sample_particles = std::numeric_limits<std::size_t>::max());

}  // namespace ff::drivers
