// The one time loop of the bonded-particle drivers (ucs, triaxial, ...). It owns what every
// such driver does the same way: checkpoint and resume, --max-steps, --max-wall, ABORT and
// signals (RunControl), progress with ETA, the long-run notice, the numerical-error path with
// its last checkpoint (checkpoint_failed/), series.csv, cracks.csv and the VTK cadence, the
// loading curve (peak, stop criteria, elastic fit), summary.json and the plots. A driver derives
// from DemRun and supplies its set-up, its per-step control (advance) and its measurements
// (measure); the hooks are called once per series row, never per step or contact.
#pragma once
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

#include "dem/dem_output.hpp"
#include "dem/dem_system.hpp"
#include "dem/sample_builder.hpp"
#include "drivers/curve_peak.hpp"
#include "drivers/driver.hpp"
#include "drivers/run_control.hpp"
#include "drivers/ucs/ucs_measure.hpp"
#include "io/checkpoint.hpp"
#include "io/csv.hpp"
#include "io/params.hpp"

namespace ff::drivers {

// The loop's counters. They live in each driver's checkpointed state struct (stored as raw
// bytes, so its layout is the checkpoint format and old checkpoints keep loading); the loop
// reaches them through these pointers, bound once by the driver.
struct DemLoopCounters {
  long* rows = nullptr;            // rows of the loading curve (series.csv)
  long* peak_row = nullptr;        // row of the largest stress
  Real* peak = nullptr;            // largest stress of the curve
  Real* strain_at_peak = nullptr;  // axial strain at that row
  long* cracks_written = nullptr;  // crack events already in cracks.csv
  long* vtk_index = nullptr;       // next VTK snapshot number
  Real* next_vtk_strain = nullptr; // axial strain of the next cadence snapshot
  int* finished = nullptr;         // 1 once summary.json is written
};

// What a driver's measure() reports for one row.
struct DemRowReport {
  bool on_curve = false;   // a point of the loading curve: `row` goes to series.csv
  Real strain = 0, stress = 0, lateral = 0;  // the point (axial strain, stress, lateral strain)
  double fraction = -1;    // of the run done, for the ETA; ignored on the curve (from the stop criteria)
};

// What the loop found, for the driver's part of summary.json and its closing line.
struct DemOutcome {
  std::string stop_reason;
  std::string no_peak;  // why there is no peak (empty: the peak is one)
  ElasticFit fit;
};

// Fixed per driver: its key prefix and the words its messages use.
struct DemRunSpec {
  std::string name;         // driver name and key prefix: NAME.series_interval, NAME.max_strain, ...
  std::string stress_name;  // "stress", "differential stress" (stop reason)
  std::string stress_column;  // series.csv column of the curve's stress (re-read on resume)
  std::string long_run_keys;  // keys that shorten a long run
  // The curve's strain columns of series.csv (re-read on resume for the elastic fit) and the
  // strain's name in the stop message; an empty lateral column: none (the fit's lateral
  // strain is 0).
  std::string strain_column = "axial_strain", lateral_column = "lateral_strain", strain_name = "axial strain";
  // The loading speed's key [m/s] (each platen or grip): refused when it moves a platen by more
  // than dem::kMaxWallStep x the smallest radius in one time step. Empty: not checked.
  std::string rate_key;
};

class DemRun {
 public:
  DemRun(const Config& cfg, const RunOptions& opt, DemRunSpec spec);
  virtual ~DemRun() = default;
  DemRun(const DemRun&) = delete;
  DemRun& operator=(const DemRun&) = delete;
  RunStatus run();  // the loop

