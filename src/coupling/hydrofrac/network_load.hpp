// injection.fluid = "network": the fluid flows from the borehole into the rock through the pore
// network of issue 16 (porenet/: Delaunay triangles in 2D, regular-triangulation tetrahedra in
// 3D; coupling/porenet/dem_porenet*.hpp), so that the pressure reaches the grains wherever the
// fluid has gone: the hole's wall, the cracks it opened (2D: broken bonds are S2S channels whose
// aperture grows with the bond's opening, Eq. B1 + opening; 3D: the throats across an opening
// crack widen with the facet) and, more slowly, the intact rock's pores (penetration).
//
// The borehole is a set of pores: those whose centroid lies in the carved hole (or a perforation
// slot), and those whose corners are all hole-wall particles (slivers between the wall grains).
//  - ramp: the hole pores are held at p0 + p(t) (Dirichlet), p(t) = initial + ramp_rate t;
//    injected = the network's fluid mass gained / rho_ref;
//  - rate: each hole pore receives the mass rate rho_ref Q V_i / V_hole (a source): the hole's
//    pressure follows from its mass balance through its own volume and the fluid's compliance
//    (V / K), the outflow into the rock included; the reported pressure is the void-weighted
//    mean of the hole pores.
// Fluid: saturated, barotropic liquid p = p0 + K ln(rho / rho_ref) (K = injection.fluid_bulk_modulus),
// viscosity network.viscosity; p0 = network.pore_pressure the rock's initial pore pressure and the
// gauge zero: the reported pressure and the grain forces use p - p0, and the in-situ stresses
// are effective stresses. A pore below the vapour pressure cavitates: it is held there, keeping
// its liquid mass (the rest of its void is vapour).
//
// Time stepping: one implicit (backward-Euler) flow step of N DEM steps; the grain forces of a
// flow step are held over the next N DEM steps. N is set by the fluid-grain stiffness: a grain
// of mass m facing a pore of void V sees the spring k = K A^2 / V (A its face: 2 r t in 2D,
// pi r^2 in 3D), and a spring sampled every N dt stays stable and accurate while N dt is a
// fraction of sqrt(m / k) (the median over the rock's pores); network.flow_every overrides. In 3D
// the held steps may predict the pressures instead (network.predict_pressures: each DEM step advances
// them by the flow's implicit step linearised at the flow step, coupling/porenet/dem_porenet3d.hpp),
// so that a water-filled network strides 20 DEM steps where the stiffness allowed 1.
// Units: SI; 2D per metre of thickness (network depth t = 1 m).
#pragma once
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "coupling/hydrofrac/borehole.hpp"
#include "coupling/hydrofrac/fluid_load.hpp"
#include "porenet/network.hpp"
#include "coupling/porenet/pressure_force.hpp"
#include "porenet/remap.hpp"

namespace ff::coupling {
class DemPorenetCoupling;
class DemPorenet3D;
}  // namespace ff::coupling

namespace ff::porenet {
class TwoPhaseFlow;
}

namespace ff::coupling::hydrofrac {

struct NetworkSettings {
  bool rate_mode = false;
  Real ramp_rate = 0;         // [Pa/s]
  Real initial_pressure = 0;  // borehole gauge pressure at the start [Pa]
  Real flow_rate = 0;         // Q [m^3/s] at rho_ref (2D: per metre)
  Real bulk_modulus = 2.2e9;  // K [Pa]
  Real density = 1000;        // rho_ref at p0 [kg/m^3]
  Real viscosity = 1e-3;      // [Pa s]
  Real pore_pressure = 1e5;   // p0 [Pa] (absolute)
  Real vapour_pressure = 2.34e3;  // [Pa]
  porenet::NetworkParams network;  // apertures (B1, B2), floors; thickness 1 m
  Real pfv_factor = 1.0;           // 3D throat conductance factor
  Real retriangulation_tolerance = 0.25;  // x mean radius
  // What a retriangulation carries over (porenet/remap.hpp): each phase's mass (the pressures then
  // shift by K x the change of the network's total void) or the pores' pressures (the mass change
  // reported: NetworkBudget::remap_change).
  porenet::RemapConserve remap = porenet::RemapConserve::Mass;
  // The pores' push on the grains: the surface (2D: arcs, B26-B27; 3D: patches) or the gradient of
  // the pores' void (conservative: coupling/porenet/pressure_force.hpp).
  coupling::PressureForce pressure_force = coupling::PressureForce::Surface;
  bool shear_forces = true;               // 2D: channel shear B25/B28
  bool drained_faces = true;              // network.faces = "drained": hull pores held at p0
  bool walls = false;                     // 3D: the six walls in the triangulation (Porenet3DParams::walls)
  bool crack_channels = false;            // 3D: Porenet3DParams::crack_channels
  bool amg = false;                       // the implicit flow's CG preconditioned by AMG (else DIC)
  long flow_every = 0;                    // DEM steps per flow step; 0: from the fluid-grain stiffness
  Real flow_safety = 0.3;                 // N dt <= safety x sqrt(m / k) (median)
  long max_flow_every = 100;
  // 3D: the held steps predict the pore pressures (coupling::Porenet3DParams::predict_pressures) where
  // the stiffness bound gives N < predict_every; N is then predict_every (or flow_every when set).
  bool predict_pressures = true;
  long predict_every = 20;
  Real cell = 0, inflate = 0, reach = 0;  // hole_surface (the wall particles)
};

// Reported at the start (log) and in summary.json.
struct NetworkInfo {
  int dim = 2;
  long pores = 0, channels = 0, hole_pores = 0, particles = 0;
  Real dt_dem = 0, dt_flow = 0;  // [s]
  long flow_every = 1;           // N
  Real dt_explicit = 0;          // the explicit scheme's stable step at the start [s]
  Real t_spring = 0;             // median sqrt(m / k) of the fluid-grain springs [s]
  Real hole_volume = 0;          // [m^3] (2D: per m)
  std::string describe() const;
};

struct NetworkBudget {
  Real injected_mass = 0;    // rate: integral of rho_ref Q dt; ramp: = the mass change [kg]
  Real pore_mass0 = 0, pore_mass = 0;  // fluid in all pores at the start and now [kg]
  Real remap_change = 0;     // mass the retriangulations added (network.remap = pressure; 0 with mass) [kg]
  Real residual = 0;         // (pore_mass - pore_mass0) - injected_mass - remap_change [kg]
  long flow_steps = 0, retriangulations = 0;
  int max_cg_iterations = 0, max_substeps = 0;
  long cavitations = 0;      // pore-steps that cavitated
  Real vapour_volume = 0;    // void not filled by liquid in cavitated pores, last flow step [m^3]
  double t_sync = 0, t_flow = 0, t_forces = 0;  // wall seconds of the network update, flow and forces
  double t_triangulation = 0;  // wall seconds of the updates that retriangulated, this process only
};

class NetworkLoad final : public FluidLoad {
 public:
  explicit NetworkLoad(NetworkSettings s, int dim);
  ~NetworkLoad() override;
  void begin(const dem::DemSystem& sys, const BoreholeGeometry& hole, const std::vector<JointPair>& joints) override;
  void add_forces(dem::DemSystem& sys) override;
  void advance(const dem::DemSystem& sys) override;
  FluidState state() const override;
  const std::vector<Index>& wall_particles() const override { return wall_; }
  // With network.walls: the gauge pressure of the wall pores on each face (what the servos add); else 0
  // (drained faces: the hull at p0).
  std::array<Real, 6> face_pressures() const override;
  void save(CheckpointWriter& w) const override;
  void load(CheckpointReader& r, const dem::DemSystem& sys) override;

