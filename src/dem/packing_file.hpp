// Packing files: a bonded-particle sample as plain text, so that fracflow can be run (and timed,
// benchmarks/dem_ucs --packing) on exactly the packing another code uses (ESyS-Particle / GenGeo
// or YADE exports, converted to this format), and so that fracflow's own samples can be handed to
// those codes (dem_ucs --write-packing).
//
// Format (3D spheres, SI units):
//
//   # anything after '#' is a comment; blank lines are ignored
//   x y z r          one particle per line: centre [m] and radius [m] (> 0), four numbers
//   ...
//   bonds            optional: the word `bonds` alone on a line, then
//   i j              one bond per line: two 0-based particle indices (line order of the particles)
//   ...
//
// Without a `bonds` line the bonds are installed by the scenario's sample.bond_gap rule, as after
// genesis (DemSystem::install_bonds); a `bonds` line followed by no pair means "no bonds".
// Errors name the file and the line: a line that is not four numbers (or, after `bonds`, two
// indices), a radius <= 0, a non-finite number, an index out of range, a bond of a particle with
// itself, a repeated bond, a second `bonds` line, a file without particles.
#pragma once
#include <iosfwd>
#include <string>
#include <utility>
#include <vector>

#include "core/types.hpp"
#include "dem/sample_builder.hpp"

namespace ff::dem {

struct PackingFile {
  std::vector<Vec3> pos;
  std::vector<Real> radius;
  bool has_bond_list = false;                  // a `bonds` line was read (its list may be empty)
  std::vector<std::pair<Index, Index>> bonds;  // i < j, in file order
};

// Parses the text of a packing file; `name` (the path) starts every error message. Throws
// InputError "name:line: what".
PackingFile parse_packing(std::istream& in, const std::string& name);
// Reads the file at `path`; throws InputError when it cannot be opened or parsed.
PackingFile read_packing_file(const std::string& path);
// Writes `p` in the format above (17 significant digits: reading it back gives the same
// numbers); `comment` becomes the first line(s), each prefixed with '#'. Throws Error on failure.
void write_packing_file(const std::string& path, const PackingFile& p, const std::string& comment);

// Places the packing in `sys` (whose settings and materials are set) instead of genesis: every
// particle in group `group` with its mass from the group's density, at rest; bonds from the list,
// or, without one, by sample.bond_gap (DemSystem::install_bonds, as build_sample does); Verlet
// skin dem.skin_ratio x mean radius; no walls; initialised. With `reorder`, the particles are
// first put in the spatial (cell raster) order that genesis uses, the bond indices renumbered
// to follow and the bonds sorted by (i, j); the packing itself is unchanged. The SampleInfo
// describes the bounding box of the spheres (axis z, height and width from it, porosity over
// the box volume). Throws InputError for a bond list with dem.bond_law = none.
SampleInfo place_packing(const PackingFile& p, const Config& cfg, DemSystem& sys, int group, bool reorder);

}  // namespace ff::dem
