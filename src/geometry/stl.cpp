#include "geometry/stl.hpp"

#include <fmt/format.h>

#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <string_view>

#include "core/error.hpp"
#include "core/log.hpp"

namespace ff::geom {
namespace {

static_assert(std::endian::native == std::endian::little, "binary STL I/O assumes a little-endian host");

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& what) {
  throw InputError(fmt::format("STL file '{}': {}", path.string(), what));
}

std::string read_all(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot be opened (missing file or no permission)");
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void check_finite(const std::filesystem::path& path, const Vec3& v, std::size_t facet) {
  if (!v.allFinite()) {
    fail(path, fmt::format("triangle {} has a NaN or infinite vertex coordinate ({}, {}, {})", facet + 1, v.x(),
                           v.y(), v.z()));
  }
}

TriangleMesh parse_binary(const std::filesystem::path& path, const std::string& data) {
  std::uint32_t n = 0;
  std::memcpy(&n, data.data() + 80, 4);
  TriangleMesh mesh;
  mesh.vertices.reserve(3 * std::size_t{n});
  mesh.triangles.reserve(n);
  for (std::size_t t = 0; t < n; ++t) {
    const char* rec = data.data() + 84 + 50 * t + 12;  // skip the stored normal
    for (int k = 0; k < 3; ++k) {
      float xyz[3];
      std::memcpy(xyz, rec + 12 * k, 12);
      const Vec3 v(xyz[0], xyz[1], xyz[2]);
      check_finite(path, v, t);
      mesh.vertices.push_back(v);
    }
    const int b = static_cast<int>(3 * t);
    mesh.triangles.push_back({b, b + 1, b + 2});
  }
  return mesh;
}

// Whitespace tokenizer that knows its line number for error messages.
class Tokens {
 public:
  explicit Tokens(std::string_view s) : s_(s) {}
  bool next(std::string_view& tok) {
    while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_]))) {
      if (s_[pos_] == '\n') ++line_;
      ++pos_;
    }
    if (pos_ >= s_.size()) return false;
    const std::size_t b = pos_;
    while (pos_ < s_.size() && !std::isspace(static_cast<unsigned char>(s_[pos_]))) ++pos_;
    tok = s_.substr(b, pos_ - b);
    return true;
  }
  void skip_line() {
    while (pos_ < s_.size() && s_[pos_] != '\n') ++pos_;
  }
  int line() const { return line_; }

 private:
  std::string_view s_;
  std::size_t pos_ = 0;
  int line_ = 1;
};

bool iequals(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (std::tolower(static_cast<unsigned char>(a[i])) != std::tolower(static_cast<unsigned char>(b[i]))) return false;
  }
  return true;
}

TriangleMesh parse_ascii(const std::filesystem::path& path, const std::string& data) {
  TriangleMesh mesh;
  Tokens tk(data);
  std::string_view tok;
  auto expect = [&](std::string_view word, std::size_t facet) {
    if (!tk.next(tok)) fail(path, fmt::format("truncated: file ends inside facet {} (expected '{}')", facet + 1, word));
    if (!iequals(tok, word)) {
      fail(path, fmt::format("line {}: expected '{}' in facet {}, found '{}'", tk.line(), word, facet + 1, tok));
    }
  };
  auto number = [&](std::size_t facet) {
    if (!tk.next(tok)) fail(path, fmt::format("truncated: file ends inside facet {}", facet + 1));
    double x = 0;
    const auto res = std::from_chars(tok.data(), tok.data() + tok.size(), x);
    if (res.ec != std::errc() || res.ptr != tok.data() + tok.size()) {
      fail(path, fmt::format("line {}: '{}' is not a number (facet {})", tk.line(), tok, facet + 1));
    }
    return x;
  };
  bool in_solid = false;
  while (tk.next(tok)) {
    if (iequals(tok, "solid")) {
      tk.skip_line();  // the solid's name
      in_solid = true;
    } else if (iequals(tok, "endsolid")) {
      tk.skip_line();
      in_solid = false;
    } else if (iequals(tok, "facet")) {
      if (!in_solid) fail(path, fmt::format("line {}: 'facet' outside 'solid ... endsolid'", tk.line()));
      const std::size_t f = mesh.triangles.size();
      expect("normal", f);
      for (int k = 0; k < 3; ++k) number(f);  // normals are recomputed from the vertex order
      expect("outer", f);
      expect("loop", f);
      const int b = static_cast<int>(mesh.vertices.size());
      for (int k = 0; k < 3; ++k) {
        expect("vertex", f);
        Vec3 v;
        for (int c = 0; c < 3; ++c) v[c] = number(f);
        check_finite(path, v, f);
        mesh.vertices.push_back(v);
      }
      expect("endloop", f);
      expect("endfacet", f);
      mesh.triangles.push_back({b, b + 1, b + 2});
    } else {
      fail(path, fmt::format("line {}: unexpected '{}' (expected 'facet' or 'endsolid')", tk.line(), tok));
    }
  }
  if (in_solid) fail(path, "truncated: missing 'endsolid'");
  return mesh;
}

