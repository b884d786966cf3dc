// Partially saturated cells: covered fractions, the PSM update and the per-particle loads
// (psm.hpp has the equations and their sources).
#include "lbm/psm.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <climits>
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
  for (int v = 0; v < (1 << k); ++v) {
    double s = a;
    int bits = 0;
    for (int i = 0; i < k; ++i)
      if (v & (1 << i)) {
        s -= m[i];
        ++bits;
      }
    if (s <= 0) continue;
    const double p = k == 2 ? s * s : s * s * s;
    acc += (bits % 2 == 0) ? p : -p;
  }
  return std::clamp(acc / (fact * prod), 0.0, 1.0);
}

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
Psm<L, T>::Psm(const Grid& grid, double tau, PsmWeighting weighting) : grid_(grid), tau_(tau), weighting_(weighting) {
  const CellIndex N = grid_.padded_size();
  for (int q = 0; q < Q; ++q) {
    const int o = L::opp[q];
    const std::int64_t cq = L::c[q][0] + grid_.px * (L::c[q][1] + grid_.py * L::c[q][2]);
    pre_[0][q] = q * N;
    pre_[1][q] = q == 0 ? 0 : o * N - cq;
    post_[0][q] = o * N;
    post_[1][q] = q == 0 ? 0 : q * N + cq;
  }
}

// AA pattern: g_q before the step is in f[q][x] (even) or f[opp q][x - c_q] (odd); the kernel
// writes g*_q to f[opp q][x] (even) or f[q][x + c_q] (odd).
template <class L, class T>
FF_LBM_INLINE void Psm<L, T>::slots(const BulkCell& b, bool odd, CellIndex* pre, CellIndex* post) const {
  if (!b.edge) {
    for (int q = 0; q < Q; ++q) {
      pre[q] = b.cell + pre_[odd][q];
      post[q] = b.cell + post_[odd][q];
    }
    return;
  }
  const CellIndex N = grid_.padded_size();
  const auto x = grid_.coords(b.cell);
  pre[0] = post[0] = b.cell;
  for (int q = 1; q < Q; ++q) {
    const int o = L::opp[q];
    const auto& c = L::c[q];
    pre[q] = odd ? o * N + grid_.neighbour(x[0], x[1], x[2], -c[0], -c[1], -c[2]) : q * N + b.cell;
    post[q] = odd ? q * N + grid_.neighbour(x[0], x[1], x[2], c[0], c[1], c[2]) : o * N + b.cell;
  }
}

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
  if (refresh_ > 0 && !ref_radius_.empty() && ref_radius_.size() == np) {
    const double lim2 = refresh_ * refresh_;
    bool keep = true;
    for (std::size_t s = 0; s < np && keep; ++s) {
      Vec3 d = p.position[s] - ref_pos_[s];
      if (D == 2) d[2] = 0;
      keep = p.radius[s] == ref_radius_[s] && d.squaredNorm() <= lim2;
    }
    if (keep) {
      take_kinematics(p);
      return;
    }
  }
  build(p);
}

template <class L, class T>
void Psm<L, T>::take_kinematics(const ParticleSet& p) {
  const std::size_t np = p.size();
  const int D = L::D;
  bool same = true;
  for (std::size_t s = 0; s < np; ++s) {
    const Kinematics k{p.velocity[s], D == 3 ? p.omega[s] : Vec3(0, 0, p.omega[s][2])};
    same = same && k.v == kin_[s].v && k.w == kin_[s].w;
    kin_[s] = k;
  }
  if (same) return;  // (quasi-static walls: nothing moves)
  const std::int64_t ncell = std::int64_t(cells_.size());
#pragma omp parallel for schedule(static) if (ncell > 16384)
  for (std::int64_t i = 0; i < ncell; ++i) {
    const Cell& c = cells_[std::size_t(i)];
    if (!c.single) continue;
    const Entry& e = entries_[std::size_t(c.first)];
    const Kinematics& m = kin_[std::size_t(e.particle)];
    const Vec3 us = m.v + m.w.cross(e.arm);
    for (int a = 0; a < D; ++a) single_us_[a][std::size_t(c.cell)] = T(us[a]);
  }
}

