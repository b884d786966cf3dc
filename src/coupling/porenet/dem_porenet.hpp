// Two-way coupling of the bonded-disc DEM (2D) with the pore network of seed 004 (Krzaczek,
// Tejchman & Nitka 2024, Granular Matter 26:38, Appendix B; porenet/ holds the network and flow).
//
// One coupled step (DemPorenetCoupling::step) uses the DemSystem's public stages:
//   update_neighbors(); compute_forces();
//   pair states from the fresh loads: sigma_n = F_n / (2 min(R_a, R_b) h), h = t or, with
//     ForceHeight::Diameter, 2 min(R_a, R_b) (compression > 0, clamped at 0 for Eq. B1), broken bonds
//     with their opening max(0, |d| - R_a - R_b);
//   retriangulate when the largest particle displacement since the last triangulation exceeds
//     `retriangulation_tolerance` x the mean radius (phase masses carried by porenet's remap), else
//     update the network's geometry with the moved discs: the new void volumes V^{n+1} (B19) drive the
//     pressure (the undrained compaction effect);
//   explicit flow sub-steps of (what is left of dt_dem) / n, n = ceil(left / (safety dt_flow)), dt_flow
//     the two-phase stable step (docs/porenet.md §3, §5), evaluated again before each sub-step; when
//     dt_flow > dt_dem one flow step per DEM step; past `implicit_above` sub-steps one implicit step
//     for the rest; after each sub-step cavitation and condensation;
//   add_external_loads(); grain forces from the gauge pressure p - p_ambient (pressure B26-B27,
//     channel shear B25, B28; wetted height t or 2 r_j, ForceHeight) into particles.ext_force;
//     integrate().
// Contacts and bonds that form between triangulations get their S2S channel at the next one.
// Results are bit-identical on any thread count (porenet's fixed-order sums; per-particle loops).
#pragma once
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "coupling/porenet/pressure_force.hpp"
#include "dem/dem_system.hpp"
#include "io/checkpoint.hpp"
#include "porenet/network.hpp"
#include "porenet/remap.hpp"
#include "porenet/two_phase.hpp"

