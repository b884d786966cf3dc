// Moving solid cells: covering, refill, links and the bounce-back post-pass (moving_boundary.hpp
// has the equations and their sources).
#include "lbm/moving_boundary.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "lbm/boundary.hpp"

namespace ff::lbm {

const char* particle_scheme_name(ParticleScheme s) {
  switch (s) {
    case ParticleScheme::Psm: return "psm";
    case ParticleScheme::StairwiseBounceBack: return "stairwise_bounce_back";
    case ParticleScheme::InterpolatedBounceBack: return "interpolated_bounce_back";
  }
  return "?";
}

template <class L, class T>
MovingBoundary<L, T>::MovingBoundary(const Grid& grid, ParticleScheme scheme, bool incompressible)
    : grid_(grid), scheme_(scheme), incompressible_(incompressible) {
  const CellIndex N = grid_.padded_size();
  for (int q = 0; q < Q; ++q) {
    const std::int64_t cq = L::c[q][0] + grid_.px * (L::c[q][1] + grid_.py * L::c[q][2]);
    pre_off_[0][q] = q * N;
    pre_off_[1][q] = q == 0 ? 0 : L::opp[q] * N - cq;
  }
}

template <class L, class T>
void MovingBoundary<L, T>::set_fluid_mask(std::vector<std::uint8_t> fluid) {
  fluid_ = std::move(fluid);
  owner_.assign(fluid_.size(), -1);
  next_.assign(fluid_.size(), -1);
  cells_.clear();
  cell_.clear();
  links_.clear();
  links_valid_ = false;
}

// AA pattern (bulk_sweep.cpp): even steps read g_q from f[q][x] and write g*_q to f[opp q][x];
// odd steps read g_q from f[opp q][x - c_q] and write g*_q to f[q][x + c_q].
template <class L, class T>
CellIndex MovingBoundary<L, T>::pre(const int* x, int q, bool odd) const {
  const CellIndex N = grid_.padded_size();
  if (q == 0) return grid_.index(x[0], x[1], x[2]);
  if (!odd) return q * N + grid_.index(x[0], x[1], x[2]);
  return L::opp[q] * N + grid_.neighbour(x[0], x[1], x[2], -L::c[q][0], -L::c[q][1], -L::c[q][2]);
}

template <class L, class T>
CellIndex MovingBoundary<L, T>::post(const int* x, int q, bool odd) const {
  const CellIndex N = grid_.padded_size();
  if (q == 0) return grid_.index(x[0], x[1], x[2]);
  if (!odd) return L::opp[q] * N + grid_.index(x[0], x[1], x[2]);
  return q * N + grid_.neighbour(x[0], x[1], x[2], L::c[q][0], L::c[q][1], L::c[q][2]);
}

template <class L, class T>
void MovingBoundary<L, T>::set_particles(const ParticleSet& p, T* f, bool odd, bool bookkeeping) {
  const std::size_t np = p.size();
  const char* name = particle_scheme_name(scheme_);
  if (p.position.size() != np || p.velocity.size() != np || p.omega.size() != np || (!p.id.empty() && p.id.size() != np))
    throw InputError(fmt::format("{} particle set: the arrays differ in length (radius {}, position {}, velocity {}, "
                                 "omega {}, id {}): all must have one entry per particle (id may be empty)",
                                 name, np, p.position.size(), p.velocity.size(), p.omega.size(), p.id.size()));
  if (np >= std::size_t(INT32_MAX)) throw InputError(fmt::format("{} particle set: more than 2^31 - 1 particles", name));
  if (fluid_.empty()) throw Error("internal: MovingBoundary used before set_fluid_mask()");
  const int D = L::D;
  const int n[3] = {grid_.nx, grid_.ny, grid_.nz};

  // Checked before anything changes, so that bad input leaves the current set intact.
  for (std::size_t s = 0; s < np; ++s) {
    const Vec3& X = p.position[s];
    const double r = p.radius[s];
    bool ok = std::isfinite(r) && r > 0;
    for (int a = 0; a < D; ++a) ok = ok && std::isfinite(X[a]) && (!grid_.periodic[a] || 2 * r < n[a]);
    if (!ok)
      throw InputError(fmt::format("{} particle {} (id {}): radius {} at ({}, {}, {}) must be finite and positive "
                                   "(and below half the lattice along a periodic axis), position finite",
                                   name, s, p.id.empty() ? s : p.id[s], r, X[0], X[1], X[2]));
  }
  stats_ = MovingBoundaryStats{};
  impulse_.assign(np, Vec3::Zero());
  impulse_torque_.assign(np, Vec3::Zero());
  // 1. The new solid cells: centres strictly inside a particle, first particle wins.
  new_cells_.clear();
  new_cell_.clear();
  nfirst_.resize(np);
  ncount_.resize(np);
  for (std::size_t s = 0; s < np; ++s) {
    nfirst_[s] = std::int32_t(new_cells_.size());
    const Vec3& X = p.position[s];
    const double r = p.radius[s];
    int lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    for (int a = 0; a < D; ++a) {
      lo[a] = int(std::ceil(X[a] - r));
      hi[a] = int(std::floor(X[a] + r));
    }
    const Vec3& v = p.velocity[s];
    const Vec3 w = D == 3 ? p.omega[s] : Vec3(0, 0, p.omega[s][2]);
    const std::uint64_t id = p.id.empty() ? std::uint64_t(s) : p.id[s];
    for (int z = lo[2]; z <= hi[2]; ++z)
      for (int y = lo[1]; y <= hi[1]; ++y) {
        // Only |x - X| < sqrt(r^2 - dy^2 - dz^2) can be inside: the row visits that range.
        const double dy = y - X[1], dz = D == 3 ? z - X[2] : 0.0;
        const double rest = r * r - dy * dy - dz * dz;
        if (rest < -1e-9) continue;  // (margins: rounding never drops a cell the test below takes)
        const double half = std::sqrt(std::max(rest, 0.0)) + 1e-9;
        const int x0 = std::max(lo[0], int(std::floor(X[0] - half))), x1 = std::min(hi[0], int(std::ceil(X[0] + half)));
        int c[3] = {0, y, z};
        bool inside = true;
        for (int a = 1; a < D; ++a) {
          c[a] = wrap_axis(c[a], n[a], grid_.periodic[a]);
          inside = inside && c[a] >= 0;
        }
        if (!inside) continue;
        for (int x = x0; x <= x1; ++x) {
          const Vec3 arm = D == 3 ? Vec3(x - X[0], y - X[1], z - X[2]) : Vec3(x - X[0], y - X[1], 0);
          if (!(arm.squaredNorm() < r * r)) continue;
          c[0] = wrap_axis(x, n[0], grid_.periodic[0]);
          if (c[0] < 0) continue;
          const CellIndex ci = grid_.index(c[0], c[1], c[2]);
          if (!fluid_[std::size_t(ci)] || next_[std::size_t(ci)] >= 0) continue;
          next_[std::size_t(ci)] = std::int32_t(new_cells_.size());
          SolidCell sc;
          sc.cell = ci;
          for (int a = 0; a < 3; ++a) sc.x[a] = c[a];
          sc.particle = std::int32_t(s);
          sc.id = id;
          sc.arm = arm;
          const Vec3 us = v + w.cross(arm);
          for (int a = 0; a < 3; ++a) sc.us[a] = T(a < D ? us[a] : 0.0);
          sc.edge = false;
          for (int a = 0; a < D; ++a) sc.edge = sc.edge || (grid_.periodic[a] && (c[a] == 0 || c[a] == n[a] - 1));
          new_cells_.push_back(sc);
          new_cell_.push_back(ci);
        }
      }
    ncount_[s] = std::int32_t(new_cells_.size()) - nfirst_[s];
  }
  // Links are rebuilt only around what changed when the set has the same particles as before.
  const bool incremental = links_valid_ && cfirst_.size() == np;
  // The cells that change: covered (fluid before) and uncovered (fluid after).
  covered_.clear();
  uncovered_.clear();
  for (std::size_t i = 0; i < new_cell_.size(); ++i)
    if (owner_[std::size_t(new_cell_[i])] < 0) covered_.push_back(std::int32_t(i));
  for (std::size_t i = 0; i < cell_.size(); ++i)
    if (next_[std::size_t(cell_[i])] < 0) uncovered_.push_back(std::int32_t(i));
  if (incremental) {
    dirty_.assign(np, 0);
    for (std::size_t s = 0; s < np; ++s) {
      bool same = ncount_[s] == ccount_[s];
      if (same) same = std::equal(new_cell_.begin() + nfirst_[s], new_cell_.begin() + nfirst_[s] + ncount_[s],
                                  cell_.begin() + cfirst_[s]);
      if (!same) dirty_[s] = 1;
    }
    for (const std::int32_t i : covered_) mark_dirty(new_cell_[std::size_t(i)]);
    for (const std::int32_t i : uncovered_) mark_dirty(cell_[std::size_t(i)]);
  }

  if (bookkeeping) {
    // 2. Covering: a cell that turns solid hands its fluid momentum to its particle.
    for (const std::int32_t i : covered_) {
      const SolidCell& sc = new_cells_[std::size_t(i)];
      double m = 1, j[3] = {0, 0, 0};
      for (int q = 0; q < Q; ++q) {
        const double g = double(f[pre(sc.x, q, odd)]);
        m += g;
        for (int a = 0; a < D; ++a) j[a] += L::c[q][a] * g;
      }
      const Vec3 J(j[0], j[1], j[2]);
      impulse_[std::size_t(sc.particle)] += J;
      impulse_torque_[std::size_t(sc.particle)] += sc.arm.cross(J);
      stats_.impulse += J;
      stats_.mass_removed += m;
      ++stats_.covered;
    }
    // 3. Refill of the cells that turn fluid: f^eq(rho_avg, u_w) with rho_avg over the neighbours
    //    that are fluid before and after, u_w the uncovering particle's velocity at the cell.
    for (const std::int32_t i : uncovered_) {
      const SolidCell& old = cells_[std::size_t(i)];
      double rsum = 0;
      int count = 0;
      for (int q = 1; q < Q; ++q) {
        int y[3];
        const CellIndex nb = grid_.neighbour(old.x[0], old.x[1], old.x[2], L::c[q][0], L::c[q][1], L::c[q][2]);
        if (!fluid_[std::size_t(nb)] || owner_[std::size_t(nb)] >= 0 || next_[std::size_t(nb)] >= 0) continue;
        const auto yc = grid_.coords(nb);
        for (int a = 0; a < 3; ++a) y[a] = yc[a];
        double rho = 1;
        for (int k = 0; k < Q; ++k) rho += double(f[pre(y, k, odd)]);
        rsum += rho;
        ++count;
      }
      const double rho = count > 0 ? rsum / count : 1.0;
      const std::size_t s = std::size_t(old.particle);
      const bool same = s < np && (p.id.empty() ? true : p.id[s] == old.id);
      Vec3 uw(old.us[0], old.us[1], old.us[2]);
      Vec3 arm = old.arm;
      if (same) {
        // The particle's current velocity at the cell centre (minimum image on periodic axes).
        const Vec3& X = p.position[s];
        for (int a = 0; a < D; ++a) {
          double d = old.x[a] - X[a];
          if (grid_.periodic[a]) d -= n[a] * std::round(d / n[a]);
          arm[a] = d;
        }
        if (D == 2) arm[2] = 0;
        const Vec3 w = D == 3 ? p.omega[s] : Vec3(0, 0, p.omega[s][2]);
        uw = p.velocity[s] + w.cross(arm);
        if (D == 2) uw[2] = 0;
      } else {
        ++stats_.unattributed;
      }
      const T u[3] = {T(uw[0]), T(uw[1]), T(D == 3 ? uw[2] : 0.0)};
      T geq[Q];
      equilibrium<L, T>(T(rho), u, geq, incompressible_);
      double j[3] = {0, 0, 0};
      for (int q = 0; q < Q; ++q) {
        f[pre(old.x, q, odd)] = geq[q];
        for (int a = 0; a < D; ++a) j[a] += L::c[q][a] * double(geq[q]);
      }
      const Vec3 J(j[0], j[1], j[2]);  // the refill's momentum as stored
      if (same) {
        impulse_[s] -= J;
        impulse_torque_[s] -= arm.cross(J);
      }
      stats_.impulse -= J;
      stats_.mass_added += rho;
      ++stats_.uncovered;
    }
  }

  // 4. Swap the sets: owner_ of the old cells cleared, of the new ones set; next_ cleared.
  for (const CellIndex c : cell_) owner_[std::size_t(c)] = -1;
  cells_.swap(new_cells_);
  cell_.swap(new_cell_);
  for (std::size_t i = 0; i < cell_.size(); ++i) {
    owner_[std::size_t(cell_[i])] = std::int32_t(i);
    next_[std::size_t(cell_[i])] = -1;
  }
  cfirst_.swap(nfirst_);
  ccount_.swap(ncount_);
  build_links(p, incremental);
  stats_.solid_cells = long(cells_.size());
  stats_.links = long(links_.size());
  force_.assign(np, Vec3::Zero());
  torque_.assign(np, Vec3::Zero());
}

// A changed cell c alters the links of the solid cells y with c = y + c_q (the link's fluid
// node) or c = y + 2 c_q (its second node): their particles are dirty. Called before the swap:
// next_ holds the new set.
template <class L, class T>
void MovingBoundary<L, T>::mark_dirty(CellIndex changed) {
  const auto x = grid_.coords(changed);
  const int n[3] = {grid_.nx, grid_.ny, grid_.nz};
  for (int q = 1; q < Q; ++q)
    for (int k = 1; k <= 2; ++k) {
      int y[3] = {x[0] - k * L::c[q][0], x[1] - k * L::c[q][1], x[2] - k * L::c[q][2]};
      bool inside = true;
      for (int a = 0; a < L::D; ++a) {
        y[a] = wrap_axis(y[a], n[a], grid_.periodic[a]);
        inside = inside && y[a] >= 0;
      }
      if (!inside) continue;
      const std::int32_t o = next_[std::size_t(grid_.index(y[0], y[1], y[2]))];
      if (o >= 0) dirty_[std::size_t(new_cells_[std::size_t(o)].particle)] = 1;
    }
}

// Wall point, fraction and velocity of a link from its solid cell's arm and the particle's motion.
template <class L, class T>
void MovingBoundary<L, T>::link_motion(MovingLink& k, const ParticleSet& p) const {
  const int D = L::D;
  const int q = k.q;
  const std::size_t s = std::size_t(k.particle);
  const double r = p.radius[s];
  const Vec3 w = D == 3 ? p.omega[s] : Vec3(0, 0, p.omega[s][2]);
  const Vec3 c(L::c[q][0], L::c[q][1], D == 3 ? L::c[q][2] : 0);
  // x relative to the centre; the wall point x_w = x - delta c_q lies on the link towards the solid.
  const Vec3 ax = cells_[std::size_t(k.solid)].arm + c;
  double delta = 0.5;
  if (scheme_ == ParticleScheme::InterpolatedBounceBack) {
    // |ax - delta c|^2 = r^2: the smaller root (|ax| >= r at delta = 0, |arm| < r at delta = 1).
    const double cc = c.squaredNorm(), b = ax.dot(c), e = ax.squaredNorm() - r * r;
    const double disc = std::max(0.0, b * b - cc * e);
    delta = std::clamp((b - std::sqrt(disc)) / cc, 0.0, 1.0);
  }
  k.delta = delta;
  const Vec3 arm = ax - delta * c;  // x_w minus the particle centre (reduce() recomputes it)
  const Vec3 uw = p.velocity[s] + w.cross(arm);
  T u[3];
  for (int a = 0; a < 3; ++a) u[a] = T(a < D ? uw[a] : 0.0);
  const T cu = L::c[q][0] * u[0] + L::c[q][1] * u[1] + L::c[q][2] * u[2];
  k.mw = T(6 * L::w[q]) * cu;
}

template <class L, class T>
void MovingBoundary<L, T>::add_links(std::int32_t solid, const ParticleSet& p) {
  const SolidCell& sc = cells_[std::size_t(solid)];
  for (int q = 1; q < Q; ++q) {
    const CellIndex xc = grid_.neighbour(sc.x[0], sc.x[1], sc.x[2], L::c[q][0], L::c[q][1], L::c[q][2]);
    if (!fluid_now(xc)) continue;
    MovingLink k;
    const auto xs = grid_.coords(xc);
    const int kx[3] = {xs[0], xs[1], xs[2]};
    k.q = std::uint8_t(q);
    k.particle = sc.particle;
    k.solid = solid;
    const CellIndex second = grid_.neighbour(xs[0], xs[1], xs[2], L::c[q][0], L::c[q][1], L::c[q][2]);
    k.has_second = fluid_now(second);
    link_motion(k, p);
    const int o = L::opp[q];
    const int x2[3] = {grid_.step(kx[0], L::c[q][0], 0), grid_.step(kx[1], L::c[q][1], 1),
                       grid_.step(kx[2], L::c[q][2], 2)};
    for (int odd = 0; odd < 2; ++odd) {
      k.slot[odd][0] = post(kx, o, odd);
      k.slot[odd][1] = post(kx, q, odd);
      k.slot[odd][2] = post(x2, o, odd);
      k.slot[odd][3] = pre(kx, q, !odd);
    }
    new_links_.push_back(k);
  }
}

// Links from the fluid cells around every solid cell, in solid-cell order then direction order
// (so grouped by particle). Incremental: a clean particle's links keep their nodes and slots and
// only move with it (link_motion, the same arithmetic as a new link: results do not depend on
// which particles were rebuilt); a dirty one's are built anew. Cost: a copy per link plus the
// new links of the dirty particles.
template <class L, class T>
void MovingBoundary<L, T>::build_links(const ParticleSet& p, bool incremental) {
  const std::size_t np = cfirst_.size();
  new_links_.clear();
  nlfirst_.resize(np);
  nlcount_.resize(np);
  for (std::size_t s = 0; s < np; ++s) {
    nlfirst_[s] = std::int32_t(new_links_.size());
    if (incremental && !dirty_[s]) {
      // Same cells in the same order: the solid index moves by the shift of the particle's range
      // (nfirst_ holds the previous ranges after the swap in set_particles()).
      const std::int32_t shift = cfirst_[s] - nfirst_[s];
      for (std::int32_t l = lfirst_[s]; l < lfirst_[s] + lcount_[s]; ++l) {
        new_links_.push_back(links_[std::size_t(l)]);
        MovingLink& k = new_links_.back();
        k.solid += shift;
        link_motion(k, p);
      }
    } else {
      for (std::int32_t i = cfirst_[s]; i < cfirst_[s] + ccount_[s]; ++i) add_links(i, p);
    }
    nlcount_[s] = std::int32_t(new_links_.size()) - nlfirst_[s];
  }
  links_.swap(new_links_);
  lfirst_.swap(nlfirst_);
  lcount_.swap(nlcount_);
  links_valid_ = true;
  link_force_.assign(3 * links_.size(), 0.0);
}

template <class L, class T>
void MovingBoundary<L, T>::apply(T* f, bool odd) {
  const bool next = !odd;
  const WallScheme ws =
      scheme_ == ParticleScheme::InterpolatedBounceBack ? WallScheme::Bouzidi : WallScheme::HalfwayBounceBack;
  const std::int64_t nl = std::int64_t(links_.size());
  // Links first: they read the post-collision populations of step t, some of which lie in slots
  // that the solid cells' reset below overwrites. Each link writes a slot its fluid cell owns.
  // Parallel only above 8192 items (a link or a reset costs about a cell update): on a loaded
  // machine a parallel region per step made a 24^3 case with 3000 links 35 times slower.
#pragma omp parallel for schedule(static) if (nl > 8192)
  for (std::int64_t l = 0; l < nl; ++l) {
    const MovingLink& k = links_[std::size_t(l)];
    const int q = k.q, o = L::opp[q];
    const CellIndex* sl = k.slot[odd];
    const T A = f[sl[0]];  // g*_o(x, t), sent into the wall
    T B = 0, C = 0;
    if (ws == WallScheme::Bouzidi && k.has_second) {
      B = f[sl[1]];  // g*_q(x, t)
      C = f[sl[2]];  // g*_o(x + c_q, t)
    }
    const T g = reflect<T>(ws, T(k.delta), k.has_second, A, B, C, k.mw);
    f[sl[3]] = g;
    for (int a = 0; a < 3; ++a) link_force_[3 * std::size_t(l) + std::size_t(a)] = double(L::c[o][a]) * (double(A) + double(g));
  }
  // Solid cells: f^eq(1, u_s) in the slots they read next step (finite values, sampled u = u_s).
  const std::int64_t nc = std::int64_t(cells_.size());
#pragma omp parallel for schedule(static) if (nc > 8192)
  for (std::int64_t i = 0; i < nc; ++i) {
    const SolidCell& sc = cells_[std::size_t(i)];
    T geq[Q];
    equilibrium<L, T>(T(1), sc.us, geq, incompressible_);
    if (sc.edge) {
      for (int q = 0; q < Q; ++q) f[pre(sc.x, q, next)] = geq[q];
    } else {
      for (int q = 0; q < Q; ++q) f[sc.cell + pre_off_[next][q]] = geq[q];
    }
  }
}

template <class L, class T>
void MovingBoundary<L, T>::reduce() {
  // The change of the set is counted once, with the first step after it.
  force_ = impulse_;
  torque_ = impulse_torque_;
  std::fill(impulse_.begin(), impulse_.end(), Vec3::Zero());
  std::fill(impulse_torque_.begin(), impulse_torque_.end(), Vec3::Zero());
  for (std::size_t l = 0; l < links_.size(); ++l) {
    const MovingLink& k = links_[l];
    const Vec3 F(link_force_[3 * l], link_force_[3 * l + 1], link_force_[3 * l + 2]);
    // The wall point x_w - X as link_motion() computed it.
    const int q = k.q;
    const Vec3 c(L::c[q][0], L::c[q][1], L::D == 3 ? L::c[q][2] : 0);
    const Vec3 ax = cells_[std::size_t(k.solid)].arm + c;
    const Vec3 arm = ax - k.delta * c;
    force_[std::size_t(k.particle)] += F;
    torque_[std::size_t(k.particle)] += arm.cross(F);
  }
}

template class MovingBoundary<D2Q9, double>;
template class MovingBoundary<D2Q9, float>;
template class MovingBoundary<D3Q19, double>;
template class MovingBoundary<D3Q19, float>;

}  // namespace ff::lbm
