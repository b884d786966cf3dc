// The hydrofrac driver's scenario: its keys (declare_params) and the checks `check` and `run`
// make before anything is built (validate_scenario), with the two derived views both use: the
// block's geometry and the LBM fluid in SI.
#include "drivers/hydrofrac/hydrofrac_params.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "core/log.hpp"
#include "dem/dem_params.hpp"
#include "dem/sample_builder.hpp"
#include "drivers/common_params.hpp"
#include "drivers/flow/flow_runner.hpp"
#include "drivers/hydrofrac/dfn.hpp"
#include "coupling/hydrofrac/lbm_load.hpp"

// The fluid loads (LBM, pore network) and the borehole geometry live in src/coupling/hydrofrac/.
namespace ff::drivers::hydrofrac {
using namespace coupling::hydrofrac;
}

namespace ff::drivers::hydrofrac {

void declare_params(ParamTable& t) {
  dem::declare_dem_params(t);
  dem::declare_sample_params(t);
  hydrofrac::declare_dfn_params(t);
  t.real("borehole.radius", 3e-3, "m", "borehole radius: particles whose centres lie closer to the block's centre axis are removed")
      .positive();
  t.real("borehole.perforation_length", 0, "m", "length of each perforation slot beyond the wall (0: none)").non_negative();
  t.real("borehole.perforation_width", 0, "m", "width of the perforation slots (0: 2 sample.radius_max)").non_negative();
  t.real("borehole.perforation_azimuth", 0, "deg", "direction of the perforation from x (the sigma_H direction)")
      .range(-360, 360);
  t.integer("borehole.perforation_sides", 2, "-", "1: one slot; 2: two opposite slots").range(1, 2);
  t.real("insitu.sigma_H", 5e6, "Pa", "maximum horizontal stress, applied along x by servo walls (compression > 0)").positive();
  t.real("insitu.sigma_h", 5e6, "Pa", "minimum horizontal stress, along y").positive();
  t.real("insitu.sigma_v", 5e6, "Pa", "vertical stress along z (3D only)").positive();
  t.real("insitu.tolerance", 0.02, "-",
         "equilibrium before injection: every wall stress within this fraction of its target and the unbalanced-force "
         "ratio below it")
      .positive();
  t.integer("insitu.max_steps", 100000, "steps", "cap of the in-situ stage (a warning when equilibrium is not reached)").positive();
  t.real("insitu.servo_velocity", 0.5, "m/s", "speed cap of the wall servos").positive();
  t.real("insitu.servo_relaxation", 0.5, "-", "servo relaxation factor alpha (PFC default 0.8)").open_range(0, 1).at_most(1);
  t.string("injection.fluid", "sleeve",
           "fluid model: sleeve (pressure on the hole's wall particles, and on connected crack faces with penetration); "
           "lbm (lattice Boltzmann fluid over the block, keys fluid.*; docs/hydrofrac.md); network (pore-network flow from the "
           "hole into the rock and its cracks, keys network.*)")
      .one_of({"sleeve", "lbm", "network"});
  // The pore network (injection.fluid = "network"; coupling/hydrofrac/network_load.hpp).
  t.real("network.viscosity", 1e-3, "Pa s",
         "network: dynamic viscosity of the injected liquid; at most 1e12 Pa s (the glass transition's viscosity: "
         "beyond, no liquid)")
      .positive()
      .at_most(1e12);
  t.real("network.density", 1000, "kg/m^3",
         "network: liquid density at network.pore_pressure; at most 1e5 kg/m^3 (mercury: 13,546)")
      .positive()
      .at_most(1e5);
  t.real("network.pore_pressure", 1e5, "Pa",
         "network: the rock's initial (absolute) pore pressure, the zero of the reported pressure and of the grain "
         "forces; at most 1 GPa (five times the highest reservoir pore pressures; water at 20 C freezes near 0.9 GPa)")
      .positive()
      .at_most(1e9);
  t.real("network.vapour_pressure", 2.34e3, "Pa", "network: a pore pulled below it cavitates (held there, its liquid mass kept)")
      .non_negative();
  t.real("network.aperture_h0", 1e-6, "m", "network, 2D: contact/bond channel aperture at zero normal stress (Eq. B1 h0)").positive();
  t.real("network.aperture_hinf", 1e-7, "m", "network, 2D: contact/bond channel aperture at infinite normal stress (Eq. B1 h_inf)")
      .positive();
  t.real("network.b2_gamma", 0.02, "-",
         "network, 2D: factor of the geometric pore-to-pore aperture (Eq. B2; 1 = the free gap between the grains: a "
         "permeable packing; 0.02: a tight rock the fluid penetrates over a few grains during the ramp)")
      .positive()
      .at_most(1);
  t.real("network.throat_factor", 1e-7, "-",
         "network, 3D: factor on the throats' geometric (PFV) conductance: 1 = the packing's own throats, through which "
         "the whole block fills within a few DEM steps; 1e-7: a tight rock the fluid penetrates over a few grains")
      .positive();
  t.real("network.max_conductance_ratio", 100, "-",
         "network, 3D: throat conductance cap, x the median at a triangulation (cf. YADE's maxKdivKmean), for the "
         "outliers of flat tetrahedra; at least 1: below the median it would clip most throats to one value (a tighter "
         "rock: lower network.throat_factor)")
      .at_least(1);
  t.real("network.retriangulation_tolerance", 0.25, "-",
         "network: retriangulate when a particle moved this many mean radii since the last triangulation")
      .positive();
  t.string("network.remap", "mass",
           "network: what a retriangulation carries over: mass (each phase's mass; every pore's pressure then shifts by "
           "the bulk modulus x the relative change of the network's total void) or pressure (each pore's pressure; the "
           "mass change is reported in summary.json's network.mass_budget_kg.remap_change; docs/saturated.md)")
      .one_of({"mass", "pressure"});
  t.string("network.pressure_forces", "surface",
           "network: the pores' push on the grains: surface (2D: the pressure on each disc's arc in the pore, seed 004 "
           "B26-B27; 3D: on each sphere's patches) or void_gradient (p dV/dx: conservative; use it with "
           "network.faces = drained: with closed faces the block breaks at its faces, docs/hydrofrac.md)")
      .one_of({"surface", "void_gradient"});
  t.integer("network.flow_every", 0, "steps",
            "network: DEM steps per implicit flow step (0: from the fluid-grain stiffness, see docs/hydrofrac.md)")
      .non_negative();
  t.boolean("network.crack_channels", true,
            "network, 3D: each throat beside a broken bond conducts the cubic law of the bond's opening w as well, "
            "w^3 r_bond / (12 mu L), not scaled by network.throat_factor (the 2D network's cracks are channels of their "
            "own); false: a crack conducts only as its widened facets (the fluid barely enters the cracks; cheaper: "
            "the crack throats' conductance is 1e4-1e7 x the matrix's, docs/hydrofrac.md)");
  t.string("network.preconditioner", "auto",
           "network: preconditioner of the implicit flow's conjugate gradients: dic (block diagonal incomplete "
           "Cholesky), amg (3D: algebraic multigrid, porenet/amg.hpp; a few times fewer iterations than DIC with crack "
           "channels; its aggregates are checkpointed, so a resume stays bit-for-bit) or auto (amg in 3D, dic in 2D)")
      .one_of({"auto", "dic", "amg"});
  t.boolean("network.predict_pressures", true,
            "network, 3D: between flow steps advance the pore pressures every DEM step by the flow's implicit step "
            "linearised at the last flow step, so that the held forces follow the grains: where the fluid-grain "
            "stiffness would allow fewer than 20 DEM steps per flow step, 20 (or network.flow_every when set)");
  t.string("network.faces", "auto",
           "network: the pores on the block's faces (3D with network.walls: the pores on the walls; otherwise the hull "
           "and every pore within one largest radius of the outermost centres): drained (held at network.pore_pressure, "
           "the far field), closed (undrained) or auto (drained in 3D, closed in 2D). Closed 3D hulls without walls "
           "fail: the flat tetrahedra between grains pressed on a wall reach 0.1-1 GPa as the grains move and break "
           "bonds at the faces (docs/hydrofrac.md)")
      .one_of({"auto", "drained", "closed"});
  t.string("network.walls", "auto",
           "network: on (3D only) puts the block's six servo walls in the triangulation (PFV's boundary spheres): the "
           "pores between the outermost grains and the walls join the network (drained faces: those pores held at "
           "network.pore_pressure instead of the hull and its band; closed: their pressure pushes the walls), and the "
           "throats take PFV's hydraulic radius (Kozeny-Carman within 0.8-1.0; docs/porenet.md section 2); off: the "
           "network ends at the hull of the grain centres; auto: on in 3D, off in 2D")
      .one_of({"auto", "on", "off"});
  t.boolean("network.vtk", true, "network: write the pores (vtk/pores_*.vtu: gauge pressure per pore) with the particle snapshots");
  // The lattice Boltzmann fluid (injection.fluid = "lbm"), SI units (coupling::FluidSpec).
  t.real("fluid.density", 1000, "kg/m^3", "lbm: fluid density").positive();
  t.real("fluid.viscosity", 1e-6, "m^2/s", "lbm: kinematic viscosity (set this or fluid.dynamic_viscosity)").positive();
  t.real("fluid.dynamic_viscosity", 0.0, "Pa s", "lbm: dynamic viscosity; replaces fluid.viscosity when > 0").non_negative();
  t.real("fluid.bulk_modulus", 0.0, "Pa",
         "lbm: effective bulk modulus K_eff = rho c_s^2, fixes the LBM step (set exactly one of fluid.bulk_modulus, "
         "fluid.sound_speed, fluid.time_step, fluid.tau; 0: not set)")
      .non_negative();
  t.real("fluid.sound_speed", 0.0, "m/s", "lbm: lattice sound speed c_s = dx / (sqrt(3) dt) (0: not set)").non_negative();
  t.real("fluid.time_step", 0.0, "s", "lbm: LBM step (0: not set)").non_negative();
  t.real("fluid.tau", 0.0, "-", "lbm: relaxation time, dt = (tau - 1/2) dx^2 / (3 nu) (0: not set)").non_negative();
  t.real("fluid.background_pressure", 0.0, "Pa",
         "lbm: pore pressure p0 outside the populations: p = p0 + K_eff (rho_lb - 1); at most 1 GPa (five times the "
         "highest reservoir pore pressures: beyond, p0 + K_eff (rho_lb - 1) loses the injection's pressure changes to "
         "round-off)")
      .non_negative()
      .at_most(1e9);
  t.real("fluid.dx", 0.0, "m", "lbm: lattice spacing (0: sample.radius_min / fluid.cells_per_radius)").non_negative();
  t.real("fluid.cells_per_radius", 1.5, "-", "lbm: cells per smallest particle radius when fluid.dx = 0 (seed 002: >= 1)")
      .positive();
  t.string("fluid.scheme", "interpolated",
           "lbm: particles in the fluid: interpolated (Bouzidi bounce-back, solid cells), stairwise (half-way "
           "bounce-back), psm (partially saturated cells: intact rock leaks, docs/coupling.md)")
      .one_of({"interpolated", "stairwise", "psm"});
  t.string("fluid.psm_weighting", "tau",
           "lbm, scheme psm: Noble & Torczynski's weighting of a partly covered cell, tau (B(eps, tau), their "
           "preferred one) or linear (B = eps: tighter throats; at tau 0.6 a sphere packing's permeability within "
           "-3..+32 % of Kozeny-Carman at 4 cells per radius, where tau gives +97..+181 %; docs/coupling.md)")
      .one_of({"tau", "linear"});
  t.boolean("fluid.moving_walls", false,
            "lbm: the particles' velocities enter the fluid's wall condition (false: quasi-static walls; true diverged "
            "on the test block, docs/hydrofrac.md)");
  t.string("fluid.faces", "closed",
           "lbm: the lattice's outer faces (the block's faces plus one cell): closed (bounce-back; fluid that reaches "
           "them pushes the servo walls, as on a lab cell's platens) or drained (held at the pore pressure p0: the far "
           "field of a borehole in a permeable formation; the fluid that seeps out leaves)")
      .one_of({"closed", "drained"});
  t.real("fluid.reference_velocity", 0.0, "m/s", "lbm: expected largest fluid speed, for the Mach check (0: no check)")
      .non_negative();
  t.real("fluid.pressure_range", 0.0, "Pa",
         "lbm: largest p - p0 expected, for the density-variation check (0: injection.max_pressure)")
      .non_negative();
  t.string("injection.mode", "ramp", "ramp: pressure rises at injection.ramp_rate; rate: pumped at injection.rate into a compressible borehole")
      .one_of({"ramp", "rate"});
  t.real("injection.ramp_rate", 1e10, "Pa/s", "pressure rise rate (ramp mode)").positive();
  t.real("injection.initial_pressure", 0, "Pa", "borehole pressure when injection starts").non_negative();
  t.real("injection.rate", 1e-3, "m^3/s", "pumped volume rate (rate mode; 2D: per metre of thickness)").positive();
  t.string("injection.lbm_source", "mass",
           "rate mode with the LBM fluid: how the pumped fluid enters: mass (a source spread over the hole's cells, "
           "the rate exact) or velocity_box (seed 003 Sec. 4.1: a square box of half the hole's radius on its axis "
           "whose cells carry the outward velocity that pumps the rate; docs/hydrofrac.md)")
      .one_of({"mass", "velocity_box"});
  t.real("injection.fluid_bulk_modulus", 2.2e9, "Pa",
         "sleeve and network: fluid bulk modulus K_f (water 2.2e9; at most 1e12, stiffer than diamond): dp/dt = K_f/V "
         "(Q - dV/dt) (the LBM fluid's: fluid.bulk_modulus)")
      .positive()
      .at_most(1e12);
  t.boolean("injection.penetration", false,
            "sleeve: fluid enters cracks connected to the hole (pressure on their faces); false: sleeve test, the wall only");
  t.integer("injection.update_interval", 20, "steps", "sleeve: steps between searches for cracks newly connected to the hole")
      .positive();
  t.real("injection.breakdown_length", 0, "m",
         "ramp mode: breakdown = pressure when the connected fracture first reaches this far beyond the hole's wall (0: one "
         "borehole radius)")
      .non_negative();
  t.real("injection.peak_drop", 0.05, "-",
         "rate mode: breakdown = the first pressure peak followed by a drop of this fraction once a crack has reached "
         "the hole")
      .open_range(0, 1);
  t.real("injection.stop_fraction", 0.5, "-", "rate mode: stop when the pressure fell below this fraction of its peak").open_range(0, 1);
  t.real("injection.stop_extent", 0.8, "-",
         "stop when the connected fracture reaches this fraction of the distance from the hole's wall to the nearest block face")
      .open_range(0, 1)
      .at_most(1);
  t.real("injection.max_pressure", 500e6, "Pa", "stop at this borehole pressure in any case").positive();
  t.real("injection.max_time", 0.05, "s", "stop after this injection time in any case").positive();
  t.real_list("measure.radii", {1.8, 2.5, 3.5}, "-",
              "distances of the measurement circles (spheres) from the hole's axis, in borehole radii (Kirsch comparison)")
      .positive();
  t.real_list("measure.angles", {0, 45, 90}, "deg", "azimuths of the measurement circles from x (sigma_H)")
      .range(-360, 360);
  t.real("measure.circle_radius", 0.4, "-", "radius of each measurement circle (sphere), in borehole radii").positive();
  t.real("measure.pressure", 0, "Pa",
         "a second elastic-state snapshot when the borehole pressure first reaches this (0: only the in-situ snapshot)")
      .non_negative();
  declare_series_interval(t, "hydrofrac", " (and stage checks)");
  t.integer("hydrofrac.vtk_interval", 0, "steps",
            "steps between VTK snapshots during injection (0: at the start of injection, at breakdown and at the end)")
      .non_negative();
  t.integer("hydrofrac.checkpoint_interval", 0, "steps",
            "steps between extra checkpoints (0: by wall clock only, output.checkpoint_wall_interval, and at the end)")
      .non_negative();
}

Block block_of(const Config& cfg) {
  Block b;
  const int dim = static_cast<int>(cfg.integer("dem.dim"));
  b.lx = cfg.real("sample.width");
  b.ly = dim == 3 ? cfg.real("sample.depth") : cfg.real("sample.height");
  b.lz = dim == 3 ? cfg.real("sample.height") : 0;
  b.centre = Vec3(0.5 * b.lx, 0.5 * b.ly, 0);
  return b;
}

// The fluid of injection.fluid = "lbm" (keys fluid.*), in SI.
coupling::FluidSpec lbm_fluid_spec(const Config& cfg) {
  coupling::FluidSpec f;
  f.density = cfg.real("fluid.density");
  f.viscosity = cfg.real("fluid.viscosity");
  f.dynamic_viscosity = cfg.real("fluid.dynamic_viscosity");
  f.dx = cfg.real("fluid.dx") > 0 ? cfg.real("fluid.dx") : cfg.real("sample.radius_min") / cfg.real("fluid.cells_per_radius");
  f.dx_key = "fluid.dx (when 0: sample.radius_min / fluid.cells_per_radius)";
  f.bulk_modulus = cfg.real("fluid.bulk_modulus");
  f.sound_speed = cfg.real("fluid.sound_speed");
  f.time_step = cfg.real("fluid.time_step");
  f.tau = cfg.real("fluid.tau");
  f.background_pressure = cfg.real("fluid.background_pressure");
  f.reference_velocity = cfg.real("fluid.reference_velocity");
  f.pressure_range = cfg.real("fluid.pressure_range") > 0 ? cfg.real("fluid.pressure_range") : cfg.real("injection.max_pressure");
  return f;
}

void validate_scenario(const Config& cfg) {
  dem::validate_dem_sample(cfg);
  // x is the sigma_H direction by name: swapped stresses still run (the fracture is then expected along
  // y), but the reported azimuths "from sigma_H" are from x.
  if (cfg.real("insitu.sigma_H") < cfg.real("insitu.sigma_h"))
    log::warn("insitu.sigma_H = {} Pa is below insitu.sigma_h = {} Pa: sigma_H acts along x, so the fracture should "
              "run along y (azimuths are reported from x); swap them to keep the names",
              cfg.real("insitu.sigma_H"), cfg.real("insitu.sigma_h"));
  for (const char* key : {"insitu.sigma_H", "insitu.sigma_h", "insitu.sigma_v"})
    if (cfg.integer("dem.dim") == 3 || std::string(key) != "insitu.sigma_v") dem::refuse_crushing_stress(cfg, key);
  if (cfg.string("sample.shape") != "box")
    cfg.fail("sample.shape", "the hydrofrac block is a box: shape = \"box\" (2D rectangle in x-y; 3D box with the borehole along z)");
  if (cfg.string("injection.fluid") == "network" &&
      !(cfg.real("network.vapour_pressure") < cfg.real("network.pore_pressure")))
    cfg.fail("network.vapour_pressure",
             fmt::format("{} Pa is not below network.pore_pressure = {} Pa: every pore would start cavitated (water at "
                         "20 C: 2.34e3 Pa; 0 lets the liquid take any tension)",
                         cfg.real("network.vapour_pressure"), cfg.real("network.pore_pressure")));
  if (cfg.string("injection.fluid") == "network" && cfg.integer("dem.dim") == 2)
    refuse_widening_aperture(cfg, "network");
  if (!(cfg.real("injection.initial_pressure") < cfg.real("injection.max_pressure")))
    cfg.fail("injection.initial_pressure",
             fmt::format("{} Pa is not below injection.max_pressure = {} Pa, where the run stops: lower it (or raise "
                         "injection.max_pressure)",
                         cfg.real("injection.initial_pressure"), cfg.real("injection.max_pressure")));
  // A liquid far softer than any (water 2.2e9 Pa, oils ~1e9): a modulus in GPa where Pa are meant
  // (2.2) pressurises the hole by nothing at a pumped rate, and makes the injected volume of a
  // pressure ramp absurd, without a word.
  constexpr Real kSoftestLiquid = 1e7;
  if (cfg.string("injection.fluid") != "lbm" && cfg.real("injection.fluid_bulk_modulus") < kSoftestLiquid)
    log::warn("injection.fluid_bulk_modulus = {:.4g} Pa is far below any liquid's (water 2.2e9 Pa, oils ~1e9): pumped "
              "at a rate the hole's fluid hardly gains pressure, and a pressure ramp counts a huge injected volume (a "
              "modulus in GPa where Pa are meant?)",
              cfg.real("injection.fluid_bulk_modulus"));
  // The pressurised elastic-state snapshot is taken once the hole reaches measure.pressure: at or
  // above the stop it never was, and summary.json had no word of it (fuzzed, session 49).
  if (cfg.real("measure.pressure") > 0 && !(cfg.real("measure.pressure") < cfg.real("injection.max_pressure")))
    cfg.fail("measure.pressure",
             fmt::format("{} Pa is not below injection.max_pressure = {} Pa, where the run stops: the pressurised "
                         "elastic-state snapshot would never be taken; lower it (0: the in-situ snapshot only)",
                         cfg.real("measure.pressure"), cfg.real("injection.max_pressure")));
  if (cfg.string("network.walls") == "on" && cfg.integer("dem.dim") != 3)
    cfg.fail("network.walls", "walls in the network are 3D (PFV's boundary spheres): dem.dim = 3, or network.walls = "
                              "\"auto\" / \"off\"");
  if (cfg.string("network.preconditioner") == "amg" && cfg.integer("dem.dim") != 3)
    cfg.fail("network.preconditioner", "amg is offered in 3D (the 2D network's checkpoint does not hold the multigrid, "
                                       "so a resume would not be bit-for-bit): \"dic\"");
  if (cfg.string("injection.lbm_source") == "velocity_box" &&
      (cfg.string("injection.fluid") != "lbm" || cfg.string("injection.mode") != "rate"))
    cfg.fail("injection.lbm_source", "velocity_box is the LBM fluid's rate-mode source: it needs injection.fluid = \"lbm\" "
                                     "and injection.mode = \"rate\"");
  // The fluid's own checks (tau, Mach, density variation; the DEM step rounds dt_lbm later).
  if (cfg.string("injection.fluid") == "lbm") {
    const coupling::FluidScales sc = coupling::derive_scales(lbm_fluid_spec(cfg));
    if (cfg.string("injection.lbm_source") == "velocity_box") {
      // The box's side speed U: the rate over its perimeter (2D: per metre; 3D: the block's height);
      // its corners move at sqrt(2) U.
      const Real b = 0.5 * cfg.real("borehole.radius");
      const Real depth = cfg.integer("dem.dim") == 3 ? cfg.real("sample.height") : 1.0;
      const Real U = cfg.real("injection.rate") / (8 * b * depth);
      const Real mach = std::sqrt(2.0) * U / sc.sound_speed;
      if (mach > coupling::kWarnMach)
        cfg.fail("injection.rate", fmt::format("{} m^3/s through the injection box (half-side {} m) moves its corners at "
                                               "Mach {:.3g} (limit {}): lower the rate, raise fluid.bulk_modulus, or use "
                                               "injection.lbm_source = \"mass\"",
                                               cfg.real("injection.rate"), b, mach, coupling::kWarnMach));
    }
    // `fracflow check` prints the LBM and DEM steps from the set-up (HydrofracRun::run), which
    // builds the sample once; here only the fluid's own keys.
  }
  const Block b = block_of(cfg);
  const Real R = cfg.real("borehole.radius"), rmax = cfg.real("sample.radius_max");
  const Real lmin = std::min(b.lx, b.ly);
  if (R < 2 * rmax)
    cfg.fail("borehole.radius", fmt::format("{} m is below 2 sample.radius_max ({} m): the hole must be several grains wide", R, 2 * rmax));
  const Real reach = R + cfg.real("borehole.perforation_length");
  if (reach > 0.35 * lmin)
    cfg.fail(cfg.real("borehole.perforation_length") > 0 ? "borehole.perforation_length" : "borehole.radius",
             fmt::format("the hole and its perforations reach {} m from the axis; keep that below 0.35 x the block's smaller "
                         "side ({} m) so that the block is much larger than the hole",
                         reach, lmin));
  // A slot wider than the hole it starts from (2e9 m was taken): a cut through the block, not a
  // perforation.
  if (cfg.real("borehole.perforation_length") > 0 && cfg.real("borehole.perforation_width") > 2 * R)
    cfg.fail("borehole.perforation_width",
             fmt::format("{} m is wider than the hole (diameter {} m): a perforation is a slot narrower than the "
                         "borehole; 0 gives 2 sample.radius_max",
                         cfg.real("borehole.perforation_width"), 2 * R));
  // Ramp mode: a breakdown length the fracture cannot reach before the run stops at stop_extent of the
  // way to the faces left the breakdown pressure null for ever (1 m in a 38 mm block).
  // (Read in ramp mode alone, so that a breakdown length set in rate mode is named as unused.)
  if (cfg.string("injection.mode") == "ramp") {
    const Real gap = 0.5 * lmin - R, set = cfg.real("injection.breakdown_length"), bd = set > 0 ? set : R;
    if (bd >= cfg.real("injection.stop_extent") * gap)
      cfg.fail("injection.breakdown_length",
               fmt::format("{} m{} is not below injection.stop_extent x the distance from the hole's wall to the nearest "
                           "face ({} x {:.4g} m), where the run stops: the fracture could never reach it; use a shorter "
                           "injection.breakdown_length (or a larger block)",
                           bd, set > 0 ? "" : " (0: one borehole radius)", cfg.real("injection.stop_extent"), gap));
  }
  const Real rho = cfg.real("measure.circle_radius");
  for (double r : cfg.real_list("measure.radii")) {
    if ((r - rho) * R < R + rmax)
      cfg.fail("measure.radii", fmt::format("a circle at {} borehole radii with measure.circle_radius = {} reaches within "
                                            "sample.radius_max of the wall; use radii >= {:.3g}",
                                            r, rho, 1 + rho + rmax / R));
    if ((r + rho) * R > 0.5 * lmin)
      cfg.fail("measure.radii", fmt::format("a circle at {} borehole radii (circle radius {} radii) leaves the block's inner "
                                            "half-width {} m; use smaller radii",
                                            r, rho, 0.5 * lmin));
  }
  if (cfg.integer("dem.dim") == 3 && cfg.real("sample.height") < 4 * rmax)
    cfg.fail("sample.height", "the 3D block must be at least 4 sample.radius_max high");
  if (!cfg.string("dfn.file").empty() || cfg.integer("dfn.count") > 0) {
    const int dim = static_cast<int>(cfg.integer("dem.dim"));
    hydrofrac::make_joints(cfg, Vec3::Zero(), Vec3(b.lx, b.ly, b.lz), b.centre, R, dim);
  }
}

}  // namespace ff::drivers::hydrofrac
