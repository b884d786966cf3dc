// Two-way coupling of the 3D bonded-sphere DEM with the PFV-style pore network (issue 16, item 7;
// porenet/network3d.cpp: regular triangulation, tetrahedral pores, facet throats).
//
// One coupled step (DemPorenet3D::step), with the DemSystem's public stages:
//   update_neighbors(); compute_forces();
//   every N-th step (Porenet3DParams::flow_every; N = 1 by default), the rest of this list, the
//   forces then held for N steps:
//   retriangulate when the largest displacement since the last triangulation exceeds
//     `retriangulation_tolerance` x the mean radius (phase masses carried over by porenet's remap,
//     conserving each phase), else update the pore volumes and throats for the moved spheres: the new
//     void volumes drive the pressure (undrained compaction);
//   flow over the DEM steps since the last flow step (none at the first): implicit two-phase (one
//     backward-Euler step; default: stiff liquids need no sub-steps) or explicit with
//     n = ceil(dt / (safety dt_stable)) sub-steps, so that the fluid's clock is the DEM's at every
//     flow step (before 2026-11-30 the flow ran over the N steps to come, ahead of the DEM, and the
//     held steps' prediction counted that outflow a second time);
//   add_external_loads(); grain forces from the gauge pressure p - p_ambient (pressure integrated over
//     each sphere's patches inside its tetrahedra, porenet::add_pressure_forces_3d); integrate().
// Pressure prediction in the held steps (Porenet3DParams::predict_pressures; on where the fluid's
// stiffness would bound N, i.e. liquid-full samples): each held step advances the pressure changes dp
// since the flow step by the flow's own backward-Euler step over one DEM step, linearised at the flow
// step: (C + dt L) dp_m = C dp_{m-1} - (V_m - V_{m-1}) - dt q, with V_m - V_0 = sum_k g_ik . (x_k - x_k0)
// (g = void_gradient), C_i = V_i / K_i (K the mixture's modulus), L the channels' mobility Laplacian
// and q the net outflow at the flow step's pressures; pores at a prescribed pressure keep dp = 0. The
// system is solved approximately by multigrid V-cycles (porenet::Amg without over-interpolation: a
// convergent stationary iteration) from dp_{m-1}; the grain forces grow by sum_i dp_i a_ij. One-level
// (Jacobi) sweeps were tried and dropped: clusters of tiny, strongly connected pores (dt sum W / C ~
// 400) kept 70 % of the change unresolved, and the force jumps at the flow steps excited the saturated
// 3D example; undrained increments (dp = -dV / C) were as bad. The flow step (every scale of drainage,
// the nonlinear equation of state) corrects the pressures every N steps. So a held force is no longer
// an explicit spring and N may reach max_flow_every: the saturated 3D sample strides 20 steps instead
// of 1 (docs/saturated.md gives accuracy and speed).
// Channel shear (Porenet3DParams::channel_shear): A_f (P_a - P_b) per throat on its three spheres.
// Results are bit-identical on any thread count.
// Cracks in 3D: a broken bond's spheres move apart, the facets they share grow in fluid area and
// hydraulic radius (update_network_3d each step), and each of those throats gains the cubic-law
// conductance of the bond's opening (Porenet3DParams::crack_channels). Staged use (drivers with their own step
// order, e.g. coupling/hydrofrac/network_load.cpp): sync(), advance_flow(), compute_fluid_forces().
#pragma once
#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <utility>
#include <vector>

#include "coupling/porenet/pressure_force.hpp"
#include "dem/dem_system.hpp"
#include "io/checkpoint.hpp"
#include "porenet/network.hpp"
#include "porenet/pcg.hpp"
#include "porenet/remap.hpp"
#include "porenet/two_phase.hpp"

