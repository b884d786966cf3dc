#include "drivers/ucs/ucs_driver.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <filesystem>

#include "core/error.hpp"
#include "core/log.hpp"
#include "core/progress.hpp"
#include "dem/dem_checkpoint.hpp"
#include "dem/dem_output.hpp"
#include "dem/dem_params.hpp"
#include "dem/sample_builder.hpp"
#include "drivers/dem_results.hpp"
#include "drivers/run_control.hpp"
#include "drivers/run_estimate.hpp"
#include "drivers/run_record.hpp"
#include "drivers/ucs/ucs_measure.hpp"
#include "fracflow/version.hpp"
#include "io/csv.hpp"
#include "io/json_out.hpp"
#include "io/plot.hpp"

namespace fs = std::filesystem;

namespace ff::drivers {

namespace {

void declare(ParamTable& t) {
  dem::declare_dem_params(t);
  dem::declare_sample_params(t);
  t.real("ucs.platen_velocity", 0.05, "m/s", "speed of each platen towards the sample").positive();
  t.real("ucs.platen_friction", 0.1, "-", "friction between platens and particles (seed 000: 0.1)").non_negative();
  t.real("ucs.stop_fraction", 0.6, "-", "stop when the axial stress has fallen below this fraction of its peak").open_range(0, 1);
  t.real("ucs.max_strain", 0.05, "-", "stop at this axial strain in any case").positive();
  t.integer("ucs.series_interval", 100, "steps", "steps between rows of series.csv").positive();
  t.real("ucs.vtk_strain_interval", 1e-3, "-", "axial strain between VTK snapshots").positive();
  t.integer("ucs.checkpoint_interval", 0, "steps",
            "steps between extra checkpoints (0: none; checkpoints come every output.checkpoint_wall_interval seconds, at "
            "the end and on interruption)")
      .non_negative();
}

// Column names end in their SI unit (_s, _Pa, _J); strains, counts and ratios have none.
const std::vector<std::string> kColumns = {"step", "time_s", "axial_strain", "axial_stress_Pa", "lateral_strain",
                                           "volumetric_strain", "cracks_tensile", "cracks_shear", "cracks_total",
                                           "intact_bonds", "kinetic_energy_J", "unbalanced_force_ratio"};

// Driver state that must survive a restart.
struct UcsState {
  Real peak_stress = 0, strain_at_peak = 0;
  long peak_row = 0, rows = 0, cracks_written = 0, vtk_index = 0;
  Real next_vtk_strain = 0, h0 = 0;
  int finished = 0;
};

}  // namespace
}  // namespace ff::drivers

namespace ff {
template <> struct is_checkpoint_pod<drivers::UcsState> : std::true_type {};
template <> struct is_checkpoint_pod<dem::SampleInfo> : std::false_type {};
}  // namespace ff

