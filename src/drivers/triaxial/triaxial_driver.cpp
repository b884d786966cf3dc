#include "drivers/triaxial/triaxial_driver.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iterator>

#include "core/error.hpp"
#include "core/log.hpp"
#include "dem/dem_params.hpp"
#include "dem/sample_builder.hpp"
#include "drivers/common_params.hpp"
#include "drivers/dem_results.hpp"
#include "drivers/dem_run_loop.hpp"
#include "drivers/triaxial/triaxial_boundary.hpp"
#include "drivers/triaxial/triaxial_lateral_setup.hpp"
#include "drivers/ucs/ucs_measure.hpp"
#include "io/csv.hpp"
#include "io/plot.hpp"
#include "dem/diagnostics.hpp"
#include "dem/membrane/membrane_boundary.hpp"

namespace fs = std::filesystem;

namespace ff::drivers {

namespace {

void declare(ParamTable& t) {
  dem::declare_dem_params(t);
  dem::declare_sample_params(t);
  t.real("triaxial.confining_pressure", 5e6, "Pa", "confining pressure sigma3 (lateral, and axial in the isotropic stage)")
      .positive();
  t.string("triaxial.lateral", "membrane",
           "lateral confinement: flexible membrane of servo-controlled triangles, a rigid cylinder with a servo on its "
           "radius, or a particle membrane (bonded spheres, each pushed by a constant force; seed 000 Fig. 15)")
      .one_of({"membrane", "rigid_cylinder", "particle_membrane"});
  t.real("triaxial.platen_velocity", 0.05, "m/s", "deviatoric stage: speed of each platen towards the sample").positive();
  t.real("triaxial.platen_friction", 0.1, "-", "friction between platens and particles (seed 000: 0.1)").non_negative();
  t.real("triaxial.servo_velocity", 1.0, "m/s",
         "speed cap of every servo (isotropic-stage platens, membrane, cylinder) and of the particle membrane's spheres in "
         "the isotropic stage; must exceed the sample's lateral bulging speed, several times the platen velocity (seed 000 "
         "uses 0.01 with slower platens)")
      .positive();
  t.real("triaxial.servo_relaxation", 0.8, "-", "servo relaxation factor alpha (PFC default 0.8)").open_range(0, 1).at_most(1);
  t.real("triaxial.isotropic_tolerance", 0.02, "-", "isotropic stage ends when platen stress and confinement are within this fraction of sigma3")
      .open_range(0, 1);
  t.integer("triaxial.isotropic_max_steps", 200000, "steps", "step cap of the isotropic stage").positive();
  t.real("triaxial.isotropic_unbalanced_ratio", 0.01, "-",
         "isotropic stage ends only once the sample's mean unbalanced-force ratio is below this (quasi-static "
         "equilibrium, METHODS.md 1.6: < 1e-2); with a particle membrane: the ratio over all particles, at most 0.05")
      .open_range(0, 1);
  t.real("triaxial.measurement_sphere_radius", 0.6, "-", "radius of the three measurement spheres on the axis, as a fraction of the sample radius")
      .open_range(0, 1);
  t.real("triaxial.stop_fraction", 0.6, "-", "stop when the differential stress has fallen below this fraction of its quasi-static peak (the largest among rows with an unbalanced-force ratio below 0.1)").open_range(0, 1);
  t.real("triaxial.max_strain", 0.06, "-", "stop at this axial strain (deviatoric stage) in any case").positive();
  declare_series_interval(t, "triaxial");
  t.real("triaxial.vtk_strain_interval", 2e-3, "-", "axial strain between VTK snapshots").positive();
  t.integer("triaxial.checkpoint_interval", 0, "steps",
            "steps between extra checkpoints (0: none; checkpoints come every output.checkpoint_wall_interval seconds, at "
            "the end of each stage and on interruption)")
      .non_negative();
  t.integer("membrane.n_theta", 24, "-", "membrane: square units around the circumference (seed 000 demo: 16)").at_least(6);
  t.integer("membrane.n_z", 0, "-", "membrane: rows of units along the axis (0: nearly square units)").non_negative();
  t.real("membrane.length_factor", 1.2, "-",
         "membrane sleeve length / sample height (longer than the sample; up to 10: a longer sleeve's elements "
         "degenerate)")
      .range(1, 10);
  t.real("membrane.clearance", 0.01, "-",
         "initial gap between sample and membrane facets (particle membrane: its inner surface), as a fraction of the "
         "sample radius")
      .non_negative();
  t.real("membrane.min_radius_fraction", 0.9, "-", "vertices never come closer to the axis than this fraction of the sample radius")
      .open_range(0, 1);
  t.real("membrane.friction", 0.0, "-",
         "friction between sample particles and the lateral boundary (flexible or particle membrane, rigid cylinder); 0: "
         "pure pressure, as a rubber sleeve that moves with the sample; -1: each particle's own contact friction "
         "(dem.contact.G-G.friction), as between particles (then the sleeve's elements, which move only along their "
         "normals, carry axial load: docs/dem.md)")
      .at_least(-1);
  t.real("particle_membrane.radius_fraction", 1.0, "-",
         "particle membrane: sphere radius as a fraction of the sample's mean particle radius (adjusted by up to 15% so "
         "that the rows fill the platen gap and the ring clears the sample by membrane.clearance)")
      .range(0.2, 3);
  t.real("particle_membrane.emod", 1e7, "Pa",
         "particle membrane: modulus of its bonds and of its spheres' mutual contacts (latex-like; its hoop stress "
         "~ emod pi r_m e_theta / (2 R) stays small beside sigma3 for e_theta of a few %)")
      .positive();
  t.boolean("particle_membrane.bonded", true,
            "particle membrane: bond ring and row neighbours (false: loose spheres that touch, each still pushed by its "
            "constant force; the sample can push between them where the ring opens)");
  t.real("particle_membrane.density", 1000, "kg/m^3",
         "particle membrane: sphere density (latex ~ 950); inertial masses are scaled up where the sample's time step needs "
         "it")
      .positive();
}

// Driver state that must survive a restart.
struct TriaxialState {
  int stage = 0;  // 0 isotropic, 1 deviatoric
  long iso_steps = 0, iso_rows = 0, rows = 0, peak_row = 0, cracks_written = 0, vtk_index = 0;
  int iso_converged = 0, finished = 0;
  Real peak_diff = 0, strain_at_peak = 0, conf_at_peak = 0;
  Real h_dev0 = 0, v_dev0 = 0, next_vtk_strain = 0;
  Real iso_axial = 0, iso_conf = 0, iso_sphere_error = 0;
  Real sphere_axial[3] = {0, 0, 0}, sphere_lateral[3] = {0, 0, 0};
  int sphere_particles[3] = {0, 0, 0};
  int iso_cracks = 0;
  Real whole_axial = 0, whole_lateral = 0;  // Love-Weber average of the whole sample over the enclosed volume
  Real sphere_porosity[3] = {0, 0, 0};
};

}  // namespace
}  // namespace ff::drivers

