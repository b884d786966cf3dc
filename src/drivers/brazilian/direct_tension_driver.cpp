// The direct tension test on the shared DEM loop. The particles of the two end slabs along the
// sample's axis (z in 3D, y in 2D) are glued to rigid grips: they get zero inverse mass and
// inertia and a prescribed velocity, so the leapfrog update keeps them moving at it (x += v dt)
// and no engine change is needed. The pulling force is the sum over a grip's particles of the
// pair forces gathered on them in the last step (contacts and bonds with the sample; forces
// between two grip particles cancel in the sum).
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>

#include "core/log.hpp"
#include "dem/dem_params.hpp"
#include "dem/diagnostics.hpp"
#include "dem/sample_builder.hpp"
#include "drivers/brazilian/brazilian_driver.hpp"
#include "drivers/brazilian/tensile_plots.hpp"
#include "drivers/common_params.hpp"
#include "drivers/dem_results.hpp"
#include "drivers/dem_run_loop.hpp"
#include "drivers/ucs/ucs_measure.hpp"

namespace ff::drivers {

namespace {

void declare(ParamTable& t) {
  dem::declare_dem_params(t);
  dem::declare_sample_params(t);
  t.real("direct_tension.grip_velocity", 0.02, "m/s", "speed of each grip away from the sample (along its axis)")
      .positive();
  t.real("direct_tension.grip_thickness", 2.0, "-",
         "particles whose centre lies within this many sample.radius_max of an end are glued to that end's grip")
      .positive();
  t.real("direct_tension.stop_fraction", 0.5, "-", "stop when the load has fallen below this fraction of its quasi-static peak (the largest among rows with an unbalanced-force ratio below 0.1)")
      .open_range(0, 1);
  t.real("direct_tension.max_strain", 0.01, "-", "stop at this axial strain (extension / free length) in any case")
      .positive();
  declare_series_interval(t, "direct_tension");
  t.real("direct_tension.vtk_strain_interval", 2e-4, "-", "axial strain between VTK snapshots").positive();
  t.integer("direct_tension.checkpoint_interval", 0, "steps",
            "steps between extra checkpoints (0: none; checkpoints come every output.checkpoint_wall_interval seconds, at "
            "the end and on interruption)")
      .non_negative();
}

void validate(const Config& cfg) {
  dem::validate_dem_sample(cfg);
  if (cfg.string("sample.shape") == "disc")
    cfg.fail("sample.shape", "direct tension pulls a bar along its axis: shape = \"box\" (2D or 3D) or \"cylinder\" (3D)");
  // Both grips and a free length of at least 4 radii between them.
  const Real g = cfg.real("direct_tension.grip_thickness") * cfg.real("sample.radius_max");
  if (cfg.real("sample.height") - 2 * g < 4 * cfg.real("sample.radius_max"))
    cfg.fail("direct_tension.grip_thickness",
             fmt::format("two grips of {} m leave less than 4 sample.radius_max free in a sample.height of {} m; use "
                         "thinner grips or a longer sample",
                         g, cfg.real("sample.height")));
}

// Signs: tension positive (load, stress, axial strain); lateral contraction is negative.
const std::vector<std::string> kColumns = {"step",           "time_s",         "grip_displacement_m",
                                           "axial_strain",   "load_N",         "tensile_stress_Pa",
                                           "lateral_strain", "cracks_tensile", "cracks_shear",
                                           "cracks_total",   "intact_bonds",   "kinetic_energy_J",
                                           "unbalanced_force_ratio"};

struct TensionState {
  Real peak_stress = 0, strain_at_peak = 0;
  long peak_row = 0, rows = 0, cracks_written = 0, vtk_index = 0;
  Real next_vtk_strain = 0;
  Real free_length = 0;  // between the grips' inner faces at the start [m]
  Real separation0 = 0;  // initial distance of the two reference grip particles along the axis [m]
  Real peak_load = 0, displacement_at_peak = 0;
  long cracks_at_peak = 0;
  int finished = 0, unused = 0;  // explicit padding: the bytes are the checkpoint format
};

}  // namespace
}  // namespace ff::drivers

namespace ff {
template <> struct is_checkpoint_pod<drivers::TensionState> : std::true_type {};
}  // namespace ff

namespace ff::drivers {
namespace {

class DirectTensionRun final : public DemRun {
 public:
  DirectTensionRun(const Config& c, const RunOptions& o)
      : DemRun(c, o, {"direct_tension", "load", "tensile_stress_Pa", "direct_tension.grip_velocity or direct_tension.max_strain",
                      "axial_strain", "lateral_strain", "axial strain", "direct_tension.grip_velocity"}) {}

