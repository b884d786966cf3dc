// The hydraulic-fracturing driver: stages, time loop, checkpoints (docs/hydrofrac.md); what it
// reports at the end: hydrofrac_summary.cpp.
//   set-up     sample (sample builder) -> borehole and perforations carved -> DFN bonds cut ->
//              servo walls on every face (x: sigma_H, y: sigma_h, 3D z: sigma_v) -> time step
//   stage 0    the walls servo to the in-situ stresses until they hold within insitu.tolerance
//              and the unbalanced-force ratio is below it (checked every series row)
//   stage 1    injection: the fluid (fluid_load.hpp) pressurises the hole; the walls keep
//              servoing to the in-situ stresses; stop at injection.stop_extent, max_pressure,
//              max_time or (rate mode) when the pressure fell below stop_fraction of its peak.
// The loop mirrors DemRun's (dem_run_loop.cpp): checkpoint/resume bit for bit, --max-steps,
// --max-wall, signals, cracks.csv and the VTK series; its curve is pressure against time.
#include "drivers/hydrofrac/hydrofrac_driver.hpp"
#include "drivers/hydrofrac/hydrofrac_run.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <memory>

#include "core/error.hpp"
#include "core/log.hpp"
#include "core/progress.hpp"
#include "coupling/fluid_spec.hpp"
#include "coupling/hydrofrac/borehole.hpp"
#include "coupling/hydrofrac/lbm_load.hpp"
#include "coupling/hydrofrac/network_load.hpp"
#include "dem/dem_checkpoint.hpp"
#include "dem/dem_output.hpp"
#include "dem/dem_params.hpp"
#include "dem/diagnostics.hpp"
#include "dem/membrane/flexible_membrane.hpp"
#include "dem/sample_builder.hpp"
#include "drivers/dem_results.hpp"
#include "drivers/flow/flow_runner.hpp"
#include "drivers/hydrofrac/dfn.hpp"
#include "drivers/hydrofrac/hydrofrac_params.hpp"
#include "drivers/hydrofrac/kirsch.hpp"
#include "drivers/hydrofrac/sleeve_load.hpp"
#include "drivers/run_control.hpp"
#include "drivers/run_estimate.hpp"
#include "io/csv.hpp"

