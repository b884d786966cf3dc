// A flow benchmark (Poiseuille channel, lid-driven cavity, cylinder in a channel) as seen
// by the shared LBM runner (flow_runner.hpp): the case describes its lattice domain, turns
// sampled fields into rows of series.csv, and writes its results at the end. The runner owns
// the solver, the time loop, units, output files, checkpoints and stability checks.
#pragma once
#include <nlohmann/json.hpp>

#include <array>
#include <filesystem>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/types.hpp"
#include "io/params.hpp"
#include "lbm/boundary.hpp"
#include "lbm/shapes.hpp"
#include "lbm/solver.hpp"
#include "lbm/units.hpp"

namespace ff::drivers {

// The lattice problem in lattice units. A 2D description (nz = 0) runs on D2Q9, or on D3Q19
// extruded along a periodic z axis of lbm.depth_cells cells; nz > 0 describes a 3D box (D3Q19
// only) whose z faces are periodic or conditions of their own (e.g. the walls of a duct).
struct DomainSpec {
  int nx = 1, ny = 1;
  int nz = 0;                                      // 0: 2D description (extruded, periodic z)
  std::array<bool, 3> periodic{};                  // x, y, z (z ignored when nz = 0)
  std::array<lbm::FaceCondition, 6> faces;         // x-, x+, y-, y+, z-, z+ (ignored on periodic axes)
  struct Object {
    std::string name;
    lbm::WallScheme scheme = lbm::WallScheme::HalfwayBounceBack;
    Vec3 center = Vec3::Zero();
    std::optional<lbm::Shape> shape;               // solid cells and link fractions
    std::vector<std::array<int, 2>> cells;         // extra solid cells (mask, image), through all z
  };
  std::vector<Object> objects;
  Vec3 body_force = Vec3::Zero();                  // lattice force density
  // Initial state (default rest); z is 0 on D2Q9.
  std::function<void(int x, int y, int z, double& rho, Vec3& u)> init;
  bool is_box() const { return nz > 0; }
};

// Macroscopic state at one sampling step, SI units, on the whole lattice: nx*ny*nz values,
// x fastest, then y, then z (nz = 1 on D2Q9).
struct FlowSample {
  long step = 0;
  double time = 0;                   // s
  int nx = 0, ny = 0, nz = 1;
  std::span<const double> pressure;  // Pa relative to the reference state
  std::span<const Vec3> velocity;    // m/s
  std::span<const std::uint8_t> solid;
  // Units of the loads below. 2D description (depth_m = 0): per unit depth, force N/m and
  // torque N (per metre of the extruded depth). 3D box (depth_m > 0, the box's z extent in m):
  // totals, force N and torque N m.
  double depth_m = 0;
  // Per solid object (same order as DomainSpec::objects), at time t - dt/2.
  std::vector<Vec3> force, torque;
  std::array<Vec3, 6> face_force{};  // walls x-, x+, y-, y+, z-, z+
  double ramp_end_time = 0;          // s: the inflow has its full speed from here on
  double max_mach = 0;
  std::size_t at(int x, int y, int z = 0) const {
    return std::size_t(x) + std::size_t(nx) * (std::size_t(y) + std::size_t(ny) * std::size_t(z));
  }
};

class FlowCase {
 public:
  virtual ~FlowCase() = default;
  // Cell size [m] from the case geometry and its resolution key.
  virtual double cell_size() const = 0;
  // Number of cells across the characteristic length, and its key (for fix suggestions).
  virtual int resolution() const = 0;
  virtual std::string resolution_key() const { return "lbm.resolution"; }
  // Largest speed expected [m/s] (Mach check before the run).
  virtual double characteristic_speed() const = 0;
  virtual DomainSpec domain(const lbm::Units& u) = 0;
  virtual std::vector<std::string> columns() const = 0;  // after the runner's "step", "time"
  virtual void measure(const FlowSample& s, std::vector<double>& row) const = 0;
  // Warnings about the case on this lattice (e.g. a length that is not a whole number of
  // cells); `check` prints them and the run logs them.
  virtual std::vector<std::string> warnings() const { return {}; }
  // True when the case expects a time-periodic flow (a vortex street): the expected
  // compressibility error is then larger (lbm::compressibility_coefficient).
  virtual bool unsteady() const { return false; }
  // Column (index into columns()) whose relative change decides steady state; none: run to end.
  virtual std::optional<int> steady_column() const { return std::nullopt; }
  // Results into `summary`, extra files and plots into `out` (history = all series rows,
  // each starting with step and time).
  virtual void finish(const FlowSample& last, const std::vector<std::vector<double>>& history,
                      const std::filesystem::path& out, bool plots, nlohmann::json& summary) const = 0;
  // One short line for the progress display.
  virtual std::string progress_text(const std::vector<double>& row) const { return {}; }
};

// Every check of a flow scenario that needs no lattice: lbm.depth_cells, lbm.tau against
// lbm.time_step, and the Mach and relaxation-time limits (lbm::Units::check). Called by each
// flow driver's validate() and by run_flow(). Throws InputError naming the key.
void validate_flow(const Config& cfg, const FlowCase& fc);

}  // namespace ff::drivers
