#include "coupling/particle_set.hpp"

namespace ff::coupling {

void fill_particle_set(const dem::ParticleStore& p, const Vec3& origin, const lbm::Units& u, int dim, lbm::ParticleSet& set,
                       double motion) {
  if (set.size() != p.size()) set.resize(p.size());
  const double dx = u.dx(), dt = u.dt(), vf = motion * dt / dx, wf = motion * dt;
  for (std::size_t i = 0; i < p.size(); ++i) {
    set.id[i] = std::uint64_t(p.id[i]);
    set.position[i] = (p.pos[i] - origin) / dx;
    set.radius[i] = p.radius[i] / dx;
    set.velocity[i] = p.vel[i] * vf;
    set.omega[i] = p.omega[i] * wf;
    if (dim == 2) {
      set.position[i].z() = 0;
      set.velocity[i].z() = 0;
      set.omega[i].x() = set.omega[i].y() = 0;
    }
  }
}

SiLoad to_si_load(const lbm::Units& u, int dim, const Vec3& f, const Vec3& m) {
  SiLoad s{Vec3(u.to_si_force(f.x(), dim), u.to_si_force(f.y(), dim), u.to_si_force(f.z(), dim)),
           Vec3(u.to_si_torque(m.x(), dim), u.to_si_torque(m.y(), dim), u.to_si_torque(m.z(), dim))};
  if (dim == 2) {
    s.force.z() = 0;
    s.torque.x() = s.torque.y() = 0;
  }
  return s;
}

}  // namespace ff::coupling