 private:
  DemLoopCounters counters() override {
    return {&st_.rows, &st_.peak_row, &st_.peak_stress, &st_.strain_at_peak, &st_.cracks_written, &st_.vtk_index,
            &st_.next_vtk_strain, &st_.finished};
  }
  void set_up() override {
    info = dem::build_sample(cfg, sys);
    dem::choose_time_step(cfg, sys);  // before the grips lose their mass
    auto& P = sys.particles;
    const int ax = info.axis;
    Real lo = std::numeric_limits<Real>::infinity(), hi = -lo;
    for (std::size_t i = 0; i < P.size(); ++i) {
      lo = std::min(lo, P.pos[i][ax] - P.radius[i]);
      hi = std::max(hi, P.pos[i][ax] + P.radius[i]);
    }
    const Real g = cfg.real("direct_tension.grip_thickness") * cfg.real("sample.radius_max");
    const Real v = cfg.real("direct_tension.grip_velocity");
    for (std::size_t i = 0; i < P.size(); ++i) {
      const bool bottom = P.pos[i][ax] < lo + g, top = P.pos[i][ax] > hi - g;
      if (!bottom && !top) continue;
      (bottom ? bottom_ : top_).push_back(static_cast<Index>(i));
      P.inv_mass[i] = 0;
      P.inv_inertia[i] = 0;
      P.vel[i].setZero();
      P.vel[i][ax] = bottom ? -v : v;
      P.omega[i].setZero();
    }
    if (bottom_.empty() || top_.empty())
      cfg.fail("direct_tension.grip_thickness", "a grip holds no particle; use a thicker grip");
    st_.free_length = hi - lo - 2 * g;
    st_.separation0 = P.pos[top_[0]][ax] - P.pos[bottom_[0]][ax];
    init_gauge(lo + g);
    log::info("direct tension: grips of {} and {} particles, free length {:.4g} m", bottom_.size(), top_.size(),
              st_.free_length);
  }
  // Lateral gauge: outer-shell particles (within two max radii of the surface) in the middle
  // half of the free length, as the UCS gauge.
  void init_gauge(Real free_lo) {
    const auto& P = sys.particles;
    const Real rmax = cfg.real("sample.radius_max");
    for (std::size_t i = 0; i < P.size(); ++i) {
      const Real h = (P.pos[i][info.axis] - free_lo) / st_.free_length;
      if (h < 0.25 || h > 0.75) continue;
      const Real d = info.cylinder ? 0.5 * info.width - std::hypot(P.pos[i].x(), P.pos[i].y())
                                   : std::min(P.pos[i].x(), info.width - P.pos[i].x());
      if (d < 2 * rmax) gauge_.push_back(static_cast<Index>(i));
    }
  }
  Real lateral_strain() const {
    const auto& P = sys.particles;
    Real sum = 0;
    for (Index i : gauge_) {
      const Vec3 x0 = P.pos[i] - P.disp[i];
      if (info.cylinder) {
        const Real r0 = std::hypot(x0.x(), x0.y());
        sum += (std::hypot(P.pos[i].x(), P.pos[i].y()) - r0) / r0;
      } else {
        const Real c = 0.5 * info.width;
        sum += (std::abs(P.pos[i].x() - c) - std::abs(x0.x() - c)) / std::abs(x0.x() - c);
      }
    }
    return gauge_.empty() ? 0 : sum / static_cast<Real>(gauge_.size());
  }
  // The grips move at a prescribed speed and are held, not balanced: the kinetic energy and the
  // unbalanced-force ratio of series.csv leave them out.
  Real sample_kinetic_energy() const {
    const auto& P = sys.particles;
    Real grips = 0;
    for (const auto* g : {&bottom_, &top_})
      for (Index i : *g) grips += 0.5 * P.mass[i] * P.vel[i].squaredNorm();
    return kinetic_energy(sys) - grips;
  }
  // max_unbalanced_force_ratio() = mean |F| over all particles / mean loaded pair force; the
  // same mean over the free particles only, from the grips' share of the sum.
  Real sample_unbalanced_force_ratio() const {
    const auto& P = sys.particles;
    Real all = 0, grips = 0;
    for (std::size_t i = 0; i < P.size(); ++i) all += P.force[i].norm();
    for (const auto* g : {&bottom_, &top_})
      for (Index i : *g) grips += P.force[i].norm();
    const Real n = static_cast<Real>(P.size()), free = n - static_cast<Real>(bottom_.size() + top_.size());
    if (!(all > 0) || !(free > 0)) return 0;
    return max_unbalanced_force_ratio(sys) * n * (all - grips) / (free * all);
  }
  void save_after_dem(CheckpointWriter& w) const override {
    w.put_value("direct_tension.state", st_);
    w.put_value("direct_tension.sample", sample_record(info));
    w.put("direct_tension.grip_bottom", bottom_);
    w.put("direct_tension.grip_top", top_);
    w.put("direct_tension.gauge", gauge_);
  }
  void load_after_dem(CheckpointReader& r) override {
    st_ = r.get_value<TensionState>("direct_tension.state");
    info = sample_info(r.get_value<SampleRecord>("direct_tension.sample"));
    r.get("direct_tension.grip_bottom", bottom_);
    r.get("direct_tension.grip_top", top_);
    r.get("direct_tension.gauge", gauge_);
  }
  void ready() override { columns = kColumns; }
  double planned_steps() const override {
    // The built sample's height (an upper bound of the free length), not the grips' measured
    // distance: a set-up that blew up must reach the loop's instability stop, not an "endless run".
    return cfg.real("direct_tension.max_strain") * info.height /
           (2 * cfg.real("direct_tension.grip_velocity") * sys.settings.dt);
  }
  DemRowReport measure() override {
    const auto& P = sys.particles;
    const int ax = info.axis;
    // The sample pulls the bottom grip towards +axis and the top one towards -axis.
    Real fb = 0, ft = 0;
    for (Index i : bottom_) fb += P.force[i][ax];
    for (Index i : top_) ft += P.force[i][ax];
    const Real load = 0.5 * (fb - ft);
    const Real displacement = P.pos[top_[0]][ax] - P.pos[bottom_[0]][ax] - st_.separation0;
    const Real strain = displacement / st_.free_length;
    const Real stress = load / info.area;
    const Real lateral = lateral_strain();
    if (stress > st_.peak_stress) {  // the loop takes this row as the new peak
      st_.peak_load = load;
      st_.displacement_at_peak = displacement;
      st_.cracks_at_peak = static_cast<long>(sys.cracks.events.size());
    }
    row = {static_cast<double>(sys.step_count), sys.time, displacement, strain, load, stress, lateral,
           static_cast<double>(sys.cracks.tensile), static_cast<double>(sys.cracks.shear),
           static_cast<double>(sys.cracks.total()), static_cast<double>(intact_bonds(sys)), sample_kinetic_energy(),
           sample_unbalanced_force_ratio()};
    status.clear();
    fmt::format_to(std::back_inserter(status), "strain {:.4f}%  stress {:.3f} MPa  cracks {}", 100 * strain,
                   1e-6 * stress, sys.cracks.total());
    return {true, strain, stress, lateral};
  }
  void summarize(nlohmann::json& j, const DemOutcome& out) override {
    const bool peak = out.no_peak.empty();
    auto or_null = [peak](Real v) { return peak ? nlohmann::json(v) : nlohmann::json(nullptr); };
    j["tensile_strength_Pa"] = or_null(st_.peak_stress);
    j["peak_load_N"] = or_null(st_.peak_load);
    j["grip_displacement_at_peak_m"] = or_null(st_.displacement_at_peak);
    j["cracks_up_to_peak"] = peak ? nlohmann::json(st_.cracks_at_peak) : nlohmann::json(nullptr);
    j["method"] = "direct tension: tensile strength = peak pulling force / cross-section; end slabs glued to rigid grips";
    j["specimen"] = {{"cross_section_m2", info.area},
                     {"free_length_m", st_.free_length},
                     {"grip_particles", bottom_.size() + top_.size()},
                     {"dim", sys.settings.dim}};
    if (sys.settings.dim == 2) j["specimen"]["note"] = "2D: loads are per metre of thickness (area = width x 1 m)";
    if (!peak) {
      j["peak"]["largest_stress_Pa"] = st_.peak_stress;
      log::warn("no tensile strength (null in summary.json): {}", out.no_peak);
    }
    // The peak among rows near equilibrium (a crack burst's one-row spike is not a strength).
    j["peak"]["quasi_static"] = peak ? quasi_static_peak_json("axial_strain") : nullptr;
    put_elastic_fit(j, out.fit,
                    "least squares on the pre-peak tension curve between 20% and 50% of the peak stress (tension "
                    "positive: Young's modulus in tension; Poisson's ratio from the mid-length lateral gauge)");
  }
  void plots() override {
    tensile_plots(opt.out_dir, cfg, "Direct tension", "grip_displacement_m", "axial_strain", "axial strain",
                  {"tensile_stress_Pa"}, "tensile stress", sys.settings.dim == 2);
  }
  void report(const DemOutcome& out) override {
    log::info("{}, {}, cracks {} ({} tensile, {} shear); {}",
              out.no_peak.empty() ? fmt::format("direct tensile strength {:.3f} MPa at axial strain {:.4f}%",
                                                1e-6 * st_.peak_stress, 100 * st_.strain_at_peak)
                                  : std::string("no tensile strength"),
              out.fit.ok() ? fmt::format("E = {:.3f} GPa, nu = {:.3f}", 1e-9 * out.fit.youngs_modulus, out.fit.poisson_ratio)
                           : std::string("no E or nu"),
              sys.cracks.total(), sys.cracks.tensile, sys.cracks.shear, out.stop_reason);
  }

  TensionState st_;
  std::vector<Index> bottom_, top_, gauge_;
};

RunStatus run(const Config& cfg, const RunOptions& opt) { return DirectTensionRun(cfg, opt).run(); }

}  // namespace

Driver direct_tension_driver() {
  return Driver{"direct_tension", "direct tension of a bonded bar with glued grips: tensile strength = peak force / area",
                declare, run, validate};
}

}  // namespace ff::drivers