 protected:
  // --- hooks ---
  virtual DemLoopCounters counters() = 0;
  // Fresh run: sample, boundaries, time step, loading velocities (nothing written yet).
  virtual void set_up() = 0;
  void refuse_loading_jump() const;
  void warn_dynamic_loading() const;  // a platen speed that is a good part of the wave speed
  // The driver's checkpoint sections, before and after the DEM system's (restoring what
  // load_dem needs first, e.g. a membrane).
  virtual void save_before_dem(CheckpointWriter&) const {}
  virtual void save_after_dem(CheckpointWriter&) const = 0;
  virtual void load_before_dem(CheckpointReader&) {}
  virtual void load_after_dem(CheckpointReader&) = 0;
  // After set-up or load: series columns, sample particles/groups, the driver's own files.
  virtual void ready() {}
  virtual std::string resume_note() const { return {}; }  // appended to "resuming at step ..."
  // Keys of the loads a driver adds to the DEM (a pore fluid's) that can blow it up too: appended to
  // the DEM's NaN error and to a non-finite measurement's, which name only the DEM's own keys.
  virtual std::string instability_advice() const { return {}; }
  // Whether series.csv is being written (false before a driver's loading stage).
  virtual bool on_curve() const { return true; }
  virtual double planned_steps() const = 0;  // upper bound of the run's steps from step 0 (long-run notice)
  // Per-step control for `steps` steps (servos...); the default just steps.
  virtual void advance(long steps) { sys.run(steps); }
  // One row: measure, fill `row` (on the curve) and `status` (the progress text).
  virtual DemRowReport measure() = 0;
  virtual void close_files() {}
  // summary.json's driver part, its plots and its closing line.
  virtual void summarize(nlohmann::json& j, const DemOutcome& out) = 0;
  virtual void plots() {}
  // After each particle snapshot number `index` (at sys.time): the driver's own VTK files.
  virtual void vtk_written(long /*index*/) {}
  virtual void report(const DemOutcome& out) = 0;

  // --- services for the hooks ---
  // Starts the loading curve: series.csv, the VTK cadence, a snapshot and a checkpoint (the end
  // of a stage).
  void begin_curve();
  void checkpoint();
  // summary.json's peak.quasi_static: the stop rule's peak (the largest stress among rows with an
  // unbalanced-force ratio below kQuasiStaticUnbalance, as series.csv holds them) with its strain
  // under `strain_key`; null without that column or such a row.
  nlohmann::json quasi_static_peak_json(const std::string& strain_key) const;

  const Config& cfg;
  const RunOptions& opt;
  const DemRunSpec spec;
  dem::DemSystem sys;
  dem::SampleInfo info;
  std::vector<std::string> columns;   // of series.csv, set by ready() at the latest
  std::vector<double> row;            // filled by measure(): one row of series.csv
  std::string status;                 // filled by measure(): the progress text
  std::size_t sample_particles = 0;   // 0: all (the rest is a boundary, e.g. a particle membrane)
  int sample_groups = -1;             // crack counts by pair of the first groups (-1: all)
  bool vtk_membrane = false;          // a membrane.pvd series

 private:
  void write_checkpoint(const std::filesystem::path& dir);
  void write_vtk();
  void check_finite(const DemRowReport& r) const;  // throws NumericalError naming the column
  void open_outputs();
  std::string curve_row(const DemRowReport& r, double& fraction);
  void finish(const std::string& stop_reason);

  RunControl control_;
  std::filesystem::path cp_dir_, cracks_csv_;
  DemLoopCounters c_;
  CsvWriter series_;
  dem::DemVtkWriter vtk_writer_;
  bool vtk_ = false;
  Real extent_ = 0, vtk_every_ = 0, stop_fraction_ = 0, max_strain_ = 0;
  std::vector<Real> e_hist_, s_hist_, l_hist_;  // the curve, for the elastic fit
  // The stop rule's peak: the largest stress among rows near equilibrium (drivers/curve_peak.hpp;
  // every row without that column), derived from series.csv (recomputed on resume: nothing in the
  // checkpoint). ubf_column_ -1: no unbalanced-force ratio column.
  long ubf_column_ = -1;
  StopPeak stop_peak_;
  void find_quasi_static_column();
  void start_energy();
  void add_energy_columns();
  bool energy_columns_ = false;                 // the energy columns follow the driver's (dem/energy.hpp)
  bool stopped_at_strain_cap_ = false;          // the last curve row reached NAME.max_strain
};

}  // namespace ff::drivers