template <class L, class T>
void Psm<L, T>::restore_geometry(const std::vector<Vec3>& positions, const std::vector<double>& radii) {
  ParticleSet g;
  g.resize(radii.size());
  g.position = positions;
  g.radius = radii;
  if (g.position.size() != g.radius.size())
    throw InputError(fmt::format("PSM geometry: {} positions for {} radii", g.position.size(), g.radius.size()));
  build(g);
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
    row_lo_.assign(std::size_t(n[1]) * std::size_t(n[2]), INT32_MAX);
    row_hi_.assign(row_lo_.size(), -1);
    single_B_.assign(N, T(0));
    for (int a = 0; a < D; ++a) {
      single_us_[a].assign(N, T(0));
      single_F_[a].assign(N, 0.0);
    }
  }
  for (const Cell& c : cells_) {
    slot_[std::size_t(c.cell)] = -1;
    single_B_[std::size_t(c.cell)] = T(0);
  }
  for (const std::int32_t sp : touched_) span_count_[std::size_t(sp)] = 0;
  touched_.clear();
  for (const std::int32_t sp : single_spans_) span_single_[std::size_t(sp)] = 0;
  single_spans_.clear();
  cells_.clear();
  kin_.resize(np);
  for (std::size_t s = 0; s < np; ++s) kin_[s] = Kinematics{p.velocity[s], D == 3 ? p.omega[s] : Vec3(0, 0, p.omega[s][2])};
  // 1. The covered fractions, particle by particle, in parallel: fixed chunks of consecutive
  //    particles (independent of the thread count), each into its own buffer, which step 2 reads
  //    in chunk order, i.e. in particle order as a serial loop would.
  const std::size_t nchunk = std::min<std::size_t>(kChunks, np);
  if (chunk_.size() < nchunk) chunk_.resize(nchunk);
  const double half_diag = D == 3 ? std::sqrt(0.75) : std::sqrt(0.5);
