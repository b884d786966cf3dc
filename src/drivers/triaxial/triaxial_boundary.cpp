#include "drivers/triaxial/triaxial_boundary.hpp"

#include <algorithm>
#include <cmath>

#include "geometry/shapes.hpp"
#include "dem/diagnostics.hpp"
#include "dem/membrane/membrane_boundary.hpp"

namespace ff::drivers {

void platen_forces(const dem::DemSystem& sys, std::size_t sample_particles, Real& bottom, Real& top) {
  // Particles push the bottom platen towards -z and the top one towards +z.
  if (sample_particles >= sys.particles.size()) {
    bottom = -sys.walls[0].force.z();
    top = sys.walls[1].force.z();
    return;
  }
  Real f[2] = {0, 0};
  for (int w = 0; w < 2; ++w) {  // candidate order, as the wall totals
    const auto& wc = sys.wall_contacts()[w];
    for (std::size_t k = 0; k < wc.particle.size(); ++k)
      if (static_cast<std::size_t>(wc.particle[k]) < sample_particles) f[w] += wc.load[k].f.z();
  }
  bottom = -f[0];
  top = f[1];
}

Real platen_stress(const dem::DemSystem& sys, Real area, std::size_t sample_particles) {
  Real bottom, top;
  platen_forces(sys, sample_particles, bottom, top);
  return 0.5 * (bottom + top) / area;
}

void servo_platens(dem::DemSystem& sys, Real target, Real area, const ServoSettings& s, std::size_t sample_particles) {
  const Real dt = sys.settings.dt;
  Real forces[2];
  platen_forces(sys, sample_particles, forces[0], forces[1]);
  for (int w = 0; w < 2; ++w) {
    auto& wall = sys.walls[w];
    const Real pushed = forces[w];  // compressive force on this platen
    // servo_law: positive = towards the sample; F^c is the signed contact force (< 0 when pushed).
    const Real v = dem::FlexibleMembrane::servo_law(target * area, -pushed, wall.contact_stiffness, dt, s.relaxation,
                                                    s.v_max);
    wall.velocity = Vec3(0, 0, w == 0 ? v : -v);
  }
}

Real cylinder_radial_force(dem::DemSystem& sys, std::size_t w) {
  const auto& wall = sys.walls[w];
  const auto& wc = sys.wall_contacts()[w];
  Real sum = 0;
  for (std::size_t k = 0; k < wc.particle.size(); ++k) {
    const Vec3& f = wc.load[k].f;  // force on the wall
    if (f.squaredNorm() == 0) continue;
    Vec3 d = sys.particles.pos[wc.particle[k]] - wall.point;
    d -= d.dot(wall.normal) * wall.normal;
    const Real rho = d.norm();
    if (rho > 0) sum += f.dot(d) / rho;
  }
  return sum;
}

namespace {
Real band_area(const dem::DemSystem& sys, Real radius) {
  return 2 * kPi * radius * (sys.walls[1].point.z() - sys.walls[0].point.z());
}
}  // namespace

void servo_cylinder(dem::DemSystem& sys, std::size_t w, Real target, const ServoSettings& s) {
  auto& wall = sys.walls[w];
  const Real f = cylinder_radial_force(sys, w);
  const Real v = dem::FlexibleMembrane::servo_law(target * band_area(sys, wall.radius), -f, wall.contact_stiffness,
                                                  sys.settings.dt, s.relaxation, s.v_max);
  wall.radial_velocity = -v;  // positive servo velocity = inward = shrinking radius
}

Real applied_confinement(dem::DemSystem& sys, const Lateral& lat) {
  if (lat.kind == LateralKind::Membrane) return dem::membrane_of(sys)->mean_confinement();
  if (lat.kind == LateralKind::ParticleMembrane)
    return dem::particle_membrane_confinement(sys.particles, lat.particles, sys.walls[0].point.z(), sys.walls[1].point.z());
  const Real r = sys.walls[lat.cylinder_wall].radius;
  return cylinder_radial_force(sys, lat.cylinder_wall) / band_area(sys, r);
}

Real enclosed_volume(const dem::DemSystem& sys, const Lateral& lat) {
  const Real z0 = sys.walls[0].point.z(), z1 = sys.walls[1].point.z();
  if (lat.kind == LateralKind::Membrane) return dem::membrane_of(sys)->enclosed_volume(z0, z1);
  if (lat.kind == LateralKind::ParticleMembrane) return dem::particle_membrane_volume(sys.particles, lat.particles, z0, z1);
  const Real r = sys.walls[lat.cylinder_wall].radius;
  return kPi * r * r * (z1 - z0);
}

std::vector<SphereStress> measure_spheres(const dem::DemSystem& sys, const dem::SampleInfo& info, Real z_bottom,
                                          Real z_top, Real radius_fraction, std::size_t sample_particles) {
  std::vector<SphereStress> out;
  const Real rs = radius_fraction * 0.5 * info.width;
  const auto& P = sys.particles;
  const std::size_t n = std::min(sample_particles, P.size());
  for (Real frac : {0.25, 0.5, 0.75}) {
    SphereStress m;
    m.centre = Vec3(0, 0, z_bottom + frac * (z_top - z_bottom));
    m.radius = rs;
    auto inside = [&](Index i) {
      return static_cast<std::size_t>(i) < n && (P.pos[i] - m.centre).squaredNorm() <= rs * rs;
    };
    Real vp = 0, solid = 0;
    m.particles = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const Real r = P.radius[i];
      solid += geom::sphere_overlap_volume(rs, r, (P.pos[i] - m.centre).norm());
      if (!inside(static_cast<Index>(i))) continue;
      vp += 4.0 / 3.0 * kPi * r * r * r;
      ++m.particles;
    }
    const Real sphere_volume = 4.0 / 3.0 * kPi * rs * rs * rs;
    m.porosity = 1 - solid / sphere_volume;
    // (1 - n) / sum(V_p) = 1 / volume: the particles' volume spread at the region's own solid fraction.
    const Real volume = vp > 0 && solid > 0 ? vp * sphere_volume / solid : 1;
    const Mat3 s = average_stress_of(sys, inside, volume);
    m.axial = -s(2, 2);
    m.lateral = -0.5 * (s(0, 0) + s(1, 1));
    out.push_back(m);
  }
  return out;
}

}  // namespace ff::drivers
