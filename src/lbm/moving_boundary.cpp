// Moving solid cells: covering, refill, links and their bounce-back, in the sweep by row or after it
// (moving_boundary.hpp has the equations and their sources).
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

template <class L, class T>
template <class K>
FF_LBM_INLINE Vec3 MovingBoundary<L, T>::link_arm(const K& k, int q, const Motion& m) const {
  const Vec3 c(L::c[q][0], L::c[q][1], L::D == 3 ? L::c[q][2] : 0);
  const Vec3 ay(k.xu[0] - m.x[0], k.xu[1] - m.x[1], L::D == 3 ? k.xu[2] - m.x[2] : 0.0);
  const Vec3 ax = ay + c;
  return ax - k.delta * c;
}

// A link's constants while its particle keeps its place: reflect()'s with u_w = 0 written as
// g = a A + b X (X = A, B or C; the same operations, so the same values), and the torque lever
// (x_w - X) x c_o per unit of exchanged momentum.
template <class L, class T>
template <class K>
void MovingBoundary<L, T>::set_constants(RowLink& h, const K& k, const Motion& m) const {
  const T delta = T(k.delta);
  if (scheme_ != ParticleScheme::InterpolatedBounceBack || !k.has_second) {
    h.a = T(1);
    h.b = T(0);
    h.second = 0;
  } else if (delta < T(0.5)) {  // Bouzidi et al. (2001), boundary.hpp reflect()
    h.a = T(2) * delta;
    h.b = T(1) - T(2) * delta;
    h.second = 2;
  } else {
    const T inv2d = T(0.5) / delta;
    h.a = inv2d;
    h.b = (T(2) * delta - T(1)) * inv2d;
    h.second = 1;
  }
  const int o = L::opp[h.q];
  const Vec3 lever = link_arm(k, h.q, m).cross(Vec3(L::c[o][0], L::c[o][1], L::D == 3 ? L::c[o][2] : 0));
  if constexpr (L::D == 3) {
    for (int a = 0; a < 3; ++a) h.lever[a] = lever[a];
  } else {
    h.lever[0] = lever[2];
  }
}

// One link's bounce-back: the reflected population into the slot its fluid node reads next step,
// and the momentum it exchanges along c_o, g*_o(x, t) + g_q(x, t + 1). At rest (kMoving false)
// from the link's constants; moving, reflect() with the wall's velocity.
template <class L, class T>
template <bool kMoving, class H, class K>
FF_LBM_INLINE double MovingBoundary<L, T>::exchange(T* f, bool odd, const H& h, const K& k, const Motion& m,
                                                   const Vec3& arm) const {
  const bool next = !odd;
  const int q = h.q, o = L::opp[q];
  CellIndex sa, sb, sc, sd;
  if (!h.edge) {
    sa = h.node + post_off_[odd][o];
    sb = h.node + post_off_[odd][q];
    sc = h.node + cq_off_[q] + post_off_[odd][o];
    sd = h.node + pre_off_[next][q];
  } else {
    const auto xs = grid_.coords(h.node);
    const int kx[3] = {xs[0], xs[1], xs[2]};
    const int x2[3] = {grid_.step(kx[0], L::c[q][0], 0), grid_.step(kx[1], L::c[q][1], 1),
                       grid_.step(kx[2], L::c[q][2], 2)};
    sa = post(kx, o, odd);
    sb = post(kx, q, odd);
    sc = post(x2, o, odd);
    sd = pre(kx, q, next);
  }
  const T A = f[sa];  // g*_o(x, t), sent into the wall
  T g, geq = 0;       // a particle at rest: g^eq_o(1, 0) = 0 into slot A
  if constexpr (!kMoving) {
    const T X = h.second == 0 ? A : f[h.second == 1 ? sb : sc];  // B = g*_q(x, t), C = g*_o(x + c_q, t)
    g = h.a * A + h.b * X;
  } else {
    const WallScheme ws =
        scheme_ == ParticleScheme::InterpolatedBounceBack ? WallScheme::Bouzidi : WallScheme::HalfwayBounceBack;
    T B = 0, C = 0;
    if (ws == WallScheme::Bouzidi && k.has_second) {
      B = f[sb];  // g*_q(x, t)
      C = f[sc];  // g*_o(x + c_q, t)
    }
    // The wall point x_w - X (arm) and its velocity u_w = v + omega x (x_w - X).
    const Vec3 ay(k.xu[0] - m.x[0], k.xu[1] - m.x[1], L::D == 3 ? k.xu[2] - m.x[2] : 0.0);
    const Vec3 uw = m.v + m.w.cross(arm);
    const T cu = T(L::c[q][0]) * T(uw[0]) + T(L::c[q][1]) * T(uw[1]) + T(L::c[q][2]) * T(L::D == 3 ? uw[2] : 0.0);
    const T mw = T(6 * L::w[q]) * cu;
    const Vec3 us = m.v + m.w.cross(ay);
    const T u0 = T(us[0]), u1 = T(us[1]), u2 = T(L::D == 3 ? us[2] : 0.0);
    const T cuo = L::c[o][0] * u0 + L::c[o][1] * u1 + L::c[o][2] * u2;
    geq = T(L::w[o]) * (T(0) + T(1) * (T(3) * cuo + T(4.5) * cuo * cuo - T(1.5) * (u0 * u0 + u1 * u1 + u2 * u2)));
    g = reflect<T>(ws, T(k.delta), k.has_second, A, B, C, mw);
  }
  f[sd] = g;
  // Slot A is also what the solid cell y = x - c_q reads from x next step (AA pattern): it
  // gets g^eq_o(1, u_s(y)) instead of the fluid's population (equilibrium(), one direction).
  f[sa] = geq;
  return double(A) + double(g);
}

