// Geometry of the hydraulic-fracturing block: carving the borehole and its perforations out of
// a bonded sample, the surface the fluid wets (a flood fill from the hole's axis), the cracks
// connected to the hole, and the main fracture's extent and orientation.
#pragma once
#include <cstdint>
#include <vector>

#include "dem/dem_system.hpp"
#include "coupling/hydrofrac/fluid_load.hpp"

namespace ff::coupling::hydrofrac {

// Whether x lies in the hole or a perforation slot, both widened by `pad` [m] (x-y only).
bool in_hole(const BoreholeGeometry& g, const Vec3& x, Real pad);

// Removes the particles with remove[i] != 0 and every bond that touches one; renumbers the
// rest in order (ids stay with their particles). Contact history is dropped (set-up only, before
// any wall exists). Returns the number removed.
std::size_t remove_particles(dem::DemSystem& sys, const std::vector<char>& remove);

// The borehole's wetted surface: the particles exposed to the hole, each with its vector area
// sum(n dA) over the part of its surface that faces the hole (n: the particle's outward normal;
// 2D: per metre of thickness), and the hole's volume. Found by flooding a grid of cells of
// size `cell` from the hole's axis through cells that no particle (radius + `inflate`) covers,
// within the hole and slots widened by `reach`; a surface point of a particle that lies in a
// flooded cell is wetted. The flood cannot leak into the pore space beyond `reach`.
struct HoleSurface {
  std::vector<Index> particle;
  std::vector<Vec3> area;  // [m^2]
  Real volume = 0;         // flooded cells' volume [m^3] (2D: per metre)
  Real effective_radius = 0;  // 2D: sqrt(A/pi); 3D: sqrt(V/(pi L))
};
HoleSurface hole_surface(const dem::DemSystem& sys, const BoreholeGeometry& g, Real cell, Real inflate, Real reach);

// Global id -> particle index (-1: none), for the crack log's ids.
std::vector<Index> index_of_ids(const dem::ParticleStore& p);

// Cracks connected to the hole: walking from the wall particles across broken bonds (crack
// events, and the joints of a DFN), every crack reached. `event` gets the crack-log indices
// reached (joint edges are walked but not listed), `joint` the joint indices reached.
void connected_cracks(const dem::DemSystem& sys, const std::vector<Index>& id_index, const std::vector<Index>& wall,
                      const std::vector<JointPair>& joints, std::vector<std::size_t>& event, std::vector<std::size_t>& joint,
                      std::vector<char>& visited_scratch);

// The main fracture from the positions of the connected cracks (x-y plane about the hole's
// axis): principal axis of sum d d^T, its azimuth from x (the sigma_H direction) in
// (-90, 90] deg, the tip-to-tip length along it, the largest distance of a crack from the axis.
struct FractureShape {
  long cracks = 0;
  Real azimuth_deg = 0, length = 0, max_distance = 0;
  Real anisotropy = 0;  // 1 - lambda2/lambda1: 0 for a round cloud, 1 for a line
  // From the cracks' normals (bond axes): the plane normal to the principal axis of sum n n^T,
  // i.e. the opening direction's normal (less sensitive to side branches than the positions).
  Real normal_azimuth_deg = 0;
};
FractureShape fracture_shape(const dem::DemSystem& sys, const std::vector<std::size_t>& events, const Vec3& centre);

}  // namespace ff::coupling::hydrofrac
