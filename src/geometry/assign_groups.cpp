#include <fmt/format.h>

#include "core/error.hpp"
#include "geometry/packing.hpp"

namespace ff::geom {

std::vector<int> assign_groups(std::span<const Vec3> centres, std::span<const Region> regions,
                               std::span<const int> region_group, int default_group,
                               std::vector<std::size_t>* assigned) {
  if (regions.size() != region_group.size()) {
    throw InputError(fmt::format("assign_groups: {} regions but {} group numbers; give one group per region",
                                 regions.size(), region_group.size()));
  }
  std::vector<Aabb> boxes;
  boxes.reserve(regions.size());
  for (const Region& r : regions) boxes.push_back(region_bounds(r));
  std::vector<int> group(centres.size(), default_group);
  if (assigned) assigned->assign(regions.size(), 0);
  for (std::size_t i = 0; i < centres.size(); ++i) {
    // The last containing region wins: search backwards and stop at the first hit.
    for (std::size_t k = regions.size(); k-- > 0;) {
      if (boxes[k].contains(centres[i]) && region_contains(regions[k], centres[i])) {
        group[i] = region_group[k];
        if (assigned) ++(*assigned)[k];
        break;
      }
    }
  }
  return group;
}

}  // namespace ff::geom
