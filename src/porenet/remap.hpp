// Carrying the fluid over to a new network after a retriangulation (issue 16, item 1).
// Each new pore takes the state of the old pore whose centroid is nearest to its own (the old
// network's centroids at the current particle positions: call update_network_2d first; cf. YADE,
// which interpolates by cell centre, METHODS §5.1): its density (single phase), or its liquid
// fraction and phase densities (two phases). The masses ρ V_new are then scaled by one factor per
// phase so that each phase's total mass equals the old total: mass is conserved to round-off,
// and the pressures change by the (small) relative volume change of the remeshing.
// Boundary conditions are not carried: set them on the new flow object before remapping.
#pragma once
#include <vector>

#include "porenet/flow.hpp"
#include "porenet/network.hpp"
#include "porenet/two_phase.hpp"

namespace ff::porenet {

// For each pore of `to`, the pore of `from` with the nearest centroid (CGAL nearest_vertex; 2D or 3D).
std::vector<Index> nearest_pores(const Network2D& from, const Network2D& to);

void remap_single_phase(const Network2D& old_net, SinglePhaseFlow& old_flow, const Network2D& new_net,
                        SinglePhaseFlow& new_flow);
void remap_two_phase(const Network2D& old_net, TwoPhaseFlow& old_flow, const Network2D& new_net,
                     TwoPhaseFlow& new_flow);

}  // namespace ff::porenet
