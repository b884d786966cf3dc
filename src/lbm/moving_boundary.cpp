// Moving solid cells: which cells the particles cover, the cells they uncover (refill) and their
// links with the fluid (moving_boundary.hpp has the equations and their sources). The links'
// bounce-back, in the sweep by row or after it, and the particles' loads: moving_boundary_links.cpp.
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
    cq_off_[q] = cq;
    pre_off_[0][q] = q * N;
    pre_off_[1][q] = q == 0 ? 0 : L::opp[q] * N - cq;
    post_off_[0][q] = q == 0 ? 0 : L::opp[q] * N;
    post_off_[1][q] = q == 0 ? 0 : q * N + cq;
  }
}

template <class L, class T>
void MovingBoundary<L, T>::set_fluid_mask(std::vector<std::uint8_t> fluid) {
  fluid_ = std::move(fluid);
  owner_.assign(fluid_.size(), -1);
  np_ = 0;
  cs_.clear();
  ls_.clear();
  cells_.clear();
  eoff_.clear();
  links_.clear();
  pending_.clear();
  ncells_ = nlinks_ = 0;
  links_valid_ = false;
  ++links_epoch_;
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
bool MovingBoundary<L, T>::on_edge(CellIndex c) const {
  const auto x = grid_.coords(c);
  const int n[3] = {grid_.nx, grid_.ny, grid_.nz};
  bool e = false;
  for (int a = 0; a < L::D; ++a) e = e || (grid_.periodic[a] && (x[a] == 0 || x[a] == n[a] - 1));
  return e;
}

// Cell centre minus particle centre, minimum image on periodic axes (2D: z = 0).
template <class L, class T>
Vec3 MovingBoundary<L, T>::arm_of(CellIndex c, std::size_t s, const std::vector<Motion>& m) const {
  const auto x = grid_.coords(c);
  const int n[3] = {grid_.nx, grid_.ny, grid_.nz};
  Vec3 arm = Vec3::Zero();
  for (int a = 0; a < L::D; ++a) {
    double d = x[a] - m[s].x[a];
    if (grid_.periodic[a]) d -= n[a] * std::round(d / n[a]);
    arm[a] = d;
  }
  return arm;
}

// Forgets every slice: the cells of the current set become "released" (refilled unless retaken).
template <class L, class T>
void MovingBoundary<L, T>::release_all() {
  for (std::size_t t = 0; t < np_; ++t) {
    const Slice& sl = cs_[t];
    for (std::int32_t i = sl.first; i < sl.first + sl.count; ++i) {
      const CellIndex c = cells_[std::size_t(i)].cell;
      owner_[std::size_t(c)] = -2 - std::int32_t(t);
      released_.push_back(c);
    }
  }
  cells_.clear();
  eoff_.clear();
  links_.clear();
  ncells_ = nlinks_ = 0;
  ++links_epoch_;
}

// Room for `need` entries in particle self's slice of arr (and of par, parallel to it): in place,
// else a new slice at the end; when that would reallocate, every slice is first packed into
// spare (with room to grow) and the arrays swapped. Slice contents keep their order.
template <class L, class T>
template <class V>
void MovingBoundary<L, T>::place(V& arr, Slice& self, std::int32_t need, std::vector<Slice>& all, V& spare,
                                 std::vector<std::int32_t>* par) {
  if (need <= self.cap) return;
  auto room = [](std::int32_t n) { return n + n / 4 + 8; };
  const std::int32_t cap = room(need);
  if (arr.size() + std::size_t(cap) > arr.capacity()) {
    std::size_t total = std::size_t(cap);
    for (const Slice& sl : all) total += std::size_t(room(sl.count));
    spare.clear();
    if (spare.capacity() < total) spare.reserve(2 * total);
    std::vector<std::int32_t> pspare;
    if (par) pspare.reserve(spare.capacity());
    for (Slice& sl : all) {
      if (&sl == &self) continue;
      const std::size_t first = spare.size();
      const std::int32_t c = room(sl.count);
      spare.insert(spare.end(), arr.begin() + sl.first, arr.begin() + sl.first + sl.count);
      spare.resize(first + std::size_t(c));
      if (par) {
        pspare.insert(pspare.end(), par->begin() + sl.first, par->begin() + sl.first + sl.count);
        pspare.resize(first + std::size_t(c));
      }
      sl.first = std::int32_t(first);
      sl.cap = c;
    }
    arr.swap(spare);
    if (arr.capacity() < 2 * total) arr.reserve(2 * total);
    if (par) {
      par->swap(pspare);
      par->reserve(arr.capacity());
    }
  }
  self.first = std::int32_t(arr.size());
  self.cap = cap;
  arr.resize(arr.size() + std::size_t(cap));
  if (par) par->resize(arr.size());
}

template <class L, class T>
void MovingBoundary<L, T>::set_particles(const ParticleSet& p, T* f, bool odd, bool bookkeeping) {
  const std::size_t np = p.size();
  const char* name = particle_scheme_name(scheme_);
  if (p.position.size() != np || p.velocity.size() != np || p.omega.size() != np || (!p.id.empty() && p.id.size() != np))
    throw InputError(fmt::format("{} particle set: the arrays differ in length (radius {}, position {}, velocity {}, "
                                 "omega {}, id {}): all must have one entry per particle (id may be empty)",
                                 name, np, p.position.size(), p.velocity.size(), p.omega.size(), p.id.size()));
  if (np >= std::size_t(1) << 30) throw InputError(fmt::format("{} particle set: more than 2^30 particles", name));
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
  // The motion of the new set (the previous one kept for the refill of cells it leaves).
  mot_.swap(prev_mot_);
  pid_.swap(prev_pid_);
  mot_.resize(np);
  pid_.resize(np);
  for (std::size_t s = 0; s < np; ++s) {
    mot_[s].x = D == 3 ? p.position[s] : Vec3(p.position[s][0], p.position[s][1], 0);
    mot_[s].v = D == 3 ? p.velocity[s] : Vec3(p.velocity[s][0], p.velocity[s][1], 0);
    mot_[s].w = D == 3 ? p.omega[s] : Vec3(0, 0, p.omega[s][2]);
    pid_[s] = p.id.empty() ? std::uint64_t(s) : p.id[s];
  }
  covered_.clear();
  released_.clear();
  if (!bookkeeping) pending_.clear();  // a resume: the populations are the checkpoint's
  // A new particle count, a new mask or a resume: everything is rebuilt.
  const bool full = !links_valid_ || np != np_ || !bookkeeping;
  if (full) {
    release_all();
    cs_.assign(np, Slice{});
    ls_.assign(np, Slice{});
    ecount_.assign(np, 0);
    rescan_.assign(np, 1);
    contested_.assign(np, 0);
    scan_x_.assign(np, Vec3::Zero());
    scan_r_.assign(np, 0.0);
    margin_.assign(np, 0.0);
    radius_.assign(np, 0.0);
    dirty_.assign(np, 1);
    delta_x_.assign(np, Vec3::Constant(std::nan("")));
    delta_r_.assign(np, 0.0);
  } else {
    dirty_.assign(np, 0);
  }
  np_ = np;

  // 1. Ownership in particle order (the first particle that contains a cell owns it), rescanning
  //    only the particles whose cells can have changed.
  for (std::size_t s = 0; s < np; ++s) {
    const double r = p.radius[s];
    radius_[s] = r;
    bool need = rescan_[s] || contested_[s] || r != scan_r_[s];
    if (!need) need = !((mot_[s].x - scan_x_[s]).norm() < margin_[s] - 1e-9);
    if (need) {
      scan(s, p);
      claim(s);
    }
    rescan_[s] = 0;
  }

  if (bookkeeping) {
    // 2. Covering: a cell that turns solid hands its fluid momentum to its particle.
    for (const CellIndex c : covered_) {
      const auto xc = grid_.coords(c);
      const int x[3] = {xc[0], xc[1], xc[2]};
      const std::size_t s = std::size_t(owner_[std::size_t(c)]);
      double m = 1, j[3] = {0, 0, 0};
      for (int q = 0; q < Q; ++q) {
        const double g = double(f[pre(x, q, odd)]);
        m += g;
        for (int a = 0; a < D; ++a) j[a] += L::c[q][a] * g;
      }
      const Vec3 J(j[0], j[1], j[2]);
      impulse_[s] += J;
      impulse_torque_[s] += arm_of(c, s, mot_).cross(J);
      stats_.impulse += J;
      stats_.mass_removed += m;
      ++stats_.covered;
      pending_.push_back(c);
    }
    // 3. Refill of the cells that turn fluid: f^eq(rho_avg, u_w) with rho_avg over the neighbours
    //    that are fluid before and after (owner -1 now), u_w the uncovering particle's velocity at
    //    the cell (its previous one if it left the set).
    for (const CellIndex c : released_) {
      const std::int32_t code = owner_[std::size_t(c)];
      if (code > -2) continue;  // taken again
      const std::size_t t = std::size_t(-2 - code);
      const auto xc = grid_.coords(c);
      const int x[3] = {xc[0], xc[1], xc[2]};
      double rsum = 0;
      int count = 0;
      for (int q = 1; q < Q; ++q) {
        const CellIndex nb = grid_.neighbour(x[0], x[1], x[2], L::c[q][0], L::c[q][1], L::c[q][2]);
        if (!fluid_[std::size_t(nb)] || owner_[std::size_t(nb)] != -1) continue;
        const auto yc = grid_.coords(nb);
        const int y[3] = {yc[0], yc[1], yc[2]};
        double rho = 1;
        for (int k = 0; k < Q; ++k) rho += double(f[pre(y, k, odd)]);
        rsum += rho;
        ++count;
      }
      const double rho = count > 0 ? rsum / count : 1.0;
      const bool same = t < np && (p.id.empty() || p.id[t] == prev_pid_[t]);
      const std::vector<Motion>& m = same ? mot_ : prev_mot_;
      const Vec3 arm = arm_of(c, t, m);
      Vec3 uw = m[t].v + m[t].w.cross(arm);
      if (D == 2) uw[2] = 0;
      if (!same) ++stats_.unattributed;
      const T u[3] = {T(uw[0]), T(uw[1]), T(D == 3 ? uw[2] : 0.0)};
      T geq[Q];
      equilibrium<L, T>(T(rho), u, geq, incompressible_);
      double j[3] = {0, 0, 0};
      for (int q = 0; q < Q; ++q) {
        f[pre(x, q, odd)] = geq[q];
        for (int a = 0; a < D; ++a) j[a] += L::c[q][a] * double(geq[q]);
      }
      const Vec3 J(j[0], j[1], j[2]);  // the refill's momentum as stored
      if (same) {
        impulse_[t] -= J;
        impulse_torque_[t] -= arm.cross(J);
      }
      stats_.impulse -= J;
      stats_.mass_added += rho;
      ++stats_.uncovered;
    }
  }
  // 4. The links that may see a changed cell; the released cells become fluid.
  if (!full) {
    for (const CellIndex c : covered_) mark_dirty(c);
    for (const CellIndex c : released_)
      if (owner_[std::size_t(c)] <= -2) mark_dirty(c);
  }
  for (const CellIndex c : released_)
    if (owner_[std::size_t(c)] <= -2) owner_[std::size_t(c)] = -1;
  // 5. Links: rebuilt for the dirty particles; the others keep theirs (Bouzidi: new fractions if moved).
  for (std::size_t s = 0; s < np; ++s)
    if (dirty_[s]) build_links(s, p);
  if (full) {
    // Room for the slices to grow without reallocation in later steps.
    cells_.reserve(2 * cells_.size() + 1024);
    eoff_.reserve(cells_.capacity());
    links_.reserve(2 * links_.size() + 1024);
  }
  links_valid_ = true;
  stats_.solid_cells = long(ncells_);
  stats_.links = long(nlinks_);
  force_.assign(np, Vec3::Zero());
  torque_.assign(np, Vec3::Zero());
  lforce_.assign(np, Vec3::Zero());
  ltorque_.assign(np, Vec3::Zero());
  applied_ = false;
}

// The cells of particle s (centres strictly inside, static fluid) in scan order into scan_, and
// its margin: the smallest distance of a lattice point from its surface (at most 1), so that no
// cell changes side while it moves less than that.
template <class L, class T>
void MovingBoundary<L, T>::scan(std::size_t s, const ParticleSet& p) {
  const int D = L::D;
  const int n[3] = {grid_.nx, grid_.ny, grid_.nz};
  const Vec3& X = mot_[s].x;
  const double r = p.radius[s];
  scan_.clear();
  int lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  for (int a = 0; a < D; ++a) {
    lo[a] = int(std::ceil(X[a] - r));
    hi[a] = int(std::floor(X[a] + r));
  }
  double margin = 1.0;
  auto gap = [&](int x, double d2) {
    const double dx = x - X[0];
    margin = std::min(margin, std::abs(std::sqrt(dx * dx + d2) - r));
  };
  const int zlo = D == 3 ? lo[2] - 1 : 0, zhi = D == 3 ? hi[2] + 1 : 0;
  for (int z = zlo; z <= zhi; ++z)
    for (int y = lo[1] - 1; y <= hi[1] + 1; ++y) {
      const double dy = y - X[1], dz = D == 3 ? z - X[2] : 0.0;
      const double d2 = dy * dy + dz * dz;
      const double rest = r * r - d2;
      // Margin: along a row the distance from the surface falls towards the crossing and rises
      // beyond it, so the points next to the crossings (or to the centre) are the nearest.
      if (rest > 0) {
        const double half = std::sqrt(rest);
        const int a0 = int(std::floor(X[0] - half)), a1 = int(std::floor(X[0] + half));
        for (int x = a0 - 1; x <= a0 + 2; ++x) gap(x, d2);
        for (int x = a1 - 1; x <= a1 + 2; ++x) gap(x, d2);
      } else {
        const int a0 = int(std::floor(X[0]));
        gap(a0, d2);
        gap(a0 + 1, d2);
      }
      if (z < lo[2] || z > hi[2] || y < lo[1] || y > hi[1]) continue;
      // Only |x - X| < sqrt(r^2 - dy^2 - dz^2) can be inside: the row visits that range.
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
        if (!fluid_[std::size_t(ci)]) continue;
        bool edge = false;
        for (int a = 0; a < D; ++a) edge = edge || (grid_.periodic[a] && (c[a] == 0 || c[a] == n[a] - 1));
        scan_.push_back(SolidCell{ci, {x, y, z}, edge});
      }
    }
  scan_x_[s] = X;
  scan_r_[s] = r;
  margin_[s] = margin;
}

