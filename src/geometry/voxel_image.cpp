#include "geometry/voxel_image.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <iterator>
#include <string>

#include "core/error.hpp"

namespace ff::geom {

std::uint16_t VoxelImage::at(const Vec3& point) const {
  const Vec3 f = (point - origin).cwiseQuotient(spacing);
  const Real fi = std::floor(f.x() + 0.5), fj = std::floor(f.y() + 0.5), fk = std::floor(f.z() + 0.5);
  if (!(fi >= 0 && fj >= 0 && fk >= 0 && fi < nx && fj < ny && fk < nz)) return 0;  // also rejects NaN
  return value[index(static_cast<int>(fi), static_cast<int>(fj), static_cast<int>(fk))];
}

bool VoxelImage::contains(const Vec3& point) const {
  const Vec3 f = (point - origin).cwiseQuotient(spacing);
  const Real fi = std::floor(f.x() + 0.5), fj = std::floor(f.y() + 0.5), fk = std::floor(f.z() + 0.5);
  return fi >= 0 && fj >= 0 && fk >= 0 && fi < nx && fj < ny && fk < nz;  // false for NaN
}

std::vector<int> label_points(const VoxelImage& image, std::span<const Vec3> points,
                              std::span<const GreyRange> ranges, int unlabelled) {
  std::vector<int> label(points.size(), unlabelled);
  for (std::size_t n = 0; n < points.size(); ++n) {
    if (!image.contains(points[n])) continue;
    const std::uint16_t v = image.at(points[n]);
    for (const GreyRange& r : ranges) {
      if (v >= r.min && v <= r.max) {
        label[n] = r.label;
        break;
      }
    }
  }
  return label;
}

namespace {

[[noreturn]] void fail(const std::filesystem::path& file, const std::string& what) {
  throw InputError(fmt::format("PGM slice '{}': {}", file.string(), what));
}

struct Slice {
  int width = 0, height = 0, maxval = 0;
  std::size_t data_offset = 0;
};

// Header: "P5" <ws> width <ws> height <ws> maxval <one whitespace byte> data; '#' comments in between.
Slice parse_header(const std::filesystem::path& file, const std::string& s) {
  if (s.size() < 2 || s[0] != 'P' || s[1] != '5') fail(file, "not a binary PGM (the file must start with 'P5')");
  std::size_t pos = 2;
  auto read_int = [&](const char* what) {
    while (pos < s.size()) {
      if (std::isspace(static_cast<unsigned char>(s[pos]))) {
        ++pos;
      } else if (s[pos] == '#') {
        while (pos < s.size() && s[pos] != '\n') ++pos;
      } else {
        break;
      }
    }
    if (pos >= s.size() || !std::isdigit(static_cast<unsigned char>(s[pos]))) {
      fail(file, fmt::format("malformed header: {} missing", what));
    }
    long long x = 0;
    while (pos < s.size() && std::isdigit(static_cast<unsigned char>(s[pos]))) {
      x = 10 * x + (s[pos] - '0');
      if (x > 1'000'000'000) fail(file, fmt::format("malformed header: {} too large", what));
      ++pos;
    }
    return static_cast<int>(x);
  };
  Slice sl;
  sl.width = read_int("width");
  sl.height = read_int("height");
  sl.maxval = read_int("maxval");
  if (pos >= s.size() || !std::isspace(static_cast<unsigned char>(s[pos]))) {
    fail(file, "malformed header: no whitespace after maxval");
  }
  sl.data_offset = pos + 1;
  if (sl.width < 1 || sl.height < 1) fail(file, fmt::format("image size {} x {} is empty", sl.width, sl.height));
  if (sl.maxval < 1 || sl.maxval > 65535) fail(file, fmt::format("maxval {} outside [1, 65535]", sl.maxval));
  return sl;
}

bool is_pgm(const std::filesystem::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".pgm";
}

}  // namespace

VoxelImage read_pgm_stack(const std::filesystem::path& folder, const Vec3& origin, const Vec3& spacing) {
  namespace fs = std::filesystem;
  if (!fs::is_directory(folder)) {
    throw InputError(fmt::format("PGM stack folder '{}' does not exist or is not a folder", folder.string()));
  }
  if (!(spacing.array() > 0).all() || !spacing.allFinite() || !origin.allFinite()) {
    throw InputError(fmt::format("PGM stack '{}': voxel spacing ({}, {}, {}) must be positive and finite",
                                 folder.string(), spacing.x(), spacing.y(), spacing.z()));
  }
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(folder)) {
    if (entry.is_regular_file() && is_pgm(entry.path())) files.push_back(entry.path());
  }
  if (files.empty()) throw InputError(fmt::format("PGM stack folder '{}' contains no *.pgm slices", folder.string()));
  std::sort(files.begin(), files.end(),
            [](const fs::path& a, const fs::path& b) { return a.filename().string() < b.filename().string(); });

