#include "dem/neighbor_list.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>

#include "core/error.hpp"

namespace ff::dem {

std::size_t NeighborList::build(std::span<const Vec3> pos, std::span<const Real> radius, Real skin) {
  const std::size_t n = pos.size();
  skin_ = skin;
  ++builds_;
  ref_pos_.assign(pos.begin(), pos.end());
  pair_i_.clear();
  pair_j_.clear();
  if (n == 0) {
    build_adjacency(0);
    return 0;
  }
  Vec3 lo = pos[0], hi = pos[0];
  Real rmax = 0;
  for (std::size_t i = 0; i < n; ++i) {
    lo = lo.cwiseMin(pos[i]);
    hi = hi.cwiseMax(pos[i]);
    rmax = std::max(rmax, radius[i]);
  }
  // Cells at least as large as the largest interaction distance, and not more than ~2 per
  // particle (particles flung far away must not create a huge grid).
  if (!(hi - lo).allFinite())
    throw NumericalError("neighbour search: a particle position is NaN or infinite; the run has become unstable "
                         "(lower dem.time_step_safety or dem.time_step)");
  Real h = 2 * rmax + skin;
  const Vec3 ext = (hi - lo).cwiseMax(Vec3::Constant(h));
  for (;;) {
    const double cells = std::ceil(ext.x() / h) * std::ceil(ext.y() / h) * std::ceil(ext.z() / h);
    if (cells <= 2.0 * static_cast<double>(n) + 27) break;
    h *= 1.26;
  }
  const int nx = std::max(1, static_cast<int>(std::ceil(ext.x() / h)));
  const int ny = std::max(1, static_cast<int>(std::ceil(ext.y() / h)));
  const int nz = std::max(1, static_cast<int>(std::ceil(ext.z() / h)));
  const std::int64_t ncell = static_cast<std::int64_t>(nx) * ny * nz;
  auto cell_coord = [&](const Vec3& x, int& cx, int& cy, int& cz) {
    cx = std::clamp(static_cast<int>((x.x() - lo.x()) / h), 0, nx - 1);
    cy = std::clamp(static_cast<int>((x.y() - lo.y()) / h), 0, ny - 1);
    cz = std::clamp(static_cast<int>((x.z() - lo.z()) / h), 0, nz - 1);
  };
  // Counting sort of particles into cells (particles of a cell in increasing index).
  // The grid never exceeds 2n + 27 cells (see above): reserve that once.
  if (cell_start_.capacity() < 2 * n + 28) cell_start_.reserve(2 * n + 28);
  if (count_.capacity() < 2 * n + 28) count_.reserve(2 * n + 28);  // also the per-cell fill counters
  cell_start_.assign(ncell + 1, 0);
  cell_of_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    int cx, cy, cz;
    cell_coord(pos[i], cx, cy, cz);
    cell_of_[i] = static_cast<Index>((static_cast<std::int64_t>(cz) * ny + cy) * nx + cx);
    ++cell_start_[cell_of_[i] + 1];
  }
  for (std::int64_t c = 0; c < ncell; ++c) cell_start_[c + 1] += cell_start_[c];
  cell_particles_.resize(n);
  {
    std::vector<std::int64_t>& fill = count_;
    fill.assign(cell_start_.begin(), cell_start_.end() - 1);
    for (std::size_t i = 0; i < n; ++i) cell_particles_[fill[cell_of_[i]]++] = static_cast<Index>(i);
  }
  // Visits the partners j > i of particle i within the cut-off, in cell order.
  auto visit = [&](std::size_t i, auto&& emit) {
    const std::int64_t c = cell_of_[i];
    const int cx = static_cast<int>(c % nx), cy = static_cast<int>((c / nx) % ny), cz = static_cast<int>(c / (static_cast<std::int64_t>(nx) * ny));
    for (int dz = -1; dz <= 1; ++dz) {
      const int z = cz + dz;
      if (z < 0 || z >= nz) continue;
      for (int dy = -1; dy <= 1; ++dy) {
        const int y = cy + dy;
        if (y < 0 || y >= ny) continue;
        for (int dx = -1; dx <= 1; ++dx) {
          const int x = cx + dx;
          if (x < 0 || x >= nx) continue;
          const std::int64_t cc = (static_cast<std::int64_t>(z) * ny + y) * nx + x;
          for (std::int64_t k = cell_start_[cc]; k < cell_start_[cc + 1]; ++k) {
            const Index j = cell_particles_[k];
            if (static_cast<std::size_t>(j) <= i) continue;
            const Real cut = radius[i] + radius[j] + skin;
            if ((pos[j] - pos[i]).squaredNorm() < cut * cut) emit(j);
          }
        }
      }
    }
  };
  count_.assign(n + 1, 0);
#pragma omp parallel for schedule(static) if (n > parallel_min_)
  for (std::size_t i = 0; i < n; ++i) {
    std::int64_t k = 0;
    visit(i, [&](Index) { ++k; });
    count_[i + 1] = k;
  }
  for (std::size_t i = 0; i < n; ++i) count_[i + 1] += count_[i];
  const std::size_t npairs = static_cast<std::size_t>(count_[n]);
  reserve_with_headroom(pair_i_, npairs);
  reserve_with_headroom(pair_j_, npairs);
  pair_i_.resize(npairs);
  pair_j_.resize(npairs);
#pragma omp parallel for schedule(static) if (n > parallel_min_)
  for (std::size_t i = 0; i < n; ++i) {
    std::int64_t k = count_[i];
    visit(i, [&](Index j) {
      pair_i_[k] = static_cast<Index>(i);
      pair_j_[k++] = j;
    });
    std::sort(pair_j_.begin() + count_[i], pair_j_.begin() + count_[i + 1]);
  }
  build_adjacency(n);
  return npairs;
}

