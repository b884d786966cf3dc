#include "drivers/ucs/ucs_driver.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <iterator>

#include "core/log.hpp"
#include "dem/dem_params.hpp"
#include "dem/sample_builder.hpp"
#include "drivers/common_params.hpp"
#include "drivers/dem_results.hpp"
#include "drivers/dem_run_loop.hpp"
#include "drivers/ucs/ucs_measure.hpp"
#include "drivers/ucs/ucs_run.hpp"
#include "io/plot.hpp"
#include "dem/diagnostics.hpp"

namespace fs = std::filesystem;

namespace ff::drivers {

// The UCS keys (with the DEM and sample keys), shared with drivers that run the same test
// (saturated_ucs).
void declare_ucs_params(ParamTable& t) {
  dem::declare_dem_params(t);
  dem::declare_sample_params(t);
  t.real("ucs.platen_velocity", 0.05, "m/s", "speed of each platen towards the sample").positive();
  t.real("ucs.platen_friction", 0.1, "-", "friction between platens and particles (seed 000: 0.1)").non_negative();
  t.real("ucs.stop_fraction", 0.6, "-", "stop when the axial stress has fallen below this fraction of its quasi-static peak (the largest among rows with an unbalanced-force ratio below 0.1)").open_range(0, 1);
  t.real("ucs.max_strain", 0.05, "-", "stop at this axial strain in any case").positive();
  declare_series_interval(t, "ucs");
  t.real("ucs.vtk_strain_interval", 1e-3, "-", "axial strain between VTK snapshots").positive();
  t.integer("ucs.checkpoint_interval", 0, "steps",
            "steps between extra checkpoints (0: none; checkpoints come every output.checkpoint_wall_interval seconds, at "
            "the end and on interruption)")
      .non_negative();
}

namespace {

// Column names end in their SI unit (_s, _Pa, _J); strains, counts and ratios have none.
const std::vector<std::string> kColumns = {"step", "time_s", "axial_strain", "axial_stress_Pa", "lateral_strain",
                                           "volumetric_strain", "cracks_tensile", "cracks_shear", "cracks_total",
                                           "intact_bonds", "kinetic_energy_J", "unbalanced_force_ratio"};

}  // namespace
}  // namespace ff::drivers

namespace ff {
template <> struct is_checkpoint_pod<drivers::UcsState> : std::true_type {};
template <> struct is_checkpoint_pod<dem::SampleInfo> : std::false_type {};
}  // namespace ff

