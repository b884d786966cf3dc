#include "drivers/sedimentation/sedimentation_driver.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <memory>

#include "core/error.hpp"
#include "core/log.hpp"
#include "core/progress.hpp"
#include "coupling/dem_time_step.hpp"
#include "coupling/sedimentation/settling_fluid.hpp"
#include "dem/dem_checkpoint.hpp"
#include "dem/dem_output.hpp"
#include "drivers/run_control.hpp"
#include "drivers/run_estimate.hpp"
#include "drivers/run_record.hpp"
#include "drivers/summary_values.hpp"
#include "fracflow/version.hpp"
#include "io/checkpoint.hpp"
#include "io/csv.hpp"
#include "io/json_out.hpp"
#include "io/plot.hpp"
#include "io/pvd.hpp"

namespace fs = std::filesystem;

namespace ff::drivers {
namespace {

constexpr const char* kName = "sedimentation";

void declare(ParamTable& t) {
  t.string("lbm.lattice", "D2Q9", "D2Q9: disks of unit thickness in the x-y plane, gravity along -y; D3Q19: spheres, "
                                  "gravity along -z")
      .one_of({"D2Q9", "D3Q19"});
  t.string("lbm.precision", "double", "storage and arithmetic precision of the populations").one_of({"double", "float"});
  t.real("lbm.dx", 1e-4, "m", "lattice spacing (cells across a particle: its diameter / dx; keep it >= 8)").positive();
  t.real("lbm.psm_refresh", 0.0, "cells",
         "keep the particles' solid fractions while every particle stays within this distance of where they were "
         "computed (velocities are taken every step); 0: recompute every step (docs/lbm.md, \"Refresh distance\")")
      .range(0, 0.5);
  t.real_list("box.size", {0.02, 0.08}, "m", "box [0, Lx] x [0, Ly] (x [0, Lz] in 3D): walls on every side, no slip")
      .size_between(2, 3);
  t.real("box.gravity", 9.81, "m/s^2", "gravity, along -y in 2D and -z in 3D").non_negative();
  t.real("fluid.density", 1000, "kg/m^3", "fluid density").positive();
  t.real("fluid.viscosity", 1e-6, "m^2/s", "kinematic viscosity (set this or fluid.dynamic_viscosity)").positive();
  t.real("fluid.dynamic_viscosity", 0.0, "Pa s", "dynamic viscosity; replaces fluid.viscosity when > 0").non_negative();
  t.real("fluid.tau", 0.0, "-",
         "relaxation time: LBM step dt = (tau - 1/2) dx^2 / (3 nu) (set exactly one of fluid.tau, fluid.time_step, "
         "fluid.sound_speed, fluid.bulk_modulus; 0: not set)")
      .non_negative();
  t.real("fluid.time_step", 0.0, "s", "LBM step (0: not set)").non_negative();
  t.real("fluid.sound_speed", 0.0, "m/s",
         "lattice sound speed c_s = dx / (sqrt(3) dt): fixes the step; the fluid's bulk modulus is rho c_s^2 (0: not set)")
      .non_negative();
  t.real("fluid.bulk_modulus", 0.0, "Pa", "effective bulk modulus K_eff = rho c_s^2: fixes the step (0: not set)")
      .non_negative();
  t.real("fluid.background_pressure", 0.0, "Pa",
         "pressure p0 carried outside the populations: p = p0 + K_eff (rho_lb - 1) (docs/coupling.md); at most 1 GPa "
         "(beyond, p0 + K_eff (rho_lb - 1) loses the flow's pressure differences to round-off)")
      .non_negative()
      .at_most(1e9);
  t.real("fluid.reference_velocity", 0.0, "m/s",
         "expected largest speed, for the Mach-number check U / c_s (0: the Stokes settling speed of the largest "
         "particle, capped by its free-fall speed sqrt(2 g d))")
      .non_negative();
  t.real_list("particles.x", {0.0099, 0.01}, "m", "particle centres, x").size_between(1, 1000);
  t.real_list("particles.y", {0.072, 0.068}, "m", "particle centres, y").size_between(1, 1000);
  t.real_list("particles.z", {}, "m", "particle centres, z (3D only)").size_between(0, 1000);
  t.real_list("particles.radius", {0.001}, "m", "radii: one value for all or one per particle").size_between(1, 1000);
  t.real("particles.density", 1010, "kg/m^3", "solid density").positive();
  t.real("dem.contact_modulus", 1e6, "Pa", "linear contact modulus (particle-particle and particle-wall)").positive();
  t.real("dem.friction", 0.1, "-", "contact friction coefficient").non_negative();
  t.real("dem.damping_ratio", 0.3, "-", "normal viscous damping of contacts, fraction of critical").range(0, 1);
  t.real("dem.time_step_safety", 0.2, "-", "DEM step = this x the critical contact step (sub-cycled in the LBM step)")
      .open_range(0, 1);
  t.real("dem.time_step", 0.0, "s",
         "DEM step wanted (0: dem.time_step_safety x the critical step); either way it is rounded down to the LBM step / n")
      .non_negative();
  t.real("run.end_time", 5.0, "s", "simulated time").positive();
  t.real("reference.terminal_velocity", 0.0, "m/s",
         "measured terminal velocity to compare with (summary.json: error of the largest settling speed; 0: none)")
      .non_negative();
  t.integer("output.samples", 500, "-", "rows of series.csv over run.end_time").at_least(1);
  t.integer("output.snapshots", 20, "-", "VTK snapshots over run.end_time (plus the first)").non_negative();
}

int dim_of(const Config& cfg) { return cfg.string("lbm.lattice") == "D3Q19" ? 3 : 2; }

coupling::FluidSpec fluid_spec(const Config& cfg) {
  coupling::FluidSpec s;
  s.density = cfg.real("fluid.density");
  s.viscosity = cfg.real("fluid.viscosity");
  s.dynamic_viscosity = cfg.real("fluid.dynamic_viscosity");
  const double nu = s.dynamic_viscosity > 0 ? s.dynamic_viscosity / s.density : s.viscosity;
  s.dx = cfg.real("lbm.dx");
  s.dx_key = "lbm.dx";
  s.tau = cfg.real("fluid.tau");
  s.time_step = cfg.real("fluid.time_step");
  s.sound_speed = cfg.real("fluid.sound_speed");
  s.bulk_modulus = cfg.real("fluid.bulk_modulus");
  s.background_pressure = cfg.real("fluid.background_pressure");
  s.reference_velocity = cfg.real("fluid.reference_velocity");
  if (s.reference_velocity == 0) {  // Stokes settling speed of the largest particle, capped by free fall
    const auto& r = cfg.real_list("particles.radius");
    const double a = *std::max_element(r.begin(), r.end()), g = cfg.real("box.gravity");
    const double drho = std::abs(cfg.real("particles.density") - s.density);
    const double stokes = 2.0 / 9.0 * drho * g * a * a / (s.density * nu);
    s.reference_velocity = std::min(stokes, std::sqrt(2 * g * 2 * a));
  }
  return s;
}

struct Geometry {
  int dim = 2;
  int n[3] = {1, 1, 1};
  std::vector<Vec3> centre;
  std::vector<double> radius;
};

coupling::SettlingBox box_of(const Config& cfg, const Geometry& g) {
  coupling::SettlingBox b;
  b.dim = g.dim;
  b.double_precision = cfg.string("lbm.precision") == "double";
  b.cells = {g.n[0], g.n[1], g.dim == 3 ? g.n[2] : 1};
  b.psm_refresh = cfg.real("lbm.psm_refresh");
  return b;
}

// The checks `fracflow check` makes too.
Geometry validate_geometry(const Config& cfg) {
  Geometry g;
  g.dim = dim_of(cfg);
  const auto& L = cfg.real_list("box.size");
  if (int(L.size()) != g.dim)
    cfg.fail("box.size", fmt::format("has {} values; a {} lattice needs {} (Lx, Ly{})", L.size(),
                                     cfg.string("lbm.lattice"), g.dim, g.dim == 3 ? ", Lz" : ""));
  const double dx = cfg.real("lbm.dx");
  for (int a = 0; a < g.dim; ++a) {
    const double c = L[std::size_t(a)] / dx;
    if (!(c < coupling::max_lattice_side()))
      cfg.fail("box.size", fmt::format("box.size[{}] = {} m is {:.4g} cells of lbm.dx = {} m; a side needs fewer than 2^30 "
                                       "cells: a smaller box or a coarser lbm.dx",
                                       a, L[std::size_t(a)], c, dx));
    g.n[a] = int(std::lround(c));
    if (std::abs(c - g.n[a]) > 1e-6 * c || g.n[a] < 8)
      cfg.fail("lbm.dx", fmt::format("{} m does not divide box.size[{}] = {} m into a whole number (>= 8) of cells "
                                     "({:.6g})",
                                     dx, a, L[std::size_t(a)], c));
  }
  coupling::check_box_memory(box_of(cfg, g), "a smaller box.size or a coarser lbm.dx");
  const auto &x = cfg.real_list("particles.x"), &y = cfg.real_list("particles.y"), &z = cfg.real_list("particles.z");
  const auto& r = cfg.real_list("particles.radius");
  const std::size_t np = x.size();
  if (y.size() != np) cfg.fail("particles.y", fmt::format("has {} values, particles.x {}", y.size(), np));
  if (g.dim == 3 && z.size() != np) cfg.fail("particles.z", fmt::format("has {} values, particles.x {}", z.size(), np));
  if (g.dim == 2 && !z.empty()) cfg.fail("particles.z", "is for 3D (lbm.lattice = \"D3Q19\"); leave it empty in 2D");
  if (r.size() != 1 && r.size() != np)
    cfg.fail("particles.radius", fmt::format("has {} values: give one for all or one per particle ({})", r.size(), np));
  for (std::size_t i = 0; i < np; ++i) {
    const Vec3 c(x[i], y[i], g.dim == 3 ? z[i] : 0.0);
    const double ri = r.size() == 1 ? r[0] : r[i];
    if (!(ri > 0)) cfg.fail("particles.radius", fmt::format("particle {}: radius {} must be positive", i, ri));
    if (2 * ri / dx < 4)
      cfg.fail("lbm.dx", fmt::format("particle {} is {:.3g} cells across (diameter / lbm.dx); at least 4 are needed, "
                                     "8 or more for forces within a few percent",
                                     i, 2 * ri / dx));
    for (int a = 0; a < g.dim; ++a)
      if (c[a] - ri < 0 || c[a] + ri > L[std::size_t(a)])
        cfg.fail(a == 0 ? "particles.x" : a == 1 ? "particles.y" : "particles.z",
                 fmt::format("particle {} (radius {} m) sticks out of the box [0, {}] m", i, ri, L[std::size_t(a)]));
    for (std::size_t j = 0; j < i; ++j)
      if ((c - g.centre[j]).norm() < ri + g.radius[j])
        cfg.fail("particles.x", fmt::format("particles {} and {} overlap", j, i));
    g.centre.push_back(c);
    g.radius.push_back(ri);
  }
  return g;
}

// The particles, walls, contact law and DEM step (the checks `fracflow check` makes too).
void build_dem(const Config& cfg, const Geometry& geo, dem::DemSystem& sys) {
  const int d = geo.dim;
  sys.settings.dim = d;
  sys.settings.local_damping = 0;  // hydrodynamic loads must not be damped
  sys.settings.gravity = -cfg.real("box.gravity") * (geo.dim == 3 ? Vec3::UnitZ() : Vec3::UnitY());
  const double rmin = *std::min_element(geo.radius.begin(), geo.radius.end());
  sys.settings.skin = 0.2 * rmin;
  sys.materials.group_names = {"particle"};
  sys.materials.density = {cfg.real("particles.density")};
  dem::LinearContact::Params lc;
  lc.emod = cfg.real("dem.contact_modulus");
  lc.kratio = 1.5;
  lc.fric = cfg.real("dem.friction");
  sys.materials.contact_params<dem::LinearContact>() = {lc};
  sys.materials.set_bond_law<dem::NoBond>();
  sys.materials.normal_damping_ratio = cfg.real("dem.damping_ratio");
  for (std::size_t i = 0; i < geo.centre.size(); ++i) {
    sys.particles.resize(i + 1);
    sys.particles.pos[i] = geo.centre[i];
    sys.particles.radius[i] = geo.radius[i];
    sys.particles.set_mass_from_density(i, sys.materials.density[0], d);
  }
  const auto& Lb = cfg.real_list("box.size");
  for (int a = 0; a < d; ++a)
    for (int side = 0; side < 2; ++side) {
      dem::Wall w;
      w.name = fmt::format("wall {}{}", "xyz"[a], side ? '+' : '-');
      w.point = Vec3::Zero();
      w.point[a] = side ? Lb[std::size_t(a)] : 0.0;
      w.normal = Vec3::Zero();
      w.normal[a] = side ? -1.0 : 1.0;
      w.friction = cfg.real("dem.friction");
      sys.walls.push_back(w);
    }
  sys.initialise();
  const double dt_auto = coupling::coupled_dem_time_step(sys, cfg.real("dem.time_step_safety"));
  const double dt_user = cfg.real("dem.time_step");
  if (dt_user > dt_auto)
    cfg.fail("dem.time_step", fmt::format("{:.4g} s is above the stable limit {:.4g} s (dem.time_step_safety {} x the "
                                           "critical contact step); set 0 for automatic or a value <= {:.4g}",
                                           dt_user, dt_auto, cfg.real("dem.time_step_safety"), dt_auto));
  sys.settings.dt = dt_user > 0 ? dt_user : dt_auto;
}

void validate(const Config& cfg) {
  dem::DemSystem probe;
  build_dem(cfg, validate_geometry(cfg), probe);  // the DEM step against its stability limit
  const auto sc = coupling::derive_scales(fluid_spec(cfg));  // throws InputError naming fluid.*
  log::info("{}", sc.describe());  // `fracflow check` shows the derived step, sound speed, K_eff and Mach number
  for (auto& w : sc.warnings) log::warn("{}", w);
}

struct State {  // runner state saved with the populations and the DEM
  std::int64_t step = 0, vtk_index = 0, finished = 0, columns = 0;
};

}  // namespace
}  // namespace ff::drivers

