#include "drivers/dem_run_loop.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.hpp"
#include "core/log.hpp"
#include "core/progress.hpp"
#include "dem/dem_checkpoint.hpp"
#include "dem/dem_params.hpp"
#include "dem/diagnostics.hpp"
#include "drivers/curve_peak.hpp"
#include "drivers/dem_results.hpp"
#include "drivers/run_estimate.hpp"
#include "drivers/run_record.hpp"
#include "fracflow/version.hpp"
#include "io/json_out.hpp"

namespace fs = std::filesystem;

namespace ff::drivers {

DemRun::DemRun(const Config& config, const RunOptions& options, DemRunSpec s)
    : cfg(config), opt(options), spec(std::move(s)), control_(config, options) {
  sys.settings = dem::build_settings(cfg);
  sys.materials = dem::build_materials(cfg);
  cp_dir_ = opt.out_dir / "checkpoint";
  cracks_csv_ = opt.out_dir / "cracks.csv";
}

void DemRun::write_checkpoint(const fs::path& dir) {
  fs::create_directories(dir);
  CheckpointWriter w(dir / "state.ffcp", /*keep_previous=*/true);
  save_before_dem(w);
  dem::save_dem(w, sys);
  save_after_dem(w);
  control_.record(w);
  w.commit();
}

// A particle snapshot, then the driver's own files for it (vtk_written).
void DemRun::write_vtk() {
  const long index = (*c_.vtk_index)++;
  vtk_writer_.write(sys, index, extent_);
  vtk_written(index);
}

void DemRun::checkpoint() {
  write_checkpoint(cp_dir_);
  control_.checkpoint_written();
}

// Energy bookkeeping over the loading curve (dem/energy.hpp): its columns follow the driver's.
void DemRun::start_energy() {
  if (!cfg.boolean("dem.energy_tracking")) return;
  sys.settings.track_energy = true;
  dem::start_energy_tracking(sys);
}

void DemRun::add_energy_columns() {
  if (!cfg.boolean("dem.energy_tracking") || energy_columns_) return;
  energy_columns_ = true;
  for (const char* c : {"energy_kinetic_J", "strain_energy_J", "boundary_work_J", "damping_dissipation_J",
                        "friction_dissipation_J", "dashpot_dissipation_J", "bond_break_energy_J", "energy_balance_error"})
    columns.emplace_back(c);
}

void DemRun::find_quasi_static_column() {
  const auto it = std::find(columns.begin(), columns.end(), "unbalanced_force_ratio");
  ubf_column_ = it == columns.end() ? -1 : static_cast<long>(it - columns.begin());
}

nlohmann::json DemRun::quasi_static_peak_json(const std::string& strain_key) const {
  if (ubf_column_ < 0 || stop_peak_.row < 0) return nullptr;
  return {{"stress_Pa", stop_peak_.stress},
          {strain_key, stop_peak_.strain},
          {"unbalanced_force_ratio_below", kQuasiStaticUnbalance}};
}

void DemRun::begin_curve() {
  *c_.next_vtk_strain = vtk_every_;
  start_energy();
  add_energy_columns();
  find_quasi_static_column();
  series_.open(opt.out_dir / "series.csv", columns);
  if (vtk_) write_vtk();
  checkpoint();  // the end of a stage
}

// Outputs. On resume, rows, crack lines and snapshots after the checkpoint are dropped: the
// run recomputes them identically.
void DemRun::open_outputs() {
  if (on_curve()) {
    add_energy_columns();
    if (!opt.resume) start_energy();
    else sys.settings.track_energy = cfg.boolean("dem.energy_tracking");  // the book comes with the checkpoint
  }
  row.reserve(columns.size() + 8);
  find_quasi_static_column();
  if (on_curve()) {
    if (opt.resume) series_.reopen(opt.out_dir / "series.csv", columns, static_cast<std::size_t>(*c_.rows));
    else series_.open(opt.out_dir / "series.csv", columns);
  }
  {
    dem::CrackLog head;
    head.events.assign(sys.cracks.events.begin(), sys.cracks.events.begin() + *c_.cracks_written);
    dem::append_cracks_csv(cracks_csv_, head, sys.materials, 0);
  }
  vtk_ = cfg.boolean("output.vtk");
  extent_ = 1.6 * std::max(info.width, info.height);
  if (vtk_) vtk_writer_.open(opt.out_dir / "vtk", opt.resume, sys.time, vtk_membrane);
  if (sample_particles > 0) vtk_writer_.set_sample_particles(sample_particles);
  if (vtk_ && !opt.resume) {
    write_vtk();
    if (on_curve()) *c_.next_vtk_strain = vtk_every_;
  }
  if (opt.resume && on_curve() && *c_.rows > 0) {  // the elastic fit needs the whole curve
    const CsvTable t = read_csv(opt.out_dir / "series.csv");
    e_hist_ = t.column(spec.strain_column);
    s_hist_ = t.column(spec.stress_column);
    l_hist_ = spec.lateral_column.empty() ? std::vector<Real>(e_hist_.size(), 0.0) : t.column(spec.lateral_column);
    // The stop rule's peak, as the rows gave it.
    const std::vector<Real>* u = ubf_column_ >= 0 ? &t.column("unbalanced_force_ratio") : nullptr;
    for (std::size_t k = 0; k < s_hist_.size(); ++k)
      stop_peak_.add(static_cast<long>(k), s_hist_[k], e_hist_[k], !u || (*u)[k] < kQuasiStaticUnbalance);
  }
}

// One point of the loading curve: its row, the peak, the VTK cadence and the stop criteria.
// Returns why the run ends here (empty: go on); `fraction` gets the progress.
std::string DemRun::curve_row(const DemRowReport& r, double& fraction) {
  if (energy_columns_) {
    const dem::EnergyReport e = dem::energy_report(sys);
    for (Real v : {e.kinetic, e.strain, e.boundary_work, e.damping, e.friction, e.dashpot, e.bond_break, e.balance_error})
      row.push_back(v);
  }
  series_.row(row);
  e_hist_.push_back(r.strain);
  s_hist_.push_back(r.stress);
  l_hist_.push_back(r.lateral);
  Real& peak = *c_.peak;
  if (r.stress > peak) {
    peak = r.stress;
    *c_.strain_at_peak = r.strain;
    *c_.peak_row = *c_.rows;
  }
  ++*c_.rows;
  if (vtk_ && r.strain >= *c_.next_vtk_strain) {
    write_vtk();
    // Step through the intervals passed; a leap of more than a million intervals (a blown-up run:
    // the interval added to a huge strain would no longer change it) jumps past the strain at once.
    Real& next = *c_.next_vtk_strain;
    if (r.strain - next > 1e6 * vtk_every_)  // (finite: check_finite ran)
      next = std::nextafter(r.strain + vtk_every_, std::numeric_limits<Real>::infinity());
    while (next <= r.strain) next += vtk_every_;
  }
  std::string stop;
  // The stop rule's peak is the quasi-static one (rows with an unbalanced-force ratio below
  // kQuasiStaticUnbalance, where the driver writes that column): a one-row spike of a crack burst
  // or of the platens' start-up is not the peak to fall from (seed 004's study, packing 11, S 1: a
  // burst row at 1494 Pa, ratio 0.49, then 777 Pa, and the run stopped at 0.0069 % strain with the
  // quasi-static curve at 637 Pa and rising). And it must lie 10 rows into the loading: a slow
  // platen's first rows are start-up noise (a saturated specimen's first row at 2 mm/s held 3.7 Pa,
  // its tenth 2 Pa, and the run stopped there).
  const bool qs = ubf_column_ >= 0;  // without the column every row counts: the curve's own peak
  stop_peak_.add(*c_.rows - 1, r.stress, r.strain,
                 !qs || row[static_cast<std::size_t>(ubf_column_)] < kQuasiStaticUnbalance);
  if (stop_peak_.fallen(r.stress, r.strain, stop_fraction_))
    stop = fmt::format("{} fell below {} of the {}peak", spec.stress_name, stop_fraction_, qs ? "quasi-static " : "");
  stopped_at_strain_cap_ = r.strain >= max_strain_;
  if (stopped_at_strain_cap_) stop = fmt::format("{} reached {}.max_strain = {}", spec.strain_name, spec.name, max_strain_);
  Real f = r.strain / max_strain_;
  if (stop_peak_.stress > 0 && r.strain > stop_peak_.strain)
    f = std::max(f, (stop_peak_.stress - r.stress) / (stop_peak_.stress * (1 - stop_fraction_)));
  fraction = std::min(f, 1.0);
  return stop;
}

// A state can blow up without a NaN position (e.g. a huge body force: velocities overflow the
// energies first); a NaN or inf measurement stops the run like a NaN position does.
void DemRun::check_finite(const DemRowReport& r) const {
  std::string what;
  if (r.on_curve)
    for (std::size_t k = 0; k < row.size() && k < columns.size() && what.empty(); ++k)
      if (!std::isfinite(row[k])) what = fmt::format("series.csv column '{}' is {}", columns[k], row[k]);
  if (what.empty() && !std::isfinite(r.strain + r.stress + r.lateral)) what = "the measured strain or stress is NaN/inf";
  if (what.empty()) return;
  throw NumericalError(fmt::format(
      "the DEM run became unstable by step {} (t = {:.6g} s): {}. The last good checkpoint stays in {}/checkpoint and "
      "the failing state is saved in {}/checkpoint_failed. Check dem.gravity and the loading rate ({}), lower "
      "dem.time_step_safety (or dem.time_step), or raise dem.local_damping{}",
      sys.step_count, sys.time, what, opt.out_dir.string(), opt.out_dir.string(), spec.long_run_keys,
      instability_advice().empty() ? "" : ". " + instability_advice()));
}

// A platen at speed v launches a compression wave that strains the sample by v/c, c its wave speed;
// where that is a good part of a rock's peak strain (0.1-1 %) the sample fails at its face before the
// load spreads through it: a dynamic test, not a strength test. c <= r/t_c, with t_c the critical step
// (of the stiffest-loaded grain) and r the smallest radius: t_c ~ r sqrt(rho/E) and a chain of grains
// carries waves at 2 r / (t_c sqrt(Z)), Z its springs per grain. So v t_c / r is a lower bound of v/c
// (ucs_2d.toml: v/c = 3.4 v t_c / r from its E and density). Measured on ucs_2d.toml (one packing),
// UCS against v t_c / r: 5.97 MPa at 1e-5, 6.89 at 3.8e-5 (the example), 6.84 at 1.1e-4, 9.45 at
// 3.0e-4, 16.3 at 9.9e-4 (session 49); the examples lie at 0.5-5e-5. Inertial masses: mass scaling
// counts.
void DemRun::warn_dynamic_loading() const {
  if (spec.rate_key.empty() || sys.particles.size() == 0) return;
  const auto& r = sys.particles.radius;
  const Real tc = dem::critical_time_step(sys), r_min = *std::min_element(r.begin(), r.end());
  const Real v = cfg.real(spec.rate_key), wave_strain = v * tc / r_min;
  constexpr Real kDynamicStrain = 2e-4;
  if (wave_strain > kDynamicStrain)
    log::warn("{} = {:.4g} m/s is at least {:.2g} of the sample's compression-wave speed (at most {:.4g} m/s, from the "
              "critical step {:.3g} s and the smallest radius {:.3g} m): the wave each platen launches strains the "
              "sample by that much, a good part of a rock's peak strain, so the test is dynamic and its peak above the "
              "quasi-static strength; quasi-static loading keeps this below {} ({} <= {:.3g} m/s){}",
              spec.rate_key, v, wave_strain, r_min / tc, tc, r_min, kDynamicStrain, spec.rate_key,
              kDynamicStrain * r_min / tc,
              cfg.boolean("dem.mass_scaling") ? "; dem.mass_scaling slowed the waves too" : "");
}

// A platen that moves a good part of a grain in one step is an impact, not a loading test (at 1e300 m/s
// the strain left the double range).
void DemRun::refuse_loading_jump() const {
  if (spec.rate_key.empty()) return;
  dem::refuse_wall_jump(cfg, spec.rate_key, sys, "platen",
                        "a loading test needs many steps per grain (quasi-static rates are 1e-3 to 1 m/s)");
}

RunStatus DemRun::run() {
  c_ = counters();
  const std::string& p = spec.name;
  vtk_every_ = cfg.real(p + ".vtk_strain_interval");
  stop_fraction_ = cfg.real(p + ".stop_fraction");
  max_strain_ = cfg.real(p + ".max_strain");
  if (opt.resume) {
    CheckpointReader r = open_checkpoint(cp_dir_ / "state.ffcp");
    load_before_dem(r);
    dem::load_dem(r, sys);
    load_after_dem(r);
    control_.restore(r);
    if (*c_.finished) {
      log::info("this run had already finished; nothing to resume");
      return RunStatus::Finished;
    }
    if (control_.resumed_at_max_steps(sys.step_count)) return RunStatus::Interrupted;
    log::info("resuming at step {} (t = {:.6g} s){}", sys.step_count, sys.time, resume_note());
  } else {
    set_up();
    refuse_endless_run(planned_steps(), spec.long_run_keys, sys.settings.dt);
    refuse_loading_jump();
    warn_dynamic_loading();
    begin_output(opt);  // the sample is built: from here on files go into out_dir
  }
  ready();
  open_outputs();

  const long every = cfg.integer(p + ".series_interval");
  const long cp_every = cfg.integer(p + ".checkpoint_interval");
  Progress progress(p, opt.progress_interval_s);
  LongRunNotice long_run(planned_steps() - static_cast<double>(sys.step_count), spec.long_run_keys, sys.step_count);
  if (!opt.resume) checkpoint();  // resumable from the start (kill -9 before the first interval)
  RunStatus run_status = RunStatus::Finished;
  std::string stop_reason;
  try {
    for (;;) {
      advance(every);
      const DemRowReport r = measure();
      check_finite(r);
      double fraction = r.fraction;
      if (r.on_curve) stop_reason = curve_row(r, fraction);
      progress.update(sys.step_count, sys.time, fraction, status);
      long_run.update(sys.step_count);
      dem::append_cracks_csv(cracks_csv_, sys.cracks, sys.materials, static_cast<std::size_t>(*c_.cracks_written));
      *c_.cracks_written = static_cast<long>(sys.cracks.events.size());
      if (!stop_reason.empty()) break;
      if (const std::string why = control_.stop_reason(sys.step_count); !why.empty()) {
        checkpoint();
        log_interruption(why, sys.step_count);
        run_status = RunStatus::Interrupted;
        break;
      }
      if (control_.checkpoint_due() || (cp_every > 0 && (sys.step_count / every) % std::max(1L, cp_every / every) == 0))
        checkpoint();
    }
  } catch (const NumericalError& e) {
    // Keep the last good checkpoint; save the failing state beside it for inspection.
    write_checkpoint(opt.out_dir / "checkpoint_failed");
    series_.close();
    close_files();
    if (dynamic_cast<const DemNotFiniteError*>(&e) && !instability_advice().empty())
      throw DemNotFiniteError(fmt::format("{}. {}", e.what(), instability_advice()));
    throw;
  }
  series_.close();
  close_files();
  if (run_status == RunStatus::Interrupted) return run_status;
  finish(stop_reason);
  return RunStatus::Finished;
}

void DemRun::finish(const std::string& stop_reason) {
  if (vtk_) write_vtk();
  DemOutcome out;
  out.stop_reason = stop_reason;
  out.fit = fit_elastic(e_hist_, s_hist_, l_hist_, static_cast<std::size_t>(*c_.peak_row));
  // No peak (still rising at the strain cap): null with the reason, never a number.
  const std::string cap_key = spec.name + ".max_strain";
  out.no_peak = peak_problem(*c_.peak, *c_.peak_row, *c_.rows, stopped_at_strain_cap_, cap_key);
  nlohmann::json j;
  j["fracflow_version"] = kVersion;
  j["driver"] = spec.name;
  j["title"] = cfg.string("title");
  j["stop_reason"] = stop_reason;
  j["strain_at_peak"] = out.no_peak.empty() ? nlohmann::json(*c_.strain_at_peak) : nlohmann::json(nullptr);
  j["peak"] = {{"reached", out.no_peak.empty()}};
  if (!out.no_peak.empty()) j["peak"]["reason"] = out.no_peak;
  summarize(j, out);
  j["cracks"] = cracks_json(sys, sample_groups);
  j["sample"] = sample_json(sys, info, sample_particles > 0 ? static_cast<long>(sample_particles) : -1L);
  j["time_step_s"] = sys.settings.dt;
  j["steps"] = sys.step_count;
  j["wall_time_s"] = control_.run_wall_s();  // every session of the run
  j["threads"] = opt.threads;
  j["parameters"] = params_json(cfg);
  add_run_record(j, opt);
  write_json_atomic(opt.out_dir / "summary.json", j);
  plots();
  // Marked finished only once summary.json exists: a run killed before this point resumes from
  // the last checkpoint and writes it again.
  *c_.finished = 1;
  checkpoint();
  report(out);
}

}  // namespace ff::drivers