#pragma omp parallel for schedule(dynamic, 1) if (np > 256)
  for (std::int64_t ch = 0; ch < std::int64_t(nchunk); ++ch) {
    std::vector<Candidate>& out = chunk_[std::size_t(ch)];
    out.clear();
    const std::size_t s0 = std::size_t(ch) * np / nchunk, s1 = std::size_t(ch + 1) * np / nchunk;
    for (std::size_t s = s0; s < s1; ++s) {
      const Vec3& X = p.position[s];
      const double r = p.radius[s];
      int lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
      for (int a = 0; a < D; ++a) {
        // Cell x spans [x - 1/2, x + 1/2]: it meets the particle for x in [X - r - 1/2, X + r + 1/2].
        lo[a] = int(std::ceil(X[a] - r - 0.5));
        hi[a] = int(std::floor(X[a] + r + 0.5));
      }
      // Along x only the cells within r + half a cell diagonal of the centre can be covered
      // (psm_cell_fraction() is 0 beyond): a row visits that range, not the whole box.
      const double reach2 = (r + half_diag) * (r + half_diag);
      for (int z = lo[2]; z <= hi[2]; ++z)
        for (int y = lo[1]; y <= hi[1]; ++y) {
          const double dy = y - X[1], dz = D == 3 ? z - X[2] : 0.0;
          const double rest = reach2 - dy * dy - dz * dz;
          if (rest < -1e-9) continue;  // (margins: rounding never drops a covered cell)
          const double half = std::sqrt(std::max(rest, 0.0)) + 1e-9;
          const int x0 = std::max(lo[0], int(std::floor(X[0] - half))), x1 = std::min(hi[0], int(std::ceil(X[0] + half)));
          const int cy = wrap_axis(y, n[1], grid_.periodic[1]), cz = D == 3 ? wrap_axis(z, n[2], grid_.periodic[2]) : 0;
          if (cy < 0 || cz < 0) continue;
          const std::int32_t row = std::int32_t(cy + n[1] * cz);
          for (int x = x0; x <= x1; ++x) {
            const int cx = wrap_axis(x, n[0], grid_.periodic[0]);
            if (cx < 0) continue;
            const CellIndex ci = grid_.index(cx, cy, cz);
            if (span_of_[std::size_t(ci)] == kNotFluid) continue;
            const Vec3 arm = D == 3 ? Vec3(x - X[0], y - X[1], z - X[2]) : Vec3(x - X[0], y - X[1], 0);
            const double eps = psm_cell_fraction(D, arm, r);
            if (eps <= 0) continue;
            out.push_back(Candidate{ci, std::int32_t(s), row, cx, eps, arm});
          }
        }
    }
  }
  // 2. Entries per cell (slot_ holds -1 - count meanwhile) and the x range touched in each row.
  std::size_t nentries = 0;
  pfirst_.assign(np + 1, 0);
  for (std::size_t ch = 0; ch < nchunk; ++ch) {
    for (const Candidate& cd : chunk_[ch]) {
      ++pfirst_[std::size_t(cd.particle) + 1];
      --slot_[std::size_t(cd.cell)];
      row_lo_[std::size_t(cd.row)] = std::min(row_lo_[std::size_t(cd.row)], cd.x);
      row_hi_[std::size_t(cd.row)] = std::max(row_hi_[std::size_t(cd.row)], cd.x);
    }
    nentries += chunk_[ch].size();
  }
  for (std::size_t s = 0; s < np; ++s) pfirst_[s + 1] += pfirst_[s];
  // 3. The covered cells in lattice order (x fastest), as the sweeps visit them: their data is
  //    then read in order (in order of first touch, the random reads of cells and entries made the
  //    update 5-10 times slower than its arithmetic).
  std::int32_t off = 0;
  for (std::size_t row = 0; row < row_lo_.size(); ++row) {
    if (row_hi_[row] < 0) continue;
    const int y = int(row % std::size_t(n[1])), z = int(row / std::size_t(n[1]));
    const bool edge_yz = (grid_.periodic[1] && (y == 0 || y == n[1] - 1)) ||
                         (D == 3 && grid_.periodic[2] && (z == 0 || z == n[2] - 1));
    for (int x = row_lo_[row]; x <= row_hi_[row]; ++x) {
      const CellIndex ci = grid_.index(x, y, z);
      std::int32_t& sl = slot_[std::size_t(ci)];
      if (sl >= -1) continue;
      const std::int32_t count = -1 - sl;
      sl = std::int32_t(cells_.size());
      // On a periodic lattice edge the neighbours wrap (slow path of the slots).
      const bool edge = edge_yz || (grid_.periodic[0] && (x == 0 || x == n[0] - 1));
      const bool boundary = span_of_[std::size_t(ci)] == kBoundaryCell;
      cells_.push_back(Cell{ci, off, 0, 0.0, T(0), boundary, edge, count == 1 && !boundary});
      off += count;
    }
    row_lo_[row] = INT32_MAX;
    row_hi_[row] = -1;
  }
  // 4. The entries grouped by cell (counting sort, stable: particle order within a cell), straight
  //    from the chunk buffers; each cell's eps summed in particle order.
  //    The candidates are in particle order, so their running index is the particle's list.
  entries_.resize(nentries);
  pentry_.resize(nentries);
  std::size_t run = 0;
  for (std::size_t ch = 0; ch < nchunk; ++ch)
    for (const Candidate& cd : chunk_[ch]) {
      Cell& c = cells_[std::size_t(slot_[std::size_t(cd.cell)])];
      const std::int32_t k = c.first + c.count++;
      entries_[std::size_t(k)] = Entry{cd.particle, T(0), cd.eps, cd.arm};
      pentry_[run++] = ParticleEntry{cd.arm, cd.cell, k, c.single};
      c.eps += cd.eps;
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
    if (c.single) {  // the fused kernel's per-cell B and u_s (as apply_span computes them)
      const Entry& e = entries_[std::size_t(c.first)];
      const Kinematics& m = kin_[std::size_t(e.particle)];
      const Vec3 us = m.v + m.w.cross(e.arm);
      single_B_[std::size_t(c.cell)] = T(B);
      for (int a = 0; a < D; ++a) single_us_[a][std::size_t(c.cell)] = T(us[a]);
    }
  }
  // Spans that run the fused kernel; the other bulk cells grouped by the span that updates them
  // (offsets in order of first touch).
  for (const Cell& c : cells_) {
    if (c.boundary) continue;
    if (c.single) {
      const std::int32_t sp = span_of_[std::size_t(c.cell)];
      if (!span_single_[std::size_t(sp)]) {
        span_single_[std::size_t(sp)] = 1;
        single_spans_.push_back(sp);
      }
      continue;
    }
    const std::int32_t sp = span_of_[std::size_t(c.cell)];
    if (span_count_[std::size_t(sp)]++ == 0) touched_.push_back(sp);
  }
  std::int32_t nbulk = 0;
  for (const std::int32_t sp : touched_) {
    span_first_[std::size_t(sp)] = nbulk;
    nbulk += span_count_[std::size_t(sp)];
    span_count_[std::size_t(sp)] = 0;
  }
  bulk_.resize(std::size_t(nbulk));
  for (std::size_t i = 0; i < cells_.size(); ++i) {
    const Cell& c = cells_[i];
    if (c.boundary || c.single) continue;
    const std::int32_t sp = span_of_[std::size_t(c.cell)];
    bulk_[std::size_t(span_first_[std::size_t(sp)] + span_count_[std::size_t(sp)]++)] = BulkCell{c.cell, std::int32_t(i), c.edge};
  }
  gpre_.resize(std::size_t(Q) * bulk_.size());
  entry_force_.resize(3 * entries_.size());  // every entry is written by its cell's update
  force_.assign(np, Vec3::Zero());
  torque_.assign(np, Vec3::Zero());
  wall_force_.assign(np, Vec3::Zero());
}

