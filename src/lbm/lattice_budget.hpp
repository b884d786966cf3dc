// Guards on a lattice's size before anything is allocated: a side whose cell count does not fit
// an int, and a lattice whose populations alone exceed this machine's memory, are input errors
// that name the keys to change (before: std::bad_alloc, or gigabytes allocated and then a crash).
#pragma once
#include <cstddef>
#include <string_view>

namespace ff::lbm {

// The most cells along one side (2^30: an int, with room for the ghost layers and row padding).
inline constexpr double kMaxLatticeSide = 1073741824.0;

// Cells along one side for a side of `cells` (= length / dx, a real): rounded to the nearest
// whole number; throws InputError naming `key` when that is not a positive int below 2^30.
int lattice_side(double cells, std::string_view key, std::string_view hint);

// Memory of a lattice of nx x ny x nz cells with q populations of value_bytes each (plus the
// per-cell fields the solver keeps): throws InputError when it exceeds the machine's physical
// memory (or `limit_bytes` when > 0, for tests), naming `hint` (the keys that set the size).
double lattice_bytes(double nx, double ny, double nz, int q, std::size_t value_bytes);
void check_lattice_memory(double nx, double ny, double nz, int q, std::size_t value_bytes, std::string_view hint,
                          double limit_bytes = 0);

}  // namespace ff::lbm