namespace ff::coupling {

struct Porenet3DParams {
  porenet::NetworkParams network;
  porenet::TwoPhaseParams fluid;
  Real pfv_factor = 1.0;        // throat conductance factor (Chareyre et al. 2012)
  Real initial_pressure = 1e5;  // [Pa]
  Real ambient_pressure = 1e5;  // outside the sample [Pa]; forces use p - ambient
  Real saturation = 1.0;        // initial liquid saturation, 0..1
  porenet::LiquidPlacement placement = porenet::LiquidPlacement::Uniform;  // where S < 1 puts the liquid
  Real retriangulation_tolerance = 0.25;  // x mean radius (cf. YADE defTolerance)
  porenet::RemapConserve remap = porenet::RemapConserve::Mass;  // what a retriangulation carries (remap.hpp)
  bool implicit = true;
  Real dt_safety = 0.9;       // explicit: flow sub-step <= safety x stable step
  long max_substeps = 100000;
  bool drained = false;       // true: hull pores held at the ambient pressure (saturation kept)
  // Sub-cycling (step()): one flow step (network update, flow over N dt_dem, pressure forces) every
  // N DEM steps, the forces held in between. N = flow_every; 0 = chosen from the fluid's stiffness
  // (fluid_stiffness, as costly as ~20 DEM steps of a 1000-sphere sample: again at the first flow step
  // after every `choose_every` DEM steps): N = floor(flow_safety min_j sqrt(m_j / k_j) / dt_dem),
  // 1 <= N <= max_flow_every (a held force is an explicit spring: stable while N dt <= ~0.3 of the
  // grain-fluid period, as the hydrofrac network's striding; gas-filled pores are soft, so partly
  // saturated samples stride far, liquid-full ones hardly). Within that bound N starts at 2 and
  // doubles after each flow step that needed no transport halving; one that needed s sub-steps
  // divides the next N by s (wide PFV throats: the phases' transport limit is below the DEM step
  // already, and a 20-fold implicit step exhausted the halvings: "phase masses (0, 0)").
  long flow_every = 1;
  // Auto N (flow_every = 0): a held cycle ends early, with a flow step. Without the prediction (soft,
  // gas-holding pores: N from the fluid's stiffness at the flow step) once a sphere has moved more than
  // hold_displacement x the mean radius since the last flow step: a pore whose gas is squeezed out
  // within the cycle stiffens past that bound unseen (the saturated 3D example at S 0.8: one pore at
  // 1.6 GPa in a crack burst, the held forces never pushing back). With the prediction once a pore's
  // void has changed by more than hold_strain of itself since the flow step (the prediction is linear
  // in it; water-full, the example's post-peak pores reached 132-364 MPa without it, 27 MPa with it,
  // 28 MPa with a flow step every DEM step). 0: never. Pre-peak neither ends a cycle early. (With
  // crack_channels a new crack ends it too, below.)
  Real hold_displacement = 0.01;
  Real hold_strain = 0.02;
  // Pressure prediction in the held steps (above), where the stiffness bound on N is below
  // max_flow_every (auto N) or for any fixed N > 1: N then up to max_flow_every (still divided by the
  // transport halvings). false: forces held as they are.
  bool predict_pressures = true;
  int predict_cycles = 2;  // V-cycles per held step (at least 1)
  Real flow_safety = 0.3;
  long max_flow_every = 20;
  long choose_every = 200;
  // Surface (the patches, PFV style; as before 2026-11-28) or the void's gradient (pressure_force.hpp).
  PressureForce pressure_force = PressureForce::Surface;
  // Channel shear on the grains (porenet::add_shear_forces_3d; 2D: B25, B28), added at each flow step
  // and held in between (the pressure prediction does not predict it). Off by default and not yet used
  // by the drivers: held, it is an explicit spring the DEM step does not include (the saturated 3D
  // example at S 0.5 went past the spinodal with it), and it halved the 3D hydrofrac block's breakdown
  // pressure (docs/porenet.md section 6).
  bool channel_shear = false;
  // The DEM's six axis-aligned plane walls (one per face of the sample's box: normals +-x, +-y, +-z) in
  // the triangulation as PFV's boundary spheres (porenet::BoxWalls): the pores between the outermost
  // spheres and the walls join the network, the walls take the pressure of their pores (added to
  // dem::Wall::force, what a servo reads), and the throats take PFV's hydraulic radius (permeability
  // within 0.8-1.0 of Kozeny-Carman; without walls the flat tetrahedra of the hull carry throats at the
  // conductance cap along the faces: docs/porenet.md section 9). With `drained` the pores on the walls
  // are the ones held at the ambient pressure. The pressure prediction does not see the walls move.
  bool walls = false;
  // Crack channels: each throat whose facet has a broken bond's two spheres among its corners (the DEM's
  // crack log) conducts a slit of the bond's opening w = |x_b - x_a| - R_a - R_b (> 0) as well:
  // g mu = w^3 r_b / (12 L) (the cubic law, METHODS 5.3b, over the half of the bond's disc, radius r_b,
  // that lies in the facet; L the throat's length), added to the facet's own conductance after its cap
  // and not scaled by pfv_factor: the crack's conductance is its opening's, not the matrix's (the 2D
  // network's broken-bond S2S channel). With the automatic N a new crack ends the held cycle (its
  // channel changes the flow the held forces were taken from). Off here and in the hydrofrac
  // (network.crack_channels: the 30,000-sphere example's CG cost), on in saturated_ucs
  // (fluid.crack_channels).
  bool crack_channels = false;
};

struct Porenet3DStats {
  long retriangulations = 0;
  long last_substeps = 0;
  Real max_displacement = 0;  // since the last triangulation [m]
  double t_triangulation = 0, t_update = 0, t_flow = 0, t_forces = 0;  // cumulative wall seconds
  long flow_every = 1;   // N of the current cycle
  long cycle_left = 0;   // DEM steps left before the next flow step
  long flow_steps = 0;   // flow steps so far
  long until_choice = 0;  // DEM steps before the stiffness bound is evaluated again (flow_every = 0)
  long stiffness_every = 1;  // N allowed by the fluid's stiffness (flow_every = 0)
  Real remap_liquid_change = 0;  // sum over retriangulations of new - old liquid mass [kg] (remap = pressure)
};

class DemPorenet3D {
 public:
  // Builds network and flow from the system's current state (3D, after sys.initialise()).
  void init(const dem::DemSystem& sys, const Porenet3DParams& params);
  void step(dem::DemSystem& sys);
  void run(dem::DemSystem& sys, long steps) {
    for (long s = 0; s < steps; ++s) step(sys);
  }