// Ownership of the scanned cells of particle s: free cells and those of later particles are taken
// (a later particle that loses one rescans), cells of earlier ones are not (s is then contested
// and rescans every set); its former cells it no longer owns are released.
template <class L, class T>
void MovingBoundary<L, T>::claim(std::size_t s) {
  const std::int32_t me = std::int32_t(s), mark = INT32_MIN + me;
  bool contested = false;
  std::size_t keep = 0;
  for (std::size_t i = 0; i < scan_.size(); ++i) {
    const CellIndex c = scan_[i].cell;
    std::int32_t& o = owner_[std::size_t(c)];
    if (o >= 0 && o < me) {
      contested = true;
      continue;
    }
    if (o == -1) covered_.push_back(c);
    else if (o > me) rescan_[std::size_t(o)] = 1;
    o = mark;
    scan_[keep++] = scan_[i];
  }
  scan_.resize(keep);
  contested_[s] = contested;
  Slice& sl = cs_[s];
  bool same = std::int32_t(keep) == sl.count;
  for (std::int32_t i = sl.first; i < sl.first + sl.count; ++i) {
    const CellIndex c = cells_[std::size_t(i)].cell;
    if (same && c != scan_[std::size_t(i - sl.first)].cell) same = false;
    if (owner_[std::size_t(c)] == me) {
      owner_[std::size_t(c)] = -2 - me;
      released_.push_back(c);
    }
  }
  for (const SolidCell& sc : scan_) owner_[std::size_t(sc.cell)] = me;
  if (same) return;
  dirty_[s] = 1;
  ncells_ += keep;
  ncells_ -= std::size_t(sl.count);
  place(cells_, sl, std::int32_t(keep), cs_, cells_spare_, &eoff_);
  for (std::size_t i = 0; i < keep; ++i) cells_[std::size_t(sl.first) + i] = scan_[i];
  sl.count = std::int32_t(keep);
}

