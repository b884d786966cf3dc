// The UCS test as a DemRun (ucs_driver.cpp), open for drivers that run the same test with more
// physics (saturated_ucs: pore fluid). UcsRun owns the sample, the platens, the time step, the gauge,
// their checkpoint sections, the curve's columns and the UCS part of summary.json; a derived run
// adds its own through the hooks below, so every fix of the UCS test reaches it too.
#pragma once
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "drivers/dem_results.hpp"
#include "drivers/dem_run_loop.hpp"
#include "drivers/ucs/ucs_measure.hpp"
#include "io/plot.hpp"

namespace ff::drivers {

// Driver state that must survive a restart (stored as raw bytes: its layout is the checkpoint
// format of "ucs.state").
struct UcsState {
  Real peak_stress = 0, strain_at_peak = 0;
  long peak_row = 0, rows = 0, cracks_written = 0, vtk_index = 0;
  Real next_vtk_strain = 0, h0 = 0;
  int finished = 0;
};

class UcsRun : public DemRun {
 public:
  UcsRun(const Config& c, const RunOptions& o)
      : DemRun(c, o, {.name = "ucs",
                       .stress_name = "stress",
                       .stress_column = "axial_stress_Pa",
                       .long_run_keys = "ucs.platen_velocity or ucs.max_strain",
                       .rate_key = "ucs.platen_velocity"}) {}

 protected:
  // --- extension hooks (all no-ops for the plain UCS test) ---
  // Fresh run: after the sample, platens, time step and gauge exist.
  virtual void after_set_up() {}
  // One time step: before, the step itself (a coupling that runs the DEM stages itself replaces
  // it) and after. Called once per step, never per particle or contact.
  virtual void before_step() {}
  virtual void dem_step() { sys.step(); }
  virtual void after_step() {}
  // series.csv: columns after the UCS ones, and their values for a row measured as `m`, appended to
  // `row` (words for the progress line appended to `status`).
  virtual void extra_columns(std::vector<std::string>& /*columns*/) const {}
  virtual void extra_row(const CompressionState& /*m*/) {}
  // summary.json's extra fields, and the closing line's extra words (after the elastic constants).
  virtual void extra_summary(nlohmann::json& /*j*/, const DemOutcome& /*out*/) {}
  virtual std::string extra_report() const { return {}; }
  // Checkpoint sections after the UCS ones (fresh state on resume: set_up is not called).
  virtual void save_extra(CheckpointWriter& /*w*/) const {}
  virtual void load_extra(CheckpointReader& /*r*/) {}
  // After the loop's particle snapshot `index` (vtk/, at sys.time).
  virtual void extra_vtk(long /*index*/) {}
  // Plots: the words before ": stress and cracks" in titles, and extra plots.
  virtual std::string test_title() const { return "Uniaxial compression"; }
  virtual void extra_plots(std::vector<PlotJob>& /*jobs*/) const {}

  const UcsState& ucs_state() const { return st_; }

 private:
  DemLoopCounters counters() final;
  void set_up() final;
  void save_after_dem(CheckpointWriter& w) const final;
  void load_after_dem(CheckpointReader& r) final;
  void ready() final;
  double planned_steps() const final;
  void advance(long steps) final;
  DemRowReport measure() final;
  void summarize(nlohmann::json& j, const DemOutcome& out) final;
  void plots() final;
  void report(const DemOutcome& out) final;
  void vtk_written(long index) final { extra_vtk(index); }

  UcsState st_;
  CompressionGauge gauge_;
};

}  // namespace ff::drivers
