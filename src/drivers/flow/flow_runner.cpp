#include "drivers/flow/flow_runner.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>

#include "core/error.hpp"
#include "drivers/flow/probes.hpp"
#include "drivers/flow/steady.hpp"
#include "core/log.hpp"
#include "core/progress.hpp"
#include "drivers/run_control.hpp"
#include "drivers/run_record.hpp"
#include "fracflow/version.hpp"
#include "drivers/run_estimate.hpp"
#include "drivers/summary_values.hpp"
#include "io/checkpoint.hpp"
#include "io/csv.hpp"
#include "io/json_out.hpp"
#include "io/plot.hpp"
#include "io/pvd.hpp"
#include "io/vtk.hpp"
#include "lbm/lattice_budget.hpp"

namespace fs = std::filesystem;

namespace ff::drivers {

void declare_lbm_params(ParamTable& t, const LbmDefaults& d) {
  t.string("lbm.lattice", "D2Q9", "velocity set; D3Q19 extrudes the 2D case along a periodic z axis").one_of({"D2Q9", "D3Q19"});
  // A fallback: flow/cylinder's duct takes its depth from channel.depth and refuses this key when
  // set, so the saved scenario of a duct run must not set it (resume reads that file).
  t.integer("lbm.depth_cells", 1, "cells", "D3Q19 only: cells along the periodic z axis").range(1, 1 << 20).fallback();
  t.string("lbm.precision", "double", "storage and arithmetic precision of the populations").one_of({"double", "float"});
  t.string("lbm.collision", "trt", "collision: two-relaxation-time (Ginzburg et al. 2008) or BGK").one_of({"trt", "bgk"});
  t.string("lbm.equilibrium", "incompressible",
           "equilibrium: compressible (rho in the momentum terms) or incompressible (He & Luo 1997: rho_0 = 1 there, "
           "so a pressure drop no longer raises the density and dynamic viscosity; removes the O(Ma^2) drag error of "
           "steady flows, docs/lbm.md)")
      .one_of({"compressible", "incompressible"});
  t.real("lbm.trt_magic", 3.0 / 16.0, "-",
         "TRT magic parameter Lambda (3/16 puts bounce-back walls exactly mid-link; 1/4 the most stable; 1/12, 1/6 "
         "cancel other errors)")
      .positive()
      .at_most(1);
  t.real("lbm.tau", d.tau, "-",
         "relaxation time: dt = (tau - 1/2) dx^2 / (3 nu); used when none of lbm.time_step, lbm.mach and "
         "lbm.target_error is set (set at most one of the four)")
      .open_range(0.5, 1e6)
      .fallback();
  t.real("lbm.time_step", 0.0, "s", "time step; tau = 1/2 + 3 nu dt / dx^2 follows (0: not set)").non_negative();
  t.real("lbm.mach", 0.0, "-",
         fmt::format("Mach number Ma = u_lb / c_s of the case's characteristic speed U: dt = Ma c_s dx / U, tau follows; "
                     "expected relative compressibility error of forces and pressures C Ma^2 (C = 1 with the "
                     "compressible equilibrium, 0.1 with the incompressible one, 2.2 for a vortex street with either: "
                     "measured, docs/lbm.md) (0: not set)"))
      .range(0, 1);
  t.real("lbm.target_error", 0.0, "-",
         fmt::format("expected relative compressibility error C Ma^2 (C as for lbm.mach) the run may make: the "
                     "driver picks Ma = sqrt(target / C), then dt and tau as for lbm.mach (0: not set)"))
      .range(0, 1);
  t.integer("lbm.resolution", d.resolution, "cells", "cells across the characteristic length of the case").range(2, 1 << 20);
  t.real("fluid.density", d.density, "kg/m^3", "fluid density").positive();
  t.real("fluid.viscosity", d.viscosity, "m^2/s", "kinematic viscosity").positive();
  t.real("run.end_time", d.end_time, "s", "simulated time at which the run stops").positive();
  t.real("run.steady_tolerance", d.steady_tolerance, "-",
         fmt::format("stop at steady state: once the mean of the monitored result over a window of one period of the "
                     "slowest acoustic mode (4 L / c_s, L the longest non-periodic side; as many whole periods as hold "
                     "{} samples) differs "
                     "(relative) by less than this from the mean {} windows earlier, at every alignment within the last "
                     "window, after the inflow ramp; the result is then within about this of its long-run value if it "
                     "settles with a time constant up to ~{} windows. A vortex street does not stop. 0: run to "
                     "run.end_time",
                     kSteadyMinSamples, kSteadyLag, kSteadyLag))
      .non_negative();
  t.real("run.inflow_ramp_time", d.inflow_ramp_time, "s",
         "inflow velocities rise from zero as sin^2 over this time; 0: full inflow from the start; -1: automatic, "
         "20 domain lengths at the lattice sound speed (5 periods of the slowest acoustic mode between a velocity "
         "inlet and a pressure outlet, which an impulsive start leaves ringing almost undamped)")
      .at_least(-1);
  declare_probe_params(t);
  t.integer("output.samples", 200, "-", "rows of series.csv over run.end_time").at_least(1);
  t.integer("output.snapshots", 10, "-", "VTK snapshots over run.end_time (plus the first and last)").non_negative();
  t.integer("output.checkpoints", 0, "-",
            "extra checkpoints evenly spread over run.end_time (0: none; checkpoints come every "
            "output.checkpoint_wall_interval seconds, at the end and on interruption)")
      .non_negative();
}

FlowUnits make_units(const Config& cfg, double dx, double u, bool unsteady) {
  const double nu = cfg.real("fluid.viscosity"), rho = cfg.real("fluid.density");
  // lbm.tau counts as set when the scenario sets it (its default is a fallback, which a saved
  // scenario.toml keeps as a comment); the other three when they are above 0.
  std::vector<lbm::UnitsMode> set;
  if (cfg.has("lbm.tau")) set.push_back(lbm::UnitsMode::Tau);
  for (auto m : {lbm::UnitsMode::TimeStep, lbm::UnitsMode::Mach, lbm::UnitsMode::TargetError})
    if (cfg.real(lbm::units_mode_key(m)) > 0) set.push_back(m);
  if (set.size() > 1)
    cfg.fail(lbm::units_mode_key(set[1]),
             fmt::format("{} and {} are both set: set at most one of lbm.tau, lbm.time_step, lbm.mach and "
                         "lbm.target_error (each fixes the time step; the others follow from it, the cell size and "
                         "the viscosity)",
                         lbm::units_mode_key(set[0]), lbm::units_mode_key(set[1])));
  FlowUnits f;
  const bool incompressible = cfg.string("lbm.equilibrium") == "incompressible";
  f.coefficient = lbm::compressibility_coefficient(incompressible, unsteady);
  f.error_model = unsteady ? "vortex shedding expected"
                           : fmt::format("{} equilibrium, steady flow", incompressible ? "incompressible" : "compressible");
  f.mode = set.empty() ? lbm::UnitsMode::Tau : set[0];
  f.by_default = set.empty();
  switch (f.mode) {
    case lbm::UnitsMode::Tau: f.units = lbm::Units::from_tau(dx, cfg.real("lbm.tau"), nu, rho); break;
    case lbm::UnitsMode::TimeStep: f.units = lbm::Units::from_time_step(dx, cfg.real("lbm.time_step"), nu, rho); break;
    case lbm::UnitsMode::Mach: f.units = lbm::Units::from_mach(dx, cfg.real("lbm.mach"), u, nu, rho); break;
    case lbm::UnitsMode::TargetError:
      f.units = lbm::Units::from_mach(dx, lbm::mach_for_error(cfg.real("lbm.target_error"), f.coefficient), u, nu, rho);
      break;
  }
  f.mach = f.units.mach(u);
  f.expected_error = lbm::expected_compressibility_error(f.mach, f.coefficient);
  return f;
}

std::string describe_flow_units(const FlowUnits& fu, const FlowCase& fc) {
  const auto& u = fu.units;
  const std::string from = fu.mode != lbm::UnitsMode::Tau ? fmt::format("{}; lbm.tau is not used", fu.key())
                           : fu.by_default                 ? "lbm.tau, its default"
                                                           : "lbm.tau";
  return fmt::format("time step dt = {:.6g} s and relaxation time tau = {:.6g} (from {}), cell size dx = {:.6g} m; Mach "
                     "number {:.3g} of the characteristic speed {:.4g} m/s ({:.4g} lattice units); expected relative "
                     "compressibility error {:.2g} ({} Ma^2: {})",
                     u.dt(), u.tau(), from, u.dx(), fu.mach, fc.characteristic_speed(),
                     u.to_lattice_velocity(fc.characteristic_speed()), fu.expected_error, fu.coefficient, fu.error_model);
}

namespace {
FlowCheckReport* g_check_report = nullptr;
}

FlowCheckReport::FlowCheckReport() { g_check_report = this; }
FlowCheckReport::~FlowCheckReport() { g_check_report = nullptr; }
void FlowCheckReport::append(const std::string& s) {
  if (g_check_report) g_check_report->text_ += s;
}
bool FlowCheckReport::active() { return g_check_report != nullptr; }

namespace {

// Runner state that must survive a restart (next to the populations and the history).
struct RunnerState {
  std::int64_t step = 0;
  std::int64_t vtk_index = 0;
  std::int64_t finished = 0;
  std::int64_t columns = 0;
};

}  // namespace
}  // namespace ff::drivers

