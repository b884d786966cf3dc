#include "coupling/hydrofrac/lbm_load.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "core/error.hpp"
#include "core/log.hpp"
#include "coupling/particle_set.hpp"
#include "coupling/hydrofrac/borehole.hpp"
#include "io/vtk.hpp"
#include "lbm/lattice_budget.hpp"
#include "lbm/solver.hpp"

namespace ff::coupling::hydrofrac {

std::string LbmInfo::describe() const {
  return fmt::format("{}\nLBM lattice {} x {} x {} cells; dt_lbm = {:.4g} s = n dt_dem with dt_dem = {:.4g} s and n = {} DEM "
                     "sub-steps per LBM step; tau = {:.4g}, Mach {:.3g}, K_eff = {:.4g} Pa",
                     scales.describe(), n[0], n[1], n[2], scales.dt(), dem_dt, stride, scales.units.tau(), scales.mach,
                     scales.bulk_modulus);
}

LbmInfo lbm_info(const LbmSettings& s, Real dem_dt) {
  LbmInfo in;
  // The user's keys first (their errors name them), then the LBM step rounded to whole DEM steps:
  // n = floor(dt_lbm / dt_dem) >= 1 and dt_lbm = n dt_dem (K_eff rises slightly; reported).
  const coupling::FluidScales first = coupling::derive_scales(s.fluid);
  in.stride = std::max<long>(1, long(std::floor(first.dt() / dem_dt * (1 + 1e-12))));
  coupling::FluidSpec f = s.fluid;
  f.tau = f.sound_speed = f.bulk_modulus = 0;
  f.time_step = double(in.stride) * dem_dt;
  try {
    in.scales = coupling::derive_scales(f);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{} (the LBM step rounded to {} DEM steps of {:.4g} s; {} fixed {:.4g} s)", e.what(),
                                 in.stride, dem_dt, first.fixed_by, first.dt()));
  }
  in.scales.fixed_by = first.fixed_by + " and the DEM step";
  in.dem_dt = dem_dt;
  return in;
}

void size_lattice(const dem::ParticleStore& P, Real dx, int dim, LbmInfo& info) {
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (std::size_t i = 0; i < P.size(); ++i)
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], P.pos[i][a] - P.radius[i]);
      hi[a] = std::max(hi[a], P.pos[i][a] + P.radius[i]);
    }
  info.n[0] = info.n[1] = info.n[2] = 1;
  const char* hint = "a coarser fluid.dx or a smaller block (sample.width, sample.height, sample.depth)";
  for (int a = 0; a < dim; ++a) {
    lo[a] -= dx;
    info.n[a] = lbm::lattice_side(std::ceil((hi[a] + dx - lo[a]) / dx), "fluid.dx", hint);
  }
  lbm::check_lattice_memory(info.n[0], info.n[1], info.n[2], dim == 3 ? 19 : 9, sizeof(double), hint);
  if (dim == 2) lo.z() = -0.5 * dx;
  info.origin = lo + Vec3::Constant(0.5 * dx);
}

namespace {

template <class L>
class LbmLoad final : public LbmLoadBase {
  using Solver = lbm::Solver<L, double>;

 public:
  explicit LbmLoad(LbmSettings s) : s_(std::move(s)) {}

