// The lattice box: nx x ny x nz cells plus one ghost layer on every side (the memory that
// bounce-back and open boundaries stream into, and the future MPI halo). 2D lattices have
// nz = 1 and no ghost layer in z. Periodic axes wrap neighbour indices instead of using
// the ghosts. Cell index = x + px*(y + py*z) in padded coordinates, x fastest; rows are padded
// so that every row's first cell sits on a 64-byte boundary (aligned vector loads and stores).
#pragma once
#include <array>
#include <cstdint>
#include <string>

namespace ff::lbm {

using CellIndex = std::int64_t;

// Face numbering used everywhere: 0 x-, 1 x+, 2 y-, 3 y+, 4 z-, 5 z+.
inline constexpr int kNumFaces = 6;
inline const char* face_name(int f) {
  static const char* n[kNumFaces] = {"x-", "x+", "y-", "y+", "z-", "z+"};
  return n[f];
}

struct Grid {
  int dim = 2;
  int nx = 1, ny = 1, nz = 1;            // interior cells
  std::array<bool, 3> periodic{};        // per axis
  int gz = 0;                            // ghost width in z (0 in 2D)
  CellIndex px = 3, py = 3, pz = 1;      // padded extents

  Grid() = default;
  Grid(int dimension, int nx_, int ny_, int nz_, std::array<bool, 3> per)
      : dim(dimension), nx(nx_), ny(ny_), nz(dimension == 2 ? 1 : nz_), periodic(per) {
    if (dim == 2) periodic[2] = true;  // a 2D lattice is trivially periodic in z
    gz = dim == 3 ? 1 : 0;
    px = ((nx + 2 + kFront + 7) / 8) * 8;
    py = ny + 2;
    pz = nz + 2 * gz;
  }
  CellIndex padded_size() const { return px * py * pz; }
  CellIndex interior_size() const { return CellIndex(nx) * ny * nz; }
  int n(int axis) const { return axis == 0 ? nx : axis == 1 ? ny : nz; }

  // Index of the cell at interior coordinates (x, y, z); -1 and n are ghost coordinates.
  static constexpr int kFront = 7;  // padding before x = -1, so that x = 0 is a multiple of 8
  CellIndex index(int x, int y, int z) const { return (x + 1 + kFront) + px * ((y + 1) + py * (z + gz)); }
  // Interior coordinates of a padded index.
  std::array<int, 3> coords(CellIndex i) const {
    const int x = int(i % px) - 1 - kFront;
    const int y = int((i / px) % py) - 1;
    const int z = int(i / (px * py)) - gz;
    return {x, y, z};
  }
  // Coordinate after a step of d along `axis`: wrapped on periodic axes, else may be a ghost.
  int step(int v, int d, int axis) const {
    v += d;
    if (periodic[axis]) {
      const int m = n(axis);
      if (v < 0) v += m;
      else if (v >= m) v -= m;
    }
    return v;
  }
  CellIndex neighbour(int x, int y, int z, int cx, int cy, int cz) const {
    return index(step(x, cx, 0), step(y, cy, 1), step(z, cz, 2));
  }
  bool is_interior(int x, int y, int z) const {
    return x >= 0 && x < nx && y >= 0 && y < ny && z >= 0 && z < nz;
  }
  // Which ghost face a (possibly ghost) coordinate lies in, -1 if interior. For ghost corners
  // the face of the highest axis wins (so a lid on y+ owns the top corners in 2D).
  int ghost_face(int x, int y, int z) const {
    if (dim == 3 && z < 0) return 4;
    if (dim == 3 && z >= nz) return 5;
    if (y < 0) return 2;
    if (y >= ny) return 3;
    if (x < 0) return 0;
    if (x >= nx) return 1;
    return -1;
  }
};

// Cell coordinate v on an axis of n cells, for particle footprints (PSM fractions, moving-boundary
// links): wrapped if periodic (v is within a period of the box for particles near it; far ones take
// the modulo), -1 when outside a closed axis.
inline int wrap_axis(int v, int n, bool periodic) {
  if (v >= 0 && v < n) return v;
  if (!periodic) return -1;
  if (v < 0 && v >= -n) return v + n;
  if (v >= n && v < 2 * n) return v - n;
  return ((v % n) + n) % n;
}

}  // namespace ff::lbm
