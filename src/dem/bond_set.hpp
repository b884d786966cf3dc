// Bond topology and states: a flat (i, j) list with i < j, the pair type of each bond, whether it
// broke, the state of the active bond law, and the per-particle adjacency the gather walks.
// Per-bond results (loads, failure flags) live here too, one slot per bond (deterministic gather).
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "dem/bond/parallel_bond.hpp"
#include "dem/bond/rotational_bond.hpp"

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
  std::vector<ParallelBond::State> parallel;      // state when the parallel bond law is active
  std::vector<RotationalBond::State> rotational;  // state when the rotational bond law is active

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