namespace ff::coupling {

// Which pores drain (held at the ambient pressure): none (closed sample, undrained), the pores on
// the convex hull within two max radii of the sample's lateral sides (x extremes), or every pore
// on the hull (all faces drained, e.g. the far field of a borehole).
enum class Drainage : std::uint8_t { Closed = 0, Sides = 1, Hull = 2 };

// Height of the wetted grain surface in B27 (A_k = height x arc) and B28 (height x L_k); it must
// be the height over which the grain's contacts and bonds carry their forces (the pressures do not
// depend on it: pore volumes and channel conductances both scale with the network's depth t).
// Thickness: fracflow's 2D discs are t = 1 m thick and the linear contact and parallel bond carry
// forces over t. Diameter: the seed's 2 r_j, for its law A1-A7, whose forces are those of spheres
// (a layer of spheres 2 r thick). Parallel bonds with the diameter height feel 2 r / t of the
// pressure's force (1e-3 for r = 0.5 mm): why 20 MPa of pore pressure left the UCS of the first
// sweep unchanged (docs/saturated.md).
enum class ForceHeight : std::uint8_t { Thickness = 0, Diameter = 1 };

struct PorenetCouplingParams {
  porenet::NetworkParams network;
  porenet::TwoPhaseParams fluid;
  Real initial_pressure = 1e5;  // [Pa]
  Real ambient_pressure = 1e5;  // outside the sample [Pa]; forces use p - ambient
  Real saturation = 1.0;        // initial liquid saturation, 0..1
  porenet::LiquidPlacement placement = porenet::LiquidPlacement::Uniform;  // where S < 1 puts the liquid
  Real retriangulation_tolerance = 0.25;  // x mean radius (cf. YADE defTolerance)
  Real dt_safety = 0.9;                   // flow sub-step <= safety x stable step
  long max_substeps = 200000;             // a flow step this small is an error, not a slow run
  // When the explicit flow would need more than this many sub-steps (liquid-full pores next to air or
  // to each other, open cracks: h^3 conductances), the rest of the DEM step is one implicit step
  // (porenet's IMPES, backward-Euler pressure, conservative phase update). 0 = always explicit (the
  // seed's scheme). 4, not 32: a partly saturated specimen with its small pores liquid-full needed
  // 20-32 sub-steps per DEM step and ran 8-12 x faster with one implicit step, its stress 1e-5 and
  // its largest pore pressure 2e-6 from the explicit run's after 20,000 DEM steps (docs/saturated.md).
  long implicit_above = 4;
  bool shear_forces = true;
  // Cavitation: a pore's liquid cannot be pulled below this absolute pressure (water's vapour
  // pressure, 2.34 kPa at 20 C); below it the pore keeps its liquid mass and fills the rest of its
  // void with vapour (modelled as the gas phase) at this pressure. Vapour exists only at this
  // pressure: a vapour pore compressed above it condenses its vapour back into liquid (first until
  // the pore is back at the vapour pressure, then all of it), so a bubble that opened while the
  // pore dilated does not stay as a gas cushion once the pore closes again. 0 = off (the
  // barotropic liquid then takes any tension: a dilating saturated sample is held together by suction).
  Real cavitation_pressure = 2.34e3;  // [Pa]
  ForceHeight force_height = ForceHeight::Thickness;
  // Surface here (the hydrofrac driver's 2D network); saturated_ucs's fluid.pressure_forces defaults to
  // the void gradient. The 2D hydrofrac test block with the void gradient cracked away from the hole at
  // 8.8 MPa (sleeve 33 MPa): not understood yet (docs/saturated.md, "Pressure forces").
  PressureForce pressure_force = PressureForce::Surface;
  Drainage drainage = Drainage::Closed;
  // What a retriangulation keeps (porenet/remap.hpp): each phase's mass (here, the hydrofrac
  // driver's network) or the pores' pressures (saturated_ucs's fluid.remap default: with water the
  // mass-conserving remap moved every pore's pressure by 1.5-5.4 MPa at a retriangulation).
  porenet::RemapConserve remap = porenet::RemapConserve::Mass;
};

struct CouplingStats {
  long retriangulations = 0;
  long last_substeps = 0;
  Real last_flow_dt = 0;    // sub-step used [s]
  Real last_stable_dt = 0;  // two-phase stable step [s]
  Real max_displacement = 0;  // since the last triangulation [m]
  long cavitations = 0;       // pore-steps that cavitated
  Real vapour_mass = 0;       // gas-phase mass created by cavitation [kg per m of depth]
  long condensations = 0;     // pore-steps whose vapour (partly) condensed
  Real condensed_mass = 0;    // vapour mass condensed back into liquid [kg per m of depth]
  long implicit_steps = 0;    // DEM steps finished by an implicit flow step (implicit_above)
  Real remap_liquid_change = 0, remap_gas_change = 0;  // sum over retriangulations of new - old mass [kg per m]
  Real remap_liquid_change_max = 0;                    // largest |change| of one retriangulation [kg per m]
};

class DemPorenetCoupling {
 public:
  // Builds pairs, network and flow from the system's current state (2D, after sys.initialise()).
  void init(dem::DemSystem& sys, const PorenetCouplingParams& params);
  void step(dem::DemSystem& sys);
  void run(dem::DemSystem& sys, long steps) {
    for (long s = 0; s < steps; ++s) step(sys);
  }