  VoxelImage img;
  img.origin = origin;
  img.spacing = spacing;
  img.nz = static_cast<int>(files.size());
  for (int k = 0; k < img.nz; ++k) {
    const fs::path& file = files[k];
    std::ifstream in(file, std::ios::binary);
    if (!in) fail(file, "cannot be opened");
    const std::string s((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const Slice sl = parse_header(file, s);
    if (k == 0) {
      img.nx = sl.width;
      img.ny = sl.height;
      img.value.resize(static_cast<std::size_t>(img.nx) * img.ny * img.nz);
    } else if (sl.width != img.nx || sl.height != img.ny) {
      fail(file, fmt::format("size {} x {} differs from the first slice '{}' ({} x {})", sl.width, sl.height,
                             files[0].filename().string(), img.nx, img.ny));
    }
    const int bytes = sl.maxval < 256 ? 1 : 2;
    const std::size_t need = static_cast<std::size_t>(img.nx) * img.ny * bytes;
    if (s.size() - sl.data_offset < need) {
      fail(file, fmt::format("truncated: {} bytes of pixel data, expected {}", s.size() - sl.data_offset, need));
    }
    const auto* px = reinterpret_cast<const unsigned char*>(s.data() + sl.data_offset);
    std::uint16_t* out = img.value.data() + img.index(0, 0, k);
    for (std::size_t n = 0; n < static_cast<std::size_t>(img.nx) * img.ny; ++n) {
      const unsigned v = bytes == 1 ? px[n] : (unsigned{px[2 * n]} << 8) | px[2 * n + 1];  // 16-bit: big-endian
      if (static_cast<int>(v) > sl.maxval) {
        fail(file, fmt::format("pixel {} has value {} above maxval {}", n, v, sl.maxval));
      }
      out[n] = static_cast<std::uint16_t>(v);
    }
  }
  return img;
}

void write_pgm_stack(const std::filesystem::path& folder, const VoxelImage& image, int bits) {
  namespace fs = std::filesystem;
  if (bits != 8 && bits != 16) throw InputError(fmt::format("write_pgm_stack: bits = {} must be 8 or 16", bits));
  if (image.nx < 1 || image.ny < 1 || image.nz < 1 ||
      image.value.size() != static_cast<std::size_t>(image.nx) * image.ny * image.nz) {
    throw InputError(fmt::format("write_pgm_stack: image {} x {} x {} does not match its {} values", image.nx,
                                 image.ny, image.nz, image.value.size()));
  }
  const unsigned maxval = bits == 8 ? 255u : 65535u;
  const auto big = std::max_element(image.value.begin(), image.value.end());
  if (*big > maxval) {
    throw InputError(fmt::format("write_pgm_stack: value {} does not fit in {} bits; use bits = 16", *big, bits));
  }
  std::error_code ec;
  fs::create_directories(folder, ec);
  if (ec) throw InputError(fmt::format("PGM stack folder '{}' cannot be created: {}", folder.string(), ec.message()));
  const std::size_t n = static_cast<std::size_t>(image.nx) * image.ny;
  std::string buf;
  for (int k = 0; k < image.nz; ++k) {
    const fs::path file = folder / fmt::format("slice_{:05d}.pgm", k);
    buf = fmt::format("P5\n{} {}\n{}\n", image.nx, image.ny, maxval);
    const std::uint16_t* src = image.value.data() + image.index(0, 0, k);
    for (std::size_t m = 0; m < n; ++m) {
      if (bits == 16) buf.push_back(static_cast<char>(src[m] >> 8));
      buf.push_back(static_cast<char>(src[m] & 0xFF));
    }
    std::ofstream out(file, std::ios::binary);
    out.write(buf.data(), static_cast<std::streamsize>(buf.size()));
    if (!out) fail(file, "write failed");
  }
}

}  // namespace ff::geom