namespace ff {
template <> struct is_checkpoint_pod<drivers::State> : std::true_type {};
}

namespace ff::drivers {
namespace {

class SedimentationRun {
 public:
  SedimentationRun(const Config& cfg, const RunOptions& opt)
      : cfg_(cfg), opt_(opt), geo_(validate_geometry(cfg)), sc_(coupling::derive_scales(fluid_spec(cfg))) {}
  RunStatus run();

 private:
  void build();
  void write_checkpoint(const fs::path& dir);
  void read_checkpoint();
  void write_vtk();
  void check_particle_speed(long step);
  void summary(double wall_s, long steps);
  Vec3 up() const { return geo_.dim == 3 ? Vec3::UnitZ() : Vec3::UnitY(); }

  const Config& cfg_;
  const RunOptions& opt_;
  Geometry geo_;
  coupling::FluidScales sc_;
  dem::DemSystem dem_;
  std::unique_ptr<coupling::SettlingFluid> fluid_;
  State st_;
  std::vector<std::string> columns_;
  std::vector<double> history_, row_;
  dem::DemVtkWriter dem_vtk_;
  PvdSeries fluid_pvd_;
};

void SedimentationRun::build() {
  build_dem(cfg_, geo_, dem_);
  fluid_ = coupling::make_settling_fluid(box_of(cfg_, geo_), sc_, dem_);
}

void SedimentationRun::write_checkpoint(const fs::path& dir) {
  fs::create_directories(dir);
  CheckpointWriter w(dir / "state.ffcp", /*keep_previous=*/true);
  fluid_->save(w);
  st_.step = fluid_->time_step();
  st_.columns = std::int64_t(columns_.size());
  w.put_value("sed.state", st_);
  w.put("sed.history", history_);
  dem::save_dem(w, dem_);
  w.commit();
}

void SedimentationRun::read_checkpoint() {
  CheckpointReader r = open_checkpoint(opt_.out_dir / "checkpoint" / "state.ffcp");
  st_ = r.get_value<State>("sed.state");
  fluid_->load(r, long(st_.step));
  r.get("sed.history", history_);
  dem::load_dem(r, dem_);
  if (std::size_t(st_.columns) != columns_.size())
    throw InputError(fmt::format("{}: the checkpoint's series has {} columns, this scenario writes {}",
                                 r.path().string(), st_.columns, columns_.size()));
}

// A grain's surface speed is the fluid's there: past the Mach limit the fluid is no longer a weakly
// compressible liquid. The fluid's own check (sampled rows) missed it: a grain driven by a huge
// body force left the box at 1e298 m/s with the fluid at rest.
void SedimentationRun::check_particle_speed(long step) {
  const auto& P = dem_.particles;
  double vmax = 0;
  std::size_t fastest = 0;
  for (std::size_t i = 0; i < P.size(); ++i) {
    const double v = P.vel[i].norm();
    if (!(v <= vmax)) {
      vmax = v;
      fastest = i;
      if (!(v == v)) break;
    }
  }
  const double mach = vmax * std::sqrt(3.0) / sc_.units.velocity_factor();
  if (mach <= coupling::kMaxMach) return;
  write_checkpoint(opt_.out_dir / "checkpoint_failed");
  throw NumericalError(fmt::format(
      "particle {} moves at {:.3g} m/s at step {}: Mach number {:.3g} in the fluid's units (limit {}); lower box.gravity "
      "or the density difference (particles.density, fluid.density), or take a shorter LBM step (fluid.sound_speed "
      "or fluid.time_step)",
      fastest, vmax, step, mach, coupling::kMaxMach));
}

void SedimentationRun::write_vtk() {
  const std::string file = fmt::format("fluid_{:06d}.vti", st_.vtk_index);
  fluid_->write_vti(opt_.out_dir / "vtk" / file);
  fluid_pvd_.add(double(fluid_->time_step()) * sc_.dt(), file);
  dem_vtk_.write(dem_, long(st_.vtk_index), 0.0);
  ++st_.vtk_index;
}

RunStatus SedimentationRun::run() {
  RunControl control(cfg_, opt_);
  build();
  const std::size_t np = dem_.particles.size();
  log::info("lattice {} {} x {} x {} cells ({}), {} particles; DEM step {:.4g} s, {} DEM sub-steps per LBM step",
            fluid_->velocity_set(), geo_.n[0], geo_.n[1], geo_.n[2], cfg_.string("lbm.precision"), np,
            fluid_->dem_dt(), fluid_->sub_steps());
  refuse_endless_run(cfg_.real("run.end_time") / sc_.dt(), "run.end_time, a larger lbm.dx or a shorter LBM step (fluid.time_step, fluid.sound_speed)");
  begin_output(opt_);  // (the fluid's warnings were logged by validate())
  const char* ax = geo_.dim == 3 ? "xyz" : "xy";
  columns_ = {"step", "time_s", "max_mach"};
  for (std::size_t i = 0; i < np; ++i) {
    for (const char* a = ax; *a; ++a) columns_.push_back(fmt::format("p{}_{}_m", i, *a));
    for (const char* a = ax; *a; ++a) columns_.push_back(fmt::format("p{}_v{}_m_per_s", i, *a));
    for (const char* a = ax; *a; ++a) columns_.push_back(fmt::format("p{}_F{}_N", i, *a));
    columns_.push_back(fmt::format("p{}_wz_rad_per_s", i));
  }
  const long steps_total = std::max(1L, std::lround(cfg_.real("run.end_time") / sc_.dt()));
  const long sample_every = std::max(1L, steps_total / cfg_.integer("output.samples"));
  const long n_samples = (steps_total + sample_every - 1) / sample_every;
  const long snaps = cfg_.integer("output.snapshots");
  const long vtk_every = cfg_.boolean("output.vtk") && snaps > 0 ? std::max(1L, n_samples / snaps) : 0;
  history_.reserve(std::size_t(n_samples + 1) * columns_.size());
  row_.reserve(columns_.size());
  const fs::path cp_dir = opt_.out_dir / "checkpoint";
  CsvWriter series;
  if (opt_.resume) {
    read_checkpoint();
    if (st_.finished) {
      log::info("this run had already finished; nothing to resume");
      return RunStatus::Finished;
    }
    if (control.resumed_at_max_steps(fluid_->time_step())) return RunStatus::Interrupted;
    series.reopen(opt_.out_dir / "series.csv", columns_, history_.size() / columns_.size());
    log::info("resuming at step {} (t = {:.6g} s)", fluid_->time_step(), double(fluid_->time_step()) * sc_.dt());
  } else {
    series.open(opt_.out_dir / "series.csv", columns_);
  }
  const double t_now = double(fluid_->time_step()) * sc_.dt();
  if (vtk_every > 0) {
    fluid_pvd_.open(opt_.out_dir / "vtk" / "fluid.pvd", opt_.resume, t_now);
    dem_vtk_.open(opt_.out_dir / "vtk", opt_.resume, t_now);
    if (!opt_.resume) write_vtk();
  }
  if (!opt_.resume) {
    write_checkpoint(cp_dir);
    control.checkpoint_written();
  }
  Progress progress(kName, opt_.progress_interval_s);
  RunStatus status = RunStatus::Finished;
  const auto t0 = std::chrono::steady_clock::now();
  const long first = fluid_->time_step();
  auto stop_now = [&](long t) {
    if (const std::string why = control.stop_reason(t); !why.empty()) {
      write_checkpoint(cp_dir);
      log_interruption(why, t);
      status = RunStatus::Interrupted;
      return true;
    }
    return false;
  };
  const auto& P = dem_.particles;
  while (fluid_->time_step() < steps_total && status == RunStatus::Finished) {
    const long t = fluid_->time_step();
    if ((t % 64 == 0 || t == opt_.max_steps) && stop_now(t)) break;
    const bool sample = (t + 1) % sample_every == 0 || t + 1 == steps_total;
    fluid_->step(sample);
    check_particle_speed(t + 1);
    if (!sample) {
      if (control.checkpoint_due()) {
        write_checkpoint(cp_dir);
        control.checkpoint_written();
      }
      continue;
    }
    // The sampled fields are those of the start of this step; the particles have moved on.
    const double mach = fluid_->max_speed() * std::sqrt(3.0);
    if (!(mach == mach) || mach > coupling::kMaxMach) {
      write_checkpoint(opt_.out_dir / "checkpoint_failed");
      throw NumericalError(fmt::format("the fluid became unstable at step {}: Mach number {:.3g} (limit {}); take a "
                                       "shorter LBM step (a higher fluid.sound_speed or fluid.bulk_modulus, a smaller "
                                       "fluid.time_step or fluid.tau; with fluid.tau set, a finer lbm.dx also shortens "
                                       "it)",
                                       t + 1, mach, coupling::kMaxMach));
    }
    row_.clear();
    row_.push_back(double(t + 1));
    row_.push_back(dem_.time);
    row_.push_back(mach);
    for (std::size_t i = 0; i < np; ++i) {
      for (int a = 0; a < geo_.dim; ++a) row_.push_back(P.pos[i][a]);
      for (int a = 0; a < geo_.dim; ++a) row_.push_back(P.vel[i][a]);
      for (int a = 0; a < geo_.dim; ++a) row_.push_back(fluid_->hydro_force()[i][a]);
      row_.push_back(P.omega[i].z());
    }
    series.row(row_);
    history_.insert(history_.end(), row_.begin(), row_.end());
    const long k = long(history_.size() / columns_.size());
    if (vtk_every > 0 && (k % vtk_every == 0 || fluid_->time_step() == steps_total)) write_vtk();
    if (control.checkpoint_due()) {
      write_checkpoint(cp_dir);
      control.checkpoint_written();
    }
    progress.update(fluid_->time_step(), dem_.time, double(fluid_->time_step()) / double(steps_total),
                    fmt::format("v0 = {:.4g} m/s", P.vel[0].dot(up())));
  }
  series.close();
  if (status == RunStatus::Interrupted) return status;
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  summary(wall, fluid_->time_step() - first);
  st_.finished = 1;
  write_checkpoint(cp_dir);
  return status;
}

void SedimentationRun::summary(double wall_s, long steps) {
  const std::size_t nc = columns_.size(), rows = history_.size() / nc, np = dem_.particles.size();
  const int D = geo_.dim;
  auto at = [&](std::size_t r, std::size_t c) { return history_[r * nc + c]; };
  auto col = [&](std::size_t i, int what, int a) { return 3 + i * std::size_t(3 * D + 1) + std::size_t(what * D + a); };
  nlohmann::json j;
  j["fracflow_version"] = kVersion;
  j["driver"] = kName;
  j["title"] = cfg_.string("title");
  j["units"] = {{"dx_m", sc_.units.dx()},
                {"lbm_dt_s", sc_.dt()},
                {"dem_dt_s", fluid_->dem_dt()},
                {"dem_sub_steps", fluid_->sub_steps()},
                {"tau", sc_.units.tau()},
                {"sound_speed_m_per_s", sc_.sound_speed},
                {"effective_bulk_modulus_Pa", sc_.bulk_modulus},
                {"mach_reference", sc_.mach},
                {"background_pressure_Pa", sc_.background_pressure},
                {"fixed_by", sc_.fixed_by}};
  j["lattice"] = {{"velocity_set", fluid_->velocity_set()}, {"cells", {geo_.n[0], geo_.n[1], geo_.n[2]}}};
  j["steps"] = fluid_->time_step();
  j["simulated_time_s"] = dem_.time;
  j["wall_time_s"] = wall_s;
  j["threads"] = opt_.threads;
  // Where the wall time went (machine-dependent; keys ending in _seconds).
  j["coupling_seconds"] = fluid_->times().coupling;
  j["lbm_seconds"] = fluid_->times().lbm;
  j["dem_seconds"] = fluid_->times().dem;
  j["mlups"] = wall_s > 0 ? double(geo_.n[0]) * geo_.n[1] * geo_.n[2] * double(steps) / wall_s * 1e-6 : 0.0;
  nlohmann::json res = nlohmann::json::object(), parts = nlohmann::json::array();
  const int g_axis = D - 1;  // gravity along -y (2D) or -z (3D)
  double mach_max = 0;
  for (std::size_t r = 0; r < rows; ++r) mach_max = std::max(mach_max, at(r, 2));
  res["max_mach"] = mach_max;
  const double mu = sc_.units.nu() * sc_.units.rho();
  for (std::size_t i = 0; i < np; ++i) {
    double vmax = 0, tmax = 0;
    for (std::size_t r = 0; r < rows; ++r)
      if (-at(r, col(i, 1, g_axis)) > vmax) {
        vmax = -at(r, col(i, 1, g_axis));
        tmax = at(r, 1);
      }
    nlohmann::json p;
    p["radius_m"] = dem_.particles.radius[i];
    p["final_position_m"] = {dem_.particles.pos[i].x(), dem_.particles.pos[i].y(), dem_.particles.pos[i].z()};
    p["max_settling_speed_m_per_s"] = vmax;
    p["time_of_max_settling_speed_s"] = tmax;
    p["reynolds_at_max_speed"] = sc_.units.rho() * vmax * 2 * dem_.particles.radius[i] / mu;
    parts.push_back(p);
  }
  res["particles"] = parts;
  if (cfg_.real("reference.terminal_velocity") > 0 && np >= 1) {
    const double ref = cfg_.real("reference.terminal_velocity"), v = parts[0]["max_settling_speed_m_per_s"];
    res["reference_terminal_velocity_m_per_s"] = ref;
    res["terminal_velocity_error"] = v / ref - 1;
  }
  if (np >= 2 && rows > 0) {
    // Drafting, kissing, tumbling of particles 0 (upper at the start) and 1: the smallest gap
    // (kissing) and the first time particle 0 is below particle 1 (tumbling).
    const double r0 = dem_.particles.radius[0], r1 = dem_.particles.radius[1];
    double gap_min = 1e300, t_gap = 0, t_swap = -1;
    const bool upper0 = geo_.centre[0][g_axis] > geo_.centre[1][g_axis];
    for (std::size_t r = 0; r < rows; ++r) {
      Vec3 d = Vec3::Zero();
      for (int a = 0; a < D; ++a) d[a] = at(r, col(0, 0, a)) - at(r, col(1, 0, a));
      const double gap = d.norm() - r0 - r1;
      if (gap < gap_min) {
        gap_min = gap;
        t_gap = at(r, 1);
      }
      if (t_swap < 0 && (d[g_axis] > 0) != upper0) t_swap = at(r, 1);
    }
    res["pair"] = {{"min_gap_m", gap_min},
                   {"min_gap_over_diameter", gap_min / (2 * r0)},
                   {"time_of_min_gap_s", t_gap},
                   {"time_order_swapped_s", t_swap < 0 ? nlohmann::json(nullptr) : nlohmann::json(t_swap)}};
  }
  j["results"] = res;
  j["parameters"] = params_json(cfg_);
  add_run_record(j, opt_);
  write_json_atomic(opt_.out_dir / "summary.json", j);
  if (!cfg_.boolean("output.plots") || rows == 0) return;
  fs::create_directories(opt_.out_dir / "plots");
  const fs::path csv = opt_.out_dir / "series.csv";
  std::vector<PlotJob> jobs;
  const std::string up_axis = D == 3 ? "z" : "y";
  {
    PlotSpec s;
    s.title = "settling speed";
    s.xlabel = "t [s]";
    s.ylabel = fmt::format("v_{} [m/s]", up_axis);
    s.x = "time_s";
    for (std::size_t i = 0; i < np; ++i) s.y.push_back(fmt::format("p{}_v{}_m_per_s", i, up_axis));
    jobs.push_back({csv, opt_.out_dir / "plots" / "velocity.png", s});
  }
  {
    PlotSpec s;  // the trajectory: particle 0 as a line, particle 1 as markers
    s.title = np >= 2 ? "trajectories (particle 1: markers)" : "trajectory";
    s.xlabel = "x [m]";
    s.ylabel = fmt::format("{} [m]", up_axis);
    s.x = "p0_x_m";
    s.y = {fmt::format("p0_{}_m", up_axis)};
    if (np >= 2) {
      s.reference_csv = csv;
      s.ref_x = "p1_x_m";
      s.ref_y = fmt::format("p1_{}_m", up_axis);
      s.ref_label = "particle 1";
    }
    jobs.push_back({csv, opt_.out_dir / "plots" / "trajectory.png", s});
  }
  {
    PlotSpec s;
    s.title = "positions";
    s.xlabel = "t [s]";
    s.ylabel = "[m]";
    s.x = "time_s";
    for (std::size_t i = 0; i < np && i < 4; ++i) {
      s.y.push_back(fmt::format("p{}_x_m", i));
      s.y.push_back(fmt::format("p{}_{}_m", i, up_axis));
    }
    jobs.push_back({csv, opt_.out_dir / "plots" / "positions.png", s});
  }
  plot_series(jobs);
}

RunStatus run(const Config& cfg, const RunOptions& opt) {
  validate(cfg);
  SedimentationRun r(cfg, opt);
  return r.run();
}

}  // namespace

Driver sedimentation_driver() {
  return {kName,
          "particles settling in a closed box of fluid (DEM-LBM coupling, partially saturated cells): drafting-"
          "kissing-tumbling of disks (2D), a settling sphere (3D)",
          declare, run, validate};
}

}  // namespace ff::drivers
