// injection.fluid = "lbm": the borehole fluid as a lattice Boltzmann fluid over the whole block
// (D2Q9 for disks, D3Q19 for spheres), coupled to the bonded particles (docs/hydrofrac.md,
// "Lattice Boltzmann fluid"). The fluid is in SI through coupling::FluidSpec: the lattice holds
// p - p0 as K_eff (rho_lb - 1) with a reduced sound speed (docs/coupling.md).
//
// Per LBM step (every n DEM steps, n = floor(dt_lbm / dt_dem); the LBM step is then n dt_dem):
//   1. the particles become the solver's ParticleSet (coupling::fill_particle_set; with quasi-static
//      walls, the default, only after one has moved 0.02 cells) and the fluid steps once;
//      with the bounce-back schemes (default: interpolated, Bouzidi) the cells inside particles
//      are solid, so intact rock holds the pressure and fluid enters only opened cracks; the PSM
//      is allowed but its covered cells leak a static pressure (docs/coupling.md);
//   2. the borehole's fluid cells get f = f^eq(rho_b, 0): ramp mode rho_b =
//      FluidScales::lattice_density(p(t)), rate mode rho_b such that the hole gains the pumped
//      mass Q dt (a uniform mass source; the pressure is then the mean over the hole's cells);
//      the mass imposed, integrated, is the injected volume (at the reference density);
//   3. drained faces (fluid.faces = "drained"): the lattice's outer layer gets f^eq(1, 0) (p0);
//   4. each particle touching fluid connected to the hole gets the solver's load (relative to
//      rho_lb = 1: p - p0), converted to SI and held over the next n DEM steps; the mean gauge
//      pressure on each face of the lattice goes to the servo walls (face_pressures()).
// Verified (test_hydrofrac_lbm_load): the wall's load is p times its wetted chord (total within
// 0.2%), a pre-cut crack fills to the hole pressure, an isolated one stays dry, and the mass budget
// (budget()) closes. fluid.moving_walls = true diverges (explicit coupling, added-mass instability:
// docs/hydrofrac.md).
// No allocation per step once the set has its size; the solver's loops are deterministic, so 1
// and 2 threads give identical results; the checkpoint holds the populations, the LBM's step and
// the last particle set, so a resumed run continues bit-for-bit.
#pragma once
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "coupling/fluid_spec.hpp"
#include "coupling/hydrofrac/fluid_load.hpp"
#include "lbm/moving_boundary.hpp"

namespace ff::coupling::hydrofrac {

struct LbmSettings {
  coupling::FluidSpec fluid;  // dx and one of bulk_modulus / sound_speed / time_step / tau set
  lbm::ParticleScheme scheme = lbm::ParticleScheme::InterpolatedBounceBack;
  lbm::PsmWeighting psm_weighting = lbm::PsmWeighting::TauDependent;
  bool rate_mode = false;
  Real ramp_rate = 0, initial_pressure = 0, flow_rate = 0;  // [Pa/s], [Pa], [m^3/s] (2D: per metre)
  // Rate mode: the pumped fluid enters as a mass source spread over the hole's cells (false) or
  // through a velocity box in the hole (seed 003 Sec. 4.1: a square of half-side box_fraction x the
  // hole's radius about its axis whose cells carry f^eq at the outward velocity that gives the rate).
  bool velocity_box = false;
  Real box_fraction = 0.5;
  Real cell = 0, inflate = 0, reach = 0;                    // wall particles (hole_surface)
  bool moving_walls = false;  // particle velocities enter bounce-back (false: quasi-static walls)
  bool drained_faces = false;  // fluid.faces = "drained": the lattice's outer layer held at p0
  Real wet_fraction = 0.5;  // a crack is wetted when its cell's p - p0 exceeds this fraction of the hole's
};

// What the LBM side derived (for the log and summary.json).
struct LbmInfo {
  coupling::FluidScales scales;
  long stride = 1;  // DEM steps per LBM step (the sub-cycle count n)
  Real dem_dt = 0;  // the DEM step [s]; dt_lbm = stride x dem_dt
  int n[3] = {1, 1, 1};
  Vec3 origin = Vec3::Zero();  // SI centre of cell (0, 0, 0)
  std::string describe() const;
};

// Where the injected fluid went (volumes at the reference density rho_f, m^3; 2D per metre):
// lattice_change = injected + drained + covering_refill + residual, the residual being what the
// walls' bounce-back (interpolation, moving-wall term) created or destroyed.
struct LbmBudget {
  Real injected = 0, lattice_change = 0, covering_refill = 0, residual = 0;
  Real drained = 0;  // mass the drained faces removed (negative: outflow); 0 with closed faces
  long lbm_steps = 0;
  long set_changes = 0;  // LBM steps that rebuilt the particles' solid cells (quasi-static walls: after 0.02 dx of motion)
  double max_mach = 0;   // largest Mach number of the fluid seen (sampled every 20 LBM steps)
};

// The fluid load; dim 2 or 3. `dem_dt` is the DEM step the driver uses.
class LbmLoadBase : public FluidLoad {
 public:
  virtual const LbmInfo& info() const = 0;
  virtual Real effective_radius() const = 0;  // of the hole's wetted surface (hole_surface), at begin()
  // Lattice fields for the VTK writer: pressure [Pa], velocity [m/s], flag (0 fluid, 1 solid).
  virtual void write_vti(const std::filesystem::path& file) const = 0;
  // Physical pressure of the lattice cell containing x [Pa] (x in SI); p0 where the cell is solid.
  virtual Real pressure_at(const Vec3& x) const = 0;
  virtual bool wet_at(const Vec3& x) const = 0;  // the cell containing x is fluid now
  // Hydrodynamic force of the last LBM step on particle i [N] (2D: per metre).
  virtual const std::vector<Vec3>& hydro_force() const = 0;
  virtual LbmBudget budget() const = 0;  // sums the lattice: once per report, not per step
};

std::unique_ptr<LbmLoadBase> make_lbm_load(const LbmSettings& s, int dim);
// The scales and stride without building a lattice (check / log).
LbmInfo lbm_info(const LbmSettings& s, Real dem_dt);
// The lattice over the particles (every particle plus one cell): sets info.n and info.origin.
void size_lattice(const dem::ParticleStore& p, Real dx, int dim, LbmInfo& info);

}  // namespace ff::coupling::hydrofrac
