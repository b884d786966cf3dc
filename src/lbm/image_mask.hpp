// Solid cells from a grey-scale image (a thin section, a CT slice, a drawn obstacle): a
// binary or ASCII PGM file (netpbm P5/P2, the format every image tool exports) is sampled
// onto the lattice, nearest pixel per cell; pixels darker than the threshold are solid.
#pragma once
#include <array>
#include <cstdint>
#include <filesystem>
#include <vector>

namespace ff::lbm {

struct GreyImage {
  int width = 0, height = 0;
  std::vector<std::uint8_t> pixels;  // row-major from the top row, 0 = black (maxval scaled to 255)
};

// Reads P2 or P5 PGM; throws ff::InputError naming the file and what is wrong.
GreyImage read_pgm(const std::filesystem::path& path);

// Cells (x, y) of an nx x ny lattice whose nearest pixel is darker than `threshold` (0..255).
// The image covers the whole lattice; its top row is the lattice row y = ny - 1.
std::vector<std::array<int, 2>> solid_cells(const GreyImage& img, int nx, int ny, int threshold = 128);

}  // namespace ff::lbm
