// Small builders shared by the coupling tests: a DEM system of free spheres/disks (linear contact,
// no bonds, no local damping) and a lattice matching a FluidSpec.
#pragma once
#include <algorithm>
#include <array>

#include "coupling/dem_lbm_coupler.hpp"
#include "dem/dem_system.hpp"
#include "lbm/solver.hpp"

namespace ff::coupling::test {

inline dem::DemSystem free_particles(int dim, double density, double emod = 1e7) {
  dem::DemSystem s;
  s.settings.dim = dim;
  s.settings.local_damping = 0;  // hydrodynamic loads are never damped
  s.materials.group_names = {"grain"};
  s.materials.density = {density};
  dem::LinearContact::Params lc;
  lc.emod = emod;
  lc.kratio = 1.5;
  lc.fric = 0.3;
  s.materials.contact_params<dem::LinearContact>() = {lc};
  s.materials.set_bond_law<dem::NoBond>();
  return s;
}

inline void add_particle(dem::DemSystem& s, const Vec3& x, double r, const Vec3& v = Vec3::Zero(),
                         const Vec3& w = Vec3::Zero()) {
  const std::size_t i = s.particles.size();
  s.particles.resize(i + 1);
  s.particles.pos[i] = x;
  s.particles.radius[i] = r;
  s.particles.vel[i] = v;
  s.particles.omega[i] = w;
  s.particles.set_mass_from_density(i, s.materials.density[0], s.settings.dim);
  s.settings.skin = std::max(s.settings.skin, 0.2 * r);
}

template <class L>
lbm::Solver<L, double> make_fluid(const FluidScales& sc, int nx, int ny, int nz, std::array<bool, 3> periodic,
                                  lbm::PsmWeighting w = lbm::PsmWeighting::TauDependent,
                                  lbm::ParticleScheme scheme = lbm::ParticleScheme::Psm) {
  lbm::Grid g(L::D, nx, ny, nz, periodic);
  lbm::SolverSettings st;
  st.tau = sc.units.tau();
  st.psm_weighting = w;
  st.particle_scheme = scheme;
  return lbm::Solver<L, double>(g, st);
}

// Finalizes the lattice and starts the fluid at rest at lattice density rho everywhere.
template <class L>
void start_at_rest(lbm::Solver<L, double>& fluid, double rho = 1) {
  fluid.finalize();
  fluid.initialize([rho](int, int, int, double& r, Vec3& u) {
    r = rho;
    u = Vec3::Zero();
  });
}

}  // namespace ff::coupling::test