namespace ff::drivers {
namespace {

void write_checkpoint(const fs::path& dir, const dem::DemSystem& sys, const UcsState& st, const dem::SampleInfo& info,
                      const CompressionGauge& gauge) {
  fs::create_directories(dir);
  CheckpointWriter w(dir / "state.ffcp", /*keep_previous=*/true);
  dem::save_dem(w, sys);
  w.put_value("ucs.state", st);
  w.put_value("ucs.sample", sample_record(info));
  w.put("ucs.gauge", gauge.particles());
  w.commit();
}

void read_checkpoint(const fs::path& dir, dem::DemSystem& sys, UcsState& st, dem::SampleInfo& info,
                     CompressionGauge& gauge) {
  CheckpointReader r = open_checkpoint(dir / "state.ffcp");
  dem::load_dem(r, sys);
  st = r.get_value<UcsState>("ucs.state");
  info = sample_info(r.get_value<SampleRecord>("ucs.sample"));
  std::vector<Index> g;
  r.get("ucs.gauge", g);
  gauge.restore(std::move(g), st.h0);
}

void make_plots(const fs::path& out, const Config& cfg) {
  if (!cfg.boolean("output.plots")) return;
  fs::create_directories(out / "plots");
  std::vector<PlotJob> jobs = {
      axial_strain_plot(out, "stress_strain_cracks", "Uniaxial compression: stress and cracks", {"axial_stress_Pa"}, 1e-6,
                        "axial stress [MPa]"),
      axial_strain_plot(out, "strains", "Uniaxial compression: strains", {"lateral_strain", "volumetric_strain"}, 100,
                        "strain [%] (compression > 0)")};
  jobs[0].spec.y2 = {"cracks_total", "cracks_tensile", "cracks_shear"};
  jobs[0].spec.y2label = "number of cracks";
  plot_series(jobs);  // one python process for both
}

RunStatus run(const Config& cfg, const RunOptions& opt) {
  const auto wall_start = std::chrono::steady_clock::now();
  RunControl control(cfg, opt);
  dem::DemSystem sys;
  sys.settings = dem::build_settings(cfg);
  sys.materials = dem::build_materials(cfg);
  dem::SampleInfo info;
  UcsState st;
  CompressionGauge gauge;
  const fs::path cp_dir = opt.out_dir / "checkpoint";
  if (opt.resume) {
    read_checkpoint(cp_dir, sys, st, info, gauge);
    if (st.finished) {
      log::info("this run had already finished; nothing to resume");
      return RunStatus::Finished;
    }
    log::info("resuming at step {} (t = {:.6g} s)", sys.step_count, sys.time);
  } else {
    info = dem::build_sample(cfg, sys);
    dem::add_platens(sys, info, cfg.real("ucs.platen_friction"));
    dem::choose_time_step(cfg, sys);
    const Real v = cfg.real("ucs.platen_velocity");
    sys.walls[0].velocity[info.axis] = v;
    sys.walls[1].velocity[info.axis] = -v;
    gauge.init(sys, info);
    st.h0 = gauge.initial_height();
    begin_output(opt);  // the sample is built: from here on files go into out_dir
  }

  // Outputs (on resume: rows and snapshots after the checkpoint are dropped; they are
  // recomputed identically).
  CsvWriter series;
  if (opt.resume) series.reopen(opt.out_dir / "series.csv", kColumns, static_cast<std::size_t>(st.rows));
  else series.open(opt.out_dir / "series.csv", kColumns);
  const fs::path cracks_csv = opt.out_dir / "cracks.csv";
  if (!opt.resume) dem::append_cracks_csv(cracks_csv, sys.cracks, sys.materials, 0);
  else {
    // Rewrite the crack file up to the checkpoint (later lines would be duplicated).
    dem::CrackLog head;
    head.events.assign(sys.cracks.events.begin(), sys.cracks.events.begin() + st.cracks_written);
    dem::append_cracks_csv(cracks_csv, head, sys.materials, 0);
  }
  const bool vtk = cfg.boolean("output.vtk");
  dem::DemVtkWriter writer;
  const Real extent = 1.6 * std::max(info.width, info.height);
  if (vtk) writer.open(opt.out_dir / "vtk", opt.resume, sys.time);
  if (vtk && !opt.resume) {
    writer.write(sys, st.vtk_index++, extent);
    st.next_vtk_strain = cfg.real("ucs.vtk_strain_interval");
  }

  const long series_every = cfg.integer("ucs.series_interval");
  const long cp_every = cfg.integer("ucs.checkpoint_interval");
  auto checkpoint = [&] {
    write_checkpoint(cp_dir, sys, st, info, gauge);
    control.checkpoint_written();
  };
  const Real stop_fraction = cfg.real("ucs.stop_fraction"), max_strain = cfg.real("ucs.max_strain");
  const Real vtk_every = cfg.real("ucs.vtk_strain_interval");
  Progress progress("ucs", opt.progress_interval_s);
  // Each platen moves at v: the strain cap is reached after max_strain h0 / (2 v dt) steps.
  LongRunNotice long_run(max_strain * st.h0 / (2 * cfg.real("ucs.platen_velocity") * sys.settings.dt) -
                             static_cast<double>(sys.step_count),
                         "ucs.platen_velocity or ucs.max_strain", sys.step_count);
  std::vector<Real> e_hist, s_hist, l_hist;
  {  // The elastic fit needs the whole curve: re-read the rows kept so far.
    if (opt.resume && st.rows > 0) {
      const CsvTable t = read_csv(opt.out_dir / "series.csv");
      e_hist = t.column("axial_strain");
      s_hist = t.column("axial_stress_Pa");
      l_hist = t.column("lateral_strain");
    }
  }
  if (!opt.resume) checkpoint();  // resumable from the start (kill -9 before the first interval)
  RunStatus status = RunStatus::Finished;
  std::string stop_reason;
  try {
    for (;;) {
      sys.run(series_every);
      const CompressionState m = gauge.measure(sys, info);
      const double row[] = {static_cast<double>(sys.step_count), sys.time, m.axial_strain, m.axial_stress,
                            m.lateral_strain, m.volumetric_strain, static_cast<double>(sys.cracks.tensile),
                            static_cast<double>(sys.cracks.shear), static_cast<double>(sys.cracks.total()),
                            static_cast<double>(sys.intact_bonds()), sys.kinetic_energy(), sys.max_unbalanced_force_ratio()};
      series.row(row);
      e_hist.push_back(m.axial_strain);
      s_hist.push_back(m.axial_stress);
      l_hist.push_back(m.lateral_strain);
      if (m.axial_stress > st.peak_stress) {
        st.peak_stress = m.axial_stress;
        st.strain_at_peak = m.axial_strain;
        st.peak_row = st.rows;
      }
      ++st.rows;
      dem::append_cracks_csv(cracks_csv, sys.cracks, sys.materials, static_cast<std::size_t>(st.cracks_written));
      st.cracks_written = static_cast<long>(sys.cracks.events.size());
      if (vtk && m.axial_strain >= st.next_vtk_strain) {
        writer.write(sys, st.vtk_index++, extent);
        while (st.next_vtk_strain <= m.axial_strain) st.next_vtk_strain += vtk_every;
      }
      const bool past_peak = st.peak_stress > 0 && st.rows > 10 && m.axial_strain > st.strain_at_peak &&
                             m.axial_stress < stop_fraction * st.peak_stress;
      if (past_peak) stop_reason = fmt::format("stress fell below {} of the peak", stop_fraction);
      if (m.axial_strain >= max_strain) stop_reason = fmt::format("axial strain reached ucs.max_strain = {}", max_strain);
      Real fraction = m.axial_strain / max_strain;
      if (st.peak_stress > 0 && m.axial_strain > st.strain_at_peak)
        fraction = std::max(fraction, (st.peak_stress - m.axial_stress) / (st.peak_stress * (1 - stop_fraction)));
      progress.update(sys.step_count, sys.time, std::min(fraction, 1.0),
                      fmt::format("strain {:.3f}%  stress {:.3f} MPa  cracks {}", 100 * m.axial_strain, 1e-6 * m.axial_stress,
                                  sys.cracks.total()));
      long_run.update(sys.step_count);
      if (!stop_reason.empty()) break;
      if (const std::string why = control.stop_reason(sys.step_count); !why.empty()) {
        checkpoint();
        log_interruption(why, sys.step_count);
        status = RunStatus::Interrupted;
        break;
      }
      if (control.checkpoint_due() ||
          (cp_every > 0 && (sys.step_count / series_every) % std::max(1L, cp_every / series_every) == 0))
        checkpoint();
    }
  } catch (const NumericalError&) {
    // Keep the last good checkpoint; save the failing state beside it for inspection.
    write_checkpoint(opt.out_dir / "checkpoint_failed", sys, st, info, gauge);
    series.close();
    throw;
  }
  series.close();
  if (status == RunStatus::Interrupted) return status;

  if (vtk) writer.write(sys, st.vtk_index++, extent);
  const ElasticFit fit = fit_elastic(e_hist, s_hist, l_hist, static_cast<std::size_t>(st.peak_row));
  nlohmann::json j;
  j["fracflow_version"] = kVersion;
  j["driver"] = "ucs";
  j["title"] = cfg.string("title");
  j["stop_reason"] = stop_reason;
  // No peak (still rising at ucs.max_strain) or no fit: null with the reason, never a number.
  const std::string no_peak = peak_problem(st.peak_stress, st.peak_row, st.rows,
                                           stop_reason.find("ucs.max_strain") != std::string::npos, "ucs.max_strain");
  j["ucs_Pa"] = no_peak.empty() ? nlohmann::json(st.peak_stress) : nlohmann::json(nullptr);
  j["strain_at_peak"] = no_peak.empty() ? nlohmann::json(st.strain_at_peak) : nlohmann::json(nullptr);
  j["peak"] = {{"reached", no_peak.empty()}};
  if (!no_peak.empty()) {
    j["peak"]["reason"] = no_peak;
    j["peak"]["largest_stress_Pa"] = st.peak_stress;
    log::warn("no UCS (null in summary.json): {}", no_peak);
  }
  put_elastic_fit(j, fit, "least squares on the pre-peak curve between 20% and 50% of the peak stress");
  j["cracks"] = cracks_json(sys);
  j["sample"] = sample_json(sys, info);
  j["time_step_s"] = sys.settings.dt;
  j["steps"] = sys.step_count;
  j["wall_time_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  j["threads"] = opt.threads;
  j["parameters"] = params_json(cfg);
  add_run_record(j, opt);
  write_json_atomic(opt.out_dir / "summary.json", j);
  make_plots(opt.out_dir, cfg);
  // Marked finished only once summary.json exists: a run killed before this point resumes from
  // the last checkpoint and writes it again.
  st.finished = 1;
  checkpoint();
  log::info("{}, {}, cracks {} ({} tensile, {} shear); {}",
            no_peak.empty() ? fmt::format("UCS {:.3f} MPa at axial strain {:.3f}%", 1e-6 * st.peak_stress, 100 * st.strain_at_peak)
                            : std::string("no UCS"),
            fit.ok() ? fmt::format("E = {:.3f} GPa, nu = {:.3f}", 1e-9 * fit.youngs_modulus, fit.poisson_ratio)
                     : std::string("no E or nu"),
            sys.cracks.total(), sys.cracks.tensile, sys.cracks.shear, stop_reason);
  return RunStatus::Finished;
}

}  // namespace

Driver ucs_driver() {
  return Driver{"ucs", "uniaxial compression of a bonded-particle sample (UCS, E, nu, cracks)", declare, run,
                dem::validate_dem_sample};
}

}  // namespace ff::drivers