  void begin(const dem::DemSystem& sys, const BoreholeGeometry& hole, const std::vector<JointPair>& joints) override {
    hole_ = hole;
    joints_ = joints;
    const auto& P = sys.particles;
    info_ = lbm_info(s_, sys.settings.dt);
    const double dx = s_.fluid.dx;
    size_lattice(P, dx, L::D, info_);  // every particle plus one cell
    const double cells = double(info_.n[0]) * info_.n[1] * info_.n[2];
    if (cells > 2e8)
      throw InputError(fmt::format("fluid.dx: {} m gives {:.3g} lattice cells over the block (at most 2e8); raise it", dx, cells));
    st_ = State{};
    st_.t0 = sys.time;
    st_.pressure = s_.initial_pressure;
    build(sys);
    fluid_->initialize([](int, int, int, double& rho, Vec3& u) {
      rho = 1;
      u = Vec3::Zero();
    });
    // The hole's fluid at the initial pressure before the first step.
    fill_set(sys);
    fluid_->set_particles(set_);
    find_loaded(sys);
    st_.mass0 = lattice_mass();
    const double rho_b = info_.scales.lattice_density(s_.initial_pressure);
    st_.injected += fluid_->impose_equilibrium(hole_cells_, rho_b, Vec3::Zero()) * cell_volume();
    st_.injected0 = st_.injected;
    measure_face_pressures();
    if (s_.moving_walls)
      log::warn("fluid.moving_walls = true: the particles' velocities enter the bounce-back walls; with explicit coupling "
                "this diverges for grains of a few cells in tight pores (added-mass instability, docs/hydrofrac.md)");
    const HoleSurface hs = hole_surface(sys, hole, s_.cell, s_.inflate, s_.reach);
    wall_ = hs.particle;
    effective_radius_ = hs.effective_radius;
  }

  void add_forces(dem::DemSystem& sys) override {
    if (st_.dem_steps % info_.stride == 0) lbm_step(sys);
    auto& p = sys.particles;
    for (std::size_t i = 0; i < p.size() && i < force_.size(); ++i) {
      p.ext_force[i] += force_[i];
      p.ext_moment[i] += torque_[i];
    }
  }
  void advance(const dem::DemSystem&) override { ++st_.dem_steps; }

  FluidState state() const override {
    FluidState f;
    f.pressure = st_.pressure;
    f.injected_volume = st_.injected;
    long nf = 0;
    for (const auto& c : hole_cells_) nf += fluid_->covered(c[0], c[1], c[2]) ? 0 : 1;
    f.borehole_volume = double(nf) * cell_volume();
    f.wetted_particles = long(std::count(loaded_.begin(), loaded_.end(), char(1)));  // touching the hole's fluid
    f.wetted_cracks = wetted_cracks_;
    return f;
  }
  const std::vector<Index>& wall_particles() const override { return wall_; }
  std::array<Real, 6> face_pressures() const override { return face_pressure_; }
  const LbmInfo& info() const override { return info_; }
  Real effective_radius() const override { return effective_radius_; }
  const std::vector<Vec3>& hydro_force() const override { return force_; }
  LbmBudget budget() const override {
    LbmBudget b;
    b.injected = st_.injected;
    b.lattice_change = (lattice_mass() - st_.mass0) * cell_volume();
    b.covering_refill = st_.changes;
    b.drained = st_.drained;
    b.residual = b.lattice_change - b.injected - b.drained - b.covering_refill;
    b.lbm_steps = st_.lbm_steps;
    b.set_changes = st_.set_changes;
    b.max_mach = st_.max_mach;
    return b;
  }

  Real pressure_at(const Vec3& x) const override {
    int c[3];
    if (!cell_of(x, c) || fluid_->covered(c[0], c[1], c[2])) return info_.scales.background_pressure;
    return info_.scales.pressure(fluid_->cell_density(c[0], c[1], c[2]));
  }
  bool wet_at(const Vec3& x) const override {
    int c[3];
    return cell_of(x, c) && !fluid_->covered(c[0], c[1], c[2]);
  }