bool starts_with_solid(const std::string& data) {
  std::size_t i = 0;
  while (i < data.size() && std::isspace(static_cast<unsigned char>(data[i]))) ++i;
  return data.size() - i >= 5 && iequals(std::string_view(data).substr(i, 5), "solid");
}

}  // namespace

TriangleMesh read_stl(const std::filesystem::path& path) {
  const std::string data = read_all(path);
  bool binary = false;
  if (data.size() >= 84) {
    std::uint32_t n = 0;
    std::memcpy(&n, data.data() + 80, 4);
    binary = data.size() == 84 + 50 * std::uint64_t{n};
    if (!binary && !starts_with_solid(data)) {
      fail(path, fmt::format("truncated or corrupt binary STL: header announces {} triangles ({} bytes) but the "
                             "file has {} bytes",
                             n, 84 + 50 * std::uint64_t{n}, data.size()));
    }
  } else if (!starts_with_solid(data)) {
    fail(path, fmt::format("truncated: {} bytes is shorter than the 84-byte binary STL header and the file does "
                           "not start with 'solid'",
                           data.size()));
  }
  TriangleMesh mesh = binary ? parse_binary(path, data) : parse_ascii(path, data);
  if (mesh.triangles.empty()) fail(path, "contains zero triangles");
  const int dropped = merge_coincident_vertices(mesh);
  if (dropped > 0) log::warn("STL file '{}': dropped {} degenerate triangles", path.string(), dropped);
  if (mesh.triangles.empty()) fail(path, "contains zero non-degenerate triangles");
  return mesh;
}

namespace {
Vec3 facet_normal(const TriangleMesh& mesh, const std::array<int, 3>& t) {
  const Vec3 n = (mesh.vertices[t[1]] - mesh.vertices[t[0]]).cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
  const Real len = n.norm();
  return len > 0 ? Vec3(n / len) : Vec3::Zero();
}

std::ofstream open_out(const std::filesystem::path& path, std::ios::openmode mode) {
  std::ofstream out(path, mode);
  if (!out) throw InputError(fmt::format("STL file '{}': cannot be created", path.string()));
  return out;
}
}  // namespace

void write_stl_binary(const std::filesystem::path& path, const TriangleMesh& mesh) {
  std::ofstream out = open_out(path, std::ios::binary);
  char header[80] = {};
  const char title[] = "fracflow binary STL";
  std::memcpy(header, title, sizeof title - 1);
  out.write(header, 80);
  const auto n = static_cast<std::uint32_t>(mesh.triangles.size());
  out.write(reinterpret_cast<const char*>(&n), 4);
  for (const auto& t : mesh.triangles) {
    float rec[12];
    const Vec3 nrm = facet_normal(mesh, t);
    for (int c = 0; c < 3; ++c) rec[c] = static_cast<float>(nrm[c]);
    for (int k = 0; k < 3; ++k) {
      for (int c = 0; c < 3; ++c) rec[3 + 3 * k + c] = static_cast<float>(mesh.vertices[t[k]][c]);
    }
    out.write(reinterpret_cast<const char*>(rec), sizeof rec);
    const std::uint16_t attribute = 0;
    out.write(reinterpret_cast<const char*>(&attribute), 2);
  }
  if (!out) throw InputError(fmt::format("STL file '{}': write failed", path.string()));
}

void write_stl_ascii(const std::filesystem::path& path, const TriangleMesh& mesh) {
  std::ofstream out = open_out(path, std::ios::out);
  out << "solid fracflow\n";
  for (const auto& t : mesh.triangles) {
    const Vec3 nrm = facet_normal(mesh, t);
    out << fmt::format("facet normal {:.9g} {:.9g} {:.9g}\n outer loop\n", nrm.x(), nrm.y(), nrm.z());
    for (int k = 0; k < 3; ++k) {
      const Vec3& v = mesh.vertices[t[k]];
      out << fmt::format("  vertex {:.9g} {:.9g} {:.9g}\n", static_cast<float>(v.x()), static_cast<float>(v.y()),
                         static_cast<float>(v.z()));
    }
    out << " endloop\nendfacet\n";
  }
  out << "endsolid fracflow\n";
  if (!out) throw InputError(fmt::format("STL file '{}': write failed", path.string()));
}

}  // namespace ff::geom
