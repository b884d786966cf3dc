// VTK XML files written directly (no VTK library): PolyData (.vtp) for particles, bonds and
// wall meshes, ImageData (.vti) for lattice fields. Data are appended raw binary
// (header_type="UInt64": each block is an 8-byte little-endian byte count, then the bytes),
// which ParaView reads without base64 decoding. Files are written atomically.
#pragma once
#include <array>
#include <bit>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <variant>

#include "core/types.hpp"

namespace ff {

static_assert(std::endian::native == std::endian::little, "the VTK and checkpoint writers assume a little-endian host");
static_assert(sizeof(Vec3) == 3 * sizeof(double) && alignof(Vec3) == alignof(double),
              "Vec3 must be exactly 3 contiguous doubles (written to VTK as a 3-component array)");
static_assert(sizeof(Quat) == 4 * sizeof(double), "Quat must be exactly 4 contiguous doubles (x, y, z, w)");

// One named array: a span over components * count scalars (tuple-major: x0 y0 z0 x1 y1 z1 ...).
// It only points at the caller's data, which must outlive the write call.
struct VtkArray {
  std::string name;
  int components = 1;
  std::variant<std::span<const double>, std::span<const float>, std::span<const std::int32_t>,
               std::span<const std::int64_t>, std::span<const std::uint8_t>>
      data;
  std::size_t scalars() const;  // number of scalars in the span
};

// Builders: Vec3 -> 3 components, Quat -> 4 components (x, y, z, w, Eigen's storage order).
VtkArray vtk_array(std::string name, std::span<const Vec3> v);
VtkArray vtk_array(std::string name, std::span<const Quat> v);
VtkArray vtk_array(std::string name, std::span<const double> v, int components = 1);
VtkArray vtk_array(std::string name, std::span<const float> v, int components = 1);
VtkArray vtk_array(std::string name, std::span<const std::int32_t> v, int components = 1);
VtkArray vtk_array(std::string name, std::span<const std::int64_t> v, int components = 1);
VtkArray vtk_array(std::string name, std::span<const std::uint8_t> v, int components = 1);

// The cells of a PolyData file.
struct VtpCells {
  enum Kind { Vertices, Lines, Triangles } kind = Vertices;
  // Point indices: pairs for Lines, triples for Triangles, one per cell for Vertices;
  // empty for Vertices means one vertex per point (particles).
  std::span<const std::int64_t> connectivity;
  std::size_t count(std::size_t n_points) const;  // number of cells
};

// Writes a PolyData file; point_data arrays have one tuple per point, cell_data one per cell.
// Throws ff::Error naming the file and array on size mismatches or bad indices.
void write_vtp(const std::filesystem::path& path, std::span<const Vec3> points, const VtpCells& cells,
               std::span<const VtkArray> point_data, std::span<const VtkArray> cell_data);

// Writes an ImageData file of nx*ny*nz cells (nz = 1 in 2D) with cell data, x fastest:
// cell (i,j,k) is tuple i + nx*(j + ny*k). origin is the corner of cell (0,0,0).
void write_vti(const std::filesystem::path& path, std::array<int, 3> cells, Vec3 origin, Vec3 spacing,
               std::span<const VtkArray> cell_data);

}  // namespace ff
