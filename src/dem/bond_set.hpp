// Bond topology and states: a flat (i, j) list with i < j, the pair type of each bond, whether it
// broke, the state of the active bond law, and the per-particle adjacency the gather walks.
// Per-bond results (loads, failure flags) live here too, one slot per bond (deterministic gather).
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "dem/laws.hpp"

namespace ff::dem {

// Per-pair result slot: force on the second particle and total moments on both.
struct PairLoad {
  Vec3 f = Vec3::Zero(), mA = Vec3::Zero(), mB = Vec3::Zero();
};

class BondSet {
 public:
  std::vector<Index> i, j;                // ends, i < j
  std::vector<std::int32_t> pair;         // pair type (Materials::pair)
  std::vector<std::uint8_t> broken;       // 0 intact, 1 tensile, 2 shear
  BondStates states;  // per bond law, the state of each bond (only the active law's is filled)

  template <class Law> std::vector<typename Law::State>& state() { return std::get<law_index<Law>(BondLaws{})>(states); }
  template <class Law> const std::vector<typename Law::State>& state() const {
    return std::get<law_index<Law>(BondLaws{})>(states);
  }

  std::size_t size() const { return i.size(); }
  std::size_t intact() const;
  // Appends bond (a, b), a < b, of pair type pt; the caller appends the law's state.
  void add(Index a, Index b, int pt);
  // Per-particle adjacency (bond index << 1 | end) and the per-bond slots, for n particles.
  void build_adjacency(std::size_t n);
  // Drops broken bonds (keeps the order of the intact ones); rebuilds the adjacency if any went.
  void compact(std::size_t n_particles);

  std::span<const std::int64_t> adjacency_offsets() const { return adj_offset_; }
  std::span<const std::int64_t> adjacency() const { return adj_; }
  std::vector<PairLoad>& loads() { return load_; }
  const std::vector<PairLoad>& loads() const { return load_; }
  std::vector<std::uint8_t>& fail_flags() { return fail_flag_; }

 private:
  std::vector<std::int64_t> adj_offset_, adj_, fill_;
  std::vector<PairLoad> load_;
  std::vector<std::uint8_t> fail_flag_;
};

}  // namespace ff::dem
