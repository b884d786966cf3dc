#include "io/vtk.hpp"

#include <fmt/format.h>

#include <numeric>
#include <vector>

#include "core/error.hpp"
#include "io/atomic_file.hpp"

namespace ff {

namespace {

struct TypeInfo {
  const char* vtk_name;
  const void* ptr;
  std::size_t bytes;
};

TypeInfo info(const VtkArray& a) {
  return std::visit(
      [](auto s) -> TypeInfo {
        using T = typename decltype(s)::value_type;
        const char* n = std::is_same_v<T, double>         ? "Float64"
                        : std::is_same_v<T, float>        ? "Float32"
                        : std::is_same_v<T, std::int32_t> ? "Int32"
                        : std::is_same_v<T, std::int64_t> ? "Int64"
                                                          : "UInt8";
        return {n, s.data(), s.size_bytes()};
      },
      a.data);
}

std::string xml_escape(std::string_view s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      default: o += c;
    }
  }
  return o;
}

// Collects the XML header and the appended blocks, then streams both to the file.
class AppendedWriter {
 public:
  explicit AppendedWriter(const std::filesystem::path& path) : path_(path) {}
  // Adds a <DataArray> element referring to the next appended block.
  void array(const std::string& indent, const char* type, const std::string& name, int components, const void* p,
             std::size_t bytes) {
    xml_ += fmt::format("{}<DataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"appended\" offset=\"{}\"/>\n",
                        indent, type, xml_escape(name), components, offset_);
    blocks_.push_back({p, bytes});
    offset_ += sizeof(std::uint64_t) + bytes;
  }
  void array(const std::string& indent, const VtkArray& a, std::size_t tuples, const char* where) {
    if (a.components < 1 || a.scalars() != tuples * static_cast<std::size_t>(a.components))
      throw Error(fmt::format("internal: VTK file '{}': {} array '{}' has {} values, expected {} tuples x {} components",
                              path_.string(), where, a.name, a.scalars(), tuples, a.components));
    const TypeInfo t = info(a);
    array(indent, t.vtk_name, a.name, a.components, t.ptr, t.bytes);
  }
  std::string& xml() { return xml_; }
  void write() {
    AtomicFileWriter f(path_);
    f.write(xml_);
    f.write("  <AppendedData encoding=\"raw\">\n   _");
    for (auto& b : blocks_) {
      const std::uint64_t n = b.bytes;  // header_type UInt64, little-endian host (static_assert in vtk.hpp)
      f.write(&n, sizeof n);
      f.write(b.ptr, b.bytes);
    }
    f.write("\n  </AppendedData>\n</VTKFile>\n");
    f.commit();
  }

 private:
  struct Block {
    const void* ptr;
    std::size_t bytes;
  };
  std::filesystem::path path_;
  std::string xml_;
  std::vector<Block> blocks_;
  std::uint64_t offset_ = 0;
};

const char* kHeader = "<?xml version=\"1.0\"?>\n<VTKFile type=\"{}\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n";

}  // namespace

std::size_t VtkArray::scalars() const {
  return std::visit([](auto s) { return s.size(); }, data);
}

VtkArray vtk_array(std::string name, std::span<const Vec3> v) {
  return {std::move(name), 3, std::span<const double>(v.empty() ? nullptr : v.data()->data(), 3 * v.size())};
}
VtkArray vtk_array(std::string name, std::span<const Quat> v) {
  return {std::move(name), 4, std::span<const double>(v.empty() ? nullptr : v.data()->coeffs().data(), 4 * v.size())};
}
VtkArray vtk_array(std::string name, std::span<const double> v, int components) { return {std::move(name), components, v}; }
VtkArray vtk_array(std::string name, std::span<const float> v, int components) { return {std::move(name), components, v}; }
VtkArray vtk_array(std::string name, std::span<const std::int32_t> v, int components) {
  return {std::move(name), components, v};
}
VtkArray vtk_array(std::string name, std::span<const std::int64_t> v, int components) {
  return {std::move(name), components, v};
}
VtkArray vtk_array(std::string name, std::span<const std::uint8_t> v, int components) {
  return {std::move(name), components, v};
}

std::size_t VtpCells::count(std::size_t n_points) const {
  switch (kind) {
    case Vertices: return connectivity.empty() ? n_points : connectivity.size();
    case Lines: return connectivity.size() / 2;
    case Triangles: return connectivity.size() / 3;
  }
  return 0;
}