  void write_vti(const std::filesystem::path& file) const override {
    const auto& g = fluid_->grid();
    const std::size_t n = std::size_t(g.nx) * g.ny * g.nz;
    std::vector<double> p(n);
    std::vector<Vec3> u(n, Vec3::Zero());
    std::vector<std::uint8_t> flag(n);
    const double uf = info_.scales.units.velocity_factor();
    const bool odd = (fluid_->time_step() & 1) != 0;
    const auto& f = fluid_->populations();
    const lbm::CellIndex N = g.padded_size();
    std::size_t k = 0;
    for (int z = 0; z < g.nz; ++z)
      for (int y = 0; y < g.ny; ++y)
        for (int x = 0; x < g.nx; ++x, ++k) {
          flag[k] = fluid_->covered(x, y, z) ? 1 : 0;
          if (flag[k]) {
            p[k] = info_.scales.background_pressure;
            continue;
          }
          // Moments of the populations the next step reads (AA slots as in Solver::cell_density).
          double rho = 1, j[3] = {0, 0, 0};  // populations shifted by their weights (collision.hpp)
          const lbm::CellIndex c = g.index(x, y, z);
          for (int q = 0; q < L::Q; ++q) {
            const double v = q == 0 ? f[c]
                             : odd  ? f[L::opp[q] * N + g.neighbour(x, y, z, -L::c[q][0], -L::c[q][1], -L::c[q][2])]
                                    : f[q * N + c];
            rho += v;
            for (int a = 0; a < 3; ++a) j[a] += L::c[q][a] * v;
          }
          p[k] = info_.scales.pressure(rho);
          u[k] = Vec3(j[0], j[1], j[2]) * (uf / rho);
        }
    const double dx = s_.fluid.dx;
    const std::array<VtkArray, 3> arrays = {vtk_array("pressure", std::span<const double>(p)),
                                            vtk_array("velocity", std::span<const Vec3>(u)),
                                            vtk_array("solid", std::span<const std::uint8_t>(flag))};
    ff::write_vti(file, {g.nx, g.ny, g.nz}, info_.origin - Vec3::Constant(0.5 * dx),
              Vec3(dx, dx, L::D == 3 ? dx : dx), arrays);
  }

  void save(CheckpointWriter& w) const override {
    w.put_value("lbm.state", st_);
    const auto& h = hole_;
    w.put("lbm.hole", std::vector<double>{h.centre.x(), h.centre.y(), h.centre.z(), h.radius, h.perforation_length,
                                          h.perforation_width, h.perforation_azimuth, double(h.perforation_sides), h.z_lo,
                                          h.z_hi, double(h.dim)});
    w.put("lbm.joints", joints_);
    w.put("lbm.wall", wall_);
    w.put_value("lbm.origin", info_.origin);
    w.put("lbm.n", std::vector<int>(info_.n, info_.n + 3));
    const auto& f = fluid_->populations();
    w.put("lbm.f", std::vector<double>(f.begin(), f.end()));
    w.put_value("lbm.time", fluid_->time_step());
    w.put("lbm.set.id", set_.id);
    w.put("lbm.set.position", set_.position);
    w.put("lbm.set.radius", set_.radius);
    w.put("lbm.set.velocity", set_.velocity);
    w.put("lbm.set.omega", set_.omega);
    w.put("lbm.force", force_);
    w.put("lbm.torque", torque_);
  }

  void load(CheckpointReader& r, const dem::DemSystem& sys) override {
    st_ = r.get_value<State>("lbm.state");
    std::vector<double> h;
    r.get("lbm.hole", h);
    if (h.size() != 11) throw InputError("checkpoint: section lbm.hole has the wrong size (another version?)");
    hole_.centre = Vec3(h[0], h[1], h[2]);
    hole_.radius = h[3];
    hole_.perforation_length = h[4];
    hole_.perforation_width = h[5];
    hole_.perforation_azimuth = h[6];
    hole_.perforation_sides = int(h[7]);
    hole_.z_lo = h[8];
    hole_.z_hi = h[9];
    hole_.dim = int(h[10]);
    r.get("lbm.joints", joints_);
    r.get("lbm.wall", wall_);
    info_ = lbm_info(s_, sys.settings.dt);
    info_.origin = r.get_value<Vec3>("lbm.origin");
    std::vector<int> n;
    r.get("lbm.n", n);
    for (int a = 0; a < 3; ++a) info_.n[a] = n.at(std::size_t(a));
    build(sys);
    std::vector<double> f;
    r.get("lbm.f", f);
    fluid_->restore(f, r.get_value<long>("lbm.time"));
    r.get("lbm.set.id", set_.id);
    r.get("lbm.set.position", set_.position);
    r.get("lbm.set.radius", set_.radius);
    r.get("lbm.set.velocity", set_.velocity);
    r.get("lbm.set.omega", set_.omega);
    fluid_->restore_particles(set_);
    find_loaded(sys);
    r.get("lbm.force", force_);
    r.get("lbm.torque", torque_);
    count_wetted(sys);
    measure_face_pressures();  // from the restored populations: what the uninterrupted run holds
  }