// A changed cell c alters the links of the solid cells y with c = y + c_q (the link's fluid
// node) or c = y + 2 c_q (its second node) and whether y is exposed: their particles are dirty.
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
      const std::int32_t o = owner_[std::size_t(grid_.index(y[0], y[1], y[2]))];
      if (o >= 0) dirty_[std::size_t(o)] = 1;
    }
}

// Bouzidi fraction of a link from its solid cell and the particle's centre and radius.
template <class L, class T>
double MovingBoundary<L, T>::link_delta(const MovingLink& k, const Motion& m, double r) const {
  if (scheme_ != ParticleScheme::InterpolatedBounceBack) return 0.5;
  const int q = k.q;
  const Vec3 c(L::c[q][0], L::c[q][1], L::D == 3 ? L::c[q][2] : 0);
  const Vec3 arm(k.xu[0] - m.x[0], k.xu[1] - m.x[1], L::D == 3 ? k.xu[2] - m.x[2] : 0.0);
  // x relative to the centre; |ax - delta c|^2 = r^2: the smaller root (|ax| >= r at delta = 0,
  // |arm| < r at delta = 1).
  const Vec3 ax = arm + c;
  const double cc = c.squaredNorm(), b = ax.dot(c), e = ax.squaredNorm() - r * r;
  const double disc = std::max(0.0, b * b - cc * e);
  return std::clamp((b - std::sqrt(disc)) / cc, 0.0, 1.0);
}

