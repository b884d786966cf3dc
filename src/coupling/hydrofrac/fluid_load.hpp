// The fluid side of the hydraulic-fracturing driver, behind one small interface, so that the
// driver's rock (block, borehole, in-situ stresses, cracks) does not depend on how the fluid is
// modelled. Three implementations: "sleeve" (src/drivers/hydrofrac/sleeve_load.hpp: a pressure on
// the particles that line the borehole, and on crack faces connected to it with penetration; the
// DEM alone), and the two that couple the rock to a second physics module and so live here, in
// src/coupling/ (docs ARCHITECTURE: the only code that sees two of them): "lbm" (lbm_load.hpp, the
// lattice Boltzmann fluid) and "network" (network_load.hpp, the pore network). borehole.hpp is the
// geometry they share with the driver (the hole's wetted surface, the cracks connected to it).
//
// The driver calls, per DEM step, in this order:
//   sys.update_neighbors(); sys.compute_forces();
//   fluid.add_forces(sys);          // ADDS fluid forces/moments to particles.ext_force/ext_moment
//   sys.add_external_loads(); sys.integrate();
//   fluid.advance(sys);             // fluid state to sys.time (pressure, volumes), after the move
// Virtual calls happen three times per step (add_forces, advance and the servos' face_pressures),
// never per particle or contact; an implementation keeps its own scratch arrays (no allocation per
// step) and must give the same result on any thread count. An LBM implementation sub-cycles or strides as it likes inside add_forces/advance (e.g.
// one LBM step every n DEM steps) and keeps the fluid state in its checkpoint sections.
#pragma once
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "core/types.hpp"
#include "dem/dem_system.hpp"
#include "io/checkpoint.hpp"

namespace ff::coupling::hydrofrac {

// The borehole as the driver carved it (2D: a circle in x-y; 3D: a vertical cylinder along z
// through the whole block) and its perforations (slots along the azimuth, from the wall out).
struct BoreholeGeometry {
  Vec3 centre = Vec3::Zero();  // on the axis (z ignored)
  Real radius = 0;             // carving radius: particles with centres closer were removed [m]
  Real perforation_length = 0, perforation_width = 0;  // [m]; length 0: none
  Real perforation_azimuth = 0;                        // [rad] from x (the sigma_H direction)
  int perforation_sides = 2;                           // 1: one slot; 2: two opposite slots
  Real z_lo = 0, z_hi = 0;                             // 3D: axial extent [m]
  int dim = 2;
};

// BoreholeGeometry as a checkpoint section (plain data, written as raw bytes): the driver's and
// the network fluid's checkpoints hold one each.
struct BoreholeRecord {
  Real cx = 0, cy = 0, radius = 0, plen = 0, pwid = 0, paz = 0, z_lo = 0, z_hi = 0;
  long sides = 2, dim = 2;
};
inline BoreholeRecord to_record(const BoreholeGeometry& g) {
  return {g.centre.x(), g.centre.y(), g.radius, g.perforation_length, g.perforation_width, g.perforation_azimuth,
          g.z_lo,       g.z_hi,       g.perforation_sides, g.dim};
}
inline BoreholeGeometry from_record(const BoreholeRecord& h) {
  BoreholeGeometry g;
  g.centre = Vec3(h.cx, h.cy, 0);
  g.radius = h.radius;
  g.perforation_length = h.plen;
  g.perforation_width = h.pwid;
  g.perforation_azimuth = h.paz;
  g.z_lo = h.z_lo;
  g.z_hi = h.z_hi;
  g.perforation_sides = static_cast<int>(h.sides);
  g.dim = static_cast<int>(h.dim);
  return g;
}

// A bond cut by a natural fracture (zero strength): its two particles' global ids and the bond
// face area [m^2] (2D: 2 r_bond x 1 m; 3D: pi r_bond^2).
struct JointPair {
  std::int64_t a = 0, b = 0;
  Real area = 0;
};

// What the driver reads back each series row (and writes to series.csv / summary.json).
struct FluidState {
  Real pressure = 0;           // borehole pressure [Pa]
  Real injected_volume = 0;    // fluid volume pumped in since injection began, at reference density [m^3]
  Real borehole_volume = 0;    // pressurised volume now (hole + wetted cracks) [m^3]
  long wetted_particles = 0;   // particles carrying a fluid load
  long wetted_cracks = 0;      // crack faces carrying a fluid load (penetration)
};

class FluidLoad {
 public:
  virtual ~FluidLoad() = default;
  // Injection starts: the rock is equilibrated under the in-situ stresses. `joints`: bonds
  // removed along natural fractures (dfn.hpp) that fluid may enter like cracks; the crack
  // events of sys.cracks come on top as bonds break.
  virtual void begin(const dem::DemSystem& sys, const BoreholeGeometry& hole, const std::vector<JointPair>& joints) = 0;
  virtual void add_forces(dem::DemSystem& sys) = 0;
  virtual void advance(const dem::DemSystem& sys) = 0;
  virtual FluidState state() const = 0;
  // Particles (indices) lining the borehole, for the fracture measurements (cracks connected
  // to the hole start from them).
  virtual const std::vector<Index>& wall_particles() const = 0;
  // Mean gauge pressure (above p0) of the fluid on each face of the block [Pa], index 2a + side
  // as sys.walls (x-, x+, y-, y+, z-, z+); dry parts of a face count as zero. The servo walls carry
  // it over their area together with the grains' contacts, as the platens of a lab cell do: they
  // hold the total stress, so pore fluid that reaches the faces unloads the skeleton (Terzaghi's
  // effective stress). Zero where the model's fluid never reaches the faces (sleeve) or pushes
  // the hull grains instead (network: a hull pore's pressure loads its grains outwards).
  virtual std::array<Real, 6> face_pressures() const { return {}; }
  // Checkpoint sections (after the DEM system's; the object is rebuilt from the scenario).
  virtual void save(CheckpointWriter& w) const = 0;
  virtual void load(CheckpointReader& r, const dem::DemSystem& sys) = 0;
};

}  // namespace ff::coupling::hydrofrac