 private:
  struct State {  // trivially copyable (a checkpoint section)
    Real t0 = 0, pressure = 0, injected = 0;
    Real mass0 = 0;    // lattice mass after the first set of particles, before the first imposition
    Real changes = 0;  // mass that covering and refill added (refill minus covered) [m^3 at rho_f]
    Real drained = 0;  // mass the drained faces added (negative: outflow) [m^3 at rho_f]
    long dem_steps = 0, lbm_steps = 0;
    long set_changes = 0;  // LBM steps that handed the solver a new particle set
    double max_mach = 0;   // largest |u| / c_s over the fluid cells, sampled every kMachEvery LBM steps
    Real injected0 = 0;    // injected volume once the hole stood at the initial pressure [m^3]
  };
  static constexpr long kMachEvery = 20;
  static constexpr double kBoxRelax = 20;  // LBM steps over which the velocity box makes up a volume owed

  double cell_volume() const { return std::pow(s_.fluid.dx, L::D); }  // 2D: per metre

  // Sum of rho over the fluid cells (lattice units), the state the next step reads.
  double lattice_mass() const {
    const auto& g = fluid_->grid();
    double m = 0;
    for (int z = 0; z < g.nz; ++z)
      for (int y = 0; y < g.ny; ++y)
        for (int x = 0; x < g.nx; ++x)
          if (!fluid_->covered(x, y, z)) m += fluid_->cell_density(x, y, z);
    return m;
  }

  // Sum of rho over the listed cells that are fluid now; `nf` gets their count.
  double uncovered_mass(const std::vector<std::array<int, 3>>& cells, long& nf) const {
    double m = 0;
    nf = 0;
    for (const auto& c : cells)
      if (!fluid_->covered(c[0], c[1], c[2])) {
        m += fluid_->cell_density(c[0], c[1], c[2]);
        ++nf;
      }
    return m;
  }

  bool cell_of(const Vec3& x, int* c) const {
    const Vec3 xl = (x - info_.origin) / s_.fluid.dx;
    c[2] = 0;
    for (int a = 0; a < L::D; ++a) {
      c[a] = int(std::floor(xl[a] + 0.5));
      if (c[a] < 0 || c[a] >= info_.n[a]) return false;
    }
    return true;
  }