// The Bouzidi fractions of particle s's links at its current position and radius (once per move).
template <class L, class T>
void MovingBoundary<L, T>::update_delta(std::size_t s) {
  if (scheme_ != ParticleScheme::InterpolatedBounceBack) return;
  if (mot_[s].x == delta_x_[s] && radius_[s] == delta_r_[s]) return;
  const Slice& sl = ls_[s];
  for (std::int32_t l = sl.first; l < sl.first + sl.count; ++l)
    links_[std::size_t(l)].delta = link_delta(links_[std::size_t(l)], mot_[s], radius_[s]);
  delta_x_[s] = mot_[s].x;
  delta_r_[s] = radius_[s];
}

// Links from the fluid cells around every solid cell of particle s, in cell order then direction
// order, and its exposed cells (a neighbour that is a static solid or off the lattice: what it
// feeds the cell is not a particle's, so the cell is reset every step; what fluid neighbours feed
// it the links replace).
template <class L, class T>
void MovingBoundary<L, T>::build_links(std::size_t s, const ParticleSet&) {
  const int n[3] = {grid_.nx, grid_.ny, grid_.nz};
  const Slice& cl = cs_[s];
  new_links_.clear();
  new_eoff_.clear();
  for (std::int32_t i = 0; i < cl.count; ++i) {
    const SolidCell& sc = cells_[std::size_t(cl.first + i)];
    int x[3] = {0, 0, 0};  // the wrapped coordinates (a solid cell lies on the lattice)
    for (int a = 0; a < L::D; ++a) x[a] = wrap_axis(sc.xu[a], n[a], grid_.periodic[a]);
    bool exposed = false;
    for (int q = 1; q < Q; ++q) {
      int xs[3];
      for (int a = 0; a < 3; ++a) xs[a] = grid_.step(x[a], L::c[q][a], a);
      const CellIndex xc = grid_.index(xs[0], xs[1], xs[2]);
      if (owner_[std::size_t(xc)] < 0 && !fluid_[std::size_t(xc)]) exposed = true;  // static solid or off the lattice
      if (!fluid_now(xc)) continue;
      MovingLink k;
      k.node = xc;
      for (int a = 0; a < 3; ++a) k.xu[a] = sc.xu[a];
      k.q = std::uint8_t(q);
      k.has_second = fluid_now(grid_.neighbour(xs[0], xs[1], xs[2], L::c[q][0], L::c[q][1], L::c[q][2]));
      k.edge = false;
      for (int a = 0; a < L::D; ++a) k.edge = k.edge || (grid_.periodic[a] && (xs[a] == 0 || xs[a] == n[a] - 1));
      k.delta = link_delta(k, mot_[s], radius_[s]);
      new_links_.push_back(k);
    }
    if (exposed) new_eoff_.push_back(i);
  }
  // In node-row order (stable: scan order within a row): a particle's links in one lattice row are
  // then one range of its slice, which apply() sums as the sweep's groups (build_rows).
  // A stable counting sort over the rows the particle's links span (scratch kept between calls: no
  // allocation once grown; periodic wraps make that span the whole axis at worst).
  if (!new_links_.empty()) {
    std::int64_t lo = node_row(new_links_[0]), hi = lo;
    for (const MovingLink& k : new_links_) {
      const std::int64_t r = node_row(k);
      lo = std::min(lo, r);
      hi = std::max(hi, r);
    }
    sort_count_.assign(std::size_t(hi - lo + 2), 0);
    for (const MovingLink& k : new_links_) ++sort_count_[std::size_t(node_row(k) - lo) + 1];
    for (std::size_t i = 1; i < sort_count_.size(); ++i) sort_count_[i] += sort_count_[i - 1];
    sorted_links_.resize(new_links_.size());
    for (const MovingLink& k : new_links_) sorted_links_[std::size_t(sort_count_[std::size_t(node_row(k) - lo)]++)] = k;
    new_links_.swap(sorted_links_);
  }
  // Exposed cells: offsets into the cell slice, stored in eoff_ alongside it.
  ecount_[s] = std::int32_t(new_eoff_.size());
  std::copy(new_eoff_.begin(), new_eoff_.end(), eoff_.begin() + cl.first);
  Slice& ll = ls_[s];
  nlinks_ += new_links_.size();
  nlinks_ -= std::size_t(ll.count);
  ++links_epoch_;
  place(links_, ll, std::int32_t(new_links_.size()), ls_, links_spare_, nullptr);
  std::copy(new_links_.begin(), new_links_.end(), links_.begin() + ll.first);
  ll.count = std::int32_t(new_links_.size());
  delta_x_[s] = mot_[s].x;
  delta_r_[s] = radius_[s];
}

