#include "drivers/triaxial/triaxial_boundary.hpp"

#include <cmath>

namespace ff::drivers {

Real platen_stress(const dem::DemSystem& sys, Real area) {
  // Particles push the bottom platen towards -z and the top one towards +z.
  return 0.5 * (-sys.walls[0].force.z() + sys.walls[1].force.z()) / area;
}

void servo_platens(dem::DemSystem& sys, Real target, Real area, const ServoSettings& s) {
  const Real dt = sys.settings.dt;
  for (int w = 0; w < 2; ++w) {
    auto& wall = sys.walls[w];
    const Real pushed = w == 0 ? -wall.force.z() : wall.force.z();  // compressive force on this platen
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

Real applied_confinement(dem::DemSystem& sys, LateralKind kind, std::size_t cylinder_wall) {
  if (kind == LateralKind::Membrane) return sys.membrane->mean_confinement();
  const Real r = sys.walls[cylinder_wall].radius;
  return cylinder_radial_force(sys, cylinder_wall) / band_area(sys, r);
}

Real enclosed_volume(const dem::DemSystem& sys, LateralKind kind, std::size_t cylinder_wall) {
  const Real z0 = sys.walls[0].point.z(), z1 = sys.walls[1].point.z();
  if (kind == LateralKind::Membrane) return sys.membrane->enclosed_volume(z0, z1);
  const Real r = sys.walls[cylinder_wall].radius;
  return kPi * r * r * (z1 - z0);
}

std::vector<SphereStress> measure_spheres(const dem::DemSystem& sys, const dem::SampleInfo& info, Real z_bottom,
                                          Real z_top, Real radius_fraction) {
  std::vector<SphereStress> out;
  const Real rs = radius_fraction * 0.5 * info.width;
  const auto& P = sys.particles;
  for (Real frac : {0.25, 0.5, 0.75}) {
    SphereStress m;
    m.centre = Vec3(0, 0, z_bottom + frac * (z_top - z_bottom));
    m.radius = rs;
    auto inside = [&](const Vec3& x) { return (x - m.centre).squaredNorm() <= rs * rs; };
    Real vp = 0;
    m.particles = 0;
    for (std::size_t i = 0; i < P.size(); ++i) {
      if (!inside(P.pos[i])) continue;
      vp += 4.0 / 3.0 * kPi * P.radius[i] * P.radius[i] * P.radius[i];
      ++m.particles;
    }
    const Real volume = vp > 0 ? vp / (1 - info.porosity) : 1;
    const Mat3 s = sys.average_stress(inside, volume);
    m.axial = -s(2, 2);
    m.lateral = -0.5 * (s(0, 0) + s(1, 1));
    out.push_back(m);
  }
  return out;
}

}  // namespace ff::drivers
