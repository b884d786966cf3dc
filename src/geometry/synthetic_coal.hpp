// Synthetic heterogeneous coal cores standing in for the CT reconstructions of seed 000 (Zhao,
// Konietzky & Herbst 2021, s. 2.2, Table 2, Fig. 4), of which no scans are available:
//   C1-like: ~20% mineral inclusions (Table 2: 19.88%) as thin vertical veins/lenses, "distributed
//            mainly parallel to the axis of the sample", all striking roughly the same way (bands);
//   C4-like: ~10% inclusions (Table 2: 10.10%) as isolated blobs "near the boundary surface in the
//            central part"; "both ends of the sample are composed of matrix".
// Inclusions are disjoint ellipsoids inside the cylinder (axis z, base centre at the origin, as
// the sample builder's vessel), so one surface file holds all of them as separate closed shells.
// The last inclusion is shrunk so that the analytic volume fraction equals the target exactly.
// A few spherical pores are added to the voxel image only. Same spec -> bit-identical output
// (std::mt19937_64, whose output sequence the C++ standard fixes; no std:: distributions).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "core/types.hpp"
#include "geometry/shapes.hpp"
#include "geometry/triangle_mesh.hpp"
#include "geometry/voxel_image.hpp"

namespace ff::geom {

enum class CoalSampleKind { C1, C4 };

struct SyntheticCoalSpec {
  CoalSampleKind kind = CoalSampleKind::C1;
  Real diameter = 25e-3;  // [m]
  Real height = 50e-3;    // [m], the generators are tuned for height ~ 2 x diameter
  std::uint64_t seed = 1;
};

// Grey values of the voxel stack (8-bit): dark air outside the core, pores darker than coal,
// mineral inclusions brightest (CT values grow with density; seed 000 s. 2.2).
struct CoalGreyValues {
  static constexpr std::uint16_t outside = 0;
  static constexpr std::uint16_t pore = 30;
  static constexpr std::uint16_t matrix = 100;
  static constexpr std::uint16_t inclusion = 200;
};

// Where the C4-like generator puts its blobs: every inclusion point lies within
// kC4SurfaceBand * radius of the lateral surface and between kC4EndMargin * height of each end.
inline constexpr Real kC4SurfaceBand = 0.4;
inline constexpr Real kC4EndMargin = 0.1;
// Target inclusion volume fractions (seed 000 Table 2, rounded).
inline constexpr Real kC1InclusionFraction = 0.20;
inline constexpr Real kC4InclusionFraction = 0.10;

struct SyntheticCoal {
  SyntheticCoalSpec spec;
  std::vector<Ellipsoid> inclusions;  // disjoint, inside the cylinder
  std::vector<Sphere> pores;          // in the matrix, voxel image only
  // Sum of the inclusion volumes over the cylinder volume.
  Real inclusion_fraction() const;
};

// Throws ff::InputError for a non-positive size and ff::Error if the inclusions cannot be placed.
SyntheticCoal make_synthetic_coal(const SyntheticCoalSpec& spec);

// All inclusions as one mesh of disjoint closed shells (icospheres refined `subdivisions` times,
// scaled so that each shell encloses its ellipsoid's volume exactly).
TriangleMesh inclusion_surface(const SyntheticCoal& coal, int subdivisions = 2);

// Voxel stack covering the cylinder's bounding box: round(diameter / voxel_size) voxels across,
// round(height / voxel_size) slices (spacing adjusted so they tile the box exactly), each voxel
// labelled by its centre with CoalGreyValues.
VoxelImage voxelize(const SyntheticCoal& coal, Real voxel_size);

// Inclusion voxels over voxels inside the cylinder (pores count as matrix volume).
Real voxel_inclusion_fraction(const VoxelImage& image);

std::string to_string(CoalSampleKind kind);

}  // namespace ff::geom

namespace ff {
using geom::CoalSampleKind;
using geom::make_synthetic_coal;
using geom::SyntheticCoal;
using geom::SyntheticCoalSpec;
}  // namespace ff