  // The solver (walls on every face; the block's pore space and surroundings start at p0) and
  // the borehole's cells (centres inside the hole or a perforation).
  void build(const dem::DemSystem& sys) {
    lbm::SolverSettings ss;
    ss.collision = lbm::CollisionModel::Trt;
    ss.tau = info_.scales.units.tau();
    ss.particle_scheme = s_.scheme;
    ss.psm_weighting = s_.psm_weighting;
    lbm::Grid g(L::D, info_.n[0], info_.n[1], info_.n[2], {false, false, false});
    fluid_ = std::make_unique<Solver>(g, ss);
    fluid_->finalize();
    hole_cells_.clear();
    const double dx = s_.fluid.dx;
    for (int z = 0; z < g.nz; ++z)
      for (int y = 0; y < g.ny; ++y)
        for (int x = 0; x < g.nx; ++x) {
          const Vec3 xs = info_.origin + dx * Vec3(x, y, L::D == 3 ? z : 0);
          if (in_hole(hole_, xs, 0)) hole_cells_.push_back({x, y, z});
        }
    if (hole_cells_.empty())
      throw InputError(fmt::format("fluid.dx: {} m is too coarse: no lattice cell centre lies in the borehole", dx));
    // The velocity box: hole cells within half-side b of the axis, velocity direction (x - c) / b per
    // axis (div = 2 / b: the outflow U x perimeter leaves through the box's sides); the rest of the
    // hole gives the box's density.
    box_cells_.clear();
    box_dir_.clear();
    box_rest_.clear();
    if (s_.rate_mode && s_.velocity_box) {
      const double b = s_.box_fraction * hole_.radius;
      for (const auto& c : hole_cells_) {
        const Vec3 xs = info_.origin + dx * Vec3(c[0], c[1], L::D == 3 ? c[2] : 0);
        const double ex = (xs.x() - hole_.centre.x()) / b, ey = (xs.y() - hole_.centre.y()) / b;
        if (std::abs(ex) <= 1 && std::abs(ey) <= 1) {
          box_cells_.push_back(c);
          box_dir_.push_back(Vec3(ex, ey, 0));
        } else {
          box_rest_.push_back(c);
        }
      }
      const double per_side = 2 * b / dx;
      if (per_side < 4)
        throw InputError(fmt::format("fluid.dx: {} m leaves the injection box (half-side {} m, half the hole's radius) "
                                     "{:.2g} cells wide; it needs at least 4 (refine fluid.dx or use "
                                     "injection.lbm_source = \"mass\")",
                                     dx, b, per_side));
      // The box's outflow per unit U (lattice units: volume per step over the box's cells' divergence).
      box_outflow_ = double(box_cells_.size()) * 2.0 / (b / dx);
    }
    face_cells_.clear();
    if (s_.drained_faces)
      for (int z = 0; z < g.nz; ++z)
        for (int y = 0; y < g.ny; ++y)
          for (int x = 0; x < g.nx; ++x)
            if (x == 0 || x == g.nx - 1 || y == 0 || y == g.ny - 1 || (L::D == 3 && (z == 0 || z == g.nz - 1)))
              face_cells_.push_back({x, y, z});
    set_.resize(sys.particles.size());
    force_.assign(sys.particles.size(), Vec3::Zero());
    torque_.assign(sys.particles.size(), Vec3::Zero());
    id_index_ = index_of_ids(sys.particles);
  }

  // Quasi-static walls unless fluid.moving_walls (motion factor 0: the moving-wall term of explicit
  // coupling is unstable for these light, confined grains; docs/hydrofrac.md).
  void fill_set(const dem::DemSystem& sys) {
    coupling::fill_particle_set(sys.particles, info_.origin, info_.scales.units, L::D, set_, s_.moving_walls ? 1.0 : 0.0);
  }

  Real pressure_now(Real t) const { return s_.initial_pressure + s_.ramp_rate * (t - st_.t0); }

  // With quasi-static walls the particle set changes only through the particles' positions: it is
  // handed to the solver again once a particle has moved kRefresh cells since the last set (the
  // rock creeps ~1e-4 cells per LBM step; rebuilding the solid cells and links of every grain each
  // step cost several LBM steps). Moving walls refresh every step (their velocities change).
  static constexpr double kRefresh = 0.02;
  bool set_stale(const dem::DemSystem& sys) const {
    const auto& p = sys.particles;
    if (s_.moving_walls || set_.size() != p.size()) return true;
    const double dx = s_.fluid.dx, lim = kRefresh * kRefresh;
    for (std::size_t i = 0; i < p.size(); ++i) {
      Vec3 d = (p.pos[i] - info_.origin) / dx - set_.position[i];
      if (L::D == 2) d.z() = 0;
      if (d.squaredNorm() > lim) return true;
    }
    return false;
  }