// The links by the lattice row of their fluid node; within a row by particle, each particle's in
// its link order (a group); groups with a cell that is not a bulk cell or a link across a periodic
// edge are late (left to apply()). Per particle, its groups in row order.
template <class L, class T>
void MovingBoundary<L, T>::build_rows() {
  const std::int64_t nrows = std::int64_t(grid_.ny) * grid_.nz;
  auto bulk = [&](CellIndex c) { return fluid_[std::size_t(c)] == 2; };
  std::vector<std::int64_t>& count = row_count_;
  count.assign(std::size_t(nrows) + 1, 0);
  link_row_.resize(links_.size());
  for (std::size_t s = 0; s < np_; ++s) update_delta(s);
  for (std::size_t s = 0; s < np_; ++s) {
    const Slice& sl = ls_[s];
    for (std::int32_t l = sl.first; l < sl.first + sl.count; ++l) {
      const std::int64_t r = node_row(links_[std::size_t(l)]);
      link_row_[std::size_t(l)] = r;
      ++count[std::size_t(r) + 1];
    }
  }
  for (std::int64_t r = 0; r < nrows; ++r) count[std::size_t(r) + 1] += count[std::size_t(r)];
  row_item_.resize(std::size_t(count[std::size_t(nrows)]));
  row_geo_.resize(row_item_.size());
  row_pos_.resize(links_.size());
  row_fill_.assign(count.begin(), count.end() - 1);
  for (std::size_t s = 0; s < np_; ++s) {
    const Slice& sl = ls_[s];
    for (std::int32_t l = sl.first; l < sl.first + sl.count; ++l) {
      const MovingLink& k = links_[std::size_t(l)];
      const std::int64_t i = row_fill_[std::size_t(link_row_[std::size_t(l)])]++;
      const bool late = k.edge || !bulk(k.node) || !bulk(k.node - cq_off_[k.q]) ||
                        (k.has_second && !bulk(k.node + cq_off_[k.q]));
      row_pos_[std::size_t(l)] = std::int32_t(i);
      RowLink& h = row_item_[std::size_t(i)];
      RowGeometry& geo = row_geo_[std::size_t(i)];
      geo = RowGeometry{k.delta, {k.xu[0], k.xu[1], k.xu[2]}, std::int32_t(s), k.has_second};
      h.node = k.node;
      h.q = k.q;
      h.edge = k.edge;
      h.late = late;
      set_constants(h, geo, mot_[s]);
    }
  }
  const_x_.resize(np_);
  const_r_.resize(np_);
  for (std::size_t s = 0; s < np_; ++s) {
    const_x_[s] = mot_[s].x;
    const_r_[s] = radius_[s];
  }
  // Groups: runs of one particle's items within a row.
  groups_.clear();
  row_group_.assign(std::size_t(nrows) + 1, 0);
  for (std::int64_t r = 0; r < nrows; ++r) {
    for (std::int64_t i = count[std::size_t(r)]; i < count[std::size_t(r) + 1]; ++i) {
      const std::int32_t particle = row_geo_[std::size_t(i)].particle;
      if (i == count[std::size_t(r)] || particle != groups_.back().particle) groups_.push_back(Group{i, 0, particle, false});
      ++groups_.back().count;
      groups_.back().late = groups_.back().late || row_item_[std::size_t(i)].late;
    }
    row_group_[std::size_t(r) + 1] = std::int64_t(groups_.size());
  }
  part_group_first_.assign(np_ + 1, 0);
  for (const Group& g : groups_) ++part_group_first_[std::size_t(g.particle) + 1];
  for (std::size_t s = 0; s < np_; ++s) part_group_first_[s + 1] += part_group_first_[s];
  part_group_.resize(groups_.size());
  row_fill_.assign(part_group_first_.begin(), part_group_first_.end() - 1);
  for (std::size_t g = 0; g < groups_.size(); ++g)
    part_group_[std::size_t(row_fill_[std::size_t(groups_[g].particle)]++)] = std::int32_t(g);
  group_force_.assign(groups_.size(), Vec3::Zero());
  group_torque_.assign(groups_.size(), Vec3::Zero());
  rows_epoch_ = links_epoch_;
}