namespace ff::drivers {

// The UCS test on the shared loop: platens approach at a constant speed; the curve is the
// platen stress against the axial strain, with the lateral strain from a mid-height gauge.
DemLoopCounters UcsRun::counters() {
  return {&st_.rows, &st_.peak_row, &st_.peak_stress, &st_.strain_at_peak, &st_.cracks_written, &st_.vtk_index,
          &st_.next_vtk_strain, &st_.finished};
}

void UcsRun::set_up() {
  info = dem::build_sample(cfg, sys);
  dem::add_platens(sys, info, cfg.real("ucs.platen_friction"));
  dem::choose_time_step(cfg, sys);
  const Real v = cfg.real("ucs.platen_velocity");
  sys.walls[0].velocity[info.axis] = v;
  sys.walls[1].velocity[info.axis] = -v;
  gauge_.init(sys, info);
  st_.h0 = gauge_.initial_height();
  after_set_up();
}

void UcsRun::save_after_dem(CheckpointWriter& w) const {
  w.put_value("ucs.state", st_);
  w.put_value("ucs.sample", sample_record(info));
  w.put("ucs.gauge", gauge_.particles());
  save_extra(w);
}

void UcsRun::load_after_dem(CheckpointReader& r) {
  st_ = r.get_value<UcsState>("ucs.state");
  info = sample_info(r.get_value<SampleRecord>("ucs.sample"));
  std::vector<Index> g;
  r.get("ucs.gauge", g);
  gauge_.restore(std::move(g), st_.h0);
  load_extra(r);
}

void UcsRun::ready() {
  columns = kColumns;
  extra_columns(columns);
}

// Each platen moves at v: the strain cap is reached after max_strain h / (2 v dt) steps (h the
// sample's height as built, not the gauge's: a sample that blew up in its set-up must reach the
// loop, which stops it with the cause, rather than look like a run that cannot end).
double UcsRun::planned_steps() const {
  return cfg.real("ucs.max_strain") * info.height / (2 * cfg.real("ucs.platen_velocity") * sys.settings.dt);
}

// The same steps as sys.run(steps) when the hooks are the defaults.
void UcsRun::advance(long steps) {
  for (long s = 0; s < steps; ++s) {
    before_step();
    dem_step();
    after_step();
  }
}

DemRowReport UcsRun::measure() {
  const CompressionState m = gauge_.measure(sys, info);
  row = {static_cast<double>(sys.step_count), sys.time, m.axial_strain, m.axial_stress, m.lateral_strain,
         m.volumetric_strain, static_cast<double>(sys.cracks.tensile), static_cast<double>(sys.cracks.shear),
         static_cast<double>(sys.cracks.total()), static_cast<double>(intact_bonds(sys)), kinetic_energy(sys),
         max_unbalanced_force_ratio(sys)};
  status.clear();
  fmt::format_to(std::back_inserter(status), "strain {:.3f}%  stress {:.3f} MPa  cracks {}", 100 * m.axial_strain,
                 1e-6 * m.axial_stress, sys.cracks.total());
  extra_row(m);
  return {true, m.axial_strain, m.axial_stress, m.lateral_strain};
}

void UcsRun::summarize(nlohmann::json& j, const DemOutcome& out) {
  j["ucs_Pa"] = out.no_peak.empty() ? nlohmann::json(st_.peak_stress) : nlohmann::json(nullptr);
  if (!out.no_peak.empty()) {
    j["peak"]["largest_stress_Pa"] = st_.peak_stress;
    log::warn("no UCS (null in summary.json): {}", out.no_peak);
  }
  // The peak among rows near equilibrium: a crack burst's one-row spike (grains thrown onto a
  // platen) is not a strength; in saturated specimens it reached 2.7 x this (drivers/curve_peak.hpp).
  j["peak"]["quasi_static"] =
      out.no_peak.empty() ? quasi_static_peak_json("axial_strain") : nullptr;
  put_elastic_fit(j, out.fit, "least squares on the pre-peak curve between 20% and 50% of the peak stress");
  extra_summary(j, out);
}

void UcsRun::plots() {
  if (!cfg.boolean("output.plots")) return;
  const fs::path& out = opt.out_dir;
  fs::create_directories(out / "plots");
  const std::string t = test_title();
  std::vector<PlotJob> jobs = {
      axial_strain_plot(out, "stress_strain_cracks", t + ": stress and cracks", {"axial_stress_Pa"}, 1e-6,
                        "axial stress [MPa]"),
      axial_strain_plot(out, "strains", t + ": strains", {"lateral_strain", "volumetric_strain"}, 100,
                        "strain [%] (compression > 0)")};
  jobs[0].spec.y2 = {"cracks_total", "cracks_tensile", "cracks_shear"};
  jobs[0].spec.y2label = "number of cracks";
  extra_plots(jobs);
  plot_series(jobs);  // one python process for all
}

void UcsRun::report(const DemOutcome& out) {
  const std::string extra = extra_report();
  log::info("{}, {}{}, cracks {} ({} tensile, {} shear); {}",
            out.no_peak.empty()
                ? fmt::format("UCS {:.3f} MPa at axial strain {:.3f}%", 1e-6 * st_.peak_stress, 100 * st_.strain_at_peak)
                : std::string("no UCS"),
            out.fit.ok() ? fmt::format("E = {:.3f} GPa, nu = {:.3f}", 1e-9 * out.fit.youngs_modulus, out.fit.poisson_ratio)
                         : std::string("no E or nu"),
            extra.empty() ? std::string() : ", " + extra, sys.cracks.total(), sys.cracks.tensile, sys.cracks.shear,
            out.stop_reason);
}

namespace {

RunStatus run(const Config& cfg, const RunOptions& opt) { return UcsRun(cfg, opt).run(); }

}  // namespace

Driver ucs_driver() {
  return Driver{"ucs", "uniaxial compression of a bonded-particle sample (UCS, E, nu, cracks)", declare_ucs_params, run,
                dem::validate_dem_sample};
}

}  // namespace ff::drivers