  const porenet::Network2D& network() const { return *net_; }
  porenet::TwoPhaseFlow& flow() { return *flow_; }
  const porenet::TwoPhaseFlow& flow() const { return *flow_; }
  const porenet::PairList& pairs() const { return pairs_; }
  const CouplingStats& stats() const { return stats_; }
  // Wall seconds spent in retriangulations (network, pairs and remap) by this process (not checkpointed).
  double triangulation_seconds() const { return t_triangulation_; }
  const PorenetCouplingParams& params() const { return prm_; }
  Real max_pressure() const;
  // Vapour mass (cavitation's part of the gas) per pore [kg per m of depth]; sum = vapour in the sample.
  std::span<const Real> vapour() const { return vap_; }
  Real total_vapour() const;
  // Fluid force of the last step on particle k [N] (x, y).
  Real fluid_fx(Index k) const { return fx_[static_cast<std::size_t>(k)]; }
  Real fluid_fy(Index k) const { return fy_[static_cast<std::size_t>(k)]; }
  // Stiffness the pore fluid adds to each grain [N/m], for the DEM's critical time step
  // (dem::critical_time_step's extra_stiffness). Pore i of void V_i pushes on grain j with
  // (p_i - p_a) h w_j (h the force height; w_j = |g_ij|, g_ij = dV_i/dx_j / t, with the void-gradient
  // force; the chord of j's arc in the pore with the arc force, B27), and moving j towards the pore by
  // dx shrinks V_i by t |g_ij| dx (the arc force kept its estimate t e_j dx / 2, e_j the triangle edge
  // opposite j), so k_j = sum_i K_i h w_j t |g_ij| / V_i, K_i = rho dp/drho of the pore's liquid-gas mixture
  // (1/K = alpha/K_q + (1 - alpha)/K_p) at its current state; pores at a prescribed pressure add
  // none. A pore held at the void floor (min_void_relative: its volume does not follow the grains now)
  // counts as if it had just come off it: the smallest pores are the stiffest springs once they open,
  // and the step must hold for the whole run (left out, the study's step would be 0.3 x 7.5e-8 s, 3 %
  // below the 2.33e-8 s that blew up: docs/saturated.md; counted, 0.3 x 3.8e-8 s); one at the
  // fraction floor (overlapping discs: V = phi x the triangle) with phi of its change. A liquid-full
  // pore of a dense packing adds about 2 Kn of seed 004's law per face.
  std::vector<Real> fluid_stiffness() const;
  // Sets every pore's pressure and saturation (tests, initial states).
  void set_uniform_state(Real p, Real saturation);

  // Checkpoint sections (prefix "porenet."): reference positions, pair list, per-pore state.
  void save(CheckpointWriter& w) const;
  // After the DemSystem was restored; params as at init.
  void load(CheckpointReader& r, dem::DemSystem& sys, const PorenetCouplingParams& params);

  // Staged use by a driver with its own step order (hydrofrac's network fluid,
  // coupling/hydrofrac/network_load.cpp), instead of step(): sync() brings the network to the
  // system's current positions and pair loads (after compute_forces), retriangulating past the
  // tolerance (returns true then: a new flow object, boundary conditions to set again); the
  // caller steps flow() itself; compute_fluid_forces() fills fluid_fx/fluid_fy from the current
  // pressures, each clamped below at p_floor (absolute: a liquid under tension cavitates, so the
  // grains feel at most ambient - p_floor of suction), without adding them to the system.
  bool sync(const dem::DemSystem& sys);
  void compute_fluid_forces(Real p_floor);

 private:
  void gather_positions(const dem::DemSystem& sys);
  void build_pairs(const dem::DemSystem& sys);
  void fill_pair_state(const dem::DemSystem& sys);
  void remap_pair_bonds(const dem::DemSystem& sys);  // pair_bond_ after the DEM dropped broken bonds
  void make_network_and_flow(std::unique_ptr<porenet::Network2D>& net, std::unique_ptr<porenet::TwoPhaseFlow>& flow);
  void set_boundaries(porenet::TwoPhaseFlow& flow, const porenet::Network2D& net);
  void retriangulate(const dem::DemSystem& sys);
  void add_forces(dem::DemSystem& sys);
  void cavitate();
  void carry_vapour(const porenet::Network2D& old_net, std::span<const Real> old_vap, std::span<const Real> old_mp);

  PorenetCouplingParams prm_;
  std::unique_ptr<porenet::Network2D> net_;
  std::unique_ptr<porenet::TwoPhaseFlow> flow_;
  porenet::PairList pairs_;
  std::vector<Index> pair_bond_;  // bond index per pair, -1 for a contact
  std::vector<std::pair<std::uint64_t, Index>> bond_keys_;  // remap_pair_bonds' scratch
  std::vector<Real> x_, y_, r_, ref_x_, ref_y_, fx_, fy_, pg_;
  // Vapour bookkeeping (cavitate): vapour mass per pore, each pore's gas mass after the last
  // cavitate() (the flow's change since then moves vapour), prescribed-pressure pores (no vapour).
  std::vector<Real> vap_, mp_prev_;
  std::vector<std::uint8_t> bc_pore_;
  Real mean_radius_ = 0;
  double t_triangulation_ = 0;
  CouplingStats stats_;
};

}  // namespace ff::coupling