namespace ff {
template <> struct is_checkpoint_pod<drivers::TriaxialState> : std::true_type {};
template <> struct is_checkpoint_pod<dem::MembraneSettings> : std::true_type {};
template <> struct is_checkpoint_pod<dem::ParticleMembraneLayout> : std::true_type {};
}  // namespace ff

namespace ff::drivers {
namespace {

// Series columns; crack counts by pair of the sample's groups (the first `groups`).
std::vector<std::string> triaxial_columns(const dem::Materials& mat, int groups) {
  // Names end in their SI unit (_s, _Pa, _J); strains, counts and ratios have none.
  std::vector<std::string> c = {"step", "time_s", "axial_strain", "axial_stress_Pa", "differential_stress_Pa", "confinement_Pa",
                                "lateral_strain", "volumetric_strain", "cracks_tensile", "cracks_shear", "cracks_total"};
  for (int a = 0; a < groups; ++a)
    for (int b = a; b < groups; ++b) {
      const std::string p = mat.group_names[a] + "-" + mat.group_names[b];
      c.push_back("cracks_" + p + "_tensile");
      c.push_back("cracks_" + p + "_shear");
    }
  for (const char* s : {"intact_bonds", "kinetic_energy_J", "unbalanced_force_ratio"}) c.emplace_back(s);
  return c;
}

void make_plots(const fs::path& out, const Config& cfg) {
  if (!cfg.boolean("output.plots")) return;
  fs::create_directories(out / "plots");
  std::vector<PlotJob> jobs = {
      axial_strain_plot(out, "stress_strain_cracks",
                        fmt::format("Triaxial compression, sigma3 = {:g} MPa: stress and cracks",
                                    1e-6 * cfg.real("triaxial.confining_pressure")),
                        {"differential_stress_Pa"}, 1e-6, "differential stress [MPa]"),
      axial_strain_plot(out, "strains", "Triaxial compression: strains", {"lateral_strain", "volumetric_strain"}, 100,
                        "strain [%] (compression > 0)"),
      axial_strain_plot(out, "confinement", "Applied lateral confinement", {"confinement_Pa"}, 1e-6, "confinement [MPa]")};
  jobs[0].spec.y2 = {"cracks_total", "cracks_tensile", "cracks_shear"};
  jobs[0].spec.y2label = "number of cracks";
  plot_series(jobs);  // one python process for all three
}

// The triaxial test's own checks that need no sample (run() and validate() both call it).
void check_triaxial_keys(const Config& cfg) {
  if (cfg.integer("dem.dim") != 3) cfg.fail("dem.dim", "a triaxial test needs a 3D cylinder sample (dim = 3)");
  if (cfg.string("sample.shape") != "cylinder") cfg.fail("sample.shape", "a triaxial test needs shape = \"cylinder\"");
  membrane_friction(cfg);
  if (cfg.string("triaxial.lateral") != "particle_membrane") return;
  if (cfg.boolean("particle_membrane.bonded") && cfg.string("dem.bond_law") == "none")
    cfg.fail("particle_membrane.bonded", "a bonded particle membrane needs bonds: set dem.bond_law = \"parallel\" or "
                                         "\"rotational\", or particle_membrane.bonded = false");
  dem::Materials m = dem::build_materials(cfg);
  try {
    dem::add_particle_membrane_group(m, particle_membrane_material(cfg));  // its group name is reserved
  } catch (const InputError& e) {
    cfg.fail("triaxial.lateral", e.what());
  }
}

void validate(const Config& cfg) {
  check_triaxial_keys(cfg);
  dem::validate_dem_sample(cfg);
  dem::refuse_crushing_stress(cfg, "triaxial.confining_pressure");
}

// The triaxial test on the shared loop: an isotropic stage (platens and lateral boundary
// servo-controlled to sigma3, isotropic.csv) until equilibrium, then the deviatoric stage
// (platens at a constant speed, the lateral boundary holding sigma3), whose curve is the
// differential stress against the axial strain.
class TriaxialRun final : public DemRun {
 public:
  TriaxialRun(const Config& c, const RunOptions& o)
      : DemRun(c, o,
               {"triaxial", "differential stress", "differential_stress_Pa",
                "triaxial.platen_velocity, triaxial.max_strain or triaxial.isotropic_max_steps", "axial_strain",
                "lateral_strain", "axial strain", "triaxial.platen_velocity"}),
        p_(c.real("triaxial.confining_pressure")),
        servo_{c.real("triaxial.servo_velocity"), c.real("triaxial.servo_relaxation")},
        every_(c.integer("triaxial.series_interval")),
        iso_max_(c.integer("triaxial.isotropic_max_steps")),
        iso_tol_(c.real("triaxial.isotropic_tolerance")),
        iso_ubf_(c.real("triaxial.isotropic_unbalanced_ratio")) {
    const std::string lateral_name = cfg.string("triaxial.lateral");
    lat_.kind = lateral_name == "membrane"         ? LateralKind::Membrane
                : lateral_name == "rigid_cylinder" ? LateralKind::RigidCylinder
                                                   : LateralKind::ParticleMembrane;
    kind_ = lat_.kind;
    check_triaxial_keys(cfg);  // checked before anything is built
  }