template <class L, class T>
void MovingBoundary<L, T>::prepare_rows() {
  // A particle that moved since its links' constants were set: its Bouzidi fractions, then the
  // constants (arms, levers) of its links.
#pragma omp parallel for schedule(static) if (nlinks_ > 8192)
  for (std::int64_t si = 0; si < std::int64_t(np_); ++si) {
    const std::size_t s = std::size_t(si);
    if (mot_[s].x == const_x_[s] && radius_[s] == const_r_[s]) continue;
    update_delta(s);
    const Slice& sl = ls_[s];
    for (std::int32_t l = sl.first; l < sl.first + sl.count; ++l) {
      const std::size_t i = std::size_t(row_pos_[std::size_t(l)]);
      row_geo_[i].delta = links_[std::size_t(l)].delta;
      set_constants(row_item_[i], row_geo_[i], mot_[s]);
    }
    const_x_[s] = mot_[s].x;
    const_r_[s] = radius_[s];
  }
}

// One link's share of its group's force and torque (the same operations in apply_group_as and in
// apply()'s pass by particle: the results do not depend on which of them ran).
template <class L, class T>
template <bool kMoving, class H, class K>
FF_LBM_INLINE void MovingBoundary<L, T>::add_link(T* f, bool odd, const H& h, const K& k, const Motion& m, Vec3& F,
                                                  Vec3& M) const {
  const int o = L::opp[h.q];
  Vec3 arm = Vec3::Zero();
  if constexpr (kMoving) arm = link_arm(k, h.q, m);
  const double ag = exchange<kMoving, H, K>(f, odd, h, k, m, arm);
  const Vec3 Fl(L::c[o][0] * ag, L::c[o][1] * ag, L::D == 3 ? L::c[o][2] * ag : 0.0);
  F += Fl;
  if constexpr (kMoving) {
    M += arm.cross(Fl);
  } else if constexpr (L::D == 3) {
    M += ag * Vec3(h.lever[0], h.lever[1], h.lever[2]);
  } else {
    M[2] += ag * h.lever[0];
  }
}

template <class L, class T>
template <bool kMoving>
FF_LBM_INLINE void MovingBoundary<L, T>::apply_group_as(T* f, bool odd, std::int64_t g) const {
  const Group& gr = groups_[std::size_t(g)];
  const Motion& m = mot_[std::size_t(gr.particle)];
  Vec3 F = Vec3::Zero(), M = Vec3::Zero();
  const RowLink* items = row_item_.data();
  const std::int64_t n_items = std::int64_t(row_item_.size());
  for (std::int64_t i = gr.first; i < gr.first + gr.count; ++i) {
    // The sweep's streams crowd out the hardware prefetcher's: fetch the links some items ahead.
    __builtin_prefetch(items + std::min(i + 12, n_items - 1), 0, 3);
    add_link<kMoving>(f, odd, items[i], row_geo_[std::size_t(i)], m, F, M);
  }
  // Each group its own entry (const: called from the sweep's threads).
  const_cast<Vec3&>(group_force_[std::size_t(g)]) = F;
  const_cast<Vec3&>(group_torque_[std::size_t(g)]) = M;
}

