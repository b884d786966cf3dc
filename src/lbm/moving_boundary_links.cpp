// The links of the moving solid cells (moving_boundary.cpp builds them): their bounce-back and
// momentum exchange, by lattice row inside the bulk sweep (the row index) or after it, and the
// particles' loads summed in a fixed order (moving_boundary.hpp has the equations and sources).
#include <algorithm>
#include <cmath>

#include "lbm/boundary.hpp"
#include "lbm/moving_boundary.hpp"

namespace ff::lbm {

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

// The members defined here, for the four lattices and precisions (the class itself is instantiated
// in moving_boundary.cpp, with the members defined there).
#define FF_MOVING_BOUNDARY_LINKS(L, T)                                                                     \
  template void MovingBoundary<L, T>::build_rows();                                                         \
  template void MovingBoundary<L, T>::prepare_rows();                                                       \
  template void MovingBoundary<L, T>::apply_rows(T*, bool, std::int64_t, std::int64_t) const;             \
  template void MovingBoundary<L, T>::apply(T*, bool, const std::vector<std::pair<std::int64_t, std::int64_t>>&); \
  template void MovingBoundary<L, T>::apply_groups(T*, bool,                                              \
                                                   const std::vector<std::pair<std::int64_t, std::int64_t>>&); \
  template void MovingBoundary<L, T>::apply_group(T*, bool, std::int64_t) const;                          \
  template void MovingBoundary<L, T>::reduce();
FF_MOVING_BOUNDARY_LINKS(D2Q9, double)
FF_MOVING_BOUNDARY_LINKS(D2Q9, float)
FF_MOVING_BOUNDARY_LINKS(D3Q19, double)
FF_MOVING_BOUNDARY_LINKS(D3Q19, float)
#undef FF_MOVING_BOUNDARY_LINKS

}  // namespace ff::lbm
