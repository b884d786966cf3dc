// Verlet neighbour list built with linked cells (Allen & Tildesley 1987, ch. 5): every pair
// i < j whose surfaces are closer than `skin` is listed once, sorted by (i, j). The list is
// rebuilt only when some particle has moved more than skin/2 since the last build, so a
// contact can never be missed in between. Building is deterministic and independent of the
// thread count (count pass + prefix sum + fill pass, each particle's partners sorted).
#pragma once
#include <span>
#include <vector>

#include "core/types.hpp"

namespace ff::dem {

// Grows a work buffer with 25% headroom, so that lists which grow slowly during a run (more
// contacts as a sample is compressed) do not reallocate at every rebuild.
template <class V>
void reserve_with_headroom(V& v, std::size_t n) {
  if (v.capacity() < n) v.reserve(n + n / 4 + 16);
}

class NeighborList {
 public:
  // Rebuilds the pair list; returns the number of pairs.
  std::size_t build(std::span<const Vec3> pos, std::span<const Real> radius, Real skin);
  // True when a particle moved more than skin/2 since the last build (positions compared with
  // those stored at the build).
  // `max_displacement`, when given, receives the largest particle travel since the build [m].
  bool needs_rebuild(std::span<const Vec3> pos, Real extra_wall_motion = 0, Real* max_displacement = nullptr) const;

  std::span<const Index> first() const { return pair_i_; }
  std::span<const Index> second() const { return pair_j_; }
  std::size_t size() const { return pair_i_.size(); }
  Real skin() const { return skin_; }
  void set_parallel_min(std::size_t n) { parallel_min_ = n; }  // shorter loops run on one thread
  // Room for `pairs` pairs before any buffer must grow (no allocation while a sample densifies).
  void reserve(std::size_t pairs) {
    pair_i_.reserve(pairs);
    pair_j_.reserve(pairs);
    adj_.reserve(2 * pairs);
  }
  long builds() const { return builds_; }
  // For each particle, the pairs it belongs to, as (pair index << 1 | is_second) entries:
  // the gather adds +F for the second particle and -F for the first.
  std::span<const std::int64_t> adjacency_offsets() const { return adj_offset_; }
  std::span<const std::int64_t> adjacency() const { return adj_; }
  // Carries per-pair history from the previous list to the current one (pairs matched by
  // (i, j); new pairs get `fresh`). Call right after build() with the old pairs saved.
  template <class T>
  static void carry_over(std::span<const Index> old_i, std::span<const Index> old_j, const std::vector<T>& old_state,
                         std::span<const Index> new_i, std::span<const Index> new_j, std::vector<T>& new_state,
                         const T& fresh);

  // Checkpoint support: the list itself and the build reference positions.
  std::vector<Index>& pair_i() { return pair_i_; }
  std::vector<Index>& pair_j() { return pair_j_; }
  std::vector<Vec3>& reference_positions() { return ref_pos_; }
  void restore(Real skin, long builds);  // after pair_i/pair_j/reference_positions were loaded
  void build_adjacency(std::size_t n_particles);

 private:
  std::vector<Index> pair_i_, pair_j_;
  std::vector<Vec3> ref_pos_;
  std::vector<std::int64_t> adj_offset_, adj_;
  // Work arrays reused between builds (no allocation in steady state).
  std::vector<std::int64_t> cell_start_, count_;
  std::vector<Index> cell_particles_, cell_of_;
  Real skin_ = 0;
  long builds_ = 0;
  std::size_t parallel_min_ = 2048;
};

template <class T>
void NeighborList::carry_over(std::span<const Index> old_i, std::span<const Index> old_j, const std::vector<T>& old_state,
                              std::span<const Index> new_i, std::span<const Index> new_j, std::vector<T>& new_state,
                              const T& fresh) {
  reserve_with_headroom(new_state, new_i.size());
  new_state.assign(new_i.size(), fresh);
  std::size_t a = 0;
  for (std::size_t b = 0; b < new_i.size(); ++b) {
    while (a < old_i.size() && (old_i[a] < new_i[b] || (old_i[a] == new_i[b] && old_j[a] < new_j[b]))) ++a;
    if (a < old_i.size() && old_i[a] == new_i[b] && old_j[a] == new_j[b]) new_state[b] = old_state[a];
  }
}

}  // namespace ff::dem