 private:
  DemLoopCounters counters() override {
    return {&st_.rows, &st_.peak_row, &st_.peak_diff, &st_.strain_at_peak, &st_.cracks_written, &st_.vtk_index,
            &st_.next_vtk_strain, &st_.finished};
  }
  void set_up() override {
    info = dem::build_sample(cfg, sys);
    dem::add_platens(sys, info, cfg.real("triaxial.platen_friction"));
    if (kind_ == LateralKind::Membrane) {
      const auto& mem = dem::attach_membrane(sys, membrane_settings(cfg, sys, info));
      sys.rebuild_neighbors();
      log::info("flexible membrane: {} x {} units, {} triangles, sleeve radius {:.4g} m", mem.settings().n_theta,
                mem.settings().n_z, mem.element_count(), mem.settings().radius);
    } else if (kind_ == LateralKind::RigidCylinder) {
      add_rigid_cylinder(sys, info, membrane_friction(cfg));
    }
    dem::choose_time_step(cfg, sys);
    if (kind_ == LateralKind::ParticleMembrane) lat_.particles = add_particle_membrane(cfg, sys, info);
  }
  // `iso_ok_rows_`: rows in a row the isotropic stage has met its criteria (it ends at 5).
  void save_before_dem(CheckpointWriter& w) const override {
    w.put_value("triaxial.iso_ok_rows", iso_ok_rows_);
    if (auto* m = dem::membrane_of(sys)) w.put_value("triaxial.membrane_settings", m->settings());
    if (kind_ == LateralKind::ParticleMembrane) w.put_value("triaxial.particle_membrane", lat_.particles);
  }
  void save_after_dem(CheckpointWriter& w) const override {
    w.put_value("triaxial.state", st_);
    w.put_value("triaxial.sample", sample_record(info));
  }
  void load_before_dem(CheckpointReader& r) override {
    iso_ok_rows_ = r.get_value<int>("triaxial.iso_ok_rows");
    if (r.has("triaxial.membrane_settings"))
      dem::attach_membrane(sys, r.get_value<dem::MembraneSettings>("triaxial.membrane_settings"));
    if ((kind_ == LateralKind::ParticleMembrane) != r.has("triaxial.particle_membrane"))
      cfg.fail("triaxial.lateral", "the checkpoint was written with another lateral boundary; resume with the scenario it "
                                   "was written with");
  }
  void load_after_dem(CheckpointReader& r) override {
    if (kind_ == LateralKind::ParticleMembrane) {  // its group comes after the scenario's, as when it was built
      lat_.particles = r.get_value<dem::ParticleMembraneLayout>("triaxial.particle_membrane");
      if (dem::add_particle_membrane_group(sys.materials, particle_membrane_material(cfg)) != lat_.particles.group)
        cfg.fail("triaxial.lateral", "the checkpoint's particle groups differ from the scenario's");
      dem::attach_particle_membrane_loads(sys, lat_.particles);  // its confining loads
    }
    st_ = r.get_value<TriaxialState>("triaxial.state");
    info = sample_info(r.get_value<SampleRecord>("triaxial.sample"));
  }
  std::string resume_note() const override { return st_.stage ? ", deviatoric stage" : ", isotropic stage"; }
  void ready() override {
    area_ = info.area;  // initial cross-section (stresses on it, as the UCS test)
    // The sample proper: a particle membrane's spheres and group come after the sample's.
    n_sample_ = lat_.sample_particles(sys);
    sample_particles = n_sample_;
    sample_groups = sys.materials.groups() - (kind_ == LateralKind::ParticleMembrane ? 1 : 0);
    vtk_membrane = kind_ == LateralKind::Membrane;
    columns = triaxial_columns(sys.materials, sample_groups);
    const std::vector<std::string> iso_cols = {"step", "time_s", "axial_stress_Pa", "confinement_Pa", "unbalanced_force_ratio"};
    if (opt.resume) iso_.reopen(opt.out_dir / "isotropic.csv", iso_cols, static_cast<std::size_t>(st_.iso_rows));
    else iso_.open(opt.out_dir / "isotropic.csv", iso_cols);
  }
  bool on_curve() const override { return st_.stage == 1; }
  // At most the isotropic cap, then the platens (v each) to the strain cap: max_strain h / (2 v dt).
  double planned_steps() const override {
    return static_cast<double>(iso_max_) + cfg.real("triaxial.max_strain") * info.height /
                                               (2 * cfg.real("triaxial.platen_velocity") * sys.settings.dt);
  }
  void advance(long steps) override {
    const std::size_t cyl = lat_.cylinder_wall;  // the rigid cylinder is wall 2 (after the platens)
    // The stage changes only in measure(): fixed for these steps (kept in registers).
    const bool iso = st_.stage == 0, cylinder = kind_ == LateralKind::RigidCylinder;
    const bool pm_limit = iso && kind_ == LateralKind::ParticleMembrane;
    for (long k = 0; k < steps; ++k) {  // servos act every step
      if (iso) servo_platens(sys, p_, area_, servo_, n_sample_);
      if (cylinder) servo_cylinder(sys, cyl, p_, servo_);
      sys.step();
      if (pm_limit) dem::limit_particle_membrane_speed(sys.particles, lat_.particles, servo_.v_max);
    }
  }
  DemRowReport measure() override {
    const Real axial = platen_stress(sys, area_, n_sample_);
    const Real conf = applied_confinement(sys, lat_);
    status.clear();
    if (st_.stage == 0) return isotropic_row(axial, conf);
    const Real h = sys.walls[1].point.z() - sys.walls[0].point.z();
    const Real ea = (st_.h_dev0 - h) / st_.h_dev0;
    const Real ev = (st_.v_dev0 - enclosed_volume(sys, lat_)) / st_.v_dev0;
    const Real el = 0.5 * (ev - ea);  // negative when bulging, as fit_elastic expects
    const Real diff = axial - p_;
    row = {static_cast<double>(sys.step_count), sys.time, ea, axial, diff, conf, el, ev,
           static_cast<double>(sys.cracks.tensile), static_cast<double>(sys.cracks.shear),
           static_cast<double>(sys.cracks.total())};
    for (int a = 0; a < sample_groups; ++a)
      for (int b = a; b < sample_groups; ++b) {
        row.push_back(static_cast<double>(sys.cracks.count(a, b, 1)));
        row.push_back(static_cast<double>(sys.cracks.count(a, b, 2)));
      }
    std::size_t bonds = intact_bonds(sys);
    if (kind_ == LateralKind::ParticleMembrane) bonds -= dem::particle_membrane_bonds(sys, lat_.particles);
    row.push_back(static_cast<double>(bonds));
    row.push_back(kinetic_energy(sys));
    row.push_back(max_unbalanced_force_ratio(sys));
    if (diff > st_.peak_diff) st_.conf_at_peak = conf;  // the loop records the peak itself
    fmt::format_to(std::back_inserter(status), "strain {:.3f}%  q {:.3f} MPa  confinement {:.3f} MPa  cracks {}", 100 * ea,
                   1e-6 * diff, 1e-6 * conf, sys.cracks.total());
    return {true, ea, diff, el};
  }
  DemRowReport isotropic_row(Real axial, Real conf);
  void end_isotropic(Real axial, Real conf);
  void close_files() override { iso_.close(); }
  void summarize(nlohmann::json& j, const DemOutcome& out) override;
  void plots() override { make_plots(opt.out_dir, cfg); }
  void report(const DemOutcome& out) override {
    log::info("triaxial sigma3 = {:.3f} MPa: {}, {}, cracks {} ({} tensile, {} shear); {}", 1e-6 * p_,
              out.no_peak.empty() ? fmt::format("peak differential stress {:.3f} MPa at axial strain {:.3f}%",
                                                1e-6 * st_.peak_diff, 100 * st_.strain_at_peak)
                                  : std::string("no peak"),
              out.fit.ok() ? fmt::format("E = {:.3f} GPa, nu = {:.3f}", 1e-9 * out.fit.youngs_modulus, out.fit.poisson_ratio)
                           : std::string("no E or nu"),
              sys.cracks.total(), sys.cracks.tensile, sys.cracks.shear, out.stop_reason);
  }

