#include "drivers/triaxial/triaxial_lateral_setup.hpp"

#include <fmt/format.h>

#include "core/error.hpp"
#include "core/log.hpp"
#include "dem/contact/boundary_friction.hpp"

namespace ff::drivers {

Real membrane_friction(const Config& cfg) {
  const Real mu = cfg.real("membrane.friction");
  if (!dem::valid_boundary_friction(mu))
    cfg.fail("membrane.friction", fmt::format("{} is neither a friction coefficient (>= 0) nor -1 (each particle's own "
                                              "contact friction)", mu));
  return mu;
}

dem::MembraneSettings membrane_settings(const Config& cfg, const dem::DemSystem& sys, const dem::SampleInfo& info) {
  const Real R = 0.5 * info.width;
  dem::MembraneSettings m = dem::membrane_around_cylinder(
      R, sys.walls[0].point.z(), sys.walls[1].point.z(), static_cast<int>(cfg.integer("membrane.n_theta")),
      static_cast<int>(cfg.integer("membrane.n_z")), cfg.real("membrane.clearance"), cfg.real("membrane.length_factor"));
  m.pressure = cfg.real("triaxial.confining_pressure");
  m.v_max = cfg.real("triaxial.servo_velocity");
  m.relaxation = cfg.real("triaxial.servo_relaxation");
  m.r_min = cfg.real("membrane.min_radius_fraction") * R;
  m.friction = membrane_friction(cfg);
  m.parallel_min = sys.settings.parallel_min;
  return m;
}

void add_rigid_cylinder(dem::DemSystem& sys, const dem::SampleInfo& info, Real friction) {
  dem::Wall c;
  c.name = "cylinder";
  c.kind = dem::Wall::Kind::CylinderInside;
  c.point = Vec3::Zero();
  c.normal = Vec3::UnitZ();
  c.radius = 0.5 * info.width;
  c.friction = friction;
  sys.walls.push_back(c);
  sys.initialise();
}

dem::ParticleMembraneMaterial particle_membrane_material(const Config& cfg) {
  dem::ParticleMembraneMaterial m;
  m.emod = cfg.real("particle_membrane.emod");
  m.density = cfg.real("particle_membrane.density");
  m.bonded = cfg.boolean("particle_membrane.bonded");
  m.friction = membrane_friction(cfg);
  return m;
}

dem::ParticleMembraneLayout add_particle_membrane(const Config& cfg, dem::DemSystem& sys, const dem::SampleInfo& info) {
  const Real R = 0.5 * info.width;
  Real rmean = 0;
  for (Real r : sys.particles.radius) rmean += r;
  rmean /= static_cast<Real>(sys.particles.size());
  dem::ParticleMembraneSpec spec;
  spec.sample_radius = R;
  spec.z_bottom = sys.walls[0].point.z();
  spec.z_top = sys.walls[1].point.z();
  spec.particle_radius = cfg.real("particle_membrane.radius_fraction") * rmean;
  spec.clearance = cfg.real("membrane.clearance") * R;
  spec.pressure = cfg.real("triaxial.confining_pressure");
  dem::ParticleMembraneLayout l;
  try {
    l = dem::add_particle_membrane(sys, spec, particle_membrane_material(cfg));
  } catch (const InputError& e) {
    cfg.fail("triaxial.lateral", e.what());
  }
  const Real f = dem::stabilise_particle_membrane(sys, l, sys.settings.dt, cfg.real("dem.time_step_safety"));
  log::info("particle membrane: {} x {} spheres of radius {:.4g} m on radius {:.4g} m (inner surface {:.4g} m), {} bonds, "
            "{:.4g} N on each{}",
            l.n_theta, l.n_z, l.particle_radius, l.centre_radius, l.inner_radius(), dem::particle_membrane_bonds(sys, l),
            l.force, f > 1 ? fmt::format("; inertial masses x {:.3g} for the time step", f) : "");
  return l;
}

}  // namespace ff::drivers