  // Particles that carry a fluid load (dry rock: only those touching fluid connected to the hole;
  // the pore pockets between intact grains are sealed, and their trapped fluid, a stiff spring at
  // K_eff, would only make the explicit coupling unstable). Depends on the set alone.
  void find_loaded(const dem::DemSystem& sys) {
    flood();
    loaded_.assign(set_.size(), 0);
    const double dx = s_.fluid.dx;
    for (std::size_t i = 0; i < set_.size(); ++i) loaded_[i] = touches_wet(set_.position[i], sys.particles.radius[i] / dx);
  }

  // The fluid's Mach number (a pass over the moments the last step stored): the largest so far for summary.json,
  // and a stop with advice past coupling::kMaxMach or at NaN (the populations' expansion no longer
  // holds; the run would only blow up later).
  void check_mach(const dem::DemSystem& sys) {
    const double mach = fluid_->max_speed() * std::sqrt(3.0);
    if (!(mach <= coupling::kMaxMach))
      throw NumericalError(fmt::format(
          "hydrofrac: the LBM fluid became unstable at t = {:.6g} s (LBM step {}): Mach number {:.3g} (limit {}). A "
          "stiffer lattice fluid (raise fluid.bulk_modulus or fluid.sound_speed: a shorter LBM step), a slower "
          "injection (lower injection.ramp_rate or injection.rate) or a more viscous fluid (fluid.viscosity) keeps "
          "the fluid's speed below the lattice's sound speed",
          sys.time, st_.lbm_steps, mach, coupling::kMaxMach));
    st_.max_mach = std::max(st_.max_mach, mach);
  }

  void lbm_step(const dem::DemSystem& sys) {
    if (set_stale(sys)) {
      fill_set(sys);
      fluid_->set_particles(set_);
      if (const auto* mb = fluid_->moving_boundary())
        st_.changes += (mb->stats().mass_added - mb->stats().mass_removed) * cell_volume();
      find_loaded(sys);
      ++st_.set_changes;
    }
    // Every kMachEvery-th step stores the moments (the fields are not read otherwise) for the Mach check.
    const bool sample = (st_.lbm_steps + 1) % kMachEvery == 0;
    fluid_->step(sample);
    ++st_.lbm_steps;
    if (sample) check_mach(sys);
    const double dt = info_.scales.dt();
    const Real t_end = st_.t0 + double(st_.lbm_steps) * dt;
    // Injection: the hole's fluid cells get the borehole density.
    if (!s_.rate_mode) {
      st_.pressure = pressure_now(t_end);
      st_.injected += fluid_->impose_equilibrium(hole_cells_, info_.scales.lattice_density(st_.pressure), Vec3::Zero()) *
                      cell_volume();
    } else if (s_.velocity_box) {
      // Seed 003 Sec. 4.1: the box's cells at the density of the hole around it and an outward velocity
      // whose flux U x (box's divergence) carries the pumped volume (at reference density) per step;
      // the mass the imposition adds is what left the box since the last step.
      long nf = 0;
      const double mass = uncovered_mass(box_rest_.empty() ? box_cells_ : box_rest_, nf);
      const double rho_b = nf > 0 ? mass / double(nf) : 1.0;
      // The box at the nominal U pumps more than U x its divergence (its edge cells also meet the slower
      // fluid outside: +25 % on the Fig. 9 block), so U follows the volume still owed against Q t,
      // relaxed over kBoxRelax steps: the pumped volume tracks Q t within a few steps' worth.
      const double step_volume = s_.flow_rate * dt;
      const double owed = st_.injected0 + s_.flow_rate * (t_end - st_.t0) - st_.injected;
      const double U = std::max(0.0, 1.0 + owed / (kBoxRelax * step_volume)) * step_volume / cell_volume() /
                       (rho_b * box_outflow_);
      st_.injected += fluid_->impose_equilibrium(box_cells_, rho_b, box_dir_, U) * cell_volume();
      st_.pressure = info_.scales.pressure(rho_b);
    } else {
      long nf = 0;
      const double mass = uncovered_mass(hole_cells_, nf);
      if (nf > 0) {
        const double rho_b = (mass + s_.flow_rate * dt / cell_volume()) / double(nf);
        st_.injected += fluid_->impose_equilibrium(hole_cells_, rho_b, Vec3::Zero()) * cell_volume();
        st_.pressure = info_.scales.pressure(rho_b);
      }
    }
    // Loads: the momentum exchange minus that of the reference fluid at rest (p0) on the same links.
    const auto& F = fluid_->particle_forces();
    const auto& M = fluid_->particle_torques();
    const auto& u = info_.scales.units;
    for (std::size_t i = 0; i < force_.size(); ++i) {
      if (!loaded_[i]) {
        force_[i] = torque_[i] = Vec3::Zero();
        continue;
      }
      const coupling::SiLoad si = coupling::to_si_load(u, L::D, F[i], M[i]);
      force_[i] = si.force;
      torque_[i] = si.torque;
    }
    // Drained faces: the far field's pore pressure p0 on the lattice's outer layer (the fluid that
    // seeps out of the block leaves; the rock's skeleton feels the seepage gradient).
    if (s_.drained_faces) st_.drained += fluid_->impose_equilibrium(face_cells_, 1.0, Vec3::Zero()) * cell_volume();
    count_wetted(sys);  // O(cracks) per LBM step
    measure_face_pressures();
  }