// f^eq(1, u_s) into the slots a solid cell reads in the next step, u_s = v + omega x arm.
template <class L, class T>
void MovingBoundary<L, T>::reset_cell(T* f, CellIndex c, bool edge, const Vec3& arm, const Motion& m, bool next) const {
  const Vec3 us = m.v + m.w.cross(arm);
  const T u[3] = {T(us[0]), T(us[1]), T(L::D == 3 ? us[2] : 0.0)};
  T geq[Q];
  equilibrium<L, T>(T(1), u, geq, incompressible_);
  if (edge) {
    const auto x = grid_.coords(c);
    const int xi[3] = {x[0], x[1], x[2]};
    for (int q = 0; q < Q; ++q) f[pre(xi, q, next)] = geq[q];
  } else {
    for (int q = 0; q < Q; ++q) f[c + pre_off_[next][q]] = geq[q];
  }
}

// The lattice row (y + ny z) of a link's fluid node, from the solid cell's unwrapped coordinates
// (no division).
template <class L, class T>
std::int64_t MovingBoundary<L, T>::node_row(const MovingLink& k) const {
  const int y = wrap_axis(k.xu[1] + L::c[k.q][1], grid_.ny, grid_.periodic[1]);
  const int z = L::D == 3 ? wrap_axis(k.xu[2] + L::c[k.q][2], grid_.nz, grid_.periodic[2]) : 0;
  return std::int64_t(y) + std::int64_t(grid_.ny) * z;
}

template class MovingBoundary<D2Q9, double>;
template class MovingBoundary<D2Q9, float>;
template class MovingBoundary<D3Q19, double>;
template class MovingBoundary<D3Q19, float>;

}  // namespace ff::lbm
