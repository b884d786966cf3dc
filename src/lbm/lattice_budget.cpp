#include "lbm/lattice_budget.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <cmath>

#include "core/error.hpp"

namespace ff::lbm {

int lattice_side(double cells, std::string_view key, std::string_view hint) {
  const double n = std::round(cells);
  if (!(n >= 1) || !(n < kMaxLatticeSide))
    throw InputError(fmt::format("{}: gives {:.4g} lattice cells along one side; a side needs 1 to 2^30 cells ({})",
                                 key, cells, hint));
  return int(n);
}

double lattice_bytes(double nx, double ny, double nz, int q, std::size_t value_bytes) {
  // Populations (one array: the AA pattern) plus the solver's per-cell fields: the sampled
  // density and velocity (4 values), flags and masks (~8 bytes).
  return nx * ny * nz * (double(q) * double(value_bytes) + 4.0 * double(value_bytes) + 8.0);
}

void check_lattice_memory(double nx, double ny, double nz, int q, std::size_t value_bytes, std::string_view hint,
                          double limit_bytes) {
  double limit = limit_bytes;
  if (!(limit > 0)) {
    const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
    if (pages <= 0 || page <= 0) return;  // unknown: let the allocation decide
    limit = double(pages) * double(page);
  }
  const double need = lattice_bytes(nx, ny, nz, q, value_bytes);
  if (need > limit)
    throw InputError(fmt::format("the lattice of {:.0f} x {:.0f} x {:.0f} cells needs about {:.3g} GiB ({} populations of {} "
                                 "bytes per cell and the solver's fields), more than the {:.3g} GiB of memory here: {}",
                                 nx, ny, nz, need / 1073741824.0, q, value_bytes, limit / 1073741824.0, hint));
}

}  // namespace ff::lbm
