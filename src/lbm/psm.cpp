// Partially saturated cells: covered fractions, the PSM update and the per-particle loads
// (psm.hpp has the equations and their sources).
#include "lbm/psm.hpp"

#include <fmt/format.h>
#include <omp.h>

#include <algorithm>
#include <cmath>

#include "core/error.hpp"

namespace ff::lbm {

namespace {

// Volume of {xi in [0,1]^k : m . xi <= a} for m_i > 0 (inclusion-exclusion over the corners of
// the cube: each corner v cuts off the simplex (a - m.v)^k / (k! prod m), signed by its parity).
double box_below_plane(const double* m, int k, double a) {
  double sum_m = 0;
  for (int i = 0; i < k; ++i) sum_m += m[i];
  if (a <= 0) return 0;
  if (a >= sum_m) return 1;
  if (k == 1) return a / m[0];
  double acc = 0, prod = 1, fact = 1;
  for (int i = 0; i < k; ++i) {
    prod *= m[i];
    fact *= i + 1;
  }
  // Corners in the order v = 0 .. 2^k - 1 (bit i: m_i subtracted, in ascending i), those with s <= 0
  // adding zero: no branch per corner (the same sums, bit for bit, as skipping them).
  auto cut = [k](double t) { return t > 0 ? (k == 2 ? t * t : t * t * t) : 0.0; };
  if (k == 2) {
    const double s1 = a - m[0];
    acc = ((cut(a) - cut(s1)) - cut(a - m[1])) + cut(s1 - m[1]);
  } else {
    const double s1 = a - m[0], s2 = a - m[1], s3 = s1 - m[1];
    acc = ((((((cut(a) - cut(s1)) - cut(s2)) + cut(s3)) - cut(a - m[2])) + cut(s1 - m[2])) + cut(s2 - m[2])) -
          cut(s3 - m[2]);
  }
  return std::clamp(acc / (fact * prod), 0.0, 1.0);
}

// Along one axis, the cells a particle (centre X, radius r) can cover: those whose centre lies within
// r + 1/2 of X. build() visits no cell outside this box, and reduce()'s blocks are sized by it.
struct AxisRange {
  int lo, hi;
};
AxisRange covered_range(double X, double r) { return {int(std::ceil(X - r - 0.5)), int(std::floor(X + r + 0.5))}; }

}  // namespace

double psm_cell_fraction(int dim, const Vec3& d, double r) {
  const double dz = dim == 3 ? d[2] : 0.0;
  const double dist = std::sqrt(d[0] * d[0] + d[1] * d[1] + dz * dz);
  const double half_diag = dim == 3 ? std::sqrt(0.75) : std::sqrt(0.5);
  if (dist + half_diag <= r) return 1;  // the farthest corner is inside
  if (dist - half_diag >= r) return 0;  // the nearest point is outside
  // Plane tangent on the ray through the cell centre, moved in by the mean gap to the surface
  // over the cell's cross-section: <rho^2>/(2 r) with <rho^2> = (D - 1)/12.
  const double rc = r - (dim - 1) / (24.0 * std::max(r, 1.0));
  double n[3] = {1, 0, 0};
  if (dist > 1e-12) n[0] = std::abs(d[0]) / dist, n[1] = std::abs(d[1]) / dist, n[2] = std::abs(dz) / dist;
  // In cell coordinates xi in [0,1]^D with the axes flipped so that n >= 0: n . xi <= rc - dist + sum(n)/2.
  double m[3];
  int k = 0;
  double a = rc - dist;
  for (int i = 0; i < dim; ++i) {
    a += 0.5 * n[i];
    // Components below 1e-4 are dropped (the cube is then a prism along that axis): this keeps
    // the 1/prod(m) of the corner sum well conditioned at an error below 1e-4.
    if (n[i] >= 1e-4) m[k++] = n[i];
    else a -= 0.5 * n[i];
  }
  return box_below_plane(m, k, a);
}

template <class L, class T>
Psm<L, T>::Psm(const Grid& grid, double tau, PsmWeighting weighting) : grid_(grid), tau_(tau), weighting_(weighting) {}

template <class L, class T>
void Psm<L, T>::set_particles(const ParticleSet& p) {
  const std::size_t np = p.size();
  if (p.position.size() != np || p.velocity.size() != np || p.omega.size() != np || (!p.id.empty() && p.id.size() != np))
    throw InputError(fmt::format("PSM particle set: the arrays differ in length (radius {}, position {}, velocity {}, "
                                 "omega {}, id {}): all must have one entry per particle (id may be empty)",
                                 np, p.position.size(), p.velocity.size(), p.omega.size(), p.id.size()));
  if (np >= std::size_t(INT32_MAX)) throw InputError("PSM particle set: more than 2^31 - 1 particles");
  const int D = L::D;
  const int n[3] = {grid_.nx, grid_.ny, grid_.nz};
  // Checked before anything changes, so that bad input leaves the current set intact.
  for (std::size_t s = 0; s < np; ++s) {
    const Vec3& X = p.position[s];
    const double r = p.radius[s];
    bool ok = std::isfinite(r) && r > 0;
    for (int a = 0; a < D; ++a) ok = ok && std::isfinite(X[a]) && (!grid_.periodic[a] || 2 * r < n[a]);
    if (!ok)
      throw InputError(fmt::format("PSM particle {} (id {}): radius {} at ({}, {}, {}) must be finite and positive "
                                   "(and below half the lattice along a periodic axis), position finite",
                                   s, p.id.empty() ? s : p.id[s], r, X[0], X[1], X[2]));
  }
  // Fractions kept: every particle within refresh_ cells of where they were computed.
  if (refresh_ > 0 && !ref_radius_.empty() && within_refresh(p, ref_pos_, ref_radius_, refresh_, D)) {
    take_kinematics(p);
    return;
  }
  build(p);
}

bool within_refresh(const ParticleSet& p, const std::vector<Vec3>& positions, const std::vector<double>& radii,
                    double cells, int dim) {
  if (positions.size() != p.size() || radii.size() != p.size()) return false;
  const double lim2 = cells * cells;
  for (std::size_t s = 0; s < p.size(); ++s) {
    Vec3 d = p.position[s] - positions[s];
    if (dim == 2) d[2] = 0;
    if (p.radius[s] != radii[s] || d.squaredNorm() > lim2) return false;
  }
  return true;
}

template <class L, class T>
void Psm<L, T>::take_kinematics(const ParticleSet& p) {
  const std::size_t np = p.size();
  bool same = true, moving = false;
  for (std::size_t s = 0; s < np; ++s) {
    const Kinematics k = kinematics(p, s);
    same = same && k.v == kin_[s].v && k.w == kin_[s].w;
    moving = moving || k.moves();
    kin_[s] = k;
  }
  moving_ = moving;
  if (same || !moving) return;  // (quasi-static walls: nothing moves; V and S not read)
  const std::int64_t ncell = std::int64_t(cells_.size());
#pragma omp parallel for schedule(static) if (ncell > 16384)
  for (std::int64_t i = 0; i < ncell; ++i) {
    const Cell& c = cells_[std::size_t(i)];
    if (!c.boundary) cell_velocity_sums(c);
  }
}

// V = sum_s B_s u_s and S = sum_s B_s u_s u_s^T of a bulk cell, u_s = v + w x arm at its centre.
template <class L, class T>
void Psm<L, T>::cell_velocity_sums(const Cell& c) {
  constexpr int D = L::D;
  const std::size_t x = std::size_t(c.cell);
  // Most cells have one particle: its V and S directly (the same values as the sums below; without
  // this case the velocity pass of benchmarks/coupled psm-r cost ~20 % more: 8.9-9.7 vs 7.1-8.8 ms).
  if (c.count == 1) {
    const Entry& e = entries_[std::size_t(c.first)];
    const Kinematics& m = kin_[std::size_t(e.particle)];
    const Vec3 us = m.v + m.w.cross(e.arm);
    const double Bs = double(e.Bs);
    int n = 0;
    for (int a = 0; a < D; ++a) {
      cell_V_[a][x] = T(Bs * us[a]);
      for (int b = a; b < D; ++b) cell_S_[n++][x] = T(Bs * us[a] * us[b]);
    }
    return;
  }
  double V[3] = {0, 0, 0}, S[6] = {0, 0, 0, 0, 0, 0};
  for (std::int32_t k = c.first; k < c.first + c.count; ++k) {
    const Entry& e = entries_[std::size_t(k)];
    const Kinematics& m = kin_[std::size_t(e.particle)];
    const Vec3 us = m.v + m.w.cross(e.arm);
    const double Bs = double(e.Bs);
    int n = 0;
    for (int a = 0; a < D; ++a) {
      V[a] += Bs * us[a];
      for (int b = a; b < D; ++b) S[n++] += Bs * us[a] * us[b];
    }
  }
  for (int a = 0; a < D; ++a) cell_V_[a][x] = T(V[a]);
  for (int n = 0; n < kS; ++n) cell_S_[n][x] = T(S[n]);
}

template <class L, class T>
void Psm<L, T>::restore_geometry(const std::vector<Vec3>& positions, const std::vector<double>& radii) {
  ParticleSet g;
  g.resize(radii.size());
  g.position = positions;  // (a length mismatch is set_particles' error)
  g.radius = radii;
  ref_radius_.clear();  // nothing to keep: built from exactly these
  set_particles(g);
}

template <class L, class T>
void Psm<L, T>::build(const ParticleSet& p) {
  const std::size_t np = p.size();
  const int D = L::D;
  const int n[3] = {grid_.nx, grid_.ny, grid_.nz};
  ++rebuilds_;
  ref_pos_ = p.position;
  ref_radius_ = p.radius;
  if (slot_.empty()) {
    const std::size_t N = std::size_t(grid_.padded_size());
    slot_.assign(N, -1);
    cell_B_.assign(N, T(0));
    cell_rho_.assign(N, T(0));
    for (int a = 0; a < D; ++a) {
      cell_V_[a].assign(N, T(0));
      cell_u_[a].assign(N, T(0));
    }
    for (int k = 0; k < kS; ++k) cell_S_[k].assign(N, T(0));
  }
  for (const Cell& c : cells_) {
    slot_[std::size_t(c.cell)] = -1;
    cell_B_[std::size_t(c.cell)] = T(0);
  }
  for (const std::int32_t sp : fused_spans_) span_fused_[std::size_t(sp)] = 0;
  fused_spans_.clear();
  // (cells_ and entries_ are overwritten below: resized, not cleared, so that only new elements are built)
  kin_.resize(np);
  moving_ = false;
  for (std::size_t s = 0; s < np; ++s) {
    kin_[s] = kinematics(p, s);
    moving_ = moving_ || kin_[s].moves();
  }
  // 1. Each particle into the lattice rows (y, z) its reach crosses, in particle order (a counting
  //    sort by row; with the unwrapped y, z for its arms).
  const std::size_t nrows = std::size_t(n[1]) * std::size_t(n[2]);
  const double half_diag = D == 3 ? std::sqrt(0.75) : std::sqrt(0.5);
  row_first_.assign(nrows + 1, 0);
  auto for_each_row = [&](std::size_t s, auto&& f) {
    const Vec3& X = p.position[s];
    const double r = p.radius[s], reach2 = (r + half_diag) * (r + half_diag);
    const AxisRange ry = covered_range(X[1], r), rz = D == 3 ? covered_range(X[2], r) : AxisRange{0, 0};
    const int lo1 = ry.lo, hi1 = ry.hi, lo2 = rz.lo, hi2 = rz.hi;
    for (int z = lo2; z <= hi2; ++z)
      for (int y = lo1; y <= hi1; ++y) {
        const double dy = y - X[1], dz = D == 3 ? z - X[2] : 0.0;
        if (reach2 - dy * dy - dz * dz < -1e-9) continue;  // (margins: rounding never drops a covered cell)
        const int cy = wrap_axis(y, n[1], grid_.periodic[1]), cz = D == 3 ? wrap_axis(z, n[2], grid_.periodic[2]) : 0;
        if (cy < 0 || cz < 0) continue;
        f(std::size_t(cy) + std::size_t(n[1]) * std::size_t(cz), y, z);
      }
  };
  for (std::size_t s = 0; s < np; ++s) for_each_row(s, [&](std::size_t row, int, int) { ++row_first_[row + 1]; });
  for (std::size_t row = 0; row < nrows; ++row) row_first_[row + 1] += row_first_[row];
  row_item_.resize(std::size_t(row_first_[nrows]));
  row_fill_.assign(row_first_.begin(), row_first_.end() - 1);
  for (std::size_t s = 0; s < np; ++s)
    for_each_row(s, [&](std::size_t row, int y, int z) {
      row_item_[std::size_t(row_fill_[row]++)] = RowItem{std::int32_t(s), y, z};
    });
  // 2. Row by row, in parallel (each row writes its own buffers): the fractions of the row's cells
  //    for each particle in turn, then its covered cells in x order, each with its entries in
  //    particle order (a stable counting sort by x).
  //    Each thread appends its rows to its own buffers (rows dealt out in fixed chunks, so that the
  //    buffers keep their sizes from step to step: no allocation once they have grown).
  const int nthreads = omp_get_max_threads();
  if (int(scratch_.size()) < nthreads) scratch_.resize(std::size_t(nthreads));
  row_out_.resize(nrows);
#pragma omp parallel if (np > 256)
  {
    const int t = omp_get_thread_num();
    RowScratch& sc = scratch_[std::size_t(t)];
    if (sc.count.size() < std::size_t(n[0]) + 1) sc.count.assign(std::size_t(n[0]) + 1, 0);
    sc.cells.clear();
    sc.entries.clear();
#pragma omp for schedule(static, 16)
    for (std::int64_t rr = 0; rr < std::int64_t(nrows); ++rr) {
      const std::size_t row = std::size_t(rr);
      RowOut& ro = row_out_[row];
      ro = RowOut{t, std::int64_t(sc.cells.size()), 0, std::int64_t(sc.entries.size()), 0, 0, 0};
      if (row_first_[row] == row_first_[row + 1]) continue;
      const int cy = int(row % std::size_t(n[1])), cz = int(row / std::size_t(n[1]));
      auto& cand = sc.cand;
      cand.clear();
      int xmin = n[0], xmax = -1;
      for (std::int64_t it = row_first_[row]; it < row_first_[row + 1]; ++it) {
        const RowItem& item = row_item_[std::size_t(it)];
        const std::size_t s = std::size_t(item.particle);
        const Vec3& X = p.position[s];
        const double r = p.radius[s], reach2 = (r + half_diag) * (r + half_diag);
        const double dy = item.y - X[1], dz = D == 3 ? item.z - X[2] : 0.0;
        // Along x only the cells within r + half a cell diagonal of the centre can be covered
        // (psm_cell_fraction() is 0 beyond): the row visits that range, not the whole box.
        const double half = std::sqrt(std::max(reach2 - dy * dy - dz * dz, 0.0)) + 1e-9;
        const AxisRange rx = covered_range(X[0], r);
        const int lo0 = rx.lo, hi0 = rx.hi;
        const int x0 = std::max(lo0, int(std::floor(X[0] - half))), x1 = std::min(hi0, int(std::ceil(X[0] + half)));
        // Cells whose farthest corner is well inside (squared distances, a margin of 1e-12 so that
        // psm_cell_fraction's own test would say 1 too) skip its square root and corner sums.
        const double inner = r > half_diag ? (r - half_diag) * (r - half_diag) * (1 - 1e-12) : -1.0;
        const double dyz2 = dy * dy + dz * dz;
        for (int x = x0; x <= x1; ++x) {
          const int cx = wrap_axis(x, n[0], grid_.periodic[0]);
          if (cx < 0) continue;
          if (span_of_[std::size_t(grid_.index(cx, cy, cz))] == kNotFluid) continue;
          const Vec3 arm = D == 3 ? Vec3(x - X[0], item.y - X[1], item.z - X[2]) : Vec3(x - X[0], item.y - X[1], 0);
          const double eps = arm[0] * arm[0] + dyz2 < inner ? 1.0 : psm_cell_fraction(D, arm, r);
          if (eps <= 0) continue;
          cand.push_back(RowCandidate{cx, item.particle, eps, arm});
          xmin = std::min(xmin, cx);
          xmax = std::max(xmax, cx);
        }
      }
      if (cand.empty()) continue;
      std::vector<Cell>& out_cells = sc.cells;
      std::vector<Entry>& out_entries = sc.entries;
      const std::int32_t e_begin = std::int32_t(out_entries.size());
      const std::size_t c_begin = out_cells.size();
      auto& count = sc.count;  // entries per x, then the first entry of each x (zero outside [xmin, xmax])
      for (const RowCandidate& c : cand) ++count[std::size_t(c.x) + 1];
      const bool edge_yz = (grid_.periodic[1] && (cy == 0 || cy == n[1] - 1)) ||
                           (D == 3 && grid_.periodic[2] && (cz == 0 || cz == n[2] - 1));
      std::int32_t first = e_begin;  // (offsets in the thread's entries, moved to entries_ below)
      for (int x = xmin; x <= xmax; ++x) {
        const std::int32_t k = count[std::size_t(x) + 1];
        if (k == 0) continue;
        const CellIndex ci = grid_.index(x, cy, cz);
        const bool edge = edge_yz || (grid_.periodic[0] && (x == 0 || x == n[0] - 1));  // (neighbours wrap)
        out_cells.push_back(Cell{ci, first, k, 0.0, T(0), span_of_[std::size_t(ci)] == kBoundaryCell, edge});
        count[std::size_t(x) + 1] = first;  // now the cursor of x's entries
        first += k;
      }
      out_entries.resize(std::size_t(e_begin) + cand.size());
      for (const RowCandidate& c : cand)
        out_entries[std::size_t(count[std::size_t(c.x) + 1]++)] = Entry{c.particle, T(0), c.eps, c.arm};
      for (int x = xmin; x <= xmax + 1; ++x) count[std::size_t(x)] = 0;
      for (std::size_t i = c_begin; i < out_cells.size(); ++i) {  // eps summed in particle order
        Cell& c = out_cells[i];
        for (std::int32_t k = c.first; k < c.first + c.count; ++k) c.eps += out_entries[std::size_t(k)].eps;
      }
      ro.cells = std::int64_t(out_cells.size() - c_begin);
      ro.entries = std::int64_t(cand.size());
    }
  }
  // 3. The rows' cells and entries concatenated in lattice order (x fastest), as the sweeps visit
  //    them (in order of first touch, the random reads of cells and entries made the update 5-10
  //    times slower than its arithmetic).
  std::size_t ncells = 0, nentries = 0;
  for (RowOut& ro : row_out_) {
    ro.cell_dest = std::int64_t(ncells);
    ro.entry_dest = std::int64_t(nentries);
    ncells += std::size_t(ro.cells);
    nentries += std::size_t(ro.entries);
  }
  if (nentries >= std::size_t(INT32_MAX)) throw InputError("PSM particle set: more than 2^31 - 1 cell entries");
  cells_.resize(ncells);
  entries_.resize(nentries);
#pragma omp parallel for schedule(dynamic, 64) if (ncells > 16384)
  for (std::int64_t rr = 0; rr < std::int64_t(nrows); ++rr) {
    const std::size_t row = std::size_t(rr);
    const RowOut& ro = row_out_[row];
    const RowScratch& sc = scratch_[std::size_t(ro.thread)];
    const std::size_t c0 = std::size_t(ro.cell_dest), e0 = std::size_t(ro.entry_dest);
    const std::int64_t shift = std::int64_t(e0) - ro.entry_begin;
    for (std::int64_t i = 0; i < ro.cells; ++i) {
      Cell c = sc.cells[std::size_t(ro.cell_begin + i)];
      c.first = std::int32_t(c.first + shift);
      cells_[c0 + std::size_t(i)] = c;
      slot_[std::size_t(c.cell)] = std::int32_t(c0 + std::size_t(i));
    }
    const auto from = sc.entries.begin() + std::ptrdiff_t(ro.entry_begin);
    std::copy(from, from + std::ptrdiff_t(ro.entries), entries_.begin() + std::ptrdiff_t(e0));
  }
  // The weights B and B_s, cell by cell (each cell writes its own entries).
  const std::int64_t ncell = std::int64_t(cells_.size());
#pragma omp parallel for schedule(static) if (ncell > 16384)
  for (std::int64_t i = 0; i < ncell; ++i) {
    Cell& c = cells_[std::size_t(i)];
    const double B = psm_weight(std::min(1.0, c.eps), tau_, weighting_);
    c.B = T(B);
    if (c.count == 1) entries_[std::size_t(c.first)].Bs = T(B);  // (most cells: no division)
    else
      for (std::int32_t k = c.first; k < c.first + c.count; ++k) entries_[std::size_t(k)].Bs = T(B * entries_[std::size_t(k)].eps / c.eps);
    if (!c.boundary) {  // the fused kernel's per-cell B, V and S (S and V only if something moves)
      cell_B_[std::size_t(c.cell)] = T(B);
      if (moving_) cell_velocity_sums(c);
    }
  }
  // Spans that run the fused kernel.
  for (const Cell& c : cells_) {
    if (c.boundary) continue;
    const std::int32_t sp = span_of_[std::size_t(c.cell)];
    if (!span_fused_[std::size_t(sp)]) {
      span_fused_[std::size_t(sp)] = 1;
      fused_spans_.push_back(sp);
    }
  }
  runs_built_ = false;  // (built by the first reduce() that needs them)
  entry_force_.resize(3 * entries_.size());  // every boundary entry is written by its cell's update
  force_.assign(np, Vec3::Zero());
  torque_.assign(np, Vec3::Zero());
  wall_force_.assign(np, Vec3::Zero());
}

template <class L, class T>
void Psm<L, T>::set_cell_spans(std::vector<std::int32_t> span_of_cell, std::size_t num_spans) {
  for (const Cell& c : cells_) {
    slot_[std::size_t(c.cell)] = -1;
    cell_B_[std::size_t(c.cell)] = T(0);
  }
  span_fused_.assign(num_spans, 0);
  fused_spans_.clear();
  cells_.clear();
  entries_.clear();
  runs_.clear();
  runs_built_ = false;
  ref_pos_.clear();  // no fractions to keep: the next set_particles() rebuilds
  ref_radius_.clear();
  span_of_ = std::move(span_of_cell);
}

// Shifted equilibrium (as equilibrium() in collision.hpp) with compile-time directions.
template <class L, class T>
FF_LBM_INLINE void psm_equilibrium(T rho, T rho_u, const T* u, T* geq) {
  const T usq15 = T(1.5) * (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
  static_for<L::Q>([&](auto q) FF_LBM_LAMBDA_INLINE {
    const T cu = cdot<L::c[q][0], L::c[q][1], L::c[q][2]>(u[0], u[1], u[2]);
    geq[q] = T(L::w[q]) * ((rho - T(1)) + rho_u * (T(3) * cu + T(4.5) * cu * cu - usq15));
  });
}

template <class L, class T>
void Psm<L, T>::apply(std::int32_t sl, const T* gpre, T* g, const Relax<T>& r, bool force, bool incomp) {
  const Cell& c = cells_[std::size_t(sl)];
  // Fluid moments of the pre-collision state (Guo's half force included, as in collide()).
  T drho = 0, j[3] = {0, 0, 0};
  static_for<Q>([&](auto q) FF_LBM_LAMBDA_INLINE {
    drho += gpre[q];
    static_for<L::D>([&](auto a) FF_LBM_LAMBDA_INLINE {
      if constexpr (L::c[q][a] > 0) j[a] += gpre[q];
      if constexpr (L::c[q][a] < 0) j[a] -= gpre[q];
    });
  });
  if (force)
    for (int a = 0; a < L::D; ++a) j[a] += T(0.5) * r.force[a];
  const T rho = T(1) + drho;
  const T rho_u = incomp ? T(1) : rho;
  const T inv = incomp ? T(1) : T(1) / rho;
  const T u[3] = {j[0] * inv, j[1] * inv, j[2] * inv};
  T geq_f[Q], geq_s[Q], sum[Q];
  psm_equilibrium<L, T>(rho, rho_u, u, geq_f);
  for (int q = 0; q < Q; ++q) sum[q] = T(0);
  for (std::int32_t k = c.first; k < c.first + c.count; ++k) {
    const Entry& e = entries_[std::size_t(k)];
    const Kinematics& m = kin_[std::size_t(e.particle)];
    const Vec3 us = m.v + m.w.cross(e.arm);
    const T ut[3] = {T(us[0]), T(us[1]), T(L::D == 3 ? us[2] : 0.0)};
    psm_equilibrium<L, T>(rho, rho_u, ut, geq_s);
    double F[3] = {0, 0, 0};
    const T Bs = e.Bs;
    static_for<Q>([&](auto q) FF_LBM_LAMBDA_INLINE {
      constexpr int o = L::opp[q];
      const T om = Bs * ((gpre[o] - gpre[q]) + (geq_s[q] - geq_f[o]));
      sum[q] += om;
      static_for<L::D>([&](auto a) FF_LBM_LAMBDA_INLINE {
        if constexpr (L::c[q][a] > 0) F[a] -= double(om);
        if constexpr (L::c[q][a] < 0) F[a] += double(om);
      });
    });
    for (int a = 0; a < 3; ++a) entry_force_[3 * std::size_t(k) + std::size_t(a)] = F[a];
  }
  const T B = c.B, fluid = T(1) - B;
  for (int q = 0; q < Q; ++q) g[q] = fluid * g[q] + B * gpre[q] + sum[q];
}

template <class L, class T>
void Psm<L, T>::reduce(const Vec3& body_force) {
  // One pass over the covered cells in lattice order (runs_: build_runs), each item adding to its
  // particle: a fixed order, the same on any thread count (per particle in parallel, the reads of the
  // cells' moments scattered over the lattice cost 3-5 times this pass; with every particle at rest
  // the pass runs in blocks of planes, the even blocks in parallel, then the odd ones). Bulk cells:
  // F_s = -B_s sum_q c_q Omega^s_q(u_s) = B_s (rho (u - u_s) - f_body), by the lattice's isotropy
  // (sum_q c_q f^eq_q(rho, w) = rho w; rho u = j + f_body / 2 with j the pre-collision momentum,
  // Guo's forcing), from the cell's moments written by the kernel; boundary cells: apply()'s forces.
  const Vec3 fb = L::D == 3 ? body_force : Vec3(body_force[0], body_force[1], 0);
  std::fill(force_.begin(), force_.end(), Vec3::Zero());
  std::fill(torque_.begin(), torque_.end(), Vec3::Zero());
  std::fill(wall_force_.begin(), wall_force_.end(), Vec3::Zero());
  // A particle's entries come in runs: its sums are carried in registers over a run and stored at
  // its end (a chain through memory per entry cost twice the arithmetic). One accumulator per pass.
  struct Acc {
    std::int32_t cur = -1;
    Vec3 F = Vec3::Zero(), M = Vec3::Zero();
  };
  auto take = [&](Acc& A, std::int32_t s) FF_LBM_LAMBDA_INLINE {
    if (s == A.cur) return;
    if (A.cur >= 0) {
      force_[std::size_t(A.cur)] = A.F;
      torque_[std::size_t(A.cur)] = A.M;
    }
    A.cur = s;
    A.F = force_[std::size_t(s)];
    A.M = torque_[std::size_t(s)];
  };
  auto flush = [&](Acc& A) {
    if (A.cur >= 0) {
      force_[std::size_t(A.cur)] = A.F;
      torque_[std::size_t(A.cur)] = A.M;
    }
  };
  auto cell_force = [&](Acc& A, const Cell& c) FF_LBM_LAMBDA_INLINE {
    if (c.boundary) {
      for (std::int32_t k = c.first; k < c.first + c.count; ++k) {
        const Entry& e = entries_[std::size_t(k)];
        const std::size_t kk = std::size_t(k);
        const Vec3 Fk(entry_force_[3 * kk], entry_force_[3 * kk + 1], entry_force_[3 * kk + 2]);
        take(A, e.particle);
        A.F += Fk;
        A.M += e.arm.cross(Fk);
      }
      return;
    }
    const std::size_t x = std::size_t(c.cell);
    const double rho = double(cell_rho_[x]);
    const Vec3 u{double(cell_u_[0][x]), double(cell_u_[1][x]), L::D == 3 ? double(cell_u_[2][x]) : 0.0};
    for (std::int32_t k = c.first; k < c.first + c.count; ++k) {
      const Entry& e = entries_[std::size_t(k)];
      const Kinematics& m = kin_[std::size_t(e.particle)];
      const Vec3 Fk = double(e.Bs) * (rho * (u - (m.v + m.w.cross(e.arm))) - fb);
      take(A, e.particle);
      A.F += Fk;
      A.M += e.arm.cross(Fk);
    }
  };
  if (moving_) {
    // Moving walls hand a new set over every step: each cell's force from its entries (building the
    // runs below would cost more than they save).
    Acc A;
    for (const Cell& c : cells_) cell_force(A, c);
    flush(A);
    return;
  }
  // Quasi-static walls (u_s = 0) keep a set for many steps: its runs, built once per set.
  if (!runs_built_) {
    build_runs();
    runs_built_ = true;
  }
  // The cells' forces B (rho u - f_b) as the fused kernel wrote them (psm_sweep.cpp).
  const int nn[3] = {grid_.nx, grid_.ny, grid_.nz};
  auto rows = [&](std::int64_t r0, std::int64_t r1) {
    Acc A;
    for (std::int64_t row = r0; row < r1; ++row) {
      const std::int64_t k0 = row_runs_[std::size_t(row)], k1 = row_runs_[std::size_t(row) + 1];
      if (k0 == k1) continue;
      const int cy = int(row % nn[1]), cz = int(row / nn[1]);
      const CellIndex base = grid_.index(0, cy, cz);
      for (std::int64_t k = k0; k < k1; ++k) {
        const Run& run = runs_[std::size_t(k)];
        const std::size_t x0 = std::size_t(base + run.x);
        if (run.particle < 0) {  // a boundary cell
          cell_force(A, cells_[std::size_t(slot_[x0])]);
          continue;
        }
        const Vec3& arm = run.arm;
        if (run.count == 1) {  // F_s = (B_s / B) B (rho u - f_b)
          const double sh = double(run.share);
          const Vec3 Fk(sh * double(cell_u_[0][x0]), sh * double(cell_u_[1][x0]),
                        L::D == 3 ? sh * double(cell_u_[2][x0]) : 0.0);
          take(A, run.particle);
          A.F += Fk;
          A.M += arm.cross(Fk);
          continue;
        }
        // A run of n cells of one particle along x (B_s = B), k = 0 .. n-1, arms a_k = a_0 + k e_x:
        // the cell forces F_k sum to F, and sum_k a_k x F_k = a_0 x F + e_x x sum_k k F_k. Two
        // contiguous sums per run instead of a force per cell.
        const T* fp[3] = {cell_u_[0].data() + x0, cell_u_[1].data() + x0, L::D == 3 ? cell_u_[2].data() + x0 : nullptr};
        double J0[3] = {0, 0, 0}, J1[3] = {0, 0, 0};
        for (std::int32_t j = 0; j < run.count; ++j) {
          const double kk = double(j);
          for (int a = 0; a < L::D; ++a) {
            const double f = double(fp[a][j]);
            J0[a] += f;
            J1[a] += kk * f;
          }
        }
        const Vec3 Fr(J0[0], J0[1], J0[2]), F1(J1[0], J1[1], J1[2]);
        take(A, run.particle);
        A.F += Fr;
        A.M += arm.cross(Fr) + Vec3(1, 0, 0).cross(F1);
      }
    }
    flush(A);
  };
  // Blocks of rows (reduce_blocks_, build_runs) at least as tall as any particle: a particle's items
  // lie in one block or two neighbours, so the even blocks run in parallel, then the odd ones. The
  // blocks do not depend on the thread count, nor then does any particle's order of sums.
  const std::int64_t nb = std::int64_t(reduce_blocks_.size()) - 1;
  if (nb <= 2) {
    rows(0, std::int64_t(row_runs_.size()) - 1);
    return;
  }
  for (std::int64_t parity = 0; parity < 2; ++parity) {
#pragma omp parallel for schedule(dynamic, 1)
    for (std::int64_t b = parity; b < nb; b += 2) rows(reduce_blocks_[std::size_t(b)], reduce_blocks_[std::size_t(b) + 1]);
  }
}

template <class L, class T>
void Psm<L, T>::build_runs() {
  // Runs never cross a row: each row's items are counted, then written, in parallel (rows in
  // lattice order, the same items on any thread count).
  const std::int64_t nrows = std::int64_t(row_out_.size());
  const int nn[3] = {grid_.nx, grid_.ny, grid_.nz};
  // An item starting at `cell` (x = cell - row_base) with entry e.
  auto item = [&](CellIndex cell, CellIndex row_base, const Entry& e, T share) {
    return Run{int(cell - row_base), 1, e.particle, share, e.arm};
  };
  auto row_items = [&](std::int64_t row, Run* out) {  // the row's item count; written where out is not null
    const RowOut& ro = row_out_[std::size_t(row)];
    std::int64_t n = 0;
    bool open = false;  // the last item is a run that the next cell may extend
    std::int32_t run_particle = -1;
    CellIndex run_next = -1;  // the cell that would extend it
    const int cy = int(row % nn[1]), cz = int(row / nn[1]);
    const CellIndex row_base = grid_.index(0, cy, cz);  // (x = cell - row_base)
    for (std::int64_t i = ro.cell_dest; i < ro.cell_dest + ro.cells; ++i) {
      const Cell& c = cells_[std::size_t(i)];
      if (c.boundary || c.count > 1) {
        if (c.boundary) {
          if (out) out[n] = Run{int(c.cell - row_base), 1, -1, T(0), Vec3::Zero()};
          ++n;
        } else {
          for (std::int32_t k = c.first; k < c.first + c.count; ++k, ++n) {
            const Entry& e = entries_[std::size_t(k)];
            if (out) out[n] = item(c.cell, row_base, e, c.B != T(0) ? T(double(e.Bs) / double(c.B)) : T(0));
          }
        }
        open = false;
        continue;
      }
      const Entry& e = entries_[std::size_t(c.first)];
      // The next cell in memory of the same particle alone: x + 1 in this row (ghost cells pad every
      // row, so a run never wraps round a periodic edge, and its arms grow by e_x from cell to cell).
      if (open && run_particle == e.particle && run_next == c.cell) {
        if (out) ++out[n - 1].count;
        ++run_next;
        continue;
      }
      if (out) out[n] = item(c.cell, row_base, e, T(1));
      ++n;
      open = true;
      run_particle = e.particle;
      run_next = c.cell + 1;
    }
    return n;
  };
  row_runs_.resize(std::size_t(nrows) + 1);
  row_runs_[0] = 0;
#pragma omp parallel for schedule(dynamic, 64) if (cells_.size() > 16384)
  for (std::int64_t row = 0; row < nrows; ++row) row_runs_[std::size_t(row) + 1] = row_items(row, nullptr);
  for (std::int64_t row = 0; row < nrows; ++row) row_runs_[std::size_t(row) + 1] += row_runs_[std::size_t(row)];
  runs_.resize(std::size_t(row_runs_[std::size_t(nrows)]));
#pragma omp parallel for schedule(dynamic, 64) if (cells_.size() > 16384)
  for (std::int64_t row = 0; row < nrows; ++row) row_items(row, runs_.data() + row_runs_[std::size_t(row)]);
  // reduce()'s blocks: whole planes (3D: the rows y + ny z of one z; 2D: single rows), as many per
  // block as the tallest particle's bounding box spans (build() visits no cell outside it), at least 4
  // blocks, and only on lattices worth a parallel pass; a box across a periodic edge: one block.
  reduce_blocks_.assign(1, 0);
  if (cells_.size() <= 16384) return;
  const int axis = L::D == 3 ? 2 : 1;
  const std::int64_t per_plane = L::D == 3 ? nn[1] : 1, nplanes = nn[axis];
  std::int64_t tall = 1;
  for (std::size_t s = 0; s < ref_pos_.size(); ++s) {
    const double X = ref_pos_[s][axis], r = ref_radius_[s];
    const AxisRange box = covered_range(X, r);
    const std::int64_t lo = box.lo, hi = box.hi;
    if (grid_.periodic[axis] && (lo < 0 || hi >= nplanes)) return;
    tall = std::max(tall, hi - lo + 1);
  }
  if (nplanes / tall < 4) return;
  for (std::int64_t pl = tall; pl < nplanes; pl += tall) reduce_blocks_.push_back(pl * per_plane);
  reduce_blocks_.push_back(nrows);
}

template <class L, class T>
PsmCells<T> Psm<L, T>::bulk_cells() {
  PsmCells<T> c;
  c.B = cell_B_.data();
  c.rho = cell_rho_.data();
  for (int a = 0; a < L::D; ++a) {
    c.V[a] = cell_V_[a].data();
    c.u[a] = cell_u_[a].data();
  }
  for (int n = 0; n < kS; ++n) c.S[n] = cell_S_[n].data();
  return c;
}

template <class L, class T>
Vec3 Psm<L, T>::book_wall_link(CellIndex cell, const Vec3& Ft) {
  const std::int32_t sl = slot_.empty() ? -1 : slot_[std::size_t(cell)];
  Vec3 booked = Vec3::Zero();
  if (sl < 0) return booked;
  const Cell& c = cells_[std::size_t(sl)];
  for (std::int32_t k = c.first; k < c.first + c.count; ++k) {
    const Entry& e = entries_[std::size_t(k)];
    const Vec3 Fs = double(e.Bs) * Ft;
    force_[std::size_t(e.particle)] += Fs;
    torque_[std::size_t(e.particle)] += e.arm.cross(Fs);
    wall_force_[std::size_t(e.particle)] += Fs;
    booked += Fs;
  }
  return booked;
}

template <class L, class T>
double Psm<L, T>::solid_fraction(CellIndex cell) const {
  if (slot_.empty()) return 0;
  const std::int32_t s = slot_[std::size_t(cell)];
  return s < 0 ? 0.0 : std::min(1.0, cells_[std::size_t(s)].eps);
}

template <class L, class T>
double Psm<L, T>::weight(CellIndex cell) const {
  if (slot_.empty()) return 0;
  const std::int32_t s = slot_[std::size_t(cell)];
  return s < 0 ? 0.0 : double(cells_[std::size_t(s)].B);
}

template class Psm<D2Q9, double>;
template class Psm<D2Q9, float>;
template class Psm<D3Q19, double>;
template class Psm<D3Q19, float>;

}  // namespace ff::lbm
