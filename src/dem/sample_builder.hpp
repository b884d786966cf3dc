// Bonded-particle sample genesis, after PFC's bonded-particle-model procedure (Potyondy &
// Cundall 2004, section 3.1): dense random packing in a rigid vessel -> frictionless
// equilibration -> isotropic stress reduced below a set value (locked-in stress) -> bonds
// installed between particles closer than a gap -> vessel removed. Groups are assigned from
// primitives and closed STL surfaces (point-in-mesh of the particle centres), then from a
// segmented voxel image (CT-like PGM stack, grey-value windows as in seed 000 s. 2.2), whose
// "pore" window removes particles before bonding.
#pragma once
#include <string>
#include <vector>

#include "dem/dem_system.hpp"
#include "geometry/voxel_image.hpp"
#include "io/params.hpp"

namespace ff::dem {

struct SampleInfo {
  int dim = 3;
  int axis = 2;               // loading axis: z in 3D, y in 2D
  Real height = 0;            // along the loading axis, platen to platen [m] (disc: its diameter)
  Real width = 0;             // cylinder or disc diameter, or box width [m]
  Real area = 0;              // loaded cross-section [m^2] (2D: width x 1 m)
  Real volume = 0;            // container volume [m^3] (2D: area of the rectangle or circle x 1 m)
  bool cylinder = true;       // round about the z axis through the origin: 3D cylinder or 2D disc (dim = 2)
  Real porosity = 0;          // after genesis
  Real locked_in_stress = 0;  // mean stress when bonds were installed [Pa], compression > 0
  std::size_t bonds = 0;
  std::size_t floaters = 0;   // particles with fewer than 3 (3D) or 2 (2D) bonds
  std::size_t pore_particles = 0;  // removed before bonding: centre in a voxel of the "pore" window
  double genesis_seconds = 0;
  // The packing genesis reached (reported in the log and summary.json).
  double packing_seconds = 0;        // geometric packer (part of genesis_seconds)
  long genesis_steps = 0;            // DEM cycles of the equilibration
  bool equilibrium_reached = false;  // unbalanced_force_ratio <= sample.genesis_tolerance
  Real unbalanced_force_ratio = 0;   // at the end of the equilibration (definition: docs/dem.md)
  Real coordination_contacts = 0;    // touching contacts per particle (2 x contacts / N) when bonded
  Real coordination_bonds = 0;       // bonds per particle (2 x bonds / N)
};

void declare_sample_params(ParamTable& t);

// Regions are tested against every particle; more are refused (read at most once per run).
inline constexpr std::size_t kMaxRegions = 10000;

// Every check of the [dem] and [sample] keys that build_sample() and the materials make before
// packing: groups and pair tables, laws, radii and sizes, porosity, regions (STL files read),
// the voxel stack (read) and the default group. The `validate` of the DEM drivers.
void validate_dem_sample(const Config& cfg);
// The isotropic stress at which the contacts of a packing of mean-size particles (radii midway
// between sample.radius_min and radius_max, the stiffest contact pair) overlap by half a radius:
// 3D force / (2r)^2, 2D force / (2r x 1 m). A confining, in-situ or locked-in stress above it
// crushes the sample instead of loading it (contact laws hold for overlaps of a few per cent).
Real crushing_stress(const Config& cfg);
// Refuses `key` (a stress in Pa) when it is at or above crushing_stress(cfg), naming the contact
// keys that set the bound.
void refuse_crushing_stress(const Config& cfg, const std::string& key);
// Installs the bonds of sample.bond_gap on the built sample, after refusing a gap above its largest
// particle radius (a bond is a cement bridge between neighbours; 1e300 m bonded every pair: memory
// grew past 6 GB for a 3D block). Returns the bond count.
std::size_t install_sample_bonds(const Config& cfg, DemSystem& sys);

// Label of the grey-value window named "pore": particles whose centre lies in such a voxel are removed.
inline constexpr int kPoreLabel = -1;

// The image of sample.voxels.* with its windows (label: group index or kPoreLabel); no windows
// when sample.voxels.folder is empty.
struct VoxelGroups {
  geom::VoxelImage image;
  std::vector<geom::GreyRange> windows;
  bool empty() const { return windows.empty(); }
};
// Reads and checks sample.voxels.* (folder relative to the scenario file's folder). Throws
// InputError naming the key for a missing or bad stack, windows that overlap or have min > max,
// a name that is neither a group nor "pore", and windows without a folder (or the reverse).
VoxelGroups read_voxel_groups(const Config& cfg, const Materials& materials);

// Builds particles, groups, masses and bonds in `sys` (whose settings/materials are set),
// removes the vessel and leaves no walls. Throws InputError for bad sample keys.
SampleInfo build_sample(const Config& cfg, DemSystem& sys);
// Adds two platens touching the sample's ends along info.axis (bottom first), with friction.
void add_platens(DemSystem& sys, const SampleInfo& info, Real friction);

// Spatial order of particles (cells of two max radii, raster z-y-x) so neighbours sit close in
// memory: order[new] = old. Genesis and loaded packings use it.
std::vector<std::size_t> spatial_order(const std::vector<Vec3>& pos, const std::vector<Real>& rad);

}  // namespace ff::dem