template <class L, class T>
void Psm<L, T>::set_cell_spans(std::vector<std::int32_t> span_of_cell, std::size_t num_spans) {
  for (const Cell& c : cells_) {
    slot_[std::size_t(c.cell)] = -1;
    single_B_[std::size_t(c.cell)] = T(0);
  }
  span_single_.assign(num_spans, 0);
  single_spans_.clear();
  cells_.clear();
  entries_.clear();
  bulk_.clear();
  touched_.clear();
  span_of_ = std::move(span_of_cell);
  span_first_.assign(num_spans, 0);
  span_count_.assign(num_spans, 0);
}

template <class L, class T>
void Psm<L, T>::save_span(std::int64_t span, const T* f, bool odd) {
  const std::int32_t k0 = span_first_[std::size_t(span)], k1 = k0 + span_count_[std::size_t(span)];
  for (std::int32_t k = k0; k < k1; ++k) {
    CellIndex pre[Q], post[Q];
    slots(bulk_[std::size_t(k)], odd, pre, post);
    T* g = &gpre_[std::size_t(Q) * std::size_t(k)];
    for (int q = 0; q < Q; ++q) g[q] = f[pre[q]];
  }
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

namespace {

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define FF_PSM_CLONES __attribute__((target_clones("default", "arch=x86-64-v3", "arch=x86-64-v4")))
#else
#define FF_PSM_CLONES
#endif

// Covered bulk cells of one span in batches of kBatch, structure of arrays, so that the arithmetic
// of the update runs over the lanes in vector registers (one cell at a time, scalar, it cost
// 10-20 times the bulk kernel's cell). Compiled like the bulk kernel (bulk_sweep.cpp): one clone
// per vector width, the same IEEE operations in each (-ffp-contract=off), so a cell's result does
// not depend on its lane, its batch or the clone.
constexpr int kBatch = 16;

template <class L, class T>
struct PsmBatch {
  alignas(64) T pre[L::Q][kBatch];   // g_q before the step
  alignas(64) T post[L::Q][kBatch];  // g*_q from the kernel, then the PSM result
  alignas(64) T sum[L::Q][kBatch];   // sum_s B_s Omega^s_q
  alignas(64) T geqf[L::Q][kBatch];  // f^eq_q(rho, u)
  alignas(64) T B[kBatch], Bs[kBatch], us[3][kBatch], rho[kBatch], rho_u[kBatch], u[3][kBatch];
  alignas(64) double F[3][kBatch];   // force of each lane's first entry
};

// Fluid moments, f^eq(rho, u), and the solid term of each lane's first particle (the others are
// added by the caller); as Psm::apply() does for one cell.
template <class L, class T, bool kForce, bool kIncomp>
FF_PSM_CLONES void psm_batch_solid(PsmBatch<L, T>& b, const T* force) {
  constexpr int Q = L::Q;
  T hf[3] = {0, 0, 0};
  if constexpr (kForce)
    for (int a = 0; a < L::D; ++a) hf[a] = T(0.5) * force[a];
  for (int i = 0; i < kBatch; ++i) {
    T drho = 0, j[3] = {0, 0, 0};
    static_for<Q>([&](auto q) FF_LBM_LAMBDA_INLINE {
      const T g = b.pre[q][i];
      drho += g;
      static_for<L::D>([&](auto a) FF_LBM_LAMBDA_INLINE {
        if constexpr (L::c[q][a] > 0) j[a] += g;
        if constexpr (L::c[q][a] < 0) j[a] -= g;
      });
    });
    if constexpr (kForce)
      for (int a = 0; a < L::D; ++a) j[a] += hf[a];
    const T rho = T(1) + drho;
    const T rho_u = kIncomp ? T(1) : rho;
    const T inv = kIncomp ? T(1) : T(1) / rho;
    const T u[3] = {j[0] * inv, j[1] * inv, j[2] * inv};
    b.rho[i] = rho;
    b.rho_u[i] = rho_u;
    const T usq15 = T(1.5) * (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    const T us[3] = {b.us[0][i], b.us[1][i], b.us[2][i]};
    const T ssq15 = T(1.5) * (us[0] * us[0] + us[1] * us[1] + us[2] * us[2]);
    T geqf[Q], geqs[Q];
    static_for<Q>([&](auto q) FF_LBM_LAMBDA_INLINE {
      const T cu = cdot<L::c[q][0], L::c[q][1], L::c[q][2]>(u[0], u[1], u[2]);
      geqf[q] = T(L::w[q]) * ((rho - T(1)) + rho_u * (T(3) * cu + T(4.5) * cu * cu - usq15));
      const T cs = cdot<L::c[q][0], L::c[q][1], L::c[q][2]>(us[0], us[1], us[2]);
      geqs[q] = T(L::w[q]) * ((rho - T(1)) + rho_u * (T(3) * cs + T(4.5) * cs * cs - ssq15));
      b.geqf[q][i] = geqf[q];
    });
    const T Bs = b.Bs[i];
    double F[3] = {0, 0, 0};
    static_for<Q>([&](auto q) FF_LBM_LAMBDA_INLINE {
      constexpr int o = L::opp[q];
      const T om = Bs * ((b.pre[o][i] - b.pre[q][i]) + (geqs[q] - geqf[o]));
      b.sum[q][i] = T(0) + om;
      static_for<L::D>([&](auto a) FF_LBM_LAMBDA_INLINE {
        if constexpr (L::c[q][a] > 0) F[a] -= double(om);
        if constexpr (L::c[q][a] < 0) F[a] += double(om);
      });
    });
    for (int a = 0; a < 3; ++a) b.F[a][i] = F[a];
  }
}

// g = (1 - B) g* + B g + sum_s B_s Omega^s, lane by lane.
template <class L, class T>
FF_PSM_CLONES void psm_batch_combine(PsmBatch<L, T>& b) {
  for (int q = 0; q < L::Q; ++q)
    for (int i = 0; i < kBatch; ++i) {
      const T B = b.B[i], fluid = T(1) - B;
      b.post[q][i] = fluid * b.post[q][i] + B * b.pre[q][i] + b.sum[q][i];
    }
}

}  // namespace

template <class L, class T>
void Psm<L, T>::apply_span(std::int64_t span, T* f, bool odd, const Relax<T>& r, bool force, bool incomp) {
  const std::int32_t k0 = span_first_[std::size_t(span)], k1 = k0 + span_count_[std::size_t(span)];
  using Fn = void (*)(PsmBatch<L, T>&, const T*);
  const Fn solid = force ? (incomp ? &psm_batch_solid<L, T, true, true> : &psm_batch_solid<L, T, true, false>)
                         : (incomp ? &psm_batch_solid<L, T, false, true> : &psm_batch_solid<L, T, false, false>);
  PsmBatch<L, T> b;
  CellIndex post[kBatch][Q];
  for (std::int32_t kb = k0; kb < k1; kb += kBatch) {
    const int n = int(std::min<std::int32_t>(kBatch, k1 - kb));
    for (int i = 0; i < n; ++i) {
      const BulkCell& bc = bulk_[std::size_t(kb + i)];
      CellIndex pre[Q];
      slots(bc, odd, pre, post[i]);
      const T* gp = &gpre_[std::size_t(Q) * std::size_t(kb + i)];
      for (int q = 0; q < Q; ++q) {
        b.pre[q][i] = gp[q];
        b.post[q][i] = f[post[i][q]];
      }
      const Cell& c = cells_[std::size_t(bc.slot)];
      const Entry& e = entries_[std::size_t(c.first)];
      b.B[i] = c.B;
      b.Bs[i] = e.Bs;
      const Kinematics& m = kin_[std::size_t(e.particle)];
      const Vec3 us = m.v + m.w.cross(e.arm);
      for (int a = 0; a < 3; ++a) b.us[a][i] = T(a < L::D ? us[a] : 0.0);
    }
    for (int i = n; i < kBatch; ++i) {  // idle lanes: a fluid at rest
      for (int q = 0; q < Q; ++q) b.pre[q][i] = b.post[q][i] = T(0);
      b.B[i] = b.Bs[i] = T(0);
      for (int a = 0; a < 3; ++a) b.us[a][i] = T(0);
    }
    solid(b, r.force);
    // Cells with more than one particle: the others' terms, in entry order (as apply()).
    for (int i = 0; i < n; ++i) {
      const Cell& c = cells_[std::size_t(bulk_[std::size_t(kb + i)].slot)];
      for (int a = 0; a < 3; ++a) entry_force_[3 * std::size_t(c.first) + std::size_t(a)] = b.F[a][i];
      if (c.count == 1) continue;
      T gpre[Q], geq_f[Q], geq_s[Q];
      for (int q = 0; q < Q; ++q) gpre[q] = b.pre[q][i], geq_f[q] = b.geqf[q][i];
      for (std::int32_t k = c.first + 1; k < c.first + c.count; ++k) {
        const Entry& e = entries_[std::size_t(k)];
        const Kinematics& m = kin_[std::size_t(e.particle)];
        const Vec3 us = m.v + m.w.cross(e.arm);
        const T ut[3] = {T(us[0]), T(us[1]), T(L::D == 3 ? us[2] : 0.0)};
        psm_equilibrium<L, T>(b.rho[i], b.rho_u[i], ut, geq_s);
        double F[3] = {0, 0, 0};
        const T Bs = e.Bs;
        static_for<Q>([&](auto q) FF_LBM_LAMBDA_INLINE {
          constexpr int o = L::opp[q];
          const T om = Bs * ((gpre[o] - gpre[q]) + (geq_s[q] - geq_f[o]));
          b.sum[q][i] += om;
          static_for<L::D>([&](auto a) FF_LBM_LAMBDA_INLINE {
            if constexpr (L::c[q][a] > 0) F[a] -= double(om);
            if constexpr (L::c[q][a] < 0) F[a] += double(om);
          });
        });
        for (int a = 0; a < 3; ++a) entry_force_[3 * std::size_t(k) + std::size_t(a)] = F[a];
      }
    }
    psm_batch_combine<L, T>(b);
    for (int i = 0; i < n; ++i)
      for (int q = 0; q < Q; ++q) f[post[i][q]] = b.post[q][i];
  }
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
void Psm<L, T>::reduce() {
  // Each particle sums its own entries in a fixed order: no atomics, the same on any thread count.
  const std::int64_t np = std::int64_t(force_.size());
#pragma omp parallel for schedule(static) if (np > 2048)
  for (std::int64_t s = 0; s < np; ++s) {
    Vec3 F = Vec3::Zero(), M = Vec3::Zero();
    for (std::int32_t i = pfirst_[std::size_t(s)]; i < pfirst_[std::size_t(s) + 1]; ++i) {
      const ParticleEntry& e = pentry_[std::size_t(i)];
      Vec3 Fk;
      if (e.single) {
        const std::size_t c = std::size_t(e.cell);
        Fk = Vec3(single_F_[0][c], single_F_[1][c], L::D == 3 ? single_F_[2][c] : 0.0);
      } else {
        const std::size_t k = std::size_t(e.k);
        Fk = Vec3(entry_force_[3 * k], entry_force_[3 * k + 1], entry_force_[3 * k + 2]);
      }
      F += Fk;
      M += e.arm.cross(Fk);
    }
    force_[std::size_t(s)] = F;
    torque_[std::size_t(s)] = M;
    wall_force_[std::size_t(s)] = Vec3::Zero();
  }
}

template <class L, class T>
PsmCells<T> Psm<L, T>::single_cells() {
  PsmCells<T> c;
  c.B = single_B_.data();
  for (int a = 0; a < L::D; ++a) {
    c.us[a] = single_us_[a].data();
    c.F[a] = single_F_[a].data();
  }
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