  // The fluid's mean gauge pressure on each of the lattice's faces (its outer layer of cells: the
  // block's faces plus one cell), K_eff (rho - 1) over the cells connected to the hole's fluid,
  // the others counting zero; summed in lattice order, O(faces) once per LBM step.
  void measure_face_pressures() {
    face_pressure_.fill(0);
    const auto& g = fluid_->grid();
    const int n[3] = {g.nx, g.ny, g.nz};
    for (int a = 0; a < L::D; ++a) {
      const int b = (a + 1) % 3, c = (a + 2) % 3;
      for (int side = 0; side < 2; ++side) {
        double sum = 0;
        int at[3];
        at[a] = side == 0 ? 0 : n[a] - 1;
        for (at[c] = 0; at[c] < n[c]; ++at[c])
          for (at[b] = 0; at[b] < n[b]; ++at[b]) {
            const std::size_t k = std::size_t(at[0]) + std::size_t(g.nx) * (std::size_t(at[1]) + std::size_t(g.ny) * at[2]);
            if (wet_[k]) sum += fluid_->cell_density(at[0], at[1], at[2]) - 1.0;
          }
        face_pressure_[std::size_t(2 * a + side)] = info_.scales.bulk_modulus * sum / (double(n[b]) * double(n[c]));
      }
    }
  }

  // The fluid connected to the hole now: flood over uncovered cells from the hole's cells along
  // the lattice's directions (8 / 18 neighbours: the populations stream diagonally too, so a
  // pocket that touches the hole's fluid only at a corner is connected); cost proportional to
  // the connected region.
  void flood() {
    const auto& g = fluid_->grid();
    if (wet_.size() != std::size_t(g.nx) * g.ny * g.nz) wet_.assign(std::size_t(g.nx) * g.ny * g.nz, 0);
    for (std::size_t k : wet_list_) wet_[k] = 0;
    wet_list_.clear();
    auto lin = [&](int x, int y, int z) { return std::size_t(x) + std::size_t(g.nx) * (std::size_t(y) + std::size_t(g.ny) * z); };
    auto push = [&](int x, int y, int z) {
      if (!g.is_interior(x, y, z)) return;
      const std::size_t k = lin(x, y, z);
      if (wet_[k] || fluid_->covered(x, y, z)) return;
      wet_[k] = 1;
      wet_list_.push_back(k);
    };
    for (const auto& c : hole_cells_) push(c[0], c[1], c[2]);
    for (std::size_t h = 0; h < wet_list_.size(); ++h) {
      const std::size_t k = wet_list_[h];
      const int x = int(k % std::size_t(g.nx)), y = int((k / std::size_t(g.nx)) % std::size_t(g.ny)),
                z = int(k / (std::size_t(g.nx) * g.ny));
      for (int q = 1; q < L::Q; ++q) push(x + L::c[q][0], y + L::c[q][1], z + L::c[q][2]);
    }
  }
  bool touches_wet(const Vec3& c, double r) const {
    const auto& g = fluid_->grid();
    const double reach = r + 1.0;
    const int z0 = L::D == 3 ? std::max(0, int(std::floor(c.z() - reach))) : 0,
              z1 = L::D == 3 ? std::min(g.nz - 1, int(std::ceil(c.z() + reach))) : 0;
    for (int z = z0; z <= z1; ++z)
      for (int y = std::max(0, int(std::floor(c.y() - reach))); y <= std::min(g.ny - 1, int(std::ceil(c.y() + reach))); ++y)
        for (int x = std::max(0, int(std::floor(c.x() - reach))); x <= std::min(g.nx - 1, int(std::ceil(c.x() + reach))); ++x)
          if (wet_[std::size_t(x) + std::size_t(g.nx) * (std::size_t(y) + std::size_t(g.ny) * z)]) return true;
    return false;
  }