namespace ff::drivers::hydrofrac {
namespace {

const std::vector<std::string> kColumns = {
    "step", "time_s", "stage", "pressure_Pa", "injected_volume_m3", "borehole_volume_m3", "sigma_xx_wall_Pa",
    "sigma_yy_wall_Pa", "sigma_zz_wall_Pa", "cracks_tensile", "cracks_shear", "cracks_total", "cracks_connected",
    "wetted_cracks", "fracture_length_m", "fracture_extent_m", "fracture_azimuth_deg", "kinetic_energy_J",
    "unbalanced_force_ratio", "sigma_xx_fluid_Pa", "sigma_yy_fluid_Pa", "sigma_zz_fluid_Pa"};
constexpr std::size_t kUnbalancedColumn = 18;  // kColumns' "unbalanced_force_ratio"

}  // namespace

HydrofracRun::HydrofracRun(const Config& c, const RunOptions& o) : cfg(c), opt(o), control_(c, o) {
  sys.settings = dem::build_settings(cfg);
  sys.materials = dem::build_materials(cfg);
  cp_dir_ = opt.out_dir / "checkpoint";
  const int dim = sys.settings.dim;
  targets_ = Vec3(cfg.real("insitu.sigma_H"), cfg.real("insitu.sigma_h"), dim == 3 ? cfg.real("insitu.sigma_v") : 0.0);
  servo_v_ = cfg.real("insitu.servo_velocity");
  servo_alpha_ = cfg.real("insitu.servo_relaxation");
}

void HydrofracRun::make_fluid() {
  hydrofrac::SleeveSettings s;
  // Keys of one mode or fluid are read in it alone, so that one set for another is named as unused
  // (injection.rate without injection.mode = "rate" ran a pressure ramp without a word; session 50).
  const std::string fluid = cfg.string("injection.fluid");
  s.rate_mode = cfg.string("injection.mode") == "rate";
  if (s.rate_mode) s.flow_rate = cfg.real("injection.rate");
  else s.ramp_rate = cfg.real("injection.ramp_rate");
  s.initial_pressure = cfg.real("injection.initial_pressure");
  if (fluid != "lbm") s.bulk_modulus = cfg.real("injection.fluid_bulk_modulus");  // (the LBM's: fluid.*)
  if (fluid == "sleeve") {
    s.penetration = cfg.boolean("injection.penetration");
    s.update_interval = cfg.integer("injection.update_interval");
  }
  // Flood-fill cells of a quarter of the smallest radius (at most ~4e6 cells); particles are
  // inflated by half the bond gap so that bonded neighbours close the wall; the flood stays
  // within 1.5 radius_max of the carved region.
  const Real rmin = cfg.real("sample.radius_min"), rmax = cfg.real("sample.radius_max");
  const Real span = 2 * (hole_.radius + hole_.perforation_length + 3 * rmax);
  Real cell = 0.25 * rmin;
  const Real zspan = sys.settings.dim == 3 ? std::max<Real>(hole_.z_hi - hole_.z_lo, cell) : cell;
  const Real cells = (span / cell) * (span / cell) * (sys.settings.dim == 3 ? zspan / cell : 1.0);
  if (cells > 4e6) cell *= std::pow(cells / 4e6, sys.settings.dim == 3 ? 1.0 / 3.0 : 0.5);
  s.cell = cell;
  s.inflate = std::min(0.5 * cfg.real("sample.bond_gap"), 0.5 * rmin);
  s.reach = 1.5 * rmax;
  if (fluid == "network") {
    hydrofrac::NetworkSettings n;
    n.rate_mode = s.rate_mode;
    n.ramp_rate = s.ramp_rate;
    n.initial_pressure = s.initial_pressure;
    n.flow_rate = s.flow_rate;
    n.bulk_modulus = s.bulk_modulus;
    n.density = cfg.real("network.density");
    n.viscosity = cfg.real("network.viscosity");
    n.pore_pressure = cfg.real("network.pore_pressure");
    n.vapour_pressure = cfg.real("network.vapour_pressure");
    // Keys of one dimension are read in it alone, so that one set in the other is named as unused
    // (network.aperture_h0 on a 3D block had no effect without a word; fuzzed, session 50).
    const bool dim3 = sys.settings.dim == 3;
    if (!dim3) {
      n.network.b1_h0 = cfg.real("network.aperture_h0");
      n.network.b1_h_inf = cfg.real("network.aperture_hinf");
      n.network.b2_gamma = cfg.real("network.b2_gamma");
    } else {
      n.network.max_cond_ratio = cfg.real("network.max_conductance_ratio");
      n.pfv_factor = cfg.real("network.throat_factor");
      n.predict_pressures = cfg.boolean("network.predict_pressures");
      n.crack_channels = cfg.boolean("network.crack_channels");
    }
    n.retriangulation_tolerance = cfg.real("network.retriangulation_tolerance");
    n.remap = cfg.string("network.remap") == "pressure" ? porenet::RemapConserve::Pressure : porenet::RemapConserve::Mass;
    n.pressure_force = cfg.string("network.pressure_forces") == "void_gradient" ? coupling::PressureForce::VoidGradient
                                                                                : coupling::PressureForce::Surface;
    n.flow_every = cfg.integer("network.flow_every");
    const std::string faces = cfg.string("network.faces");
    n.drained_faces = faces == "drained" || (faces == "auto" && dim3);
    n.walls = dim3 && cfg.string("network.walls") != "off";
    const std::string pre = cfg.string("network.preconditioner");
    n.amg = pre == "amg" || (pre == "auto" && dim3);
    n.cell = s.cell;
    n.inflate = s.inflate;
    n.reach = s.reach;
    auto nl = std::make_unique<hydrofrac::NetworkLoad>(n, sys.settings.dim);
    net_ = nl.get();
    fluid_ = std::move(nl);
    return;
  }
  if (fluid != "lbm") {
    fluid_ = std::make_unique<hydrofrac::SleeveLoad>(s);
    return;
  }
  hydrofrac::LbmSettings l;
  l.fluid = lbm_fluid_spec(cfg);
  const std::string scheme = cfg.string("fluid.scheme");
  l.scheme = scheme == "psm"         ? lbm::ParticleScheme::Psm
             : scheme == "stairwise" ? lbm::ParticleScheme::StairwiseBounceBack
                                     : lbm::ParticleScheme::InterpolatedBounceBack;
  if (l.scheme == lbm::ParticleScheme::Psm)  // (read with the PSM alone: named as unused with the others)
    l.psm_weighting =
        cfg.string("fluid.psm_weighting") == "linear" ? lbm::PsmWeighting::Linear : lbm::PsmWeighting::TauDependent;
  l.moving_walls = cfg.boolean("fluid.moving_walls");
  l.drained_faces = cfg.string("fluid.faces") == "drained";
  l.rate_mode = s.rate_mode;
  l.ramp_rate = s.ramp_rate;
  l.initial_pressure = s.initial_pressure;
  l.flow_rate = s.flow_rate;
  l.velocity_box = cfg.string("injection.lbm_source") == "velocity_box";
  l.cell = s.cell;
  l.inflate = s.inflate;
  l.reach = s.reach;
  auto lb = hydrofrac::make_lbm_load(l, sys.settings.dim);
  lbm_ = lb.get();
  fluid_ = std::move(lb);
}

void HydrofracRun::set_up() {
  info = dem::build_sample(cfg, sys);
  const int dim = sys.settings.dim;
  auto& P = sys.particles;
  const Block b = block_of(cfg);
  hole_.dim = dim;
  hole_.centre = b.centre;
  hole_.radius = cfg.real("borehole.radius");
  hole_.perforation_length = cfg.real("borehole.perforation_length");
  // The slot's width, azimuth and sides are read only when there is a slot, so that one set without
  // borehole.perforation_length is named as unused (the hole had no perforation without a word).
  if (hole_.perforation_length > 0) {
    hole_.perforation_width = cfg.real("borehole.perforation_width") > 0 ? cfg.real("borehole.perforation_width")
                                                                          : 2 * cfg.real("sample.radius_max");
    hole_.perforation_azimuth = cfg.real("borehole.perforation_azimuth") * kPi / 180;
    hole_.perforation_sides = static_cast<int>(cfg.integer("borehole.perforation_sides"));
  }
  std::vector<char> remove(P.size(), 0);
  for (std::size_t i = 0; i < P.size(); ++i) remove[i] = hydrofrac::in_hole(hole_, P.pos[i], 0) ? 1 : 0;
  const std::size_t removed = hydrofrac::remove_particles(sys, remove);
  // The block's faces touch the outermost particles (the genesis shrinks the radii a little).
  Vec3 lo = Vec3::Constant(std::numeric_limits<Real>::infinity()), hi = -lo;
  for (std::size_t i = 0; i < P.size(); ++i) {
    lo = lo.cwiseMin(P.pos[i] - Vec3::Constant(P.radius[i]));
    hi = hi.cwiseMax(P.pos[i] + Vec3::Constant(P.radius[i]));
  }
  hole_.z_lo = dim == 3 ? lo.z() : 0;
  hole_.z_hi = dim == 3 ? hi.z() : 0;
  long joints_outside = 0;
  std::string joints_short;
  const auto joints = hydrofrac::make_joints(cfg, lo, hi, hole_.centre, hole_.radius, dim, &joints_outside, &joints_short);
  if (!joints_short.empty()) log::warn("{}", joints_short);
  if (joints_outside > 0)
    log::warn("hydrofrac: {} of the {} fractures of dfn.file are centred outside the block (they cut only where they "
              "reach into it)",
              joints_outside, joints.size());
  joints_ = hydrofrac::cut_bonds(sys, joints);
  sys.walls.clear();
  const char* names[6] = {"x-", "x+", "y-", "y+", "z-", "z+"};
  for (int a = 0; a < dim; ++a)
    for (int side = 0; side < 2; ++side) {
      dem::Wall w;
      w.name = names[2 * a + side];
      w.point = Vec3::Zero();
      w.point[a] = side == 0 ? lo[a] : hi[a];
      w.normal = Vec3::Zero();
      w.normal[a] = side == 0 ? 1 : -1;
      w.friction = 0;
      sys.walls.push_back(w);
    }
  sys.initialise();
  dem::choose_time_step(cfg, sys);
  // Servos that move a wall by a good part of a grain in one step (1e6 m/s: the walls jumped through the
  // block and ended at 0 MPa after insitu.max_steps, blamed on too few steps).
  dem::refuse_wall_jump(cfg, "insitu.servo_velocity", sys, "servo walls",
                        "the servos need many steps per grain (the default is 0.5 m/s)");
  log::info("hydrofrac: {} particles, {} bonds; borehole radius {:.4g} m ({} particles removed){}; {} natural fractures "
            "cutting {} bonds; time step {:.3g} s",
            P.size(), intact_bonds(sys), hole_.radius, removed,
            hole_.perforation_length > 0 ? fmt::format(", perforation {:.4g} m at {:.1f} deg", hole_.perforation_length,
                                                       cfg.real("borehole.perforation_azimuth"))
                                         : std::string(),
            joints.size(), joints_.size(), sys.settings.dt);
}

// Area of each pair of opposite walls [m^2; 2D: m^2 per m of thickness].
Vec3 HydrofracRun::wall_areas() const {
  const int dim = sys.settings.dim;
  const auto& W = sys.walls;
  const Real len[3] = {W[1].point.x() - W[0].point.x(), W[3].point.y() - W[2].point.y(),
                       dim == 3 ? W[5].point.z() - W[4].point.z() : 1.0};
  Vec3 area = Vec3::Zero();
  for (int a = 0; a < dim; ++a) area[a] = dim == 3 ? len[(a + 1) % 3] * len[(a + 2) % 3] : len[1 - a];
  return area;
}

// The fluid's mean gauge pressure on each face (FluidLoad::face_pressures); zero before injection.
std::array<Real, 6> HydrofracRun::face_pressures() const {
  return st_.stage == 1 ? fluid_->face_pressures() : std::array<Real, 6>{};
}

// Mean compressive stress on each pair of opposite walls [Pa]: the grains' contacts plus the
// fluid's push on the faces (fluid_wall_stress), the total stress the servos hold.
Vec3 HydrofracRun::wall_stress() const {
  const auto& W = sys.walls;
  const Vec3 area = wall_areas();
  Vec3 s = Vec3::Zero();
  for (int a = 0; a < sys.settings.dim; ++a) {
    // Particles push the low wall towards -a and the high one towards +a.
    s[a] = 0.5 * (-W[2 * a].force[a] + W[2 * a + 1].force[a]) / area[a];
  }
  return s + fluid_wall_stress();
}

// The fluid's share of wall_stress(): the mean gauge pressure on each pair of faces (zero before
// injection and for fluids that never reach the faces).
Vec3 HydrofracRun::fluid_wall_stress() const {
  Vec3 s = Vec3::Zero();
  const auto p = face_pressures();
  for (int a = 0; a < sys.settings.dim; ++a) s[a] = 0.5 * (p[std::size_t(2 * a)] + p[std::size_t(2 * a + 1)]);
  return s;
}

void HydrofracRun::servo() {
  const Vec3 area = wall_areas();
  const std::array<Real, 6> fluid = face_pressures();
  for (int a = 0; a < sys.settings.dim; ++a) {
    for (int side = 0; side < 2; ++side) {
      auto& w = sys.walls[2 * a + side];
      // What the wall carries: the grains' contacts and the fluid that reached its face.
      const Real pushed = (side == 0 ? -w.force[a] : w.force[a]) + fluid[std::size_t(2 * a + side)] * area[a];
      const Real v = dem::FlexibleMembrane::servo_law(targets_[a] * area[a], -pushed, w.contact_stiffness,
                                                      sys.settings.dt, servo_alpha_, servo_v_);
      w.velocity = Vec3::Zero();
      w.velocity[a] = side == 0 ? v : -v;
    }
  }
}

// The stages of DemSystem::step() with the fluid's loads between the forces and the motion.
void HydrofracRun::advance(long steps) {
  const bool inject = st_.stage == 1;
  for (long k = 0; k < steps; ++k) {
    servo();
    sys.update_neighbors();
    sys.compute_forces();
    if (inject) fluid_->add_forces(sys);
    sys.add_external_loads();
    sys.integrate();
    if (inject) fluid_->advance(sys);
  }
}

Real HydrofracRun::face_gap() const {
  const auto& W = sys.walls;
  const Real a = st_.effective_radius > 0 ? st_.effective_radius : hole_.radius;
  return std::min({hole_.centre.x() - W[0].point.x(), W[1].point.x() - hole_.centre.x(), hole_.centre.y() - W[2].point.y(),
                   W[3].point.y() - hole_.centre.y()}) -
         a;
}

std::vector<CircleRecord> HydrofracRun::snapshot(Real pressure) const {
  std::vector<CircleRecord> out;
  const int dim = sys.settings.dim;
  const Real R = hole_.radius, a = st_.effective_radius;
  const Real rho = cfg.real("measure.circle_radius") * R;
  const Real zc = dim == 3 ? 0.5 * (hole_.z_lo + hole_.z_hi) : 0.0;
  auto one = [&](Real dx, Real dy, Real rad, Real r_over_a, Real ang, bool far) {
    const CircleStress m = hydrofrac::measure_circle(sys, Vec3(hole_.centre.x() + dx, hole_.centre.y() + dy, zc), rad);
    const Vec3 k = hydrofrac::kirsch_average(targets_.x(), targets_.y(), pressure, a, dx, dy, rad, dim);
    CircleRecord c;
    c.r_over_a = r_over_a;
    c.angle_deg = ang;
    c.x = dx;
    c.y = dy;
    c.radius = rad;
    c.porosity = m.porosity;
    c.particles = m.particles;
    c.far = far;
    c.xx = m.xx;
    c.yy = m.yy;
    c.xy = m.xy;
    c.zz = m.zz;
    c.k_xx = k.x();
    c.k_yy = k.y();
    c.k_xy = k.z();
    c.pressure = pressure;
    out.push_back(c);
  };
  for (double r : cfg.real_list("measure.radii"))
    for (double ang : cfg.real_list("measure.angles")) {
      const Real t = ang * kPi / 180;
      one(r * R * std::cos(t), r * R * std::sin(t), rho, r * R / a, ang, false);
    }
  // Interior stress: four circles half-way between the axis and the block's corners.
  const auto& W = sys.walls;
  const Real hx = 0.5 * (W[1].point.x() - W[0].point.x()), hy = 0.5 * (W[3].point.y() - W[2].point.y());
  const Real q = std::min(hx, hy);
  for (int s = 0; s < 4; ++s) {
    const Real dx = (s % 2 ? 0.5 : -0.5) * hx, dy = (s / 2 ? 0.5 : -0.5) * hy;
    one(dx, dy, 0.3 * q, std::hypot(dx, dy) / a, std::atan2(dy, dx) * 180 / kPi, true);
  }
  return out;
}

void HydrofracRun::begin_injection() {
  st_.stage = 1;
  st_.injection_step = sys.step_count;
  st_.injection_time = sys.time;
  fluid_->begin(sys, hole_, joints_);
  if (lbm_) log::info("hydrofrac: lattice Boltzmann fluid ({}): {}", cfg.string("fluid.scheme"), lbm_->info().describe());
  if (net_) log::info("hydrofrac: {}", net_->info().describe());
  st_.effective_radius = lbm_   ? lbm_->effective_radius()
                         : net_ ? net_->effective_radius()
                                : static_cast<hydrofrac::SleeveLoad&>(*fluid_).effective_radius();
  insitu_ = snapshot(0);
  const Vec3 ws = wall_stress();
  Real far_xx = 0, far_yy = 0;
  int nf = 0;
  for (const auto& c : insitu_)
    if (c.far) far_xx += c.xx, far_yy += c.yy, ++nf;
  log::info("hydrofrac: in-situ stage {} after {} steps: walls {:.4g} / {:.4g}{} MPa (targets {:.4g} / {:.4g}{}), interior "
            "circles {:.3f} / {:.3f} MPa; hole: {} wall particles, effective radius {:.4g} m",
            st_.equilibrium ? "in equilibrium" : "NOT in equilibrium", st_.insitu_steps, 1e-6 * ws.x(), 1e-6 * ws.y(),
            sys.settings.dim == 3 ? fmt::format(" / {:.4g}", 1e-6 * ws.z()) : std::string(), 1e-6 * targets_.x(),
            1e-6 * targets_.y(), sys.settings.dim == 3 ? fmt::format(" / {:.4g}", 1e-6 * targets_.z()) : std::string(),
            1e-6 * far_xx / nf, 1e-6 * far_yy / nf, fluid_->wall_particles().size(), st_.effective_radius);
  vtk();
  checkpoint();
}

void HydrofracRun::vtk() {
  if (!vtk_on_) return;
  const Real extent = 1.6 * std::max(sys.walls[1].point.x() - sys.walls[0].point.x(), sys.walls[3].point.y() - sys.walls[2].point.y());
  if (lbm_ && st_.stage == 1) {
    const std::string name = fmt::format("fluid_{:05d}.vti", st_.vtk_index);
    lbm_->write_vti(opt.out_dir / "vtk" / name);
    fluid_pvd_.add(sys.time, name);
  }
  if (net_ && st_.stage == 1 && cfg.boolean("network.vtk")) {
    const std::string name = fmt::format("pores_{:05d}.vtu", st_.vtk_index);
    net_->write_vtu(opt.out_dir / "vtk" / name, sys);
    pores_pvd_.add(sys.time, name);
  }
  vtk_writer_.write(sys, st_.vtk_index++, extent);
  st_.last_vtk_time = sys.time;
}

void HydrofracRun::measure_row() {
  const Vec3 ws = wall_stress(), fws = fluid_wall_stress();
  const hydrofrac::FluidState f = st_.stage == 1 ? fluid_->state() : hydrofrac::FluidState{};
  long connected = 0;
  shape_ = {};
  extent_ = 0;
  if (st_.stage == 1) {
    if (id_index_.size() != static_cast<std::size_t>(sys.particles.next_id)) id_index_ = hydrofrac::index_of_ids(sys.particles);
    hydrofrac::connected_cracks(sys, id_index_, fluid_->wall_particles(), joints_, ev_, jt_, visited_);
    connected = static_cast<long>(ev_.size());
    shape_ = hydrofrac::fracture_shape(sys, ev_, hole_.centre);
    extent_ = std::max<Real>(0, shape_.max_distance - st_.effective_radius);
  }
  row_ = {static_cast<double>(sys.step_count), sys.time, static_cast<double>(st_.stage), f.pressure, f.injected_volume,
          f.borehole_volume, ws.x(), ws.y(), ws.z(), static_cast<double>(sys.cracks.tensile),
          static_cast<double>(sys.cracks.shear), static_cast<double>(sys.cracks.total()), static_cast<double>(connected),
          static_cast<double>(f.wetted_cracks), shape_.length, extent_, shape_.azimuth_deg, kinetic_energy(sys),
          max_unbalanced_force_ratio(sys), fws.x(), fws.y(), fws.z()};
  for (double v : row_)
    if (!std::isfinite(v))
      throw NumericalError(fmt::format(
          "the hydrofrac run became unstable by step {} (t = {:.6g} s): a series.csv value is {}. The last good checkpoint "
          "stays in {}/checkpoint. Lower dem.time_step_safety, injection.ramp_rate or injection.rate, or insitu.servo_velocity",
          sys.step_count, sys.time, v, opt.out_dir.string()));
  // A connected crack far outside the block: a bonded pair was thrown out (an unstable coupling that
  // has not produced NaN yet); its extent would be reported as the fracture's (seen at 1.7e21 x).
  if (st_.stage == 1 && extent_ > 10 * face_gap())
    throw NumericalError(fmt::format(
        "the hydrofrac run became unstable by step {} (t = {:.6g} s): a connected crack lies {:.3g} m beyond the hole's "
        "wall, {:.3g} times the distance to the block's faces (grains were thrown out of the block). The last good "
        "checkpoint stays in {}/checkpoint. Lower dem.time_step_safety, injection.ramp_rate or injection.rate{}",
        sys.step_count, sys.time, extent_, extent_ / face_gap(), opt.out_dir.string(),
        cfg.string("injection.fluid") == "lbm" && cfg.boolean("fluid.moving_walls") ? ", or set fluid.moving_walls = false"
                                                                                    : ""));
  series_.row(row_);
  ++st_.rows;
  status_.clear();
  if (st_.stage == 0)
    fmt::format_to(std::back_inserter(status_), "in-situ: walls {:.3f}/{:.3f} MPa, unbalanced {:.3g}", 1e-6 * ws.x(),
                   1e-6 * ws.y(), row_[kUnbalancedColumn]);
  else
    fmt::format_to(std::back_inserter(status_), "p {:.3f} MPa  cracks {} ({} connected)  fracture {:.3g} m", 1e-6 * f.pressure,
                   sys.cracks.total(), connected, extent_);
}

void HydrofracRun::save(const fs::path& dir) {
  fs::create_directories(dir);
  CheckpointWriter w(dir / "state.ffcp", /*keep_previous=*/true);
  dem::save_dem(w, sys);
  w.put_value("hydrofrac.state", st_);
  w.put_value("hydrofrac.sample", sample_record(info));
  w.put_value("hydrofrac.hole", hydrofrac::to_record(hole_));
  w.put("hydrofrac.joints", joints_);
  w.put("hydrofrac.insitu", insitu_);
  w.put("hydrofrac.probe", probe_);
  if (st_.stage == 1) fluid_->save(w);
  control_.record(w);
  w.commit();
}

void HydrofracRun::load() {
  CheckpointReader r = open_checkpoint(cp_dir_ / "state.ffcp");
  dem::load_dem(r, sys);
  st_ = r.get_value<HfState>("hydrofrac.state");
  info = sample_info(r.get_value<SampleRecord>("hydrofrac.sample"));
  hole_ = hydrofrac::from_record(r.get_value<hydrofrac::BoreholeRecord>("hydrofrac.hole"));
  r.get("hydrofrac.joints", joints_);
  r.get("hydrofrac.insitu", insitu_);
  r.get("hydrofrac.probe", probe_);
  if (st_.stage == 1) fluid_->load(r, sys);
  control_.restore(r);
}

// Upper bound of the run's steps from step 0: the in-situ cap plus the injection's time.
double HydrofracRun::planned_steps() const {
  const bool rate_mode = cfg.string("injection.mode") == "rate";
  const Real max_t = cfg.real("injection.max_time");
  return static_cast<double>(cfg.integer("insitu.max_steps")) +
         (rate_mode ? max_t : std::min(max_t, cfg.real("injection.max_pressure") / cfg.real("injection.ramp_rate"))) /
             sys.settings.dt;
}

// Read before the set-up ends (run and resume alike), each in its mode alone, so that one set for
// the other mode is named as unused (injection.stop_fraction in ramp mode never stopped a run; session 50).
void HydrofracRun::read_mode_rules() {
  if (cfg.string("injection.mode") == "rate") {
    peak_drop_ = cfg.real("injection.peak_drop");
    stop_fraction_ = cfg.real("injection.stop_fraction");
  } else {
    breakdown_length_ = cfg.real("injection.breakdown_length");
  }
}

RunStatus HydrofracRun::run() {
  make_fluid();
  read_mode_rules();
  if (opt.resume) {
    load();
    if (st_.finished) {
      log::info("this run had already finished; nothing to resume");
      return RunStatus::Finished;
    }
    if (control_.resumed_at_max_steps(sys.step_count)) return RunStatus::Interrupted;
    log::info("resuming at step {} (t = {:.6g} s), {}", sys.step_count, sys.time, st_.stage == 0 ? "in-situ stage" : "injecting");
  } else {
    set_up();
    refuse_endless_run(planned_steps(), kShortenKeys, sys.settings.dt);
    if (lbm_ && FlowCheckReport::active()) {  // `fracflow check`: the LBM and DEM steps as the run will log them
      hydrofrac::LbmSettings l;
      l.fluid = hydrofrac::lbm_fluid_spec(cfg);
      hydrofrac::LbmInfo in = hydrofrac::lbm_info(l, sys.settings.dt);
      hydrofrac::size_lattice(sys.particles, l.fluid.dx, sys.settings.dim, in);
      FlowCheckReport::append(fmt::format("hydrofrac: lattice Boltzmann fluid ({}): {}\n(lattice from the block before the "
                                          "walls servo: the run's may differ by a cell)\n",
                                          cfg.string("fluid.scheme"), in.describe()));
    }
    begin_output(opt);
  }
  // Outputs; on resume, rows, crack lines and snapshots after the checkpoint are dropped (the
  // run recomputes them identically).
  const fs::path cracks_csv = opt.out_dir / "cracks.csv";
  if (opt.resume) series_.reopen(opt.out_dir / "series.csv", kColumns, static_cast<std::size_t>(st_.rows));
  else series_.open(opt.out_dir / "series.csv", kColumns);
  {
    dem::CrackLog head;
    head.events.assign(sys.cracks.events.begin(), sys.cracks.events.begin() + st_.cracks_written);
    dem::append_cracks_csv(cracks_csv, head, sys.materials, 0);
  }
  vtk_on_ = cfg.boolean("output.vtk");
  if (vtk_on_) vtk_writer_.open(opt.out_dir / "vtk", opt.resume, sys.time);
  if (vtk_on_ && lbm_) fluid_pvd_.open(opt.out_dir / "vtk" / "fluid.pvd", opt.resume, sys.time);
  if (vtk_on_ && net_ && cfg.boolean("network.vtk")) pores_pvd_.open(opt.out_dir / "vtk" / "pores.pvd", opt.resume, sys.time);
  if (!opt.resume) {
    vtk();
    checkpoint();
  }
  row_.reserve(kColumns.size());
  const long every = cfg.integer("hydrofrac.series_interval");
  const long cp_every = cfg.integer("hydrofrac.checkpoint_interval");
  const long vtk_every = cfg.integer("hydrofrac.vtk_interval");
  const Real tol = cfg.real("insitu.tolerance");
  const long insitu_max = cfg.integer("insitu.max_steps");
  const bool rate_mode = cfg.string("injection.mode") == "rate";
  const Real bd_len = breakdown_length_ > 0 ? breakdown_length_ : hole_.radius;
  const Real probe_p = cfg.real("measure.pressure");
  const Real max_p = cfg.real("injection.max_pressure"), max_t = cfg.real("injection.max_time");
  const Real stop_extent = cfg.real("injection.stop_extent");
  auto wall_list = [&](const Vec3& v) {
    return sys.settings.dim == 3 ? fmt::format("{:.4g} / {:.4g} / {:.4g}", 1e-6 * v.x(), 1e-6 * v.y(), 1e-6 * v.z())
                                 : fmt::format("{:.4g} / {:.4g}", 1e-6 * v.x(), 1e-6 * v.y());
  };
  Progress progress("hydrofrac", opt.progress_interval_s);
  LongRunNotice long_run(planned_steps() - static_cast<double>(sys.step_count), kShortenKeys, sys.step_count);
  std::string stop;
  try {
    for (;;) {
      advance(every);
      measure_row();
      double fraction = -1;
      if (st_.stage == 0) {
        st_.insitu_steps = sys.step_count;
        const Vec3 ws = wall_stress();
        Real err = 0;
        for (int a = 0; a < sys.settings.dim; ++a) err = std::max(err, std::abs(ws[a] - targets_[a]) / targets_[a]);
        const bool eq = err <= tol && row_[kUnbalancedColumn] <= tol && st_.rows >= 3;
        fraction = 0.5 * static_cast<double>(sys.step_count) / static_cast<double>(insitu_max);
        if (eq || sys.step_count >= insitu_max) {
          st_.equilibrium = eq;
          // Walls still far from their targets: breakdown pressures of such a block mean nothing.
          if (!eq && err > 0.5)
            throw NumericalError(fmt::format(
                "hydrofrac: the in-situ stage reached insitu.max_steps = {} with the walls at {} MPa, up to {:.0f}% away "
                "from their targets ({} MPa; insitu.sigma_H, insitu.sigma_h{}). Raise insitu.max_steps (or "
                "insitu.servo_velocity) if the walls were still closing in (the progress lines show their stresses), or "
                "lower the in-situ stresses if the block cannot carry them",
                insitu_max, wall_list(ws), 100 * err, wall_list(targets_), sys.settings.dim == 3 ? ", insitu.sigma_v" : ""));
          if (!eq)
            log::warn("hydrofrac: the in-situ stage reached insitu.max_steps = {} without equilibrium (largest wall-stress "
                      "error {:.3g}, unbalanced-force ratio {:.3g}, tolerance {}); injecting anyway",
                      insitu_max, err, row_[kUnbalancedColumn], tol);
          begin_injection();
        }
      } else {
        const Real p = row_[3];
        const Real injected_time = static_cast<Real>(sys.step_count - st_.injection_step) * sys.settings.dt;
        if (!st_.initiation_found && row_[12] > 0) {
          st_.initiation_found = 1;
          st_.initiation_pressure = p;
        }
        if (!st_.probe_taken && probe_p > 0 && p >= probe_p) {
          st_.probe_taken = 1;
          st_.probe_pressure_actual = p;
          probe_ = snapshot(p);
        }
        if (p > st_.peak_pressure) {
          st_.peak_pressure = p;
          st_.peak_time = sys.time;
          st_.peak_cracks = sys.cracks.total();
        }
        if (!st_.breakdown_found) {
          // Rate mode: a drop counts once a crack has reached the hole; before, the pressure of the hole's
          // pores also rises and falls as the rock settles (a "breakdown" of 35 kPa with no crack at all).
          const bool bd = rate_mode ? (st_.peak_pressure > 0 && st_.initiation_found && p < (1 - peak_drop_) * st_.peak_pressure)
                                    : extent_ >= bd_len;
          if (bd) {
            st_.breakdown_found = 1;
            st_.breakdown_row = st_.rows - 1;
            st_.breakdown_pressure = rate_mode ? st_.peak_pressure : p;
            st_.breakdown_time = rate_mode ? st_.peak_time : sys.time;
            st_.breakdown_cracks = rate_mode ? st_.peak_cracks : sys.cracks.total();
            st_.bd_azimuth = shape_.azimuth_deg;
            st_.bd_length = shape_.length;
            st_.bd_extent = extent_;
            st_.bd_anisotropy = shape_.anisotropy;
            st_.bd_normal_azimuth = shape_.normal_azimuth_deg;
            st_.bd_connected = shape_.cracks;
            vtk();
          }
        }
        if (vtk_every > 0 && sys.time - st_.last_vtk_time >= static_cast<Real>(vtk_every) * sys.settings.dt - 1e-15) vtk();
        const Real gap = face_gap();
        if (extent_ >= stop_extent * gap)
          stop = fmt::format("the fracture reached {:.3g} of the distance from the hole to the block's faces (injection.stop_extent)",
                             extent_ / gap);
        else if (p >= max_p)
          stop = fmt::format("the borehole pressure reached injection.max_pressure = {} Pa", max_p);
        else if (injected_time >= max_t)
          stop = fmt::format("the injection time reached injection.max_time = {} s", max_t);
        else if (rate_mode && st_.breakdown_found && p < stop_fraction_ * st_.peak_pressure)
          stop = fmt::format("the pressure fell below injection.stop_fraction = {} of its peak", stop_fraction_);
        fraction = 0.5 + 0.5 * std::min(1.0, rate_mode ? injected_time / max_t : std::max(extent_ / (stop_extent * gap), p / max_p));
      }
      progress.update(sys.step_count, sys.time, fraction, status_);
      long_run.update(sys.step_count);
      dem::append_cracks_csv(cracks_csv, sys.cracks, sys.materials, static_cast<std::size_t>(st_.cracks_written));
      st_.cracks_written = static_cast<long>(sys.cracks.events.size());
      if (!stop.empty()) break;
      if (const std::string why = control_.stop_reason(sys.step_count); !why.empty()) {
        checkpoint();
        log_interruption(why, sys.step_count);
        series_.close();
        return RunStatus::Interrupted;
      }
      if (control_.checkpoint_due() || (cp_every > 0 && (sys.step_count / every) % std::max(1L, cp_every / every) == 0))
        checkpoint();
    }
  } catch (const NumericalError& e) {
    save(opt.out_dir / "checkpoint_failed");
    series_.close();
    // The DEM's own message blames its step; during injection the fluid's load is as likely.
    if (dynamic_cast<const DemNotFiniteError*>(&e) && st_.stage == 1)
      throw DemNotFiniteError(fmt::format(
          "{}. The fluid loads the rock too (borehole pressure {:.4g} Pa): check injection.{}{}", e.what(),
          fluid_ ? fluid_->state().pressure : 0.0, rate_mode ? "rate" : "ramp_rate and injection.initial_pressure",
          net_   ? ", network.viscosity, network.pore_pressure and injection.fluid_bulk_modulus"
          : lbm_ ? ", fluid.bulk_modulus (or fluid.sound_speed) and fluid.viscosity"
                 : ""));
    throw;
  }
  series_.close();
  finish(stop);
  return RunStatus::Finished;
}

namespace {

RunStatus run(const Config& cfg, const RunOptions& opt) {
  // On resume the scenario is the results folder's copy: files it names (dfn.file) are relative
  // to the original scenario's folder, and the block is in the checkpoint.
  if (!opt.resume) hydrofrac::validate_scenario(cfg);
  return HydrofracRun(cfg, opt).run();
}

}  // namespace
}  // namespace ff::drivers::hydrofrac

namespace ff::drivers {

Driver hydrofrac_driver() {
  return Driver{"hydrofrac",
                "hydraulic fracturing from a borehole in a bonded block under servo-controlled in-situ stresses; the fluid a sleeve pressure, an LBM fluid or the pore network (injection.fluid)",
                hydrofrac::declare_params, hydrofrac::run, hydrofrac::validate_scenario};
}

}  // namespace ff::drivers