void write_vtp(const std::filesystem::path& path, std::span<const Vec3> points, const VtpCells& cells,
               std::span<const VtkArray> point_data, std::span<const VtkArray> cell_data) {
  const std::size_t np = points.size();
  const std::size_t per_cell = cells.kind == VtpCells::Lines ? 2 : cells.kind == VtpCells::Triangles ? 3 : 1;
  if (cells.connectivity.size() % per_cell != 0)
    throw Error(fmt::format("internal: VTK file '{}': connectivity of {} entries is not a multiple of {}", path.string(),
                            cells.connectivity.size(), per_cell));
  for (std::int64_t i : cells.connectivity)
    if (i < 0 || static_cast<std::uint64_t>(i) >= np)
      throw Error(fmt::format("internal: VTK file '{}': cell refers to point {} of {}", path.string(), i, np));
  const std::size_t nc = cells.count(np);

  // Vertices without connectivity are one per point: 0..n-1. Offsets are each cell's end.
  std::vector<std::int64_t> own_conn, offsets(nc);
  std::span<const std::int64_t> conn = cells.connectivity;
  if (cells.kind == VtpCells::Vertices && conn.empty()) {
    own_conn.resize(np);
    std::iota(own_conn.begin(), own_conn.end(), std::int64_t{0});
    conn = own_conn;
  }
  for (std::size_t c = 0; c < nc; ++c) offsets[c] = static_cast<std::int64_t>((c + 1) * per_cell);

  AppendedWriter w(path);
  auto& x = w.xml();
  x += fmt::format(fmt::runtime(kHeader), "PolyData");
  x += "  <PolyData>\n";
  const char* cell_tag = cells.kind == VtpCells::Vertices ? "Verts" : cells.kind == VtpCells::Lines ? "Lines" : "Polys";
  x += fmt::format("    <Piece NumberOfPoints=\"{}\" NumberOfVerts=\"{}\" NumberOfLines=\"{}\" NumberOfStrips=\"0\" NumberOfPolys=\"{}\">\n",
                   np, cells.kind == VtpCells::Vertices ? nc : 0, cells.kind == VtpCells::Lines ? nc : 0,
                   cells.kind == VtpCells::Triangles ? nc : 0);
  x += "      <PointData>\n";
  for (auto& a : point_data) w.array("        ", a, np, "point");
  x += "      </PointData>\n      <CellData>\n";
  for (auto& a : cell_data) w.array("        ", a, nc, "cell");
  x += "      </CellData>\n      <Points>\n";
  w.array("        ", "Float64", "Points", 3, np ? points.data()->data() : nullptr, np * sizeof(Vec3));
  x += fmt::format("      </Points>\n      <{}>\n", cell_tag);
  w.array("        ", "Int64", "connectivity", 1, conn.data(), conn.size_bytes());
  w.array("        ", "Int64", "offsets", 1, offsets.data(), offsets.size() * sizeof(std::int64_t));
  x += fmt::format("      </{}>\n    </Piece>\n  </PolyData>\n", cell_tag);
  w.write();
}

void write_vti(const std::filesystem::path& path, std::array<int, 3> cells, Vec3 origin, Vec3 spacing,
               std::span<const VtkArray> cell_data) {
  if (cells[0] < 1 || cells[1] < 1 || cells[2] < 1)
    throw Error(fmt::format("internal: VTK image '{}' of {}x{}x{} cells", path.string(), cells[0], cells[1], cells[2]));
  const std::size_t nc = static_cast<std::size_t>(cells[0]) * static_cast<std::size_t>(cells[1]) * static_cast<std::size_t>(cells[2]);
  AppendedWriter w(path);
  auto& x = w.xml();
  x += fmt::format(fmt::runtime(kHeader), "ImageData");
  const std::string extent = fmt::format("0 {} 0 {} 0 {}", cells[0], cells[1], cells[2]);
  x += fmt::format("  <ImageData WholeExtent=\"{}\" Origin=\"{} {} {}\" Spacing=\"{} {} {}\">\n", extent, origin.x(), origin.y(),
                   origin.z(), spacing.x(), spacing.y(), spacing.z());
  x += fmt::format("    <Piece Extent=\"{}\">\n      <PointData>\n      </PointData>\n      <CellData>\n", extent);
  for (auto& a : cell_data) w.array("        ", a, nc, "cell");
  x += "      </CellData>\n    </Piece>\n  </ImageData>\n";
  w.write();
}

}  // namespace ff