  const Real p_;
  const ServoSettings servo_;
  const long every_, iso_max_;
  const Real iso_tol_, iso_ubf_;
  Lateral lat_;
  LateralKind kind_;
  TriaxialState st_;
  int iso_ok_rows_ = 0;
  Real area_ = 0;
  std::size_t n_sample_ = 0;
  CsvWriter iso_;
};

DemRowReport TriaxialRun::isotropic_row(Real axial, Real conf) {
  st_.iso_steps += every_;
  // A particle membrane's forces are constant, so there is no lateral servo to wait for, and
  // its reported confinement follows its own radius. Its stage waits instead until its spheres
  // have arrived and settled: the ratio over all particles, sample and spheres. That ratio
  // levels off near 0.02 as the spheres keep creeping into the sample's surface hollows, so its
  // limit stays at 0.05 (the sample-only ratio falls below 0.01 before the spheres even touch).
  const bool pm = kind_ == LateralKind::ParticleMembrane;
  const Real ubf = pm ? max_unbalanced_force_ratio(sys) : max_unbalanced_force_ratio(sys, n_sample_);
  iso_.row({static_cast<double>(sys.step_count), sys.time, axial, conf, ubf});
  ++st_.iso_rows;
  // Converged when both boundary stresses have stayed within the tolerance for 5 rows and the
  // sample is in equilibrium (its measurement spheres then agree with the boundary).
  const bool lateral_ok = pm || std::abs(conf - p_) <= iso_tol_ * p_;
  const bool ok = std::abs(axial - p_) <= iso_tol_ * p_ && lateral_ok && ubf < (pm ? std::max(iso_ubf_, 0.05) : iso_ubf_);
  iso_ok_rows_ = ok ? iso_ok_rows_ + 1 : 0;
  fmt::format_to(std::back_inserter(status), "isotropic: platens {:.3f} MPa, confinement {:.3f} MPa (target {:.3f})",
                 1e-6 * axial, 1e-6 * conf, 1e-6 * p_);
  DemRowReport r;
  r.fraction = std::min(1.0, static_cast<double>(st_.iso_steps) / iso_max_);
  if (iso_ok_rows_ >= 5 || st_.iso_steps >= iso_max_) end_isotropic(axial, conf);
  return r;
}

// The isotropic stage's record (boundary, measurement spheres, whole sample), then the
// deviatoric stage starts.
void TriaxialRun::end_isotropic(Real axial, Real conf) {
  st_.iso_converged = iso_ok_rows_ >= 5;
  if (!st_.iso_converged)
    log::warn("isotropic stage did not converge in {} steps (platens {:.3f} MPa, confinement {:.3f} MPa, target "
              "{:.3f} MPa); continuing. Raise triaxial.isotropic_max_steps or triaxial.servo_velocity",
              st_.iso_steps, 1e-6 * axial, 1e-6 * conf, 1e-6 * p_);
  st_.iso_axial = axial;
  st_.iso_conf = conf;
  const auto spheres = measure_spheres(sys, info, sys.walls[0].point.z(), sys.walls[1].point.z(),
                                       cfg.real("triaxial.measurement_sphere_radius"), n_sample_);
  st_.iso_sphere_error = 0;
  {  // By equilibrium the whole sample's average stress equals the boundary stresses.
    const std::size_t n = n_sample_;
    const Mat3 w = average_stress_of(sys, [n](Index i) { return static_cast<std::size_t>(i) < n; }, enclosed_volume(sys, lat_));
    st_.whole_axial = -w(2, 2);
    st_.whole_lateral = -0.5 * (w(0, 0) + w(1, 1));
  }
  for (std::size_t s = 0; s < 3; ++s) {
    st_.sphere_axial[s] = spheres[s].axial;
    st_.sphere_lateral[s] = spheres[s].lateral;
    st_.sphere_particles[s] = spheres[s].particles;
    st_.sphere_porosity[s] = spheres[s].porosity;
    st_.iso_sphere_error = std::max({st_.iso_sphere_error, std::abs(spheres[s].axial - axial) / axial,
                                     std::abs(spheres[s].lateral - conf) / conf});
  }
  log::info("isotropic stage: {} steps; platens {:.3f} MPa, confinement {:.3f} MPa; measurement spheres: axial "
            "{:.3f}/{:.3f}/{:.3f} MPa, lateral {:.3f}/{:.3f}/{:.3f} MPa; largest deviation from the boundary {:.1f}% "
            "({} 5%)",
            st_.iso_steps, 1e-6 * axial, 1e-6 * conf, 1e-6 * st_.sphere_axial[0], 1e-6 * st_.sphere_axial[1],
            1e-6 * st_.sphere_axial[2], 1e-6 * st_.sphere_lateral[0], 1e-6 * st_.sphere_lateral[1],
            1e-6 * st_.sphere_lateral[2], 100 * st_.iso_sphere_error, st_.iso_sphere_error <= 0.05 ? "within" : "NOT within");
  if (kind_ == LateralKind::ParticleMembrane) {  // the estimate of add_particle_membrane(), now with contacts
    const Real crit = critical_time_step(sys);
    if (sys.settings.dt > crit)
      log::warn("particle membrane: the time step {:.4g} s exceeds the critical step {:.4g} s with the membrane "
                "pressing; lower dem.time_step_safety", sys.settings.dt, crit);
    else
      log::info("particle membrane pressing: critical time step {:.4g} s (time step {:.4g} s)", crit, sys.settings.dt);
  }
  const Real v_platen = cfg.real("triaxial.platen_velocity");
  st_.stage = 1;
  st_.h_dev0 = sys.walls[1].point.z() - sys.walls[0].point.z();
  st_.v_dev0 = enclosed_volume(sys, lat_);
  sys.walls[0].velocity = Vec3(0, 0, v_platen);
  sys.walls[1].velocity = Vec3(0, 0, -v_platen);
  st_.iso_cracks = static_cast<int>(sys.cracks.total());
  begin_curve();  // series.csv, VTK cadence, snapshot, checkpoint
}

void TriaxialRun::summarize(nlohmann::json& j, const DemOutcome& out) {
  j["lateral"] = cfg.string("triaxial.lateral");
  j["confining_pressure_Pa"] = p_;
  auto at_peak = [&](Real v) { return out.no_peak.empty() ? nlohmann::json(v) : nlohmann::json(nullptr); };
  j["peak_differential_stress_Pa"] = at_peak(st_.peak_diff);
  j["peak_axial_stress_Pa"] = at_peak(st_.peak_diff + p_);
  j["confinement_at_peak_Pa"] = at_peak(st_.conf_at_peak);
  if (!out.no_peak.empty()) {
    j["peak"]["largest_differential_stress_Pa"] = st_.peak_diff;
    log::warn("no peak differential stress (null in summary.json): {}", out.no_peak);
  }
  // The peak among rows near equilibrium (a crack burst's one-row spike is not a strength).
  j["peak"]["quasi_static"] =
      out.no_peak.empty() ? quasi_static_peak_json("axial_strain") : nullptr;
  put_elastic_fit(j, out.fit, "least squares on the pre-peak differential stress between 20% and 50% of its peak");
  nlohmann::json spheres = nlohmann::json::array();
  for (int s = 0; s < 3; ++s)
    spheres.push_back({{"axial_Pa", st_.sphere_axial[s]}, {"lateral_Pa", st_.sphere_lateral[s]},
                       {"particles", st_.sphere_particles[s]}, {"porosity", st_.sphere_porosity[s]}});
  j["isotropic_stage"] = {{"steps", st_.iso_steps},
                          {"converged", st_.iso_converged != 0},
                          {"platen_stress_Pa", st_.iso_axial},
                          {"confinement_Pa", st_.iso_conf},
                          {"cracks", st_.iso_cracks},
                          {"measurement_spheres", spheres},
                          {"whole_sample_axial_Pa", st_.whole_axial},
                          {"whole_sample_lateral_Pa", st_.whole_lateral},
                          {"sphere_radius_fraction", cfg.real("triaxial.measurement_sphere_radius")},
                          {"largest_sphere_deviation", st_.iso_sphere_error},
                          {"spheres_within_5_percent", st_.iso_sphere_error <= 0.05}};
  if (dem::membrane_of(sys)) {
    const auto& m = *dem::membrane_of(sys);
    std::vector<Real> rad(m.settings().n_z + 1), z(m.settings().n_z + 1);
    m.radial_profile(rad, z);
    j["membrane"] = {{"elements", m.element_count()}, {"n_theta", m.settings().n_theta}, {"n_z", m.settings().n_z},
                     {"ring_radius_m", rad}, {"ring_z_m", z}};
  }
  if (kind_ == LateralKind::ParticleMembrane) {
    const auto& l = lat_.particles;
    std::vector<Real> rad(static_cast<std::size_t>(l.n_z)), z(rad.size());
    dem::particle_membrane_profile(sys.particles, l, rad, z);
    j["particle_membrane"] = {{"particles", l.count()},
                              {"n_theta", l.n_theta},
                              {"n_z", l.n_z},
                              {"particle_radius_m", l.particle_radius},
                              {"initial_centre_radius_m", l.centre_radius},
                              {"initial_inner_radius_m", l.inner_radius()},
                              {"force_per_particle_N", l.force},
                              {"total_force_N", l.total_force()},
                              {"bonds", dem::particle_membrane_bonds(sys, l)},
                              {"inertial_mass_factor", l.mass_factor},
                              {"ring_centre_radius_m", rad},
                              {"ring_z_m", z}};
  }
}

RunStatus run(const Config& cfg, const RunOptions& opt) { return TriaxialRun(cfg, opt).run(); }

}  // namespace

Driver triaxial_driver() {
  return Driver{"triaxial",
                "triaxial compression in a flexible membrane, rigid cylinder or particle membrane (isotropic stage, then "
                "deviatoric loading)",
                declare, run, validate};
}

}  // namespace ff::drivers
