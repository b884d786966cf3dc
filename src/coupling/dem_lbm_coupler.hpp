// Two-way coupling of the bonded-particle DEM (src/dem) with the lattice Boltzmann fluid
// (src/lbm) through partially saturated cells (Noble & Torczynski 1998; lbm/psm.hpp). The only
// code that sees both modules. docs/coupling.md describes the scheme, the units and the tests.
//
// One coupled step (time t -> t + dt_lbm):
//   1. the DEM particles (SI) become an lbm::ParticleSet (coupling/particle_set.hpp; lattice units: positions relative to
//      the centre of cell (0, 0, 0), radii / dx, v dt / dx, omega dt; ids carried along);
//      disks on D2Q9, spheres on D3Q19;
//   2. the fluid steps once with them (Solver::set_particles, step) and returns each
//      particle's force and torque, converted to SI (2D: per metre of depth, which is the force
//      on the DEM's disks of unit thickness);
//   3. the pressure on the dry side of a particle (its surface facing solid lattice cells or a
//      closed box face) is added: F_dry = + sum_k p_s n_k dA_k over the surface quadrature
//      points k that lie in dry cells, p_s = p0 + K_eff (rho_s - 1) the physical pressure of the
//      fluid around the particle (docs/coupling.md, "Pressure load");
//   4. optional buoyancy of a fully immersed particle, -rho_f V_s g (the fluid carries no body
//      force then: the hydrostatic gradient is not on the lattice);
//   5. n = ceil(dt_lbm / dt_dem) DEM sub-steps of dt_lbm / n, each adding the step's
//      hydrodynamic force and torque into ext_force / ext_moment between add_external_loads()
//      and integrate() (the force is held over the LBM step).
// Action and reaction: the fluid loses exactly the momentum the particles receive (F dt_lbm),
// so fluid + particles conserve momentum to round-off in a closed periodic box (tested).
// No allocation in step() (buffers sized at construction or on a change of particle count);
// every loop has a fixed order, so 1 and 2 threads give identical results.
#pragma once
#include <array>
#include <vector>

#include "coupling/dem_time_step.hpp"
#include "coupling/fluid_spec.hpp"
#include "dem/dem_system.hpp"
#include "lbm/solver.hpp"

namespace ff::coupling {

struct CouplerSettings {
  // SI position of the centre of lattice cell (0, 0, 0); a box [0, L] of n cells has 0.5 dx.
  Vec3 origin = Vec3::Zero();
  bool buoyancy = true;        // add -rho_f V g to every particle (fully immersed particles)
  bool pressure_load = true;   // step 3 above (dry-side pressure)
  // Surface points of the dry-side pressure: 2D: this many angles; 3D: quadrature / 8 Gauss-Legendre
  // latitudes times twice as many longitudes (64: 8 x 16 = 128 points).
  int quadrature = 64;
  // The particles' velocities in the fluid's walls: 1 moving walls; 0 quasi-static walls (the
  // hydrofrac LBM fluid's default, coupling/hydrofrac/lbm_load.cpp).
  double wall_motion = 1.0;
  // > 0: the set is handed to the fluid again only once a particle has moved this many cells since
  // the last hand-over (and the fluid steps with the set it has in between), as the hydrofrac LBM
  // fluid does with quasi-static walls; 0: every step (needed with moving walls: their velocities
  // change every step).
  double set_refresh = 0.0;
};

template <class L, class T>
class DemLbmCoupler {
 public:
  // dem.settings.dt is the DEM step wanted (e.g. a fraction of the critical step); the coupler
  // rounds it down to dt_lbm / n. dem.settings.dim must be L::D.
  DemLbmCoupler(dem::DemSystem& dem, lbm::Solver<L, T>& fluid, const FluidScales& scales, const CouplerSettings& s);

  // One LBM step and n DEM sub-steps. With sample_fluid the solver stores the fluid fields of
  // the step (density(), velocity()) - needed anyway where a particle has a dry side.
  void step(bool sample_fluid = false);

  long sub_steps() const { return n_sub_; }
  long handovers() const { return handovers_; }  // steps that handed the set to the fluid
  double dem_dt() const { return dem_.settings.dt; }
  double dt() const { return scales_.dt(); }
  const FluidScales& scales() const { return scales_; }
  // Loads of the last step on each particle [N], [N m] (2D: on the unit-thickness disk).
  const std::vector<Vec3>& hydro_force() const { return force_; }    // PSM + dry-side pressure + buoyancy
  const std::vector<Vec3>& hydro_torque() const { return torque_; }
  const std::vector<Vec3>& pressure_force() const { return dry_force_; }  // dry-side part alone
  const std::vector<double>& particle_pressure() const { return p_particle_; }  // p_s [Pa] (where dry)
  const lbm::ParticleSet& particle_set() const { return set_; }
  CouplerTimes times;

  // Total momentum of the fluid [kg m/s] (2D: per metre of depth) from the fields sampled by the
  // last step(true): sum over fluid cells of rho u at the start of that step.
  Vec3 fluid_momentum() const;
  // SI <-> lattice positions.
  Vec3 to_lattice(const Vec3& x) const { return (x - cs_.origin) / dx_; }
  bool dry(const Vec3& x_lattice) const;  // the cell nearest to a lattice point is solid or beyond a Wall face

 private:
  void build_set();
  bool set_stale() const;  // a particle moved set_refresh cells since the last hand-over
  void pressure_loads();
  void resize(std::size_t n);

  dem::DemSystem& dem_;
  lbm::Solver<L, T>& fluid_;
  FluidScales scales_;
  CouplerSettings cs_;
  double dx_;
  long n_sub_ = 1;
  long handovers_ = 0;
  lbm::ParticleSet set_;
  std::vector<Vec3> handed_;  // positions of the set last handed to the fluid (set_refresh > 0)
  std::vector<double> handed_r_;
  std::vector<char> has_dry_;  // per particle: a surface point lies in a dry cell
  // Per particle: no dry cell within reach of its surface points while it stays within kDryMove
  // (per axis) of dry_x_ (lattice units; the lattice's geometry is fixed once the coupler exists).
  static constexpr double kDryMove = 0.5;
  std::vector<char> dry_clear_;
  std::vector<Vec3> dry_x_;
  std::vector<double> dry_r_;
  bool clear_box(const Vec3& x, double r) const;  // no dry cell that a surface point can reach
  std::vector<Vec3> force_, torque_, dry_force_;
  std::vector<double> p_particle_;
  // Unit-sphere (circle) quadrature: outward normals and weights (sum of weights = 4 pi or 2 pi).
  std::vector<Vec3> qn_;
  std::vector<double> qw_;
};

extern template class DemLbmCoupler<lbm::D2Q9, double>;
extern template class DemLbmCoupler<lbm::D2Q9, float>;
extern template class DemLbmCoupler<lbm::D3Q19, double>;
extern template class DemLbmCoupler<lbm::D3Q19, float>;

}  // namespace ff::coupling
