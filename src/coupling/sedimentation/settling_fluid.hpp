// The fluid of the sedimentation driver (src/drivers/sedimentation/): a closed box of liquid, at
// rest at the start, with the DEM's particles resolved in it (partially saturated cells, the
// DemLbmCoupler), behind one small interface so that the driver sees the DEM and this, never the
// LBM (docs ARCHITECTURE: src/coupling/ is the only code that sees two physics modules). Virtual
// calls happen once per LBM step, never per cell or particle.
#pragma once
#include <array>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "core/types.hpp"
#include "coupling/fluid_spec.hpp"
#include "dem/dem_system.hpp"
#include "io/checkpoint.hpp"

namespace ff::coupling {

struct SettlingBox {
  int dim = 2;                       // 2: D2Q9 (disks in x-y); 3: D3Q19 (spheres)
  bool double_precision = true;      // populations in double (else float)
  std::array<int, 3> cells = {8, 8, 1};  // lattice cells per axis (nz = 1 in 2D); every face a no-slip wall
  double psm_refresh = 0;            // lbm::SolverSettings::psm_refresh [cells]
};

// The lattice checks `fracflow check` makes for a box (throws InputError; `advice` names the keys).
double max_lattice_side();  // cells per axis, exclusive
void check_box_memory(const SettlingBox& box, const std::string& advice);

class SettlingFluid {
 public:
  virtual ~SettlingFluid() = default;
  // One LBM step with its DEM sub-steps (DemLbmCoupler::step); `sample`: the fluid's fields are
  // kept for max_speed() and write_vti().
  virtual void step(bool sample) = 0;
  virtual long time_step() const = 0;
  virtual double max_speed() const = 0;                       // lattice units, last sampled step; NaN if any cell is
  virtual const std::vector<Vec3>& hydro_force() const = 0;   // per particle [N], of the last step
  virtual double dem_dt() const = 0;                          // [s]
  virtual long sub_steps() const = 0;                         // DEM steps per LBM step
  virtual const CouplerTimes& times() const = 0;
  virtual std::string_view velocity_set() const = 0;          // "D2Q9" or "D3Q19"
  // "D2Q9 double 60x120x1": what a checkpoint was written from.
  virtual std::string lattice() const = 0;
  // Checkpoint sections sed.lattice, lbm.populations, sed.psm_positions and sed.psm_radii; load
  // refuses a checkpoint of another lattice (InputError) and sets the fluid's time step.
  virtual void save(CheckpointWriter& w) const = 0;
  virtual void load(CheckpointReader& r, long time_step) = 0;
  // The last sampled step's pressure [Pa], velocity [m/s] and solid fraction, one image file.
  virtual void write_vti(const std::filesystem::path& file) = 0;
};

std::unique_ptr<SettlingFluid> make_settling_fluid(const SettlingBox& box, const FluidScales& scales,
                                                   dem::DemSystem& dem);

}  // namespace ff::coupling