  // Wetted cracks: crack points (broken bonds and joints) whose lattice cell is fluid with p - p0
  // above wet_fraction of the hole's.
  void count_wetted(const dem::DemSystem& sys) {
    const double dp = st_.pressure - info_.scales.background_pressure;
    auto wet = [&](const Vec3& x) {
      int c[3];
      if (!cell_of(x, c) || fluid_->covered(c[0], c[1], c[2])) return false;
      return info_.scales.pressure(fluid_->cell_density(c[0], c[1], c[2])) - info_.scales.background_pressure >
             s_.wet_fraction * dp;
    };
    long n = 0;
    for (const auto& e : sys.cracks.events)
      if (!in_hole(hole_, e.position, 0) && wet(e.position)) ++n;
    const auto& P = sys.particles;
    for (const auto& j : joints_) {
      const Index a = id_index_[std::size_t(j.a)], b = id_index_[std::size_t(j.b)];
      if (a < 0 || b < 0) continue;
      const Vec3 xc = P.pos[a] + (P.pos[b] - P.pos[a]) * (P.radius[a] / (P.radius[a] + P.radius[b]));
      if (wet(xc)) ++n;
    }
    wetted_cracks_ = n;
  }

  LbmSettings s_;
  LbmInfo info_;
  BoreholeGeometry hole_;
  std::vector<JointPair> joints_;
  std::vector<Index> wall_, id_index_;
  std::unique_ptr<Solver> fluid_;
  std::vector<std::array<int, 3>> hole_cells_;
  std::vector<std::array<int, 3>> box_cells_, box_rest_;  // the velocity box's cells; the hole's others
  std::vector<Vec3> box_dir_;                             // per box cell: its velocity / U
  double box_outflow_ = 0;                                // lattice volume per step per unit U
  std::vector<std::array<int, 3>> face_cells_;  // the lattice's outer layer (drained faces only)
  lbm::ParticleSet set_;
  std::vector<Vec3> force_, torque_;
  State st_;
  long wetted_cracks_ = 0;
  std::array<Real, 6> face_pressure_{};  // measure_face_pressures, after each LBM step [Pa]
  Real effective_radius_ = 0;
  std::vector<std::uint8_t> wet_;
  std::vector<char> loaded_;  // per particle: touches the hole's fluid (find_loaded)
  std::vector<std::size_t> wet_list_;
};

}  // namespace

std::unique_ptr<LbmLoadBase> make_lbm_load(const LbmSettings& s, int dim) {
  if (dim == 3) return std::make_unique<LbmLoad<lbm::D3Q19>>(s);
  return std::make_unique<LbmLoad<lbm::D2Q9>>(s);
}

}  // namespace ff::coupling::hydrofrac
