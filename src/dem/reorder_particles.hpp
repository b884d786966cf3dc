// Reordering the particle arrays (a space-filling-curve sort for cache locality, or the
// migration of a future MPI decomposition) without breaking what refers to particles by index.
#pragma once
#include <vector>

#include "dem/dem_system.hpp"

namespace ff::dem {

// Permutes the particles of `sys`: the particle at new index k is the one that was at order[k]
// (order: a permutation of 0..n-1, checked). Every declared particle field moves (global ids
// with them); bond ends, the neighbour list (pairs kept as (i < j) and sorted, contact history
// and last loads turned round where a pair's ends swap), its reference positions, wall
// candidates and boundaries (Boundary::reorder) are renumbered; the crack log names global ids
// and is untouched. Bonds keep their order and their ends (bond i need not be < j afterwards).
// Call between steps. Indices held outside the system (a driver's) are the caller's to map.
// The next step equals the unreordered one up to rounding: each particle's sum over its
// contacts runs in another order (partners sorted by their new indices).
void reorder_particles(DemSystem& sys, const std::vector<Index>& order);

}  // namespace ff::dem