void NeighborList::build_adjacency(std::size_t n) {
  adj_offset_.assign(n + 1, 0);
  for (std::size_t p = 0; p < pair_i_.size(); ++p) {
    ++adj_offset_[pair_i_[p] + 1];
    ++adj_offset_[pair_j_[p] + 1];
  }
  for (std::size_t i = 0; i < n; ++i) adj_offset_[i + 1] += adj_offset_[i];
  reserve_with_headroom(adj_, static_cast<std::size_t>(adj_offset_[n]));
  adj_.resize(adj_offset_[n]);
  count_.assign(adj_offset_.begin(), adj_offset_.end());
  for (std::size_t p = 0; p < pair_i_.size(); ++p) {  // increasing pair index per particle
    adj_[count_[pair_i_[p]]++] = static_cast<std::int64_t>(p) << 1;
    adj_[count_[pair_j_[p]]++] = (static_cast<std::int64_t>(p) << 1) | 1;
  }
}

void NeighborList::restore(Real skin, long builds) {
  skin_ = skin;
  builds_ = builds;
  build_adjacency(ref_pos_.size());
}

bool NeighborList::needs_rebuild(std::span<const Vec3> pos, Real extra_wall_motion, Real* max_displacement) const {
  if (max_displacement) *max_displacement = 0;
  if (ref_pos_.size() != pos.size()) return true;
  const Real lim2 = 0.25 * skin_ * skin_;
  Real max2 = 0;
  const std::size_t n = pos.size();
#pragma omp parallel for reduction(max : max2) schedule(static) if (n > parallel_min_)
  for (std::size_t i = 0; i < n; ++i) max2 = std::max(max2, (pos[i] - ref_pos_[i]).squaredNorm());
  if (max_displacement) *max_displacement = std::sqrt(max2);
  // Two particles approaching each other can each move skin/2.
  return std::sqrt(max2) + extra_wall_motion > 0.5 * skin_ || max2 > lim2;
}

}  // namespace ff::dem