// Particle s's links one node row at a time, after the sweep (no row index: a set that changed
// within the last steps): each row's sum from zero in link order, the particle's the sum of the
// rows' in row order, as apply_group_as and apply() do with the index.
template <class L, class T>
template <bool kMoving>
void MovingBoundary<L, T>::particle_links(T* f, bool odd, std::size_t s, Vec3& F, Vec3& M) const {
  const bool next = !odd;
  const Motion& m = mot_[s];
  const Slice& sl = ls_[s];
  const std::int32_t end = sl.first + sl.count;
  F = Vec3::Zero();
  M = Vec3::Zero();
  std::int64_t row = -1;
  Vec3 Fg = Vec3::Zero(), Mg = Vec3::Zero();
  for (std::int32_t l = sl.first; l < end; ++l) {
    // The populations are far from cache (the sweep streamed the lattice since): fetch the two
    // slots of a link some links ahead (they are the solid cell's and the fluid node's).
    constexpr std::int32_t kAhead = 12;
    if (l + kAhead < end) {
      const MovingLink& a = links_[std::size_t(l + kAhead)];
      if (!a.edge) {
        __builtin_prefetch(f + a.node + post_off_[odd][L::opp[a.q]], 1);
        __builtin_prefetch(f + a.node + pre_off_[next][a.q], 1);
        if (scheme_ == ParticleScheme::InterpolatedBounceBack && a.has_second) {
          __builtin_prefetch(f + a.node + post_off_[odd][a.q], 0);
          __builtin_prefetch(f + a.node + cq_off_[a.q] + post_off_[odd][L::opp[a.q]], 0);
        }
      }
    }
    const MovingLink& k = links_[std::size_t(l)];
    const std::int64_t r = node_row(k);
    if (r != row) {
      if (row >= 0) {
        F += Fg;
        M += Mg;
      }
      Fg = Vec3::Zero();
      Mg = Vec3::Zero();
      row = r;
    }
    if constexpr (kMoving) {
      add_link<true>(f, odd, k, k, m, Fg, Mg);  // (a moving link reads no constants)
    } else {
      RowLink h;
      h.node = k.node;
      h.q = k.q;
      h.edge = k.edge;
      set_constants(h, k, m);
      add_link<false>(f, odd, h, k, m, Fg, Mg);
    }
  }
  if (row >= 0) {
    F += Fg;
    M += Mg;
  }
}

template <class L, class T>
FF_LBM_INLINE void MovingBoundary<L, T>::apply_group(T* f, bool odd, std::int64_t g) const {
  const Motion& m = mot_[std::size_t(groups_[std::size_t(g)].particle)];
  if (m.moves()) apply_group_as<true>(f, odd, g);
  else apply_group_as<false>(f, odd, g);  // a particle at rest: no moving-wall term
}

template <class L, class T>
void MovingBoundary<L, T>::apply_rows(T* f, bool odd, std::int64_t r0, std::int64_t r1) const {
  for (std::int64_t g = row_group_[std::size_t(r0)]; g < row_group_[std::size_t(r1)]; ++g)
    if (!groups_[std::size_t(g)].late) apply_group(f, odd, g);
}

template <class L, class T>
void MovingBoundary<L, T>::apply(T* f, bool odd, const std::vector<std::pair<std::int64_t, std::int64_t>>& inline_rows) {
  const bool next = !odd;
  const std::int64_t np = std::int64_t(np_);
  if (!rows_ready()) {
    // No row index (the links changed within the last steps): particle by particle.
    // Parallel only above 8192 items (a link or a reset costs about a cell update): on a loaded
    // machine a parallel region per step made a 24^3 case with 3000 links 35 times slower.
#pragma omp parallel for schedule(static) if (nlinks_ > 8192)
    for (std::int64_t s = 0; s < np; ++s) {
      update_delta(std::size_t(s));
      const Motion& m = mot_[std::size_t(s)];
      if (m.moves())
        particle_links<true>(f, odd, std::size_t(s), lforce_[std::size_t(s)], ltorque_[std::size_t(s)]);
      else
        particle_links<false>(f, odd, std::size_t(s), lforce_[std::size_t(s)], ltorque_[std::size_t(s)]);
    }
  } else {
    apply_groups(f, odd, inline_rows);
  }
  // Exposed solid cells: f^eq(1, u_s) in all the slots they read next step (after the links: they
  // read slots that this overwrites).
#pragma omp parallel for schedule(static) if (ncells_ > 8192)
  for (std::int64_t s = 0; s < np; ++s) {
    const Slice& sl = cs_[std::size_t(s)];
    const Motion& m = mot_[std::size_t(s)];
    const std::int32_t ne = reset_all_ ? sl.count : ecount_[std::size_t(s)];
    for (std::int32_t e = 0; e < ne; ++e) {
      const SolidCell& sc = cells_[std::size_t(sl.first + (reset_all_ ? e : eoff_[std::size_t(sl.first + e)]))];
      const Vec3 arm(sc.xu[0] - m.x[0], sc.xu[1] - m.x[1], L::D == 3 ? sc.xu[2] - m.x[2] : 0.0);
      reset_cell(f, sc.cell, sc.edge, arm, m, next);
    }
  }
  // Cells covered since the last step: once (they held fluid).
  for (const CellIndex c : pending_) {
    const std::int32_t o = owner_[std::size_t(c)];
    if (o >= 0) reset_cell(f, c, on_edge(c), arm_of(c, std::size_t(o), mot_), mot_[std::size_t(o)], next);
  }
  pending_.clear();
  applied_ = true;
  // Links that stood for two steps get their row index (its build costs a few steps' links; a set
  // that changes every step never pays it): the sweep applies them from the next step on.
  stood_ = applied_epoch_ == links_epoch_ ? stood_ + 1 : 0;
  applied_epoch_ = links_epoch_;
  if (stood_ >= 2 && !rows_ready() && row_index_) build_rows();
}

