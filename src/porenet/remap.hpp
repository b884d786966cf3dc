// Carrying the fluid over to a new network after a retriangulation (issue 16, item 1).
// Each new pore takes the state of the old pore whose centroid is nearest to its own (the old
// network's centroids at the current particle positions: call update_network_2d first; cf. YADE,
// which interpolates by cell centre, METHODS §5.1): its density (single phase), or its liquid
// fraction and phase densities (two phases). RemapConserve::Mass: the masses ρ V_new are then
// scaled by one factor per phase so that each phase's total mass equals the old total: mass is
// conserved to round-off, and the pressures change by the relative change of the network's total
// void times the phase's bulk modulus. That change is not small for a liquid: the floors of
// network.cpp (overlap, min_void_relative) and folded (inverted) triangles make the total void
// depend on the triangulation (measured in seed 004's 2D specimen: +0.07 % and +0.25 % at two
// retriangulations of the same positions, 39-40 of 384 pores at the floor), i.e. jumps of 1.5 and
// 5.4 MPa in every pore of a water-saturated sample. RemapConserve::Pressure: no scaling, each
// new pore keeps its source's densities (pressures carried over exactly); the phases' masses then
// change by the void model's difference, returned for the caller to report.
// Boundary conditions are not carried: set them on the new flow object before remapping.
#pragma once
#include <cstdint>
#include <vector>

#include "porenet/flow.hpp"
#include "porenet/network.hpp"
#include "porenet/two_phase.hpp"

namespace ff::porenet {

// For each pore of `to`, the pore of `from` with the nearest centroid (CGAL nearest_vertex; 2D or 3D).
std::vector<Index> nearest_pores(const Network2D& from, const Network2D& to);

void remap_single_phase(const Network2D& old_net, SinglePhaseFlow& old_flow, const Network2D& new_net,
                        SinglePhaseFlow& new_flow);
enum class RemapConserve : std::uint8_t { Mass = 0, Pressure = 1 };
struct RemapChange {
  Real liquid = 0, gas = 0;  // new total - old total [kg] (round-off with Mass)
};
RemapChange remap_two_phase(const Network2D& old_net, TwoPhaseFlow& old_flow, const Network2D& new_net,
                            TwoPhaseFlow& new_flow, RemapConserve conserve = RemapConserve::Mass);

}  // namespace ff::porenet
