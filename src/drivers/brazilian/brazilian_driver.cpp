// The Brazilian (indirect tensile) test on the shared DEM loop. Geometry: the sample of
// build_sample, a disc in the x-y plane (2D, unit thickness) or a cylinder with axis z (3D, its
// length sample.height is the thickness t), centred on the z axis; two rigid platens normal to
// y approach at a constant speed and load it across the diameter on the y axis.
#include "drivers/brazilian/brazilian_driver.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <iterator>

#include "core/log.hpp"
#include "dem/dem_params.hpp"
#include "dem/diagnostics.hpp"
#include "dem/sample_builder.hpp"
#include "drivers/brazilian/tensile_plots.hpp"
#include "drivers/common_params.hpp"
#include "drivers/dem_results.hpp"
#include "drivers/dem_run_loop.hpp"

namespace ff::drivers {

namespace {

void declare(ParamTable& t) {
  dem::declare_dem_params(t);
  dem::declare_sample_params(t);
  t.real("brazilian.platen_velocity", 0.05, "m/s", "speed of each platen towards the sample (along y)").positive();
  t.real("brazilian.platen_friction", 0.1, "-", "friction between platens and particles").non_negative();
  t.real("brazilian.stop_fraction", 0.6, "-", "stop when the load has fallen below this fraction of its quasi-static peak (the largest among rows with an unbalanced-force ratio below 0.1)").open_range(0, 1);
  t.real("brazilian.max_strain", 0.03, "-", "stop at this diametral strain (platen approach / diameter) in any case")
      .positive();
  t.real("brazilian.centre_gauge_radius", 0.25, "-",
         "radius of the central circle (3D: cylinder through the thickness) where the stress is averaged, as a "
         "fraction of the disc radius")
      .open_range(0, 1);
  declare_series_interval(t, "brazilian");
  t.real("brazilian.vtk_strain_interval", 1e-3, "-", "diametral strain between VTK snapshots").positive();
  t.integer("brazilian.checkpoint_interval", 0, "steps",
            "steps between extra checkpoints (0: none; checkpoints come every output.checkpoint_wall_interval seconds, at "
            "the end and on interruption)")
      .non_negative();
}

void validate(const Config& cfg) {
  dem::validate_dem_sample(cfg);
  if (cfg.string("sample.shape") == "box")
    cfg.fail("sample.shape",
             "the Brazilian test loads a disc across its diameter: shape = \"disc\" in 2D (dem.dim = 2), or \"cylinder\" "
             "in 3D (a cylinder lying on its side; sample.height is its thickness)");
}

// Column names end in their SI unit; strains, counts and ratios have none. Signs: load and
// diametral strain positive in compression (the platens approach); stresses positive in tension.
const std::vector<std::string> kColumns = {
    "step",          "time_s",         "platen_displacement_m", "diametral_strain", "load_N",
    "tensile_stress_Pa", "centre_stress_across_Pa", "centre_stress_along_Pa", "cracks_tensile", "cracks_shear",
    "cracks_total",  "intact_bonds",   "kinetic_energy_J",      "unbalanced_force_ratio"};

// Driver state that must survive a restart (raw bytes in the checkpoint).
struct BrazilianState {
  Real peak_stress = 0, strain_at_peak = 0;
  long peak_row = 0, rows = 0, cracks_written = 0, vtk_index = 0;
  Real next_vtk_strain = 0;
  Real h0 = 0;  // initial platen separation [m]
  // At the peak load: load, platen approach, centre stresses and crack count.
  Real peak_load = 0, displacement_at_peak = 0, across_at_peak = 0, along_at_peak = 0;
  long cracks_at_peak = 0;
  int finished = 0, unused = 0;  // explicit padding: the bytes are the checkpoint format
};

}  // namespace
}  // namespace ff::drivers

namespace ff {
template <> struct is_checkpoint_pod<drivers::BrazilianState> : std::true_type {};
}  // namespace ff

namespace ff::drivers {
namespace {

class BrazilianRun final : public DemRun {
 public:
  BrazilianRun(const Config& c, const RunOptions& o)
      : DemRun(c, o, {"brazilian", "load", "tensile_stress_Pa", "brazilian.platen_velocity or brazilian.max_strain",
                      "diametral_strain", "", "diametral strain", "brazilian.platen_velocity"}) {
    D_ = cfg.real("sample.diameter");
    t_ = sys.settings.dim == 3 ? cfg.real("sample.height") : 1.0;  // 2D: disks of unit thickness
    gauge_radius_ = cfg.real("brazilian.centre_gauge_radius") * 0.5 * D_;
  }

