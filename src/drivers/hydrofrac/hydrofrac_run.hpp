// The hydrofrac driver's run (internal to src/drivers/hydrofrac/): one HydrofracRun per `fracflow
// run`. hydrofrac_driver.cpp holds its stages, time loop and checkpoints; hydrofrac_summary.cpp what
// it reports at the end (summary.json, plots).
#pragma once
#include <nlohmann/json.hpp>

#include <array>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "coupling/hydrofrac/borehole.hpp"
#include "coupling/hydrofrac/lbm_load.hpp"
#include "coupling/hydrofrac/network_load.hpp"
#include "dem/dem_output.hpp"
#include "dem/dem_system.hpp"
#include "dem/sample_builder.hpp"
#include "drivers/driver.hpp"
#include "drivers/hydrofrac/hydrofrac_params.hpp"
#include "drivers/hydrofrac/kirsch.hpp"
#include "drivers/hydrofrac/sleeve_load.hpp"
#include "drivers/run_control.hpp"
#include "io/csv.hpp"
#include "io/pvd.hpp"

namespace ff::drivers::hydrofrac {

namespace fs = std::filesystem;

// The loop's state (raw bytes in the checkpoint: its layout is the format).
struct HfState {
  long rows = 0, cracks_written = 0, vtk_index = 0, stage = 0, finished = 0;
  long insitu_steps = 0, injection_step = 0, equilibrium = 0;
  long breakdown_found = 0, breakdown_row = 0, probe_taken = 0, initiation_found = 0;
  Real breakdown_pressure = 0, breakdown_time = 0, peak_pressure = 0, peak_time = 0;
  Real initiation_pressure = 0, effective_radius = 0, probe_pressure_actual = 0;
  long breakdown_cracks = 0, peak_cracks = 0;
  Real last_vtk_time = 0;
  Real bd_azimuth = 0, bd_length = 0, bd_extent = 0, bd_anisotropy = 0, bd_normal_azimuth = 0;  // the fracture at breakdown
  long bd_connected = 0;
  Real injection_time = 0;  // sys.time when injection began
};

// One measurement circle with Kirsch's prediction (compression positive), a checkpoint record.
struct CircleRecord {
  Real r_over_a = 0, angle_deg = 0, x = 0, y = 0, radius = 0, porosity = 0;
  long particles = 0, far = 0;  // far: one of the four interior-stress circles
  Real xx = 0, yy = 0, xy = 0, zz = 0, k_xx = 0, k_yy = 0, k_xy = 0, pressure = 0;
};

class HydrofracRun {
 public:
  HydrofracRun(const Config& c, const RunOptions& o);
  RunStatus run();

 private:
  void set_up();
  double planned_steps() const;
  static constexpr const char* kShortenKeys = "injection.ramp_rate, injection.max_time or insitu.max_steps";
  void make_fluid();
  void servo();
  void advance(long steps);
  Vec3 wall_areas() const;
  std::array<Real, 6> face_pressures() const;
  Vec3 wall_stress() const;
  Vec3 fluid_wall_stress() const;
  Real face_gap() const;  // distance from the hole's wall to the nearest wall [m]
  void measure_row();
  std::vector<CircleRecord> snapshot(Real pressure) const;
  void save(const fs::path& dir);
  void load();
  void checkpoint() {
    save(cp_dir_);
    control_.checkpoint_written();
  }
  void begin_injection();
  void vtk();
  void finish(const std::string& stop);
  void plots();
  nlohmann::json circles_json(const std::vector<CircleRecord>& c) const;

  const Config& cfg;
  const RunOptions& opt;
  RunControl control_;
  dem::DemSystem sys;
  dem::SampleInfo info;
  BoreholeGeometry hole_;
  std::vector<hydrofrac::JointPair> joints_;
  std::unique_ptr<hydrofrac::FluidLoad> fluid_;
  hydrofrac::LbmLoadBase* lbm_ = nullptr;  // fluid_ when injection.fluid = "lbm"
  hydrofrac::NetworkLoad* net_ = nullptr;  // fluid_ when injection.fluid = "network"
  PvdSeries pores_pvd_;                    // vtk/pores.pvd: the pore network, same times as the particles
  PvdSeries fluid_pvd_;                    // vtk/fluid.pvd: the lattice, same times as the particles
  HfState st_;
  Vec3 targets_;
  Real servo_v_ = 0, servo_alpha_ = 0;
  // The injection mode's rules (read_mode_rules): rate mode, the breakdown's pressure drop and the
  // stop's fraction of the peak; ramp mode, the breakdown's fracture length (0: one hole radius).
  Real peak_drop_ = 0, stop_fraction_ = 0, breakdown_length_ = 0;
  void read_mode_rules();
  std::vector<CircleRecord> insitu_, probe_;
  fs::path cp_dir_;
  CsvWriter series_;
  dem::DemVtkWriter vtk_writer_;
  bool vtk_on_ = false;
  std::vector<double> row_;
  std::string status_;
  // fracture measurement scratch (refreshed each row)
  std::vector<Index> id_index_;
  std::vector<std::size_t> ev_, jt_;
  std::vector<char> visited_;
  hydrofrac::FractureShape shape_;
  Real extent_ = 0;  // connected fracture beyond the wall [m]
};

}  // namespace ff::drivers::hydrofrac
