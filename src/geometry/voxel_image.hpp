// 3D label image (CT / micro-CT segmentation) stored as a stack of 2D binary PGM slices.
// Conventions: slice k of the sorted file list is z index k; image row r is y index j = r and
// column c is x index i = c. `origin` is the centre of voxel (0, 0, 0) (as VTK image data), so voxel
// (i, j, k) covers origin + ((i, j, k) +- 1/2) * spacing. Thresholds -> labels are left to callers.
#pragma once
#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

#include "core/types.hpp"

namespace ff::geom {

struct VoxelImage {
  int nx = 0, ny = 0, nz = 0;
  Vec3 origin{Vec3::Zero()};
  Vec3 spacing{Vec3::Ones()};
  std::vector<std::uint16_t> value;  // x fastest: value[(k * ny + j) * nx + i]

  std::size_t index(int i, int j, int k) const {
    return (static_cast<std::size_t>(k) * ny + j) * nx + i;
  }
  // Value of the voxel containing `point` (nearest voxel centre); 0 outside the image.
  std::uint16_t at(const Vec3& point) const;
  // Whether `point` lies in a voxel of the image (0 from at() is then a real grey value).
  bool contains(const Vec3& point) const;
};

// A window of grey values [min, max] (both included) that maps to `label`: a material group, or
// a caller's code such as "pore" (segmentation by thresholds, as for CT scans in seed 000 s. 2.2).
struct GreyRange {
  std::uint16_t min = 0, max = 0;
  int label = 0;
};

// For each point: the label of the first range holding the value of the voxel that contains the
// point, or `unlabelled` for points outside the image and values that no range holds.
std::vector<int> label_points(const VoxelImage& image, std::span<const Vec3> points,
                              std::span<const GreyRange> ranges, int unlabelled);

// Reads every *.pgm file of `folder` (binary P5, maxval <= 65535: 8-bit for maxval < 256, else
// 16-bit big-endian), sorted by file name (zero-pad the numbers: slice_010 sorts after slice_009).
// All slices must have the same size. Throws ff::InputError naming the file and the problem.
VoxelImage read_pgm_stack(const std::filesystem::path& folder, const Vec3& origin, const Vec3& spacing);

// Writes slice_00000.pgm, slice_00001.pgm ... (one per z level) into `folder` (created if needed)
// with `bits` = 8 (maxval 255) or 16 (maxval 65535). Throws ff::InputError if a value does not fit.
void write_pgm_stack(const std::filesystem::path& folder, const VoxelImage& image, int bits);

}  // namespace ff::geom

namespace ff {
using geom::GreyRange;
using geom::label_points;
using geom::read_pgm_stack;
using geom::VoxelImage;
using geom::write_pgm_stack;
}  // namespace ff