 private:
  DemLoopCounters counters() override {
    return {&st_.rows, &st_.peak_row, &st_.peak_stress, &st_.strain_at_peak, &st_.cracks_written, &st_.vtk_index,
            &st_.next_vtk_strain, &st_.finished};
  }
  void set_up() override {
    info = dem::build_sample(cfg, sys);
    dem::SampleInfo across = info;
    across.axis = 1;  // platens normal to y, whatever the sample's own axis
    dem::add_platens(sys, across, cfg.real("brazilian.platen_friction"));
    dem::choose_time_step(cfg, sys);
    const Real v = cfg.real("brazilian.platen_velocity");
    sys.walls[0].velocity.y() = v;
    sys.walls[1].velocity.y() = -v;
    st_.h0 = sys.walls[1].point.y() - sys.walls[0].point.y();
    if (sys.settings.dim == 3 && (t_ < 0.4 * D_ || t_ > 0.6 * D_))
      log::warn("brazilian: the disc is {:.3g} diameters thick (sample.height / sample.diameter); the ISRM suggested "
                "method asks for a thickness of about the radius (0.5)",
                t_ / D_);
  }
  void save_after_dem(CheckpointWriter& w) const override {
    w.put_value("brazilian.state", st_);
    w.put_value("brazilian.sample", sample_record(info));
  }
  void load_after_dem(CheckpointReader& r) override {
    st_ = r.get_value<BrazilianState>("brazilian.state");
    info = sample_info(r.get_value<SampleRecord>("brazilian.sample"));
  }
  void ready() override { columns = kColumns; }
  // Each platen moves at v: the strain cap is reached after max_strain D / (2 v dt) steps.
  double planned_steps() const override {
    return cfg.real("brazilian.max_strain") * D_ / (2 * cfg.real("brazilian.platen_velocity") * sys.settings.dt);
  }
  DemRowReport measure() override {
    const auto& bottom = sys.walls[0];
    const auto& top = sys.walls[1];
    const Real displacement = st_.h0 - (top.point.y() - bottom.point.y());
    const Real strain = displacement / D_;
    // The particles push the bottom platen towards -y and the top one towards +y.
    const Real load = 0.5 * (-bottom.force.y() + top.force.y());
    const Real nominal = 2 * load / (kPi * D_ * t_);  // ISRM (1978)
    // Love-Weber average over the central circle (tension +); x is across the loaded diameter.
    const Real a2 = gauge_radius_ * gauge_radius_;
    const Mat3 s = average_stress(sys, [a2](const Vec3& x) { return x.x() * x.x() + x.y() * x.y() < a2; },
                                      kPi * a2 * t_);
    if (nominal > st_.peak_stress) {  // the loop takes this row as the new peak
      st_.peak_load = load;
      st_.displacement_at_peak = displacement;
      st_.across_at_peak = s(0, 0);
      st_.along_at_peak = s(1, 1);
      st_.cracks_at_peak = static_cast<long>(sys.cracks.events.size());
    }
    row = {static_cast<double>(sys.step_count), sys.time, displacement, strain, load, nominal, s(0, 0), s(1, 1),
           static_cast<double>(sys.cracks.tensile), static_cast<double>(sys.cracks.shear),
           static_cast<double>(sys.cracks.total()), static_cast<double>(intact_bonds(sys)), kinetic_energy(sys),
           max_unbalanced_force_ratio(sys)};
    status.clear();
    fmt::format_to(std::back_inserter(status), "diametral strain {:.3f}%  2P/(pi D t) {:.3f} MPa  cracks {}",
                   100 * strain, 1e-6 * nominal, sys.cracks.total());
    return {true, strain, nominal, 0};
  }
  void summarize(nlohmann::json& j, const DemOutcome& out) override {
    const bool peak = out.no_peak.empty();
    auto or_null = [peak](Real v) { return peak ? nlohmann::json(v) : nlohmann::json(nullptr); };
    j["tensile_strength_Pa"] = or_null(st_.peak_stress);
    j["peak_load_N"] = or_null(st_.peak_load);
    j["platen_displacement_at_peak_m"] = or_null(st_.displacement_at_peak);
    j["method"] = "ISRM (1978) suggested method: tensile strength = 2 P / (pi D t), P the peak load between flat "
                  "rigid platens";
    j["specimen"] = {{"diameter_m", D_}, {"thickness_m", t_}, {"dim", sys.settings.dim}};
    if (sys.settings.dim == 2) j["specimen"]["note"] = "2D disc: loads are per metre of thickness (t = 1 m)";
    // The elastic disc under diametral point loads has +2P/(pi D t) across and -6P/(pi D t)
    // along the loaded diameter at its centre (Timoshenko & Goodier 1970 s. 41; Hondros 1959).
    const Real rho = cfg.real("brazilian.centre_gauge_radius");
    const Real p = st_.peak_load > 0 ? 2 * st_.peak_load / (kPi * D_ * t_) : 0.0;
    j["centre_stress_at_peak"] = {
        {"gauge_radius_m", gauge_radius_},
        {"across_Pa", or_null(st_.across_at_peak)},
        {"along_Pa", or_null(st_.along_at_peak)},
        {"across_over_2P_piDt", p > 0 ? or_null(st_.across_at_peak / p) : nlohmann::json(nullptr)},
        {"along_over_2P_piDt", p > 0 ? or_null(st_.along_at_peak / p) : nlohmann::json(nullptr)},
        // Averaged over a circle of rho R (the field integrated numerically): 1 - rho^2 and -(3 - rho^2).
        {"elastic_disc_across_over_2P_piDt", 1 - rho * rho},
        {"elastic_disc_along_over_2P_piDt", -(3 - rho * rho)}};
    // A valid test splits from the centre: cracks up to the peak near the centre, not at the platens.
    long centre = 0, platens = 0;
    const Real R = 0.5 * D_;
    for (long k = 0; k < st_.cracks_at_peak && peak; ++k) {
      const Vec3& x = sys.cracks.events[static_cast<std::size_t>(k)].position;
      if (std::hypot(x.x(), x.y()) < 0.5 * R) ++centre;
      if (std::abs(x.y()) > 0.75 * R) ++platens;
    }
    j["cracks_up_to_peak"] = {{"total", peak ? nlohmann::json(st_.cracks_at_peak) : nlohmann::json(nullptr)},
                              {"within_half_radius_of_centre", peak ? nlohmann::json(centre) : nlohmann::json(nullptr)},
                              {"near_platens", peak ? nlohmann::json(platens) : nlohmann::json(nullptr)},
                              {"near_platens_means", "|y| > 0.75 R, where the platens crush the disc"}};
    if (peak && platens > centre)
      log::warn("brazilian: of the {} cracks before the peak, {} lie near the platens and {} within R/2 of the centre: "
                "the platens crushed the disc before it split, so the peak may not measure the tensile strength (a "
                "valid test splits from the centre, ISRM 1978)",
                st_.cracks_at_peak, platens, centre);
    if (!peak) {
      j["peak"]["largest_stress_Pa"] = st_.peak_stress;
      log::warn("no tensile strength (null in summary.json): {}", out.no_peak);
    }
    // The peak among rows near equilibrium (a crack burst's one-row spike is not a strength).
    j["peak"]["quasi_static"] =
        peak ? quasi_static_peak_json("diametral_strain") : nullptr;
  }
  void plots() override {
    tensile_plots(opt.out_dir, cfg, "Brazilian test", "platen_displacement_m", "diametral_strain", "diametral strain",
                  {"tensile_stress_Pa", "centre_stress_across_Pa"}, "2P/(pi D t) and centre stress across",
                  sys.settings.dim == 2);
  }
  void report(const DemOutcome& out) override {
    log::info("{}, cracks {} ({} tensile, {} shear); {}",
              out.no_peak.empty()
                  ? fmt::format("Brazilian tensile strength {:.3f} MPa (peak load {:.4g} N{}) at diametral strain {:.3f}%",
                                1e-6 * st_.peak_stress, st_.peak_load, sys.settings.dim == 2 ? " per m" : "",
                                100 * st_.strain_at_peak)
                  : std::string("no tensile strength"),
              sys.cracks.total(), sys.cracks.tensile, sys.cracks.shear, out.stop_reason);
  }

  BrazilianState st_;
  Real D_ = 0, t_ = 0, gauge_radius_ = 0;
};

RunStatus run(const Config& cfg, const RunOptions& opt) { return BrazilianRun(cfg, opt).run(); }

}  // namespace

Driver brazilian_driver() {
  return Driver{"brazilian", "Brazilian (indirect tensile) test of a bonded disc or cylinder: tensile strength 2P/(pi D t)",
                declare, run, validate};
}

}  // namespace ff::drivers