  const porenet::Network2D& network() const { return *net_; }
  porenet::TwoPhaseFlow& flow() { return *flow_; }
  const Porenet3DStats& stats() const { return stats_; }
  long early_flow_steps() const { return early_flow_steps_; }  // cycles ended by hold_displacement / hold_strain
  const Porenet3DParams& params() const { return prm_; }
  Real max_pressure() const;
  // Fluid force of the last step on particle k [N].
  Vec3 fluid_force(Index k) const { return {fx_[k], fy_[k], fz_[k]}; }
  // With walls: the fluid's force of the last flow step on box wall w (2 axis + side; side 1 the upper),
  // outward along the axis [N], and the DemSystem's index of that wall.
  Real wall_fluid_force(int w) const { return wall_force_[static_cast<std::size_t>(w)]; }
  int wall_index(int w) const { return wall_ids_[static_cast<std::size_t>(w)]; }
  // ... and that force over the wall's area between the other walls (at the last sync) [Pa].
  Real wall_fluid_pressure(int w) const {
    Real area = 1;
    for (std::size_t a = 0; a < 3; ++a)
      if (static_cast<int>(a) != w / 2) area *= box_.hi[a] - box_.lo[a];
    return wall_force_[static_cast<std::size_t>(w)] / area;
  }
  // Stiffness the pore fluid adds to each sphere [N/m], for the DEM's critical step (as
  // DemPorenetCoupling::fluid_stiffness in 2D): tetrahedron i pushes on sphere j with p_i a_ij
  // (a_ij = porenet::unit_patch_force_3d; with the void-gradient force a_ij = g_ij) and moving j by dx
  // changes V_i by g_ij.dx (void_gradient), so
  // pore i adds K_i a_ij g_ij^T / V_i to j's stiffness; k_j = sum_i K_i |a_ij| |g_ij| / V_i bounds its
  // largest eigenvalue. K_i the mixture's modulus; pores at a prescribed pressure add none; one at
  // the fraction floor (overlapping spheres, V = phi V_tet) phi of the tetrahedron's change. A pore held
  // at void_floor adds none (its void does not move now), or with open_floored as if it had just come
  // off it (the stiffest spring once it opens: what an explicit flow needs; the implicit flow evens a
  // small pore out with its neighbours within the step, and the saturated example's step 7.6e-8 s,
  // above even the instantaneous limit 6.3e-8 s, ran stable to 1.1 % strain, while open_floored gives
  // 1.1e-8 s: docs/saturated.md).
  std::vector<Real> fluid_stiffness(bool open_floored) const;
  // dV/dx_j [m^2] of the pore of sphere j's corner entry e (network().pp_pore[e]); a = its patch force
  // per unit pressure (porenet::unit_patch_force_3d); phi of the tetrahedron's at the fraction floor
  // (overlapping spheres: V = phi V_tet). floored = true: 0 at void_floor (the stored void does not
  // move); false: as if the pore had just come off it.
  Vec3 void_gradient(Index j, Index e, const Vec3& a, bool floored) const;
  // Sets every pore's pressure and saturation.
  void set_uniform_state(Real p, Real saturation);
  // Pressure (and saturation) at the pores whose centroid is within `radius` of `centre` (injection).
  std::vector<Index> pores_near(const Vec3& centre, Real radius) const;