  const NetworkInfo& info() const { return info_; }
  bool drained_faces() const { return s_.drained_faces; }
  bool walls() const { return s_.walls; }
  bool crack_channels() const { return c3_ != nullptr && s_.crack_channels; }  // 3D only (the 2D cracks are channels)
  bool amg() const { return s_.amg; }
  bool predicting() const { return predict_; }  // 3D: the held steps predict the pressures
  NetworkBudget budget() const;
  Real effective_radius() const { return st_.effective_radius; }
  const porenet::Network2D& network() const;
  const std::vector<Index>& hole_pores() const { return hole_pores_; }
  // The grain force of the last flow step on particle k [N] (2D: per metre).
  Vec3 fluid_force(Index k) const { return force_[static_cast<std::size_t>(k)]; }
  // Pores as cells over the particles (2D triangles, 3D tetrahedra) with the gauge pressure, the
  // void volume and a hole flag: an unstructured VTK file.
  void write_vtu(const std::filesystem::path& file, const dem::DemSystem& sys) const;

 private:
  double t_retriangulation_ = 0;  // this process's (not checkpointed)
  struct State {  // (trivially copyable: a checkpoint section)
    Real t0 = 0, t_last = 0, pressure = 0, volume = 0, injected_mass = 0, mass0 = 0, mass = 0, effective_radius = 0;
    long steps = 0, flow_steps = 0, wetted = 0, flow_every = 1;
    int max_cg = 0, max_sub = 0;
    double t_sync = 0, t_flow = 0, t_forces = 0;
    long retriangulations = 0, cavitations = 0;
    Real vapour_volume = 0;
    Real band_lo[3] = {0, 0, 0}, band_hi[3] = {0, 0, 0};  // 3D drained faces: pores outside are held at p0
  };
  porenet::TwoPhaseFlow& flow();
  const porenet::TwoPhaseFlow& flow() const;
  Real remap_change() const;  // liquid mass the retriangulations added so far [kg]
  void make_coupling();
  void find_hole_pores(const porenet::Network2D& net);
  void drain_faces(porenet::TwoPhaseFlow& f, const porenet::Network2D& net) const;
  void set_hole_bc(porenet::TwoPhaseFlow& f, const porenet::Network2D& net, Real time);
  void flow_step(const dem::DemSystem& sys);          // network_flow_step with the keys in its errors
  void network_flow_step(const dem::DemSystem& sys);
  void gather_forces();
  void measure(const dem::DemSystem& sys);
  void cavitate();
  Real total_mass();
  Real spring_time(const dem::DemSystem& sys) const;

  NetworkSettings s_;
  int dim_ = 2;
  Real rho_vapour_liquid_ = 0;  // liquid density at the vapour pressure
  std::vector<Real> cp_, ca_, cmq_, cmp_, crq_, crp_;  // cavitation scratch
  Real now_ = 0;  // time of the flow step in progress (the 3D on_network hook's p(t))
  bool predict_ = false;  // 3D: the held steps predict the pressures (NetworkSettings::predict_pressures)
  BoreholeGeometry hole_;
  State st_;
  NetworkInfo info_;
  std::vector<Index> wall_, hole_pores_;
  std::vector<char> is_wall_;
  std::vector<Vec3> force_;
  std::vector<Index> id_index_;
  std::vector<Real> scratch_;
  std::unique_ptr<coupling::DemPorenetCoupling> c2_;
  std::unique_ptr<coupling::DemPorenet3D> c3_;
};

}  // namespace ff::coupling::hydrofrac
