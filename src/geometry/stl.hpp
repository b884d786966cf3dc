// STL surface files (ASCII and binary). Coordinates are taken as they are (no unit scaling).
#pragma once
#include <filesystem>

#include "geometry/triangle_mesh.hpp"

namespace ff::geom {

// Reads an ASCII or binary STL. A file is binary when its size is exactly 84 + 50 n bytes with n
// the triangle count stored at byte 80 (binary files may also start with "solid"), ASCII when it
// starts with "solid", and an error otherwise. Coincident vertices are merged (bit-identical
// coordinates) and degenerate triangles dropped. Throws ff::InputError naming the file and the
// problem: missing, truncated, malformed, NaN/infinite coordinates, or no triangles.
TriangleMesh read_stl(const std::filesystem::path& path);

// Writes little-endian binary STL (float32 coordinates, facet normals from the vertex order).
void write_stl_binary(const std::filesystem::path& path, const TriangleMesh& mesh);
// Writes ASCII STL with 9 significant digits (float32 coordinates survive a round trip).
void write_stl_ascii(const std::filesystem::path& path, const TriangleMesh& mesh);

}  // namespace ff::geom

namespace ff {
using geom::read_stl;
using geom::write_stl_ascii;
using geom::write_stl_binary;
}  // namespace ff
