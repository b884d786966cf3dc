// The hydrofrac driver's scenario keys and their checks (hydrofrac_params.cpp).
#pragma once
#include "core/types.hpp"
#include "coupling/fluid_spec.hpp"
#include "io/params.hpp"

namespace ff::drivers::hydrofrac {

// Every key of driver = "hydrofrac" (with the DEM, sample and DFN keys it uses).
void declare_params(ParamTable& t);
// What `check` and `run` refuse before building anything: the block, the borehole and its
// perforations against the block, the measurement circles, the DFN, the LBM fluid's scales.
void validate_scenario(const Config& cfg);

// Geometry of the block from the sample keys: 2D box (x: width, y: height), 3D box (x: width,
// y: depth, z: height); the borehole on the axis through the middle (3D: along z).
struct Block {
  Real lx = 0, ly = 0, lz = 0;
  Vec3 centre = Vec3::Zero();
};
Block block_of(const Config& cfg);

// The fluid of injection.fluid = "lbm" (keys fluid.*), in SI.
coupling::FluidSpec lbm_fluid_spec(const Config& cfg);

}  // namespace ff::drivers::hydrofrac