// With the row index: the groups the sweep did not apply, then each particle's sum.
template <class L, class T>
void MovingBoundary<L, T>::apply_groups(T* f, bool odd, const std::vector<std::pair<std::int64_t, std::int64_t>>& inline_rows) {
  const std::int64_t np = std::int64_t(np_);
  if (inline_rows.empty()) prepare_rows();  // (the sweep did when it applied rows)
  // 1. The links the sweep did not apply (apply_rows): every group of the rows outside
  //    inline_rows, the late groups inside them. Each link writes slots only it touches.
  std::vector<std::pair<std::int64_t, std::int64_t>>& done = done_rows_;  // (kept: no allocation per step)
  done.clear();
  for (const auto& d : inline_rows)
    if (d.first < d.second) done.push_back(d);
  std::sort(done.begin(), done.end());
  const std::int64_t nrows = std::int64_t(row_group_.size()) - 1;
  deferred_groups_.clear();
  std::int64_t r = 0;
  auto all_of = [&](std::int64_t a, std::int64_t b) {
    for (std::int64_t g = row_group_[std::size_t(a)]; g < row_group_[std::size_t(b)]; ++g) deferred_groups_.push_back(g);
  };
  for (const auto& [a, b] : done) {
    if (r < a) all_of(r, a);
    for (std::int64_t g = row_group_[std::size_t(a)]; g < row_group_[std::size_t(b)]; ++g)
      if (groups_[std::size_t(g)].late) deferred_groups_.push_back(g);
    r = std::max(r, b);
  }
  if (r < nrows) all_of(r, nrows);
  const std::int64_t nt = std::int64_t(deferred_groups_.size());
#pragma omp parallel for schedule(dynamic, 256) if (nt > 4096)
  for (std::int64_t i = 0; i < nt; ++i) apply_group(f, odd, deferred_groups_[std::size_t(i)]);
  // 2. Each particle's load: its groups' sums in row order (the same on any thread count and
  //    whichever rows the sweep applied).
#pragma omp parallel for schedule(static) if (nlinks_ > 8192)
  for (std::int64_t s = 0; s < np; ++s) {
    Vec3 F = Vec3::Zero(), M = Vec3::Zero();
    for (std::int64_t j = part_group_first_[std::size_t(s)]; j < part_group_first_[std::size_t(s) + 1]; ++j) {
      F += group_force_[std::size_t(part_group_[std::size_t(j)])];
      M += group_torque_[std::size_t(part_group_[std::size_t(j)])];
    }
    lforce_[std::size_t(s)] = F;
    ltorque_[std::size_t(s)] = M;
  }
}

template <class L, class T>
void MovingBoundary<L, T>::reduce() {
  // The change of the set is counted once, with the first step after it.
  for (std::size_t s = 0; s < force_.size(); ++s) {
    force_[s] = impulse_[s];
    torque_[s] = impulse_torque_[s];
    if (applied_) {
      force_[s] += lforce_[s];
      torque_[s] += ltorque_[s];
    }
  }
  std::fill(impulse_.begin(), impulse_.end(), Vec3::Zero());
  std::fill(impulse_torque_.begin(), impulse_torque_.end(), Vec3::Zero());
  applied_ = false;
}

template class MovingBoundary<D2Q9, double>;
template class MovingBoundary<D2Q9, float>;
template class MovingBoundary<D3Q19, double>;
template class MovingBoundary<D3Q19, float>;

}  // namespace ff::lbm