namespace ff {
template <> struct is_checkpoint_pod<drivers::RunnerState> : std::true_type {};
}

namespace ff::drivers {
namespace {

template <class L, class T>
class Runner {
 public:
  Runner(const Config& cfg, const RunOptions& opt, FlowCase& fc, std::string_view driver)
      : cfg_(cfg), opt_(opt), fc_(fc), driver_(driver),
        fu_(make_units(cfg, fc.cell_size(), fc.characteristic_speed(), fc.unsteady())), units_(fu_.units),
        probes_(read_probes(cfg, L::D == 3, L::D == 3 ? double(cfg.integer("lbm.depth_cells")) * fc.cell_size() : 0.0),
                fc.cell_size()) {}

  RunStatus run();

 private:
  void build();
  void sample(FlowSample& s);
  void write_vtk(const FlowSample& s);
  void write_checkpoint(const fs::path& dir);
  void read_checkpoint();
  [[noreturn]] void unstable(const std::string& what);
  void summary(const FlowSample& last, const std::string& stop_reason, double loop_seconds, long loop_steps);

  const Config& cfg_;
  const RunOptions& opt_;
  FlowCase& fc_;
  std::string driver_;
  FlowUnits fu_;
  lbm::Units units_;
  Probes probes_;
  double steady_drift_ = -1;  // last drift of the steady-state test (-1: not evaluated)
  DomainSpec dom_;
  std::unique_ptr<lbm::Solver<L, T>> sol_;
  int nz_ = 1;
  RunnerState st_;
  std::vector<double> history_;  // all series rows, flattened (reserved once)
  std::size_t ncols_ = 0;
  PvdSeries pvd_;
  // Output buffers, allocated once (no allocation in the time loop).
  std::vector<double> pressure_;
  std::vector<Vec3> velocity_;
  std::vector<std::uint8_t> solid_;
  std::vector<double> row_;
  double ramp_end_time_ = 0;
};

template <class L, class T>
void Runner<L, T>::build() {
  dom_ = fc_.domain(units_);
  // A 2D description is extruded along a periodic z axis (D3Q19) or has none (D2Q9); a 3D box
  // brings its own depth and z faces.
  const bool box = dom_.is_box();
  if (box && L::D != 3)
    throw InputError(fmt::format("{}: this case builds a 3D box ({} x {} x {} cells); set lbm.lattice = \"D3Q19\"",
                                 driver_, dom_.nx, dom_.ny, dom_.nz));
  nz_ = L::D == 3 ? (box ? dom_.nz : int(cfg_.integer("lbm.depth_cells"))) : 1;
  const bool pz = !box || dom_.periodic[2];
  lbm::check_lattice_memory(dom_.nx, dom_.ny, nz_, L::Q, sizeof(T),
                            L::D == 3 && !box ? "lower lbm.resolution, lbm.depth_cells or the domain's size"
                                              : "lower lbm.resolution or the domain's size");
  lbm::Grid g(L::D, dom_.nx, dom_.ny, nz_, {dom_.periodic[0], dom_.periodic[1], pz});
  lbm::SolverSettings s;
  s.collision = cfg_.string("lbm.collision") == "bgk" ? lbm::CollisionModel::Bgk : lbm::CollisionModel::Trt;
  s.tau = units_.tau();
  s.magic = cfg_.real("lbm.trt_magic");
  s.incompressible = cfg_.string("lbm.equilibrium") == "incompressible";
  s.body_force = dom_.body_force;
  sol_ = std::make_unique<lbm::Solver<L, T>>(g, s);
  for (int f = 0; f < 2 * L::D; ++f)
    if (!g.periodic[f / 2]) sol_->set_face(f, dom_.faces[f]);
  for (auto& o : dom_.objects) {
    const int id = sol_->add_object(o.name, o.scheme, o.center);
    if (o.shape) sol_->add_shape(id, *o.shape);
    for (auto& c : o.cells)
      for (int z = 0; z < nz_; ++z) sol_->set_solid(c[0], c[1], z, id);
  }
  sol_->finalize();
  auto init = dom_.init;
  sol_->initialize([&](int x, int y, int z, double& rho, Vec3& u) {
    if (init) init(x, y, z, rho, u);
  });
  const std::size_t n = std::size_t(dom_.nx) * dom_.ny * nz_;
  pressure_.assign(n, 0.0);
  velocity_.assign(n, Vec3::Zero());
  solid_.assign(n, 0);
}

template <class L, class T>
void Runner<L, T>::sample(FlowSample& s) {
  const auto& g = sol_->grid();
  double umax = 0;
  for (int z = 0; z < nz_; ++z)
    for (int y = 0; y < g.ny; ++y)
      for (int x = 0; x < g.nx; ++x) {
        const std::size_t i = std::size_t(x) + std::size_t(g.nx) * (std::size_t(y) + std::size_t(g.ny) * z);
        const bool solid = sol_->is_solid(x, y, z);
        solid_[i] = solid ? 1 : 0;
        pressure_[i] = solid ? 0.0 : units_.to_si_pressure(sol_->density(x, y, z));
        const Vec3 u = solid ? Vec3::Zero() : sol_->velocity(x, y, z);
        velocity_[i] = units_.to_si_velocity(1.0) * u;
        if (!solid) umax = std::max(umax, u.norm());
      }
  s.step = sol_->time_step();
  s.time = double(s.step) * units_.dt();
  s.nx = g.nx;
  s.ny = g.ny;
  s.nz = nz_;
  s.pressure = std::span<const double>(pressure_);
  s.velocity = std::span<const Vec3>(velocity_);
  s.solid = std::span<const std::uint8_t>(solid_);
  const auto& objs = sol_->objects();
  s.force.resize(dom_.objects.size());
  s.torque.resize(dom_.objects.size());
  // 2D description: loads per unit depth (N/m, N; the extruded depth is nz_ cells). 3D box:
  // total loads (N, N m).
  const bool box = dom_.is_box();
  s.depth_m = box ? nz_ * units_.dx() : 0.0;
  const double fscale = box ? units_.to_si_force(1.0, 3) : units_.to_si_force(1.0, 2) / nz_;
  for (std::size_t k = 0; k < dom_.objects.size(); ++k) {
    const auto& o = objs[lbm::Solver<L, T>::kFirstUserObject + k];
    s.force[k] = fscale * o.force;
    s.torque[k] = fscale * units_.dx() * o.torque;
  }
  for (int f = 0; f < 6; ++f) s.face_force[f] = fscale * objs[f].force;
  s.max_mach = std::sqrt(3.0) * sol_->max_speed();
  s.ramp_end_time = ramp_end_time_;
}

template <class L, class T>
void Runner<L, T>::write_vtk(const FlowSample& s) {
  // The whole box: nx x ny x nz cells (the sample buffers hold all of them).
  const auto& g = sol_->grid();
  const std::string file = fmt::format("flow_{:06d}.vti", st_.vtk_index++);
  const VtkArray arrays[] = {vtk_array("pressure", std::span<const double>(pressure_)),
                             vtk_array("velocity", std::span<const Vec3>(velocity_)),
                             vtk_array("solid", std::span<const std::uint8_t>(solid_))};
  const double dx = units_.dx();
  write_vti(opt_.out_dir / "vtk" / file, {g.nx, g.ny, nz_}, Vec3::Zero(), Vec3(dx, dx, dx), arrays);
  pvd_.add(s.time, file);
}

template <class L, class T>
void Runner<L, T>::write_checkpoint(const fs::path& dir) {
  fs::create_directories(dir);
  CheckpointWriter w(dir / "state.ffcp", /*keep_previous=*/true);
  const auto& f = sol_->populations();
  w.put("lbm.populations", std::vector<T>(f.begin(), f.end()));
  st_.step = sol_->time_step();
  st_.columns = std::int64_t(ncols_);
  w.put_value("flow.state", st_);
  w.put("flow.history", history_);
  w.put_string("flow.lattice", fmt::format("{} {} {}x{}x{}", L::name, sizeof(T) == 8 ? "double" : "float", dom_.nx,
                                           dom_.ny, nz_));
  w.commit();
}

template <class L, class T>
void Runner<L, T>::read_checkpoint() {
  CheckpointReader r = open_checkpoint(opt_.out_dir / "checkpoint" / "state.ffcp");
  const std::string expect = fmt::format("{} {} {}x{}x{}", L::name, sizeof(T) == 8 ? "double" : "float", dom_.nx,
                                         dom_.ny, nz_);
  const std::string have = r.get_string("flow.lattice");
  if (have != expect)
    throw InputError(fmt::format("{}: the checkpoint holds a {} lattice but the scenario builds {}", r.path().string(),
                                 have, expect));
  std::vector<T> f;
  r.get("lbm.populations", f);
  st_ = r.get_value<RunnerState>("flow.state");
  sol_->restore(f, long(st_.step));
  r.get("flow.history", history_);
  if (std::size_t(st_.columns) != ncols_)
    throw InputError(fmt::format("{}: the checkpoint's series has {} columns, this scenario writes {}", r.path().string(),
                                 st_.columns, ncols_));
}

template <class L, class T>
void Runner<L, T>::unstable(const std::string& what) {
  write_checkpoint(opt_.out_dir / "checkpoint_failed");
  // With TRT already on, its magic parameter is the other knob (near 0 the antisymmetric rate sits at 1/2).
  const lbm::SolverSettings& solver = sol_->settings();
  const std::string collision = solver.collision == lbm::CollisionModel::Trt
                                    ? fmt::format("a relaxation time further from 1/2 (now tau = {:.4g}) or lbm.trt_magic "
                                                  "nearer 1/4 (now {:.4g})",
                                                  units_.tau(), solver.magic)
                                    : fmt::format("use lbm.collision = \"trt\" with a relaxation time further from 1/2 "
                                                  "(now tau = {:.4g})",
                                                  units_.tau());
  throw NumericalError(fmt::format(
      "the LBM became unstable at step {} (t = {:.6g} s): {}. The state is saved in {}. To fix it, raise {} (finer "
      "cells, lower Mach number) or lower the time step, or {}",
      sol_->time_step(), double(sol_->time_step()) * units_.dt(), what, (opt_.out_dir / "checkpoint_failed").string(),
      fc_.resolution_key(), collision));
}

template <class L, class T>
RunStatus Runner<L, T>::run() {
  RunControl control(cfg_, opt_);
  {
    const auto chk = units_.check(fc_.characteristic_speed(), fc_.resolution(), fc_.resolution_key(), fu_.mode,
                                  cfg_.string("lbm.collision"), fu_.coefficient);
    if (!chk.error.empty()) cfg_.fail(fu_.key(), chk.error);
    build();
    log::info("{}", units_.describe(L::D));
    log::info("lattice {} {} x {} x {} ({} precision, {}): {} fluid cells, {} on boundaries, {} solid links",
              L::name, dom_.nx, dom_.ny, nz_, sizeof(T) == 8 ? "double" : "single", cfg_.string("lbm.collision"),
              sol_->num_fluid_cells(), sol_->num_boundary_cells(), [&] {
                long n = 0;
                for (auto& o : sol_->objects()) n += o.links;
                return n;
              }());
    log::info("{}", describe_flow_units(fu_, fc_));
    for (auto& w : chk.warnings) log::warn("{}", w);
    for (auto& w : fc_.warnings()) log::warn("{}", w);
  }
  // With lbm.tau setting the step, dt = (tau - 1/2) dx^2 / (3 nu): a viscosity far off (1e300 m^2/s
  // fuzzed) makes it tiny, and the advice named only the resolution and tau.
  const std::string shorten =
      std::string_view(fu_.key()) == "lbm.tau"
          ? fmt::format("run.end_time, a smaller {}, a larger lbm.tau or a lower fluid.viscosity (now {:.4g} m^2/s; the "
                        "step is (tau - 1/2) dx^2 / (3 nu))",
                        fc_.resolution_key(), cfg_.real("fluid.viscosity"))
          : fmt::format("run.end_time, a smaller {} or a larger {}", fc_.resolution_key(), fu_.key());
  refuse_endless_run(cfg_.real("run.end_time") / units_.dt(), shorten);
  // A ramp that outlasts the run leaves nothing at full inflow to measure (and 1e300 s overflowed
  // the step count into a negative sample index: a crash).
  if (const double ramp = cfg_.real("run.inflow_ramp_time"); ramp > 0 && !(ramp < cfg_.real("run.end_time")))
    cfg_.fail("run.inflow_ramp_time",
              fmt::format("{:.4g} s does not end before run.end_time = {:.4g} s: nothing would be measured at the full "
                          "inflow; give a shorter ramp, -1 (automatic) or 0 (none)",
                          ramp, cfg_.real("run.end_time")));
  begin_output(opt_);  // the lattice is built and checked: from here on files go into out_dir
  const long steps_total = std::max(1L, std::lround(cfg_.real("run.end_time") / units_.dt()));
  const long samples = cfg_.integer("output.samples");
  const long sample_every = std::max(1L, steps_total / samples);
  const long n_samples = (steps_total + sample_every - 1) / sample_every;
  auto every = [&](long n) { return n > 0 ? std::max(1L, n_samples / n) : 0L; };
  const long vtk_every = cfg_.boolean("output.vtk") ? every(cfg_.integer("output.snapshots")) : 0;
  const long cp_every = every(cfg_.integer("output.checkpoints"));
  const double steady_tol = cfg_.real("run.steady_tolerance");
  const double ramp_time = cfg_.real("run.inflow_ramp_time");
  // The slowest acoustic mode runs along the axis of the inflow face(s).
  int inflow_extent = 0;
  for (int f = 0; f < 4; ++f) {
    const auto& fc = dom_.faces[f];
    if (!dom_.periodic[f / 2] && (fc.kind == lbm::FaceCondition::Kind::Velocity ||
                                  (fc.kind == lbm::FaceCondition::Kind::Wall && fc.profile)))
      inflow_extent = std::max(inflow_extent, f < 2 ? dom_.nx : dom_.ny);
  }
  const long ramp_steps = inflow_extent == 0 ? 0
                          : ramp_time < 0    ? std::lround(20.0 * std::sqrt(3.0) * inflow_extent)
                                             : std::lround(ramp_time / units_.dt());
  ramp_end_time_ = double(ramp_steps) * units_.dt();
  if (ramp_steps > 0)
    log::info("inflow ramped up over {} steps ({:.4g} s)", ramp_steps, double(ramp_steps) * units_.dt());
  const auto steady_col = fc_.steady_column();
  // Steady-state window (steady.hpp): one period of the slowest acoustic mode, 4 L / c_s.
  const int acoustic_extent = std::max(dom_.periodic[0] ? 0 : dom_.nx, dom_.periodic[1] ? 0 : dom_.ny) > 0
                                  ? std::max(dom_.periodic[0] ? 0 : dom_.nx, dom_.periodic[1] ? 0 : dom_.ny)
                                  : std::max(dom_.nx, dom_.ny);
  // The smallest whole number of periods that holds kSteadyMinSamples samples (a window
  // of 10 coarse samples that is not a whole number of periods would let the ringing through).
  const double acoustic_period = 4.0 * std::sqrt(3.0) * acoustic_extent;  // steps
  const double periods = std::max(1.0, std::ceil(double(kSteadyMinSamples * sample_every) / acoustic_period));
  const long steady_window =
      std::max(kSteadyMinSamples, std::lround(periods * acoustic_period / double(sample_every)));

  const std::vector<std::string> columns = series_columns(cfg_, fc_, probes_);
  ncols_ = columns.size();
  history_.reserve(std::size_t(n_samples) * ncols_);
  CsvWriter series;
  const fs::path cp_dir = opt_.out_dir / "checkpoint";
  if (opt_.resume) {
    read_checkpoint();
    if (st_.finished) {
      log::info("this run had already finished; nothing to resume");
      return RunStatus::Finished;
    }
    if (control.resumed_at_max_steps(sol_->time_step())) return RunStatus::Interrupted;
    series.reopen(opt_.out_dir / "series.csv", columns, history_.size() / ncols_);
    log::info("resuming at step {} (t = {:.6g} s)", sol_->time_step(), double(sol_->time_step()) * units_.dt());
  } else {
    series.open(opt_.out_dir / "series.csv", columns);
  }
  if (vtk_every > 0) pvd_.open(opt_.out_dir / "vtk" / "flow.pvd", opt_.resume, double(sol_->time_step()) * units_.dt());
  FlowSample s;
  row_.reserve(columns.size());
  if (!opt_.resume && vtk_every > 0) {
    sample(s);
    write_vtk(s);
  }

  Progress progress(driver_, opt_.progress_interval_s);
  LongRunNotice long_run(double(steps_total - sol_->time_step()), shorten, sol_->time_step());
  if (!opt_.resume) {  // resumable from the start (kill -9 before the first interval)
    write_checkpoint(cp_dir);
    control.checkpoint_written();
  }
  RunStatus status = RunStatus::Finished;
  std::string stop_reason = fmt::format("reached run.end_time = {} s", cfg_.real("run.end_time"));
  const auto loop_start = std::chrono::steady_clock::now();
  const long loop_first_step = sol_->time_step();
  // Stop requests and wall-clock checkpoints are also honoured between samples (polled every
  // kPollSteps steps), so a run whose samples lie minutes apart still stops within seconds of a
  // SIGTERM. The populations and the step are the whole state, and samples fall on multiples of
  // sample_every, so a checkpoint between two samples resumes bit for bit too.
  constexpr long kPollSteps = 256;
  auto stop_now = [&](long t) {
    if (const std::string why = control.stop_reason(t); !why.empty()) {
      write_checkpoint(cp_dir);
      log_interruption(why, t);
      status = RunStatus::Interrupted;
      return true;
    }
    return false;
  };
  while (sol_->time_step() < steps_total) {
    const long next_sample = std::min((sol_->time_step() / sample_every + 1) * sample_every, steps_total);
    bool stopped = false;
    while (sol_->time_step() < next_sample) {
      const long t = sol_->time_step();
      if (t <= ramp_steps && ramp_steps > 0) {
        const double a = std::sin(0.5 * M_PI * double(t) / double(ramp_steps));
        sol_->set_inflow_scale(a * a);
      }
      sol_->step(t == next_sample - 1);
      if (((t + 1) % kPollSteps == 0 || t + 1 == opt_.max_steps) && t + 1 < next_sample) {
        if ((stopped = stop_now(t + 1))) break;
        if (control.checkpoint_due()) {
          write_checkpoint(cp_dir);
          control.checkpoint_written();
        }
      }
    }
    if (stopped) break;
    sample(s);
    if (!(s.max_mach == s.max_mach)) unstable("the velocity field holds NaN");
    if (s.max_mach > 0.3) unstable(fmt::format("the Mach number reached {:.3g} (limit 0.3)", s.max_mach));
    row_.clear();
    row_.push_back(double(s.step));
    row_.push_back(s.time);
    fc_.measure(s, row_);
    probes_.measure(s, row_);
    series.row(row_);
    history_.insert(history_.end(), row_.begin(), row_.end());
    const long k = long(history_.size() / ncols_);
    const bool last = sol_->time_step() >= steps_total;
    bool steady = false;
    if (steady_col && steady_tol > 0) {
      // Samples after the inflow ramp (steady.hpp): the drift of the window mean.
      const std::size_t c = std::size_t(*steady_col) + 2;
      const long first = (ramp_steps + sample_every - 1) / sample_every;  // first sample at or after the ramp
      const long n = k - first;
      const double* h = history_.data();
      const std::size_t nc = ncols_;
      const double drift =
          steady_drift([&](long i) { return h[std::size_t(first + i) * nc + c]; }, n, steady_window);
      if (std::isfinite(drift)) steady_drift_ = drift;
      if (drift < steady_tol) {
        steady = true;
        stop_reason = fmt::format("steady state: the mean of {} over {} samples ({:.4g} s, {:g} period(s) of the "
                                  "slowest acoustic mode) changed by {:.3g} (relative) over the last {} windows, below "
                                  "run.steady_tolerance = {}",
                                  columns[c], steady_window, double(steady_window * sample_every) * units_.dt(),
                                  periods, drift,
                                  kSteadyLag, steady_tol);
        log::info("{}", stop_reason);
      }
    }
    const bool done = last || steady;
    if (vtk_every > 0 && (k % vtk_every == 0 || done)) write_vtk(s);
    if (done) break;
    if (stop_now(sol_->time_step())) break;
    if (control.checkpoint_due() || (cp_every > 0 && k % cp_every == 0)) {
      write_checkpoint(cp_dir);
      control.checkpoint_written();
    }
    progress.update(sol_->time_step(), s.time, double(sol_->time_step()) / double(steps_total), fc_.progress_text(row_));
    long_run.update(sol_->time_step());
  }
  const double loop_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - loop_start).count();
  series.close();
  if (status == RunStatus::Interrupted) return status;
  summary(s, stop_reason, loop_s, sol_->time_step() - loop_first_step);
  // Marked finished only once summary.json exists (a run killed before resumes and writes it).
  st_.finished = 1;
  write_checkpoint(cp_dir);
  return status;
}

template <class L, class T>
void Runner<L, T>::summary(const FlowSample& last, const std::string& stop_reason, double loop_s, long loop_steps) {
  nlohmann::json j;
  j["fracflow_version"] = kVersion;
  j["driver"] = driver_;
  j["title"] = cfg_.string("title");
  j["stop_reason"] = stop_reason;
  j["lattice"] = {{"velocity_set", L::name},
                  {"precision", sizeof(T) == 8 ? "double" : "float"},
                  {"collision", cfg_.string("lbm.collision")},
                  {"cells", {dom_.nx, dom_.ny, nz_}},
                  {"fluid_cells", sol_->num_fluid_cells()},
                  {"boundary_cells", sol_->num_boundary_cells()}};
  j["steady_state"] = {{"tolerance", cfg_.real("run.steady_tolerance")},
                       {"final_drift", steady_drift_ < 0 ? nlohmann::json(nullptr) : nlohmann::json(steady_drift_)}};
  j["units"] = {{"dx_m", units_.dx()},
                {"dt_s", units_.dt()},
                {"tau", units_.tau()},
                {"chosen_by", fu_.by_default ? std::string("lbm.tau (default)") : std::string(fu_.key())},
                {"mach", fu_.mach},
                {"expected_compressibility_error", fu_.expected_error},
                {"compressibility_coefficient", fu_.coefficient},
                {"nu_lattice", units_.nu_lb()},
                {"velocity_factor_m_per_s", units_.velocity_factor()},
                {"pressure_factor_Pa", units_.pressure_factor()},
                {"force_factor_N_per_m", units_.force_factor()},
                {"mach_characteristic", std::sqrt(3.0) * units_.to_lattice_velocity(fc_.characteristic_speed())},
                {"mach_max_final", last.max_mach}};
  j["steps"] = sol_->time_step();
  j["simulated_time_s"] = double(sol_->time_step()) * units_.dt();
  j["wall_time_s"] = loop_s;
  j["mlups"] = loop_s > 0 ? double(sol_->num_fluid_cells()) * double(loop_steps) / loop_s * 1e-6 : 0.0;
  j["threads"] = opt_.threads;
  nlohmann::json results = nlohmann::json::object();
  const bool plots = cfg_.boolean("output.plots");
  if (plots) fs::create_directories(opt_.out_dir / "plots");
  std::vector<std::vector<double>> rows;
  for (std::size_t i = 0; i + ncols_ <= history_.size(); i += ncols_)
    rows.emplace_back(history_.begin() + std::ptrdiff_t(i), history_.begin() + std::ptrdiff_t(i + ncols_));
  fc_.finish(last, rows, opt_.out_dir, plots, results);
  if (!probes_.empty() && !rows.empty()) {  // final values: the last row of series.csv
    const auto& r = rows.back();
    std::size_t at = ncols_ - (probes_.set().points.size() * (L::D == 3 ? 4 : 3) + (probes_.set().delta_p ? 1 : 0));
    nlohmann::json pj = nlohmann::json::object();
    for (std::size_t i = 0; i < probes_.set().points.size(); ++i) {
      const auto& p = probes_.set().points[i];
      nlohmann::json e = {{"x_m", p.position.x()}, {"y_m", p.position.y()}};
      if (L::D == 3) e["z_m"] = p.position.z();
      e["p_Pa"] = r[at++];
      e["ux_m_per_s"] = r[at++];
      e["uy_m_per_s"] = r[at++];
      if (L::D == 3) e["uz_m_per_s"] = r[at++];
      if (i < probes_.stencils().size()) e["interpolation"] = probes_.stencils()[i].method;
      pj[p.name] = e;
    }
    results["probes"] = pj;
    if (probes_.set().delta_p) {
      results["delta_p_Pa"] = r[at];
      results["delta_p_probes"] = {probes_.set().points[(*probes_.set().delta_p)[0]].name,
                                   probes_.set().points[(*probes_.set().delta_p)[1]].name};
    }
  }
  j["results"] = results;
  j["parameters"] = params_json(cfg_);  // typed, as the DEM drivers write them
  add_run_record(j, opt_);
  write_json_atomic(opt_.out_dir / "summary.json", j);
}

template <class L, class T>
RunStatus run_typed(const Config& cfg, const RunOptions& opt, FlowCase& fc, std::string_view driver) {
  Runner<L, T> r(cfg, opt, fc, driver);
  return r.run();
}

}  // namespace

RunStatus run_flow(const Config& cfg, const RunOptions& opt, FlowCase& fc, std::string_view driver) {
  const bool d3 = cfg.string("lbm.lattice") == "D3Q19";
  const bool dbl = cfg.string("lbm.precision") == "double";
  validate_flow(cfg, fc);  // the checks `fracflow check` makes too (units, probes)
  if (d3) return dbl ? run_typed<lbm::D3Q19, double>(cfg, opt, fc, driver) : run_typed<lbm::D3Q19, float>(cfg, opt, fc, driver);
  return dbl ? run_typed<lbm::D2Q9, double>(cfg, opt, fc, driver) : run_typed<lbm::D2Q9, float>(cfg, opt, fc, driver);
}

}  // namespace ff::drivers