  // Checkpoint sections (prefix "porenet3d."): triangulation positions, per-pore state, CG start.
  void save(CheckpointWriter& w) const;
  void load(CheckpointReader& r, const dem::DemSystem& sys, const Porenet3DParams& params);

  // The network to the system's current positions, retriangulating past the tolerance (true
  // then: on_network has run for the new network).
  bool sync(const dem::DemSystem& sys);
  // One flow step of dt (implicit, or explicit sub-steps).
  void advance_flow(Real dt);
  // Grain forces (fluid_force) from the current pressures clamped below at p_floor (absolute;
  // cavitation bounds the suction), not added to the system.
  void compute_fluid_forces(Real p_floor);

  // The held steps' pressure prediction (above) for staged use: start_prediction after a flow step's
  // compute_fluid_forces (dt_dem: the DEM step the held steps take), add_predicted_forces in each held
  // step (the forces that the predicted change of p, clamped below at p_floor as compute_fluid_forces
  // clamps p, adds to the held ones), stop_prediction for cycles without it.
  void start_prediction(Real dt_dem) {
    pred_dt_ = dt_dem;
    linearise_pressures();
  }
  void stop_prediction() { pred_g_.clear(); }
  bool predicting() const { return !pred_g_.empty(); }
  // Of stats().t_forces: this process's wall seconds in step()'s held-step predictions (not in the
  // checkpoint, whose stats keep their layout).
  double prediction_seconds() const { return t_predict_; }
  void add_predicted_forces(dem::DemSystem& sys, Real p_floor = -std::numeric_limits<Real>::infinity());

  // Called after every (re)build of the network, before the state is carried over: boundary conditions.
  std::function<void(porenet::TwoPhaseFlow&, const porenet::Network2D&)> on_network;

 private:
  void gather(const dem::DemSystem& sys);
  void make_network_and_flow(std::unique_ptr<porenet::Network2D>& net, std::unique_ptr<porenet::TwoPhaseFlow>& flow);
  void set_boundaries(porenet::TwoPhaseFlow& flow, const porenet::Network2D& net);
  void retriangulate();
  void add_crack_channels(const dem::DemSystem& sys);  // crack_channels: after every geometry update
  void flow_step(Real dt);
  void add_forces(dem::DemSystem& sys);
  void linearise_pressures();                       // pred_* at the flow step (predict_pressures)
  porenet::CsrView fill_prediction_matrix();        // pred_sys_'s values from pred_c_, pred_w_ (creates it)
  long choose_flow_every(const dem::DemSystem& sys) const;  // the stiffness bound on N (flow_every = 0)
  bool moved_past_hold(const dem::DemSystem& sys) const;     // hold_displacement exceeded since the flow step
  porenet::Particles3D view() const { return {x_, y_, z_, r_, {}}; }

