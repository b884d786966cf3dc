#include "lbm/image_mask.hpp"

#include <fmt/format.h>

#include <cctype>
#include <charconv>
#include <fstream>
#include <iterator>
#include <string>

#include "core/error.hpp"

namespace ff::lbm {

namespace {
// Next header token of a PGM file, skipping white space and # comments.
std::string token(const std::string& s, std::size_t& i) {
  for (;;) {
    while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
    if (i < s.size() && s[i] == '#') {
      while (i < s.size() && s[i] != '\n') ++i;
      continue;
    }
    break;
  }
  const std::size_t b = i;
  while (i < s.size() && !std::isspace(static_cast<unsigned char>(s[i]))) ++i;
  return s.substr(b, i - b);
}
}  // namespace

GreyImage read_pgm(const std::filesystem::path& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw InputError(fmt::format("cannot open the image '{}'", path.string()));
  const std::string s((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  std::size_t i = 0;
  const std::string magic = token(s, i);
  if (magic != "P5" && magic != "P2")
    throw InputError(fmt::format("'{}' is not a PGM image (P2 or P5); convert it, e.g. `convert in.png out.pgm`",
                                 path.string()));
  GreyImage img;
  long maxval = 0;
  try {
    img.width = std::stoi(token(s, i));
    img.height = std::stoi(token(s, i));
    maxval = std::stol(token(s, i));
  } catch (const std::exception&) {
    throw InputError(fmt::format("'{}': unreadable PGM header (width, height, maxval)", path.string()));
  }
  if (img.width <= 0 || img.height <= 0 || maxval <= 0 || maxval > 65535)
    throw InputError(fmt::format("'{}': bad PGM size {} x {} or maxval {}", path.string(), img.width, img.height, maxval));
  const std::size_t n = std::size_t(img.width) * std::size_t(img.height);
  img.pixels.resize(n);
  auto scale = [maxval](long v) { return std::uint8_t(std::min(255L, v * 255 / maxval)); };
  // A value outside 0 .. maxval (a P2 file edited by hand, a 16-bit P5 with a wrong maxval) has no
  // grey level: it used to wrap round (-5 became light, 999 dark).
  auto check_pixel = [&](std::size_t k, long v) {
    if (v < 0 || v > maxval)
      throw InputError(fmt::format("'{}': pixel {} (row {}, column {}) is {}, outside 0 to the maxval {} of the header",
                                   path.string(), k + 1, k / std::size_t(img.width) + 1, k % std::size_t(img.width) + 1, v,
                                   maxval));
  };
  if (magic == "P5") {
    ++i;  // the single white-space character after maxval
    const std::size_t bytes = maxval > 255 ? 2 : 1;
    if (s.size() < i + n * bytes)
      throw InputError(fmt::format("'{}': the image data is truncated ({} of {} pixels)", path.string(),
                                   (s.size() - std::min(s.size(), i)) / bytes, n));
    for (std::size_t k = 0; k < n; ++k) {
      const long v = bytes == 1 ? static_cast<unsigned char>(s[i + k])
                                : 256L * static_cast<unsigned char>(s[i + 2 * k]) + static_cast<unsigned char>(s[i + 2 * k + 1]);
      check_pixel(k, v);
      img.pixels[k] = scale(v);
    }
  } else {
    for (std::size_t k = 0; k < n; ++k) {
      const std::string t = token(s, i);
      if (t.empty()) throw InputError(fmt::format("'{}': the image has fewer than {} pixels", path.string(), n));
      long v = -1;
      const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
      if (ec != std::errc() || end != t.data() + t.size())
        throw InputError(fmt::format("'{}': pixel {} (row {}, column {}) is '{}', not a whole number from 0 to the "
                                     "maxval {}",
                                     path.string(), k + 1, k / std::size_t(img.width) + 1, k % std::size_t(img.width) + 1, t,
                                     maxval));
      check_pixel(k, v);
      img.pixels[k] = scale(v);
    }
  }
  return img;
}

std::vector<std::array<int, 2>> solid_cells(const GreyImage& img, int nx, int ny, int threshold) {
  std::vector<std::array<int, 2>> cells;
  for (int y = 0; y < ny; ++y)
    for (int x = 0; x < nx; ++x) {
      const int px = std::min(img.width - 1, int((x + 0.5) * img.width / nx));
      const int row = std::min(img.height - 1, int((ny - 1 - y + 0.5) * img.height / ny));
      if (img.pixels[std::size_t(row) * std::size_t(img.width) + std::size_t(px)] < threshold) cells.push_back({x, y});
    }
  return cells;
}

}  // namespace ff::lbm
