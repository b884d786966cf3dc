// Solver: construction, state, the boundary-cell path and force reduction. The geometry
// classification is in solver_setup.cpp, the bulk sweep in bulk_sweep.cpp.
#include "lbm/solver.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/error.hpp"

namespace ff::lbm {

template <class L, class T>
Solver<L, T>::Solver(const Grid& grid, const SolverSettings& settings) : grid_(grid), settings_(settings) {
  if (grid.dim != L::D)
    throw Error(fmt::format("internal: a {} solver needs a {}-dimensional grid", L::name, L::D));
  if (!(settings.tau > 0.5))
    throw InputError(fmt::format("LBM relaxation time tau = {} must be above 1/2", settings.tau));
  if (!(settings.psm_refresh >= 0 && settings.psm_refresh <= 0.5))
    throw InputError(fmt::format("LBM PSM refresh distance {} cells must lie in [0, 0.5] (0: recompute the solid "
                                 "fractions every step)", settings.psm_refresh));
  set_body_force(settings.body_force);
  const CellIndex N = n_();
  f_.assign(std::size_t(Q) * N, T(0));
  type_.assign(N, CellType::Fluid);
  object_.assign(N, -1);
  drho_.assign(N, T(0));
  for (auto& u : u_) u.assign(N, T(0));
  for (int f = 0; f < kNumFaces; ++f) {
    const int axis = f / 2;
    faces_[f].kind = grid_.periodic[axis] ? FaceCondition::Kind::Periodic : FaceCondition::Kind::Wall;
    SolidObject o;
    o.name = fmt::format("wall {}", face_name(f));
    objects_.push_back(o);
  }
}

template <class L, class T>
void Solver<L, T>::set_face(int f, const FaceCondition& c) {
  const int axis = f / 2;
  const bool periodic = c.kind == FaceCondition::Kind::Periodic;
  if (periodic != grid_.periodic[axis])
    throw InputError(fmt::format("face {}: {} axis {} is {}periodic in the grid; periodic faces come in pairs and are "
                                 "set with the grid",
                                 face_name(f), periodic ? "cannot be periodic:" : "cannot take a wall or open condition:",
                                 "xyz"[axis], grid_.periodic[axis] ? "" : "not "));
  if (c.kind == FaceCondition::Kind::Outflow && c.outflow == FaceCondition::Outflow::Convective &&
      !(std::isfinite(c.convective_velocity) && c.convective_velocity >= 0))
    throw InputError(fmt::format("face {}: convective outflow velocity {} must be a lattice speed >= 0 (0: the "
                                 "face's mean outflow speed)",
                                 face_name(f), c.convective_velocity));
  faces_[f] = c;
  inflow_wall_[f] = c.kind == FaceCondition::Kind::Wall && bool(c.profile);
  if (c.kind == FaceCondition::Kind::Wall) objects_[f].velocity = c.velocity;
}

template <class L, class T>
int Solver<L, T>::add_object(std::string name, WallScheme scheme, const Vec3& center) {
  SolidObject o;
  o.name = std::move(name);
  o.scheme = scheme;
  o.center = center;
  objects_.push_back(o);
  return int(objects_.size()) - 1;
}

template <class L, class T>
void Solver<L, T>::add_shape(int object, const Shape& shape) {
  objects_.at(object).shape = shape;
  for (int z = 0; z < grid_.nz; ++z)
    for (int y = 0; y < grid_.ny; ++y)
      for (int x = 0; x < grid_.nx; ++x)
        if (inside(shape, Vec3(x, y, z))) set_solid(x, y, z, object);
}

template <class L, class T>
void Solver<L, T>::set_solid(int x, int y, int z, int object) {
  const CellIndex i = grid_.index(x, y, z);
  type_[i] = CellType::Solid;
  object_[i] = std::int16_t(object);
}

template <class L, class T>
void Solver<L, T>::set_object_motion(int object, const Vec3& velocity, const Vec3& omega) {
  objects_.at(object).velocity = velocity;
  objects_.at(object).omega = omega;
  compute_link_velocities();
}

template <class L, class T>
void Solver<L, T>::set_body_force(const Vec3& f) {
  settings_.body_force = f;
  const double fa[3] = {f[0], f[1], L::D == 3 ? f[2] : 0.0};
  relax_ = make_relax<T>(settings_.collision, settings_.tau, settings_.magic, fa);
}

template <class L, class T>
Vec3 Solver<L, T>::wall_velocity(int object, const Vec3& x) const {
  const SolidObject& o = objects_[object];
  return o.velocity + o.omega.cross(x - o.center);
}

template <class L, class T>
void Solver<L, T>::compute_link_velocities() {
  link_uw_.assign(3 * links_.size(), T(0));
  for (std::size_t l = 0; l < links_.size(); ++l) {
    const Link& k = links_[l];
    const BoundaryCell& b = bcells_[k.cell];
    const int o = L::opp[k.q];
    const Vec3 xw = Vec3(b.x, b.y, b.z) + double(k.delta) * Vec3(L::c[o][0], L::c[o][1], L::c[o][2]);
    const Vec3 uw = k.object < kNumFaces && inflow_wall_[k.object] ? faces_[k.object].profile(b.x, b.y, b.z)
                                                                   : wall_velocity(k.object, xw);
    for (int a = 0; a < 3; ++a) link_uw_[3 * l + a] = T(a < L::D ? uw[a] : 0.0);
  }
}

template <class L, class T>
void Solver<L, T>::initialize(const std::function<void(int, int, int, double&, Vec3&)>& init) {
  const CellIndex N = n_();
  std::fill(f_.begin(), f_.end(), T(0));
  for (int z = 0; z < grid_.nz; ++z)
    for (int y = 0; y < grid_.ny; ++y)
      for (int x = 0; x < grid_.nx; ++x) {
        const CellIndex i = grid_.index(x, y, z);
        double rho = 1;
        Vec3 u = Vec3::Zero();
        if (type_[i] == CellType::Fluid) init(x, y, z, rho, u);
        const T uu[3] = {T(u[0]), T(u[1]), T(L::D == 3 ? u[2] : 0.0)};
        T geq[Q];
        equilibrium<L, T>(T(rho), uu, geq, settings_.incompressible);
        for (int q = 0; q < Q; ++q) f_[q * N + i] = geq[q];
        drho_[i] = T(rho - 1);
        for (int a = 0; a < 3; ++a) u_[a][i] = uu[a];
      }
  // The first (even) step bounces the population found in the solid neighbour's slot
  // f[opp q][x - c_q] and adds the moving-wall term: store the initial f_q(x) minus that term,
  // so that step 0 starts from the initial state itself rather than from an empty wall.
  for (std::size_t l = 0; l < links_.size(); ++l) {
    const Link& k = links_[l];
    const BoundaryCell& b = bcells_[k.cell];
    const int q = k.q;
    const CellIndex src = grid_.neighbour(b.x, b.y, b.z, -L::c[q][0], -L::c[q][1], -L::c[q][2]);
    const T* uw = &link_uw_[3 * l];
    const T mw = T(6 * L::w[q]) * (L::c[q][0] * uw[0] + L::c[q][1] * uw[1] + L::c[q][2] * uw[2]);
    f_[L::opp[q] * N + src] = f_[q * N + b.cell] - mw;
  }
  // Outflow nodes: the convective state of time 0 (incoming populations and outflow speed, in
  // the open ghost x - n), and for a solid donor the slots the first step bounces back.
  for (const std::int32_t i : outflow_cells_) {
    const BoundaryCell& b = bcells_[i];
    const OpenNode<T>& nd = open_[b.open];
    f_[nd.ghost] = T(-nd.sign) * u_[nd.axis][b.cell];
    for (int q = 1; q < Q; ++q) {
      if (!(b.open_mask & (1u << q))) continue;
      f_[q * N + nd.ghost] = f_[q * N + b.cell];
      if (nd.donor < 0)
        f_[L::opp[q] * N + grid_.neighbour(b.x, b.y, b.z, -L::c[q][0], -L::c[q][1], -L::c[q][2])] = f_[q * N + b.cell];
    }
  }
  time_ = 0;
}

template <class L, class T>
void Solver<L, T>::restore(const std::vector<T>& f, long time_step) {
  if (f.size() != f_.size())
    throw InputError(fmt::format("checkpoint holds {} populations, this lattice needs {}: the checkpoint belongs to "
                                 "another scenario",
                                 f.size(), f_.size()));
  std::copy(f.begin(), f.end(), f_.begin());
  time_ = time_step;
}

template <class L, class T>
Vec3 Solver<L, T>::velocity(int x, int y, int z) const {
  const CellIndex i = grid_.index(x, y, z);
  return Vec3(u_[0][i], u_[1][i], u_[2][i]);
}

template <class L, class T>
std::size_t Solver<L, T>::num_bulk_cells() const {
  return std::size_t(num_bulk_cells_);
}

template <class L, class T>
double Solver<L, T>::max_speed() const {
  double m = 0;
  bool nan = false;
  auto visit = [&](CellIndex i) {
    const double u2 = double(u_[0][i]) * u_[0][i] + double(u_[1][i]) * u_[1][i] + double(u_[2][i]) * u_[2][i];
    if (std::isnan(u2) || std::isnan(double(drho_[i]))) nan = true;
    else m = std::max(m, u2);
  };
  for_each_bulk_cell([&](CellIndex i, std::size_t) { visit(i); });
  for (auto& b : bcells_) visit(b.cell);
  return nan ? std::nan("") : std::sqrt(m);
}

template <class L, class T>
double Solver<L, T>::total_mass() const {
  double m = 0;
  for (int z = 0; z < grid_.nz; ++z)
    for (int y = 0; y < grid_.ny; ++y)
      for (int x = 0; x < grid_.nx; ++x) {
        const CellIndex i = grid_.index(x, y, z);
        if (type_[i] == CellType::Fluid && !(mb_ && mb_->solid(i))) m += 1.0 + double(drho_[i]);
      }
  return m;
}

// ---------------------------------------------------------------- time step

template <class L, class T>
void Solver<L, T>::step(bool sample) {
  const bool odd = (time_ & 1) != 0;
  save_interpolation_inputs(odd);
  save_outflow_inputs(odd);
  const bool psm = psm_ && psm_->active();
  if (psm && psm_kinds_stale_)
    throw Error("internal: LBM geometry finalized after set_particles(): set the particles again before stepping");
  if (mb_ && mb_->active() && psm_kinds_stale_)
    throw Error("internal: LBM geometry finalized after set_particles(): set the particles again before stepping");
  bulk_sweep(odd, sample);  // covered bulk cells: the fused PSM kernel on their spans
  boundary_sweep(odd, sample);
  if (psm) psm_->reduce(Vec3(double(relax_.force[0]), double(relax_.force[1]), double(relax_.force[2])));
  // Solid particle cells: the links' bounce-back into the slots of the next step, then the reset.
  if (mb_) {
    if (mb_->active()) mb_->apply(f_.data(), odd, mb_inline_rows_);
    mb_->reduce();
  }
  reduce_forces();
  ++time_;
}

// The interpolated schemes need g*_q(x, t) of the population leaving the wall, which the
// neighbour x + c_q consumes during the same in-place step: copy it first.
template <class L, class T>
void Solver<L, T>::save_interpolation_inputs(bool odd) {
  const CellIndex N = n_();
  for (std::size_t l = 0; l < links_.size(); ++l) {
    const Link& k = links_[l];
    if (k.scheme == WallScheme::HalfwayBounceBack || !k.has_second) continue;
    const BoundaryCell& b = bcells_[k.cell];
    const int q = k.q, o = L::opp[q];
    // Post-collision slot of the previous step: even step -> own cell, swapped slot;
    // odd step -> the neighbour along c_q, regular slot.
    const CellIndex at = odd ? o * N + b.cell
                             : q * N + grid_.neighbour(b.x, b.y, b.z, L::c[q][0], L::c[q][1], L::c[q][2]);
    link_saved_[l] = f_[at];
  }
}

// Outflow donors that are bulk cells: their pre-collision populations g_q(x + n, t+1) are in the
// slots the bulk kernel overwrites, so copy them first (even step: own slots f[q][y]; odd step:
// the neighbours' swapped slots f[opp q][y - c_q]). Donors that are boundary cells copy theirs
// during their own update. Then each convective face's speed U from the previous step's
// outflow speeds, summed in node order (the same on any thread count).
template <class L, class T>
void Solver<L, T>::save_outflow_inputs(bool odd) {
  if (outflow_cells_.empty()) return;
  const CellIndex N = n_();
  for (const BulkDonor& d : bulk_donors_) {
    T* row = &donor_g_[std::size_t(Q) * d.row];
    row[0] = f_[d.cell];
    for (int q = 1; q < Q; ++q)
      row[q] = odd ? f_[L::opp[q] * N + grid_.neighbour(d.x, d.y, d.z, -L::c[q][0], -L::c[q][1], -L::c[q][2])]
                   : f_[q * N + d.cell];
  }
  std::array<double, kNumFaces> sum{};
  std::array<long, kNumFaces> count{};
  for (const std::int32_t i : outflow_cells_) {
    const OpenNode<T>& nd = open_[bcells_[i].open];
    sum[nd.face] += double(f_[nd.ghost]);
    ++count[nd.face];
  }
  for (int f = 0; f < kNumFaces; ++f) {
    const FaceCondition& fc = faces_[f];
    convective_u_[f] = T(0);
    if (fc.kind != FaceCondition::Kind::Outflow || fc.outflow != FaceCondition::Outflow::Convective) continue;
    // Backflow would make the implicit update an extrapolation against the flow: U >= 0.
    const double U = fc.convective_velocity > 0 ? fc.convective_velocity
                                                : (count[f] > 0 ? std::max(0.0, sum[f] / double(count[f])) : 0.0);
    convective_u_[f] = T(U);
  }
}

// Outflow nodes read what their donors (one layer inside) gathered this step, so they run in a
// second pass after every other boundary cell; each pass is parallel (cells own their slots).
template <class L, class T>
void Solver<L, T>::boundary_sweep(bool odd, bool sample) {
  const std::int64_t nb = std::int64_t(bcells_.size());
#pragma omp parallel for schedule(static) if (nb > kParallelMinCells / 8)
  for (std::int64_t i = 0; i < nb; ++i)
    if (!bcells_[std::size_t(i)].outflow) update_boundary_cell(std::size_t(i), odd, sample);
  const std::int64_t no = std::int64_t(outflow_cells_.size());
#pragma omp parallel for schedule(static) if (no > kParallelMinCells / 8)
  for (std::int64_t k = 0; k < no; ++k) update_boundary_cell(std::size_t(outflow_cells_[std::size_t(k)]), odd, sample);
}

// Unknown populations (c_q . n > 0) of an outflow node x from its donor x + n:
//   zero-gradient: g_q(x, t+1) = d_q
//   convective (Yang 2013, Comput. Math. Appl. 65:160, its convective condition with the face's
//   average speed or a set one; Lou, Guo & Shi 2013, Phys. Rev. E 87:063301):
//   g_q(x, t+1) = [g_q(x, t) + U d_q] / (1 + U), the implicit upwind form of dg/dt + U dg/dn_out = 0,
// with d_q = g_q(x + n, t+1) + w_q delta. The plain copy (delta = 0) hands the node the donor's
// density: where a flow has a density drop drho across the last cell, the node gains mass every
// step and the density of the whole lattice rises by about drho/3 per step without end (found in
// the Poiseuille test; derivation in docs/lbm.md). delta = rho(x) - rho(x + n) makes the
// unknowns carry the node's own density instead: with K the known populations of x, D the donor's
// unknown ones and W their weights, rho(x) - 1 = K + D + W delta, so delta = (K + D - rho_d + 1) / (1 - W).
// g_q(x, t) is kept in the slot q of the ghost x - n (never streamed: c_q points inward).
// A solid donor leaves nothing to copy: the node then bounces its unknowns back.
template <class L, class T>
void Solver<L, T>::apply_outflow(T* g, const BoundaryCell& b, const OpenNode<T>& nd, const CellIndex* src, bool odd) {
  const CellIndex N = n_();
  const bool convective = nd.kind == OpenKind::Convective;
  const T U = convective_u_[nd.face];
  const T* d = nd.donor >= 0 ? &donor_g_[std::size_t(Q) * nd.donor] : nullptr;
  T delta = 0;
  if (d && nd.density_free) {
    T known = g[0], unknown = 0, drho_d = d[0], W = 0;
    for (int q = 1; q < Q; ++q) {
      drho_d += d[q];
      if (b.open_mask & (1u << q)) {
        unknown += d[q];
        W += T(L::w[q]);
      } else {
        known += g[q];
      }
    }
    delta = (known + unknown - drho_d) / (T(1) - W);
  }
  for (int q = 1; q < Q; ++q) {
    if (!(b.open_mask & (1u << q))) continue;
    const T dq = d ? d[q] + T(L::w[q]) * delta : (odd ? f_[q * N + b.cell] : f_[L::opp[q] * N + src[q]]);
    if (convective) {
      T& prev = f_[q * N + nd.ghost];
      g[q] = (prev + U * dq) / (T(1) + U);
      prev = g[q];
    } else {
      g[q] = dq;
    }
  }
}

template <class L, class T>
void Solver<L, T>::update_boundary_cell(std::size_t i, bool odd, bool sample) {
  const BoundaryCell& b = bcells_[i];
  const CellIndex N = n_();
  T g[Q];
  CellIndex src[Q];  // x - c_q (so src[opp q] = x + c_q)
  for (int q = 0; q < Q; ++q) src[q] = grid_.neighbour(b.x, b.y, b.z, -L::c[q][0], -L::c[q][1], -L::c[q][2]);

  // 1. Streamed populations (AA pattern: even reads the own slot, odd the neighbour's swapped slot).
  g[0] = f_[b.cell];
  for (int q = 1; q < Q; ++q) {
    if ((b.link_mask | b.open_mask) & (1u << q)) continue;
    g[q] = odd ? f_[L::opp[q] * N + src[q]] : f_[q * N + b.cell];
  }
  // 2. Wall links: bounce-back (plain or interpolated) and the momentum exchange.
  for (int l = b.first_link; l < b.first_link + b.num_links; ++l) {
    const Link& k = links_[l];
    const int q = k.q, o = L::opp[q];
    const T A = odd ? f_[q * N + b.cell] : f_[o * N + src[q]];  // g*_o(x, t), where the wall left it
    const T* uw = &link_uw_[3 * l];
    const T cu = L::c[q][0] * uw[0] + L::c[q][1] * uw[1] + L::c[q][2] * uw[2];
    // rho_w = rho_0 = 1 (nearly incompressible, [S003] Sec. 2.3.2); inflow walls follow the ramp.
    const T mw = T(6 * L::w[q]) * cu * (k.object < kNumFaces && inflow_wall_[k.object] ? inflow_scale_ : T(1));
    const T B = link_saved_[l];
    const T C = k.has_second ? g[o] : T(0);
    const T gq = reflect<T>(k.scheme, T(k.delta), k.has_second, A, B, C, mw);
    g[q] = gq;
    // Momentum exchange on the link ([S003] Eq. 11) in the Galilean-invariant form of
    // Wen et al. (2014): F = (c_o - u_w) f*_o - (c_q - u_w) f_q, with c_q = -c_o.
    for (int a = 0; a < 3; ++a)
      link_force_[3 * l + a] = double(L::c[o][a]) * (double(A) + double(gq)) - double(uw[a]) * (double(A) - double(gq));
  }
  // 3. Open faces (Zou-He / Hecht-Harting): needs every other population first. Outflow
  //    faces copy or convect from the donor layer instead.
  if (b.outflow) {
    apply_outflow(g, b, open_[b.open], src, odd);
  } else if (b.open >= 0) {
    OpenNode<T> nd = open_[b.open];
    if (!nd.pressure)
      for (int a = 0; a < 3; ++a) nd.u[a] *= inflow_scale_;
    zou_he<L, T>(g, nd, settings_.incompressible);
  }
  // An outflow donor hands its gathered populations g_q(x, t+1) to the node outside it.
  if (b.capture >= 0) std::copy(g, g + Q, &donor_g_[std::size_t(Q) * b.capture]);
  // 4. Collide (a cell covered by particles keeps its pre-collision populations for the PSM).
  const std::int32_t psm_slot = psm_ && psm_->active() ? psm_->slot(b.cell) : -1;
  T gpre[Q];
  if (psm_slot >= 0) std::copy(g, g + Q, gpre);
  T drho, u[3];
  const bool force = settings_.body_force.squaredNorm() > 0;
  auto run = [&]<CollisionModel M, bool kIncomp>() {
    if (force) collide<L, T, M, true, kIncomp>(g, relax_, drho, u);
    else collide<L, T, M, false, kIncomp>(g, relax_, drho, u);
  };
  const bool trt = settings_.collision == CollisionModel::Trt;
  if (settings_.incompressible) {
    if (trt) run.template operator()<CollisionModel::Trt, true>();
    else run.template operator()<CollisionModel::Bgk, true>();
  } else {
    if (trt) run.template operator()<CollisionModel::Trt, false>();
    else run.template operator()<CollisionModel::Bgk, false>();
  }
  if (psm_slot >= 0) psm_->apply(psm_slot, gpre, g, relax_, force, settings_.incompressible);
  // 5. Store: even -> own cell, swapped slot; odd -> neighbour x + c_q, regular slot.
  f_[b.cell] = g[0];
  for (int q = 1; q < Q; ++q) {
    const int o = L::opp[q];
    if (odd) f_[q * N + src[o]] = g[q];
    else f_[o * N + b.cell] = g[q];
  }
  // Outflow speed of this node, for the face's convective speed of the next step.
  if (b.outflow) {
    const OpenNode<T>& nd = open_[b.open];
    f_[nd.ghost] = T(-nd.sign) * u[nd.axis];
  }
  if (sample) {
    drho_[b.cell] = drho;
    for (int a = 0; a < 3; ++a) u_[a][b.cell] = u[a];
  }
}

template <class L, class T>
void Solver<L, T>::moving_particles(const ParticleSet& p, bool bookkeeping) {
  if (!mb_) mb_ = std::make_unique<MovingBoundary<L, T>>(grid_, settings_.particle_scheme, settings_.incompressible);
  if (psm_kinds_stale_) {
    std::vector<std::uint8_t> fluid(std::size_t(n_()), 0);
    for (std::size_t i = 0; i < fluid.size(); ++i) fluid[i] = type_[i] == CellType::Fluid;
    for_each_bulk_cell([&](CellIndex i, std::size_t) { fluid[std::size_t(i)] = 2; });  // bulk cells
    mb_->set_fluid_mask(std::move(fluid));
    psm_kinds_stale_ = false;
  }
  mb_->set_reset_all(settings_.body_force.squaredNorm() > 0);
  mb_->set_row_index(settings_.links_in_sweep);
  mb_->set_particles(p, f_.data(), (time_ & 1) != 0, bookkeeping);
}

template <class L, class T>
void Solver<L, T>::restore_particles(const ParticleSet& last) {
  if (settings_.particle_scheme != ParticleScheme::Psm) moving_particles(last, false);
  else set_particles(last);
}

template <class L, class T>
void Solver<L, T>::restore_psm_geometry(const std::vector<Vec3>& positions, const std::vector<double>& radii) {
  if (settings_.particle_scheme != ParticleScheme::Psm) return;
  prepare_psm();
  psm_->restore_geometry(positions, radii);
}

template <class L, class T>
void Solver<L, T>::set_particles(const ParticleSet& p) {
  if (settings_.particle_scheme != ParticleScheme::Psm) return moving_particles(p, true);
  prepare_psm();
  psm_->set_particles(p);
}

// The PSM object and its cell classification (again after finalize() changed the geometry).
template <class L, class T>
void Solver<L, T>::prepare_psm() {
  if (!psm_) {
    psm_ = std::make_unique<Psm<L, T>>(grid_, settings_.tau, settings_.psm_weighting);
    psm_->set_refresh(settings_.psm_refresh);
  }
  if (psm_kinds_stale_) {
    std::vector<std::int32_t> span_of(std::size_t(n_()), Psm<L, T>::kNotFluid);
    for_each_bulk_cell([&](CellIndex i, std::size_t s) { span_of[std::size_t(i)] = std::int32_t(s); });
    for (const BoundaryCell& b : bcells_) span_of[std::size_t(b.cell)] = Psm<L, T>::kBoundaryCell;
    psm_->set_cell_spans(std::move(span_of), spans_.size());
    psm_kinds_stale_ = false;
  }
}

template <class L, class T>
const std::vector<Vec3>& Solver<L, T>::particle_forces() const {
  static const std::vector<Vec3> none;
  if (mb_) return mb_->forces();
  return psm_ ? psm_->forces() : none;
}

template <class L, class T>
const std::vector<Vec3>& Solver<L, T>::particle_torques() const {
  static const std::vector<Vec3> none;
  if (mb_) return mb_->torques();
  return psm_ ? psm_->torques() : none;
}

// Sums the link forces per object in link order: the same result on any thread count.
// Runs after Psm::reduce(), which it adds the particles' share of covered cells' wall links to.
template <class L, class T>
void Solver<L, T>::reduce_forces() {
  for (auto& o : objects_) {
    o.force.setZero();
    o.torque.setZero();
  }
  for (std::size_t l = 0; l < links_.size(); ++l) {
    const Link& k = links_[l];
    const BoundaryCell& b = bcells_[k.cell];
    if (mb_ && mb_->solid(b.cell)) continue;  // a particle covers the cell: its wall sees no fluid there
    SolidObject& obj = objects_[k.object];
    Vec3 F(link_force_[3 * l], link_force_[3 * l + 1], link_force_[3 * l + 2]);
    // A cell covered by PSM particles: the share B_s of the exchange's part tangential to the wall
    // pushes particle s; the wall keeps the normal part and (1 - B) of the tangential one
    // (lbm/psm.hpp, "Wall links of covered cells"). Wall normal: the sum of the cell's link
    // directions towards the wall.
    if (psm_ && psm_->active() && psm_->slot(b.cell) >= 0) {
      Vec3 n = Vec3::Zero();
      for (int j = b.first_link; j < b.first_link + b.num_links; ++j) {
        const int oj = L::opp[links_[std::size_t(j)].q];
        n += Vec3(L::c[oj][0], L::c[oj][1], L::c[oj][2]);
      }
      const double nn = n.squaredNorm();
      const Vec3 Ft = nn > 0 ? Vec3(F - (F.dot(n) / nn) * n) : F;
      F -= psm_->book_wall_link(b.cell, Ft);
    }
    const int o = L::opp[k.q];
    const Vec3 xw = Vec3(b.x, b.y, b.z) + double(k.delta) * Vec3(L::c[o][0], L::c[o][1], L::c[o][2]);
    obj.force += F;
    obj.torque += (xw - obj.center).cross(F);
  }
}

// Slot of g_q(x) for the next step (AA pattern, bulk_sweep.cpp): even steps read f[q][x], odd
// steps f[opp q][x - c_q].
template <class L, class T>
bool Solver<L, T>::covered(int x, int y, int z) const {
  const CellIndex c = grid_.index(x, y, z);
  return type_[c] != CellType::Fluid || (mb_ && mb_->solid(c));
}

template <class L, class T>
double Solver<L, T>::cell_density(int x, int y, int z) const {
  const bool odd = (time_ & 1) != 0;
  const CellIndex N = n_(), c = grid_.index(x, y, z);
  double rho = 1.0 + double(f_[c]);  // populations are stored shifted by their weights (collision.hpp)
  for (int q = 1; q < Q; ++q)
    rho += odd ? double(f_[L::opp[q] * N + grid_.neighbour(x, y, z, -L::c[q][0], -L::c[q][1], -L::c[q][2])])
               : double(f_[q * N + c]);
  return rho;
}

template <class L, class T>
double Solver<L, T>::put_equilibrium(const std::array<int, 3>& x, const T* geq, double rho) {
  const double added = rho - cell_density(x[0], x[1], x[2]);
  const bool odd = (time_ & 1) != 0;
  const CellIndex N = n_(), c = grid_.index(x[0], x[1], x[2]);
  f_[c] = geq[0];
  for (int q = 1; q < Q; ++q)
    f_[odd ? L::opp[q] * N + grid_.neighbour(x[0], x[1], x[2], -L::c[q][0], -L::c[q][1], -L::c[q][2]) : q * N + c] = geq[q];
  return added;
}

template <class L, class T>
double Solver<L, T>::impose_equilibrium(const std::vector<std::array<int, 3>>& cells, double rho, const Vec3& u) {
  T geq[Q];
  const T uu[3] = {T(u.x()), T(u.y()), T(u.z())};
  equilibrium<L, T>(T(rho), uu, geq, settings_.incompressible);
  double added = 0;
  for (const auto& x : cells)
    if (!covered(x[0], x[1], x[2])) added += put_equilibrium(x, geq, rho);
  return added;
}

template <class L, class T>
double Solver<L, T>::impose_equilibrium(const std::vector<std::array<int, 3>>& cells, double rho,
                                        const std::vector<Vec3>& u_dir, double u_scale) {
  T geq[Q];
  double added = 0;
  for (std::size_t k = 0; k < cells.size(); ++k) {
    if (covered(cells[k][0], cells[k][1], cells[k][2])) continue;
    const T uu[3] = {T(u_scale * u_dir[k].x()), T(u_scale * u_dir[k].y()), T(u_scale * u_dir[k].z())};
    equilibrium<L, T>(T(rho), uu, geq, settings_.incompressible);
    added += put_equilibrium(cells[k], geq, rho);
  }
  return added;
}

template class Solver<D2Q9, double>;
template class Solver<D2Q9, float>;
template class Solver<D3Q19, double>;
template class Solver<D3Q19, float>;

}  // namespace ff::lbm