  const porenet::BoxWalls* box() const { return prm_.walls ? &box_ : nullptr; }

  Porenet3DParams prm_;
  std::array<int, 6> wall_ids_{};             // walls: DemSystem wall of box wall w
  porenet::BoxWalls box_, ref_box_;           // walls: now and at the last triangulation
  std::array<Real, 6> wall_force_{};          // walls: fluid force, outward [N]
  std::vector<Index> id_index_;               // crack channels: particle index of each global id (-1: none)
  std::unique_ptr<porenet::Network2D> net_;
  std::unique_ptr<porenet::TwoPhaseFlow> flow_;
  // x_, y_, z_: the positions of the last sync (the flow step's; hold_displacement measures from them).
  std::vector<Real> x_, y_, z_, r_, ref_x_, ref_y_, ref_z_, fx_, fy_, fz_, pg_;
  long early_flow_steps_ = 0;  // cycles hold_displacement / hold_strain ended early (checkpointed)
  Real pred_strain_ = 0;       // the last held step's largest |V - V0| / V0 (checkpointed)
  double t_predict_ = 0;  // prediction_seconds()
  std::size_t cracks_at_flow_ = 0;  // the DEM's crack log's length at the last flow step (checkpointed)
  Real mean_radius_ = 0;
  Porenet3DStats stats_;
  // Pressure prediction (predict_pressures), fixed from one flow step to the next, checkpointed:
  std::vector<Real> pred_g_;   // 12 per pore (pore-major, by corner): dV_i/dx_k [m^2]
  std::vector<Real> pred_a_;   // 3 per corner entry (network().pp_*): force on the sphere per unit pressure [m^2]
  std::vector<Real> pred_x0_;  // 3 per sphere: positions at the flow step [m]
  std::vector<Real> pred_c_;   // per pore: storage V / K [m^3/Pa]; < 0: no change (prescribed, no modulus)
  std::vector<Real> pred_w_;   // per channel: mobility [m^3/(Pa s)]
  std::vector<Real> pred_q_;   // per pore: its net outflow at the flow step's pressures [m^3/s]
  std::vector<Real> pred_b_;   // per pore: -(V - V0) at the last held step [m^3]
  std::vector<Real> pred_dp_;  // per pore: the predicted p - p(flow step) [Pa]
  std::vector<Real> pred_v0_;  // per pore: its void at the flow step [m^3] (hold_strain)
  std::vector<Real> pred_tmp_, pred_rhs_, pred_z_;  // per pore, scratch
  std::unique_ptr<porenet::PressureSystem> pred_sys_;  // C + dt L of the held steps (pattern, values)
  // Its V-cycle, without over-interpolation: exact Galerkin coarse matrices and symmetric Gauss-Seidel
  // make the stationary iteration an A-norm contraction (with the factor 1.5, meant for CG, it diverged).
  porenet::Amg pred_amg_{porenet::AmgParams{.over_interp = 1.0}};
  Real pred_dt_ = 0;  // the DEM step of the prediction [s]
  long pred_geom_age_ = 0;  // DEM steps since pred_g_, pred_a_ were taken
  // The checkpointed per-pore/channel/entry arrays of the prediction (save and load).
  static constexpr std::pair<const char*, std::vector<Real> DemPorenet3D::*> kPredSections[] = {
      {"g", &DemPorenet3D::pred_g_}, {"a", &DemPorenet3D::pred_a_}, {"x0", &DemPorenet3D::pred_x0_},
      {"c", &DemPorenet3D::pred_c_}, {"w", &DemPorenet3D::pred_w_}, {"q", &DemPorenet3D::pred_q_},
      {"b", &DemPorenet3D::pred_b_}, {"dp", &DemPorenet3D::pred_dp_}, {"v0", &DemPorenet3D::pred_v0_}};
};

}  // namespace ff::coupling
