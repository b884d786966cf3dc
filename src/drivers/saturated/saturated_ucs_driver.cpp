// Uniaxial compression of a partially saturated bonded specimen (seed 004, Krzaczek, Tejchman &
// Nitka 2024): the UCS test (UcsRun: sample, platens, time step, gauge, curve, checkpoints) plus the
// pore fluid through UcsRun's hooks. 2D discs: seed 004's network (DemPorenetCoupling, explicit
// flow, contact channels, cavitation); 3D spheres: the PFV-style network of tetrahedral pores and
// facet throats (DemPorenet3D, implicit flow by default). Either one steps the DEM stages itself
// inside each time step. Extra series columns: the largest and the mean pore pressure, the liquid
// saturation, the retriangulations and the flow sub-steps.
#include "drivers/saturated/saturated_ucs_driver.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>

#include "core/log.hpp"
#include "coupling/porenet/dem_porenet.hpp"
#include "coupling/porenet/dem_porenet3d.hpp"
#include "drivers/common_params.hpp"
#include "dem/dem_params.hpp"
#include "dem/diagnostics.hpp"
#include "dem/sample_builder.hpp"
#include "drivers/ucs/ucs_driver.hpp"
#include "drivers/ucs/ucs_run.hpp"
#include "io/pvd.hpp"
#include "io/vtk.hpp"

namespace fs = std::filesystem;

namespace ff::drivers {

namespace {

void declare(ParamTable& t) {
  declare_ucs_params(t);
  t.real("fluid.saturation", 1.0, "-", "initial liquid saturation of the pores (0: dry, gas only; 1: liquid only)")
      .range(0, 1);
  t.string("fluid.liquid_placement", "uniform",
           "where a saturation below 1 puts the liquid: uniform (every pore holds that fraction) or "
           "smallest_pores_first (capillary equilibrium of a wetting liquid: the smallest pores full, the largest "
           "gas only; docs/saturated.md)")
      .one_of({"uniform", "smallest_pores_first"});
  t.real("fluid.liquid_viscosity", 1e-3, "Pa s",
         "dynamic viscosity of the liquid (water: 1e-3); at most 1e12 Pa s (the glass transition's viscosity: beyond, "
         "no liquid)")
      .positive()
      .at_most(1e12);
  t.real("fluid.gas_viscosity", 1.8e-5, "Pa s", "dynamic viscosity of the gas (air: 1.8e-5); at most 1 Pa s")
      .positive()
      .at_most(1.0);
  t.string("fluid.liquid_eos", "barotropic",
           "liquid equation of state: barotropic (constant bulk modulus) or peng_robinson (PR + Peneloux water, seed 004 "
           "B10-B22; ~3.3x stiffer than real water)")
      .one_of({"barotropic", "peng_robinson"});
  t.real("fluid.liquid_bulk_modulus", 2.2e9, "Pa",
         "bulk modulus of the barotropic liquid (water: 2.2e9; at most 1e12, stiffer than diamond)")
      .positive()
      .at_most(1e12);
  t.string("fluid.gas_eos", "ideal", "gas equation of state: ideal (air) or peng_robinson (PR air)")
      .one_of({"ideal", "peng_robinson"});
  t.real("fluid.initial_pressure", 1e5, "Pa",
         "initial pore pressure, also the ambient pressure outside; at most 1 GPa (water at 20 C freezes near 0.9 GPa)")
      .positive()
      .at_most(1e9);
  t.string("fluid.drainage", "sides",
           "pores held at the ambient pressure: sides (hull pores at the free lateral faces; platens impermeable) or "
           "closed (undrained sample)")
      .one_of({"sides", "closed"});
  t.real("fluid.aperture_h0", 1e-6, "m", "2D: Eq. B1 contact/bond channel aperture at zero normal stress").positive()
      .fallback();
  t.real("fluid.aperture_hinf", 1e-7, "m", "2D: Eq. B1 aperture at infinite normal stress").positive()
      .fallback();
  t.real("fluid.aperture_gamma", 0.01, "-",
         "2D: Eq. B2 reduction factor of pore-to-pore channel apertures (1: the free gap between the grains)")
      .positive()
      .at_most(1)
      .fallback();
  t.real("fluid.pfv_factor", 1.0, "-",
         "3D: factor on the PFV throat conductance A_f R_h^2 / (2 mu L) (Chareyre et al. 2012; < 1: tighter, "
         "concrete-like throats)")
      .positive()
      .fallback();
  t.string("fluid.flow_scheme", "auto",
           "time stepping of the pore flow: auto (2D explicit sub-steps, one implicit step past fluid.implicit_above "
           "of them; 3D implicit), explicit (2D: sub-steps only, the seed's scheme) or implicit (3D only: one "
           "backward-Euler step per DEM step)")
      .one_of({"auto", "explicit", "implicit"});
  t.integer("fluid.implicit_above", 4, "-",
            "2D, flow_scheme auto: a DEM step whose explicit flow would need more than this many sub-steps gets one "
            "implicit (backward-Euler pressure) step instead (0 = always explicit sub-steps)")
      .non_negative()
      .fallback();
  t.integer("fluid.flow_every", 0, "-",
            "3D: one flow step (network update, flow, pressure forces) every this many DEM steps, the forces held in "
            "between (1: every step); 0 = automatic: at most 20, doubling from 2 while the flow needs no transport "
            "halving, divided by its halvings otherwise, and, without fluid.predict_pressures, at most 0.3 of the "
            "stiffest grain-fluid period (re-evaluated every 200 DEM steps: saturated samples then hardly stride)")
      .non_negative()
      .fallback();
  t.real("fluid.hold_displacement", 0.01, "-",
         "3D, automatic fluid.flow_every, cycles without fluid.predict_pressures: a flow step comes early once a "
         "grain has moved this fraction of the mean radius since the last one (a pore whose gas the grains squeeze "
         "out within a held cycle stiffens past the bound the cycle was chosen by: one pore reached 1.6 GPa in a crack "
         "burst without it); 0 = never")
      .non_negative()
      .fallback();
  t.real("fluid.hold_strain", 0.02, "-",
         "3D, automatic fluid.flow_every, cycles with fluid.predict_pressures: a flow step comes early once a pore's "
         "void has changed by this fraction of itself since the last one (the prediction is linear in it: the water-full "
         "example reached 132-434 MPa in single pores after the peak without it, 27 MPa with it); 0 = never")
      .non_negative()
      .fallback();
  t.boolean("fluid.predict_pressures", true,
            "3D, between flow steps: advance the pore pressures every DEM step by the flow's implicit step linearised "
            "at the last flow step (multigrid V-cycles), so that the held forces follow the grains; on where the "
            "fluid's stiffness would bound fluid.flow_every (water-full samples) or when fluid.flow_every > 1 "
            "(false: the forces held as they are)")
      .fallback();
  t.boolean("fluid.crack_channels", true,
            "3D: each throat beside a broken bond conducts the cubic law of the bond's opening as well "
            "(coupling::Porenet3DParams::crack_channels; with the automatic fluid.flow_every a new crack ends the held "
            "cycle); false: a crack conducts only as its widened facets (the default before 2026-11-30)")
      .fallback();
  t.string("fluid.preconditioner", "dic",
           "3D implicit flow: preconditioner of the conjugate-gradient pressure solve: dic (block diagonal incomplete "
           "Cholesky) or amg (algebraic multigrid, porenet/amg.hpp: fewer iterations on large networks, but on the "
           "5,000-pore example its flow took 1.7x DIC's time at S 0.8; its aggregates are checkpointed, so a resume "
           "stays bit-for-bit)")
      .one_of({"dic", "amg"})
      .fallback();
  t.real("fluid.cg_tolerance", 1e-12, "-",
         "3D implicit flow: relative residual of the conjugate-gradient pressure solve (porenet; the phase masses stay "
         "conserved at any value, the channel fluxes being antisymmetric)")
      .open_range(0, 1)
      .fallback();
  t.real("fluid.min_void_relative", 0.05, "-",
         "floor of a pore's void volume as a fraction of the mean cell (slivers set the explicit flow step)")
      .open_range(0, 1);
  t.real("fluid.retriangulation_tolerance", 0.25, "-",
         "retriangulate when a particle has moved this fraction of the mean radius since the last triangulation")
      .positive();
  t.boolean("fluid.shear_forces", true, "2D: add the channel shear forces (B25, B28) to the pressure forces (B26-B27)")
      .fallback();
  t.real("fluid.cavitation_pressure", 2.34e3, "Pa",
         "2D: absolute pressure below which a pore's liquid cavitates (vapour fills the rest of its void at this "
         "pressure; water at 20 C: 2.34e3; otherwise at least 1e-3); 0 = the liquid takes any tension")
      .non_negative()
      .fallback();
  t.string("fluid.force_height", "auto",
           "2D: wetted height of a grain in B27/B28, to match the height its contacts and bonds act over: thickness (1 m "
           "discs: linear/parallel laws), diameter (the seed's 2 r_j: spheres in one layer, its cohesive law A1-A7), "
           "auto (diameter with dem.contact_law = cohesive, else thickness)")
      .one_of({"auto", "thickness", "diameter"})
      .fallback();
  t.string("fluid.pressure_forces", "auto",
           "how a pore's pressure pushes the grains at its corners: void_gradient (p dV/dx_j, the change of the pore's "
           "void as the grain moves: the fluid's work is sum p dV, a liquid-full pore a conservative spring), surface "
           "(the pressure over the grain's wetted surface in the pore: seed 004's B26-B27 arc in 2D, the spherical "
           "patches in 3D; not the gradient of the void, so a saturated specimen can flutter: docs/saturated.md), "
           "auto (void_gradient in 2D, surface in 3D)")
      .one_of({"auto", "void_gradient", "surface"});
  t.string("fluid.remap", "pressure",
           "2D: what a retriangulation carries over to the new network: pressure (each new pore takes its nearest old "
           "pore's densities; the phases' masses change by the void model's dependence on the triangulation, reported "
           "in summary.json) or mass (each phase's total conserved to round-off, every pore's pressure then shifted by "
           "K x that relative change: 1.5-5.4 MPa with water in seed 004's specimen, docs/saturated.md)")
      .one_of({"pressure", "mass"})
      .fallback();
  t.boolean("fluid.stiffness_in_time_step", true,
            "the DEM's critical time step counts the stiffness the pore fluid adds to each grain (a liquid-full "
            "pore adds ~2 contact stiffnesses per face; false: contacts and bonds only, as before 2026-11-27)");
}

// Keys of one dimension only: set in the other, they are an error (not silently ignored). They are
// declared .fallback() so that the saved scenario of a run (read back by `fracflow resume`) leaves
// them unset unless the user set them.
const std::vector<std::string> k2DOnly = {"fluid.aperture_h0", "fluid.aperture_hinf", "fluid.aperture_gamma",
                                          "fluid.shear_forces", "fluid.cavitation_pressure", "fluid.force_height",
                                          "fluid.remap", "fluid.implicit_above"};
const std::vector<std::string> k3DOnly = {"fluid.pfv_factor", "fluid.cg_tolerance", "fluid.flow_every",
                                          "fluid.predict_pressures", "fluid.crack_channels", "fluid.hold_displacement",
                                          "fluid.hold_strain", "fluid.preconditioner"};

porenet::TwoPhaseParams fluid_params(const Config& cfg) {
  porenet::TwoPhaseParams f;
  const Real T = 293.15;
  f.liquid = cfg.string("fluid.liquid_eos") == "peng_robinson"
                 ? porenet::Eos::water_pr(T)
                 : porenet::Eos::barotropic(1000, cfg.real("fluid.initial_pressure"), cfg.real("fluid.liquid_bulk_modulus"));
  f.gas = cfg.string("fluid.gas_eos") == "peng_robinson" ? porenet::Eos::air_pr(T) : porenet::Eos::ideal_gas(T, 28.9586);
  f.mu_liquid = cfg.real("fluid.liquid_viscosity");
  f.mu_gas = cfg.real("fluid.gas_viscosity");
  return f;
}

porenet::LiquidPlacement liquid_placement(const Config& cfg) {
  return cfg.string("fluid.liquid_placement") == "smallest_pores_first" ? porenet::LiquidPlacement::SmallestPoresFirst
                                                                        : porenet::LiquidPlacement::Uniform;
}

// fluid.pressure_forces; auto: the void gradient in 2D, the surface (patches) in 3D.
coupling::PressureForce pressure_force(const Config& cfg, bool dim3) {
  const std::string& v = cfg.string("fluid.pressure_forces");
  if (v == "auto") return dim3 ? coupling::PressureForce::Surface : coupling::PressureForce::VoidGradient;
  return v == "surface" ? coupling::PressureForce::Surface : coupling::PressureForce::VoidGradient;
}

coupling::PorenetCouplingParams coupling_params(const Config& cfg) {
  coupling::PorenetCouplingParams p;
  p.fluid = fluid_params(cfg);
  p.initial_pressure = p.ambient_pressure = cfg.real("fluid.initial_pressure");
  p.saturation = cfg.real("fluid.saturation");
  p.placement = liquid_placement(cfg);
  p.drainage = cfg.string("fluid.drainage") == "closed" ? coupling::Drainage::Closed : coupling::Drainage::Sides;
  p.network.b1_h0 = cfg.real("fluid.aperture_h0");
  p.network.b1_h_inf = cfg.real("fluid.aperture_hinf");
  p.network.b2_gamma = cfg.real("fluid.aperture_gamma");
  p.network.min_void_relative = cfg.real("fluid.min_void_relative");
  p.retriangulation_tolerance = cfg.real("fluid.retriangulation_tolerance");
  p.shear_forces = cfg.boolean("fluid.shear_forces");
  p.cavitation_pressure = cfg.real("fluid.cavitation_pressure");
  const std::string& h = cfg.string("fluid.force_height");
  const bool diameter = h == "diameter" || (h == "auto" && cfg.string("dem.contact_law") == dem::CohesiveContact::name);
  p.force_height = diameter ? coupling::ForceHeight::Diameter : coupling::ForceHeight::Thickness;
  p.pressure_force = pressure_force(cfg, false);
  p.remap = cfg.string("fluid.remap") == "mass" ? porenet::RemapConserve::Mass : porenet::RemapConserve::Pressure;
  // flow_scheme = explicit: the seed's explicit sub-steps only.
  p.implicit_above = cfg.string("fluid.flow_scheme") == "explicit" ? 0 : cfg.integer("fluid.implicit_above");
  return p;
}

coupling::Porenet3DParams params_3d(const Config& cfg) {
  coupling::Porenet3DParams p;
  p.fluid = fluid_params(cfg);
  p.initial_pressure = p.ambient_pressure = cfg.real("fluid.initial_pressure");
  p.saturation = cfg.real("fluid.saturation");
  p.placement = liquid_placement(cfg);
  p.network.min_void_relative = cfg.real("fluid.min_void_relative");
  p.pfv_factor = cfg.real("fluid.pfv_factor");
  p.fluid.cg_tolerance = cfg.real("fluid.cg_tolerance");
  p.fluid.preconditioner =
      cfg.string("fluid.preconditioner") == "amg" ? porenet::Preconditioner::AMG : porenet::Preconditioner::DIC;
  p.retriangulation_tolerance = cfg.real("fluid.retriangulation_tolerance");
  p.implicit = cfg.string("fluid.flow_scheme") != "explicit";
  p.flow_every = cfg.integer("fluid.flow_every");
  p.predict_pressures = cfg.boolean("fluid.predict_pressures");
  p.hold_displacement = cfg.real("fluid.hold_displacement");
  p.hold_strain = cfg.real("fluid.hold_strain");
  p.crack_channels = cfg.boolean("fluid.crack_channels");
  p.drained = false;  // the lateral hull pores only: set by SaturatedUcsRun's on_network
  p.pressure_force = pressure_force(cfg, true);
  return p;
}

// Checkpointed with the UCS state (raw bytes: the layout is the format of "saturated.state").
struct SatExtra {
  Real max_pore_pressure = 0;  // largest pore pressure of any step [Pa]
  Real void0 = 0;              // the network's void volume at the start [m^3]
  Real liquid_mass0 = 0, gas_mass0 = 0;  // [kg] (2D: per m of depth)
  Real critical_dry = 0, critical_wet = 0;  // DEM critical step without / with the pore fluid [s]
};

// 3D, drained sides: the sample's extent along the loading axis at the start and its largest radius.
// Fixed for the run (every rebuild of the network drains the same band) and checkpointed: taken
// again from the positions at a resume, it would drain other pores than the uninterrupted run.
struct DrainBand {
  Real lo = 0, hi = 0, rmax = 0;  // [m]
};

}  // namespace
}  // namespace ff::drivers

namespace ff {
template <> struct is_checkpoint_pod<drivers::SatExtra> : std::true_type {};
template <> struct is_checkpoint_pod<drivers::DrainBand> : std::true_type {};
}  // namespace ff

namespace ff::drivers {
namespace {

// The pore fluid of either dimension: seed 004's 2D network or the 3D PFV network.
class PoreFluid {
 public:
  void init(dem::DemSystem& sys, const Config& cfg, const dem::SampleInfo& info) {
    dim3_ = info.dim == 3;
    if (dim3_) band_ = drain_band(sys, info.axis);
    setup(cfg, info);
    if (dim3_) {
      const auto prm = params_3d(cfg);
      // A fixed stride past the automatic one's cap: one flow step in a whole run at 1e6 (fuzzed 2026-11-30),
      // the held forces (and their linear prediction) carrying the fluid; cycles of a fixed N never end early.
      if (const long cap = coupling::Porenet3DParams{}.max_flow_every; prm.flow_every > cap)
        log::warn("fluid.flow_every = {} holds the pore forces (and, with fluid.predict_pressures, their linear "
                  "prediction) for {} DEM steps between flow steps, past the automatic stride's cap of {}, the range "
                  "checked against a flow step every DEM step; a fixed stride is never cut short (fluid.hold_strain, "
                  "fluid.hold_displacement and new cracks end only automatic cycles). 0 chooses it",
                  prm.flow_every, prm.flow_every, cap);
      c3_.init(sys, prm);
    } else {
      c2_.init(sys, coupling_params(cfg));
    }
    start_session();
  }
  void load(CheckpointReader& r, dem::DemSystem& sys, const Config& cfg, const dem::SampleInfo& info) {
    dim3_ = info.dim == 3;
    if (dim3_) band_ = r.get_value<DrainBand>("saturated.drain_band");
    setup(cfg, info);
    if (dim3_) c3_.load(r, sys, params_3d(cfg));
    else c2_.load(r, sys, coupling_params(cfg));
    start_session();
  }
  void save(CheckpointWriter& w) const {
    if (dim3_) {
      w.put_value("saturated.drain_band", band_);
      c3_.save(w);
    } else {
      c2_.save(w);
    }
  }
  void step(dem::DemSystem& sys) {
    try {
      if (dim3_) c3_.step(sys);
      else c2_.step(sys);
    } catch (const NumericalError& e) {  // the pore network's own words name no keys: add them
      throw NumericalError(fmt::format(
          "{}. The pore fluid's inputs to check: {}, fluid.liquid_viscosity and fluid.gas_viscosity (the flow's "
          "mobility), fluid.liquid_bulk_modulus (the liquid's stiffness), fluid.initial_pressure{}",
          e.what(),
          dim3_ ? "fluid.pfv_factor (the throats' conductance)"
                : "fluid.aperture_h0, fluid.aperture_hinf and fluid.aperture_gamma (the channels' conductance)",
          dim3_ ? ", fluid.hold_displacement, fluid.hold_strain, fluid.cg_tolerance"
                : ", fluid.cavitation_pressure, fluid.implicit_above"));
    }
  }
  bool dim3() const { return dim3_; }
  const porenet::Network2D& network() const { return dim3_ ? c3_.network() : c2_.network(); }
  porenet::TwoPhaseFlow& flow() { return dim3_ ? c3_.flow() : c2_.flow(); }
  Real max_pressure() const { return dim3_ ? c3_.max_pressure() : c2_.max_pressure(); }
  long retriangulations() const { return dim3_ ? c3_.stats().retriangulations : c2_.stats().retriangulations; }
  // Network builds and remaps (3D: with the first build): wall seconds over the run (3D, checkpointed) or
  // this process (2D); and their share of this process's wall time since the fluid was set up.
  double triangulation_seconds() const { return dim3_ ? c3_.stats().t_triangulation : c2_.triangulation_seconds(); }
  double triangulation_share() const {
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - session_start_).count();
    return wall > 0 ? (triangulation_seconds() - session_tri0_) / wall : 0.0;
  }
  long substeps() const { return dim3_ ? c3_.stats().last_substeps : c2_.stats().last_substeps; }
  long flow_every() const { return dim3_ ? c3_.stats().flow_every : 1; }  // DEM steps per flow step
  const coupling::DemPorenetCoupling& c2() const { return c2_; }
  const coupling::DemPorenet3D& c3() const { return c3_; }
  Index drained_pores() const { return drained_; }

  // Void-weighted mean pressure [Pa] and the total void volume [m^3 (2D: per m of depth x t)].
  void mean_pressure(Real& p_mean, Real& void_volume) {
    const auto& net = network();
    const auto p = flow().pressure();
    Real pv = 0, v = 0;
    for (Index i = 0; i < net.n_pores(); ++i) {
      pv += p[i] * net.pore_void[i];
      v += net.pore_void[i];
    }
    p_mean = pv / v;
    void_volume = v;
  }

 private:
  static DrainBand drain_band(const dem::DemSystem& sys, int axis) {
    DrainBand b{std::numeric_limits<Real>::infinity(), -std::numeric_limits<Real>::infinity(), 0};
    for (std::size_t k = 0; k < sys.particles.size(); ++k) {
      b.rmax = std::max(b.rmax, sys.particles.radius[k]);
      b.lo = std::min(b.lo, sys.particles.pos[k][axis]);
      b.hi = std::max(b.hi, sys.particles.pos[k][axis]);
    }
    return b;
  }
  void setup(const Config& cfg, const dem::SampleInfo& info) {
    if (!dim3_) return;
    // Sides drained: hull pores whose centroid is more than two max radii from both ends of the
    // sample along the loading axis (the platens are impermeable), at every (re)build.
    if (cfg.string("fluid.drainage") != "sides") return;
    const Real p_out = cfg.real("fluid.initial_pressure"), s_out = cfg.real("fluid.saturation");
    const int axis = info.axis;
    const DrainBand b = band_;
    c3_.on_network = [this, b, p_out, s_out, axis](porenet::TwoPhaseFlow& f, const porenet::Network2D& net) {
      drained_ = 0;
      for (Index i = 0; i < net.n_pores(); ++i) {
        if (!net.pore_hull[i]) continue;
        const Real c = axis == 0 ? net.pore_cx[i] : axis == 1 ? net.pore_cy[i] : net.pore_cz[i];
        if (c - b.lo < 2 * b.rmax || b.hi - c < 2 * b.rmax) continue;
        f.set_bc(i, porenet::PoreBc::Pressure, p_out, s_out);
        ++drained_;
      }
    };
  }

  bool dim3_ = false;
  std::chrono::steady_clock::time_point session_start_{};
  double session_tri0_ = 0;
  void start_session() {
    session_start_ = std::chrono::steady_clock::now();
    session_tri0_ = triangulation_seconds();
  }
  DrainBand band_;
  Index drained_ = 0;
  coupling::DemPorenetCoupling c2_;
  coupling::DemPorenet3D c3_;
};

class SaturatedUcsRun final : public UcsRun {
 public:
  using UcsRun::UcsRun;

 private:
  void after_set_up() override {
    fluid_.init(sys, cfg, info);
    include_fluid_stiffness();
    const auto& net = fluid_.network();
    if (fluid_.dim3())
      log::info("pore network (3D): {} pores, {} throats, {} drained; DEM step {:.3g} s, {} flow", net.n_pores(),
                net.n_channels(), fluid_.drained_pores(), sys.settings.dt,
                fluid_.c3().params().implicit ? "implicit" : "explicit");
    else {
      // Pores whose void is a floor push no grain (porenet/forces.cpp): say how many there are.
      Index at_relative = 0, at_fraction = 0;
      for (Index k = 0; k < net.n_pores(); ++k) {
        const porenet::VoidFloor f = porenet::void_floor_of(net, k);
        at_relative += f == porenet::VoidFloor::Relative;
        at_fraction += f == porenet::VoidFloor::Fraction;
      }
      const Real stable = fluid_.flow().stable_dt();
      log::info("pore network: {} pores, {} channels ({} pairs); DEM step {:.3g} s, flow stable step {:.3g} s; {} pores "
                "at the void floor (fluid.min_void_relative x the mean cell), {} at {} of their triangle (overlapping "
                "discs)",
                net.n_pores(), net.n_channels(), fluid_.c2().pairs().size(), sys.settings.dt, stable, at_relative,
                at_fraction, net.params.min_void_fraction);
      // Known here, before anything is written: `check` passed fluid.aperture_h0 = 1e300 and the run
      // then stopped at its first step (fuzzed, session 49).
      if (!(stable > 0))
        throw InputError(fmt::format(
            "{}: the pore network's flow allows no time step (its stable step is {} s: a channel's conductance, ~h^3 / "
            "mu, is infinite or not a number); check fluid.aperture_h0, fluid.aperture_hinf and fluid.aperture_gamma "
            "(the channels' apertures, micrometres: 1e-6 m) and fluid.liquid_viscosity and fluid.gas_viscosity",
            cfg.scenario_name(), stable));
    }
    Real p;
    fluid_.mean_pressure(p, ex_.void0);
    ex_.liquid_mass0 = fluid_.flow().total_liquid_mass();
    ex_.gas_mass0 = fluid_.flow().total_gas_mass();
  }
  // The pore water pushes each grain back like a spring (DemPorenetCoupling::fluid_stiffness), on
  // top of its contacts and bonds: the DEM step is chosen again with it, as dem::choose_time_step
  // chose it without (same keys, same rules), from the fluid's state at the start (S = 1: every
  // pore liquid-stiff, the stiffest it gets; a gas cushion stiffens only as it is squeezed).
  void include_fluid_stiffness() {
    ex_.critical_dry = dem::critical_time_step(sys);
    const auto k =
        fluid_.dim3() ? fluid_.c3().fluid_stiffness(!fluid_.c3().params().implicit) : fluid_.c2().fluid_stiffness();
    ex_.critical_wet = dem::critical_time_step(sys, k);
    const bool use = cfg.boolean("fluid.stiffness_in_time_step");
    log::info("critical DEM step {:.4g} s with the pore fluid's stiffness ({:.4g} s without){}", ex_.critical_wet,
              ex_.critical_dry, use ? "" : ": not used (fluid.stiffness_in_time_step = false)");
    if (use) dem::choose_time_step(cfg, sys, k);
  }
  void dem_step() override { fluid_.step(sys); }
  std::string instability_advice() const override {
    return fmt::format(
        "The pore fluid pushes the grains too (largest pore pressure so far {:.4g} Pa): check "
        "fluid.initial_pressure and fluid.liquid_bulk_modulus, keep fluid.stiffness_in_time_step = true{}",
        ex_.max_pore_pressure, fluid_.dim3() ? ", lower fluid.hold_displacement and fluid.hold_strain" : "");
  }
  void after_step() override {
    const Real pm = fluid_.max_pressure();
    if (pm > ex_.max_pore_pressure) ex_.max_pore_pressure = pm;
  }
  void extra_columns(std::vector<std::string>& c) const override {
    for (const char* k : {"max_pore_pressure_Pa", "mean_pore_pressure_Pa", "saturation", "retriangulations",
                          "flow_substeps", "flow_every"})
      c.emplace_back(k);
  }
  void extra_row(const CompressionState& m) override {
    Real pmean, v;
    fluid_.mean_pressure(pmean, v);
    for (const double x : {fluid_.max_pressure(), pmean, fluid_.flow().saturation(),
                           static_cast<double>(fluid_.retriangulations()), static_cast<double>(fluid_.substeps()),
                           static_cast<double>(fluid_.flow_every())})
      row.push_back(x);
    if (m.axial_stress >= ucs_state().peak_stress) write_pores("pores_at_peak.csv");
    fmt::format_to(std::back_inserter(status), "  p_max {:.4g} MPa", 1e-6 * fluid_.max_pressure());
  }
  void save_extra(CheckpointWriter& w) const override {
    w.put_value("saturated.state", ex_);
    fluid_.save(w);
  }
  void load_extra(CheckpointReader& r) override {
    ex_ = r.get_value<SatExtra>("saturated.state");
    fluid_.load(r, sys, cfg, info);
    resume_time_ = sys.time;
  }

  // The pore field for pictures. 2D: triangle corners; 3D: tetrahedron centroid and void.
  void write_pores(const std::string& name) {
    const auto& net = fluid_.network();
    const auto p = fluid_.flow().pressure();
    const auto a = fluid_.flow().liquid_fraction();
    std::ofstream f(opt.out_dir / name);
    if (fluid_.dim3()) {
      f << "x_m,y_m,z_m,void_m3,hull,pressure_Pa,liquid_fraction\n";
      for (Index i = 0; i < net.n_pores(); ++i)
        f << fmt::format("{:.9g},{:.9g},{:.9g},{:.6g},{},{:.9g},{:.6g}\n", net.pore_cx[i], net.pore_cy[i],
                         net.pore_cz[i], net.pore_void[i], int(net.pore_hull[i]), p[i], a[i]);
      return;
    }
    f << "x0_m,y0_m,x1_m,y1_m,x2_m,y2_m,pressure_Pa,liquid_fraction\n";
    for (Index i = 0; i < net.n_pores(); ++i) {
      for (int k = 0; k < 3; ++k) {
        const auto& q = sys.particles.pos[static_cast<std::size_t>(net.pore_v[3 * i + k])];
        f << fmt::format("{:.9g},{:.9g},", q.x(), q.y());
      }
      f << fmt::format("{:.9g},{:.6g}\n", p[i], a[i]);
    }
  }

  // vtk/pores_INDEX.vtp beside the particles: 2D the triangles (cells), 3D the tetrahedra's
  // centroids (vertices), with pressure, liquid fraction and void volume.
  void extra_vtk(long index) override {
    const fs::path dir = opt.out_dir / "vtk";
    if (!pvd_.is_open()) pvd_.open(dir / "pores.pvd", opt.resume, opt.resume ? resume_time_ : sys.time);
    const auto& net = fluid_.network();
    const auto n = static_cast<std::size_t>(net.n_pores());
    const auto p = fluid_.flow().pressure();
    const auto a = fluid_.flow().liquid_fraction();
    std::vector<Vec3> pts;
    std::vector<std::int64_t> conn;
    if (fluid_.dim3()) {
      pts.reserve(n);
      for (std::size_t i = 0; i < n; ++i) pts.emplace_back(net.pore_cx[i], net.pore_cy[i], net.pore_cz[i]);
    } else {
      pts.assign(sys.particles.pos.begin(), sys.particles.pos.end());
      conn.assign(net.pore_v.begin(), net.pore_v.end());
    }
    const std::vector<VtkArray> data = {vtk_array("pressure_Pa", p), vtk_array("liquid_fraction", a),
                                        vtk_array("void_volume_m3", std::span<const Real>(net.pore_void)),
                                        vtk_array("hull", std::span<const std::uint8_t>(net.pore_hull))};
    const std::string file = fmt::format("pores_{:06d}.vtp", index);
    if (fluid_.dim3()) write_vtp(dir / file, pts, VtpCells{}, data, {});
    else write_vtp(dir / file, pts, VtpCells{VtpCells::Triangles, conn}, {}, data);
    pvd_.add(sys.time, file);
  }

  void extra_summary(nlohmann::json& j, const DemOutcome& out) override {
    auto& f = j["fluid"];
    f["dimension"] = fluid_.dim3() ? 3 : 2;
    f["max_pore_pressure_Pa"] = ex_.max_pore_pressure;
    f["saturation_initial"] = cfg.real("fluid.saturation");
    f["liquid_placement"] = cfg.string("fluid.liquid_placement");
    f["saturation_final"] = fluid_.flow().saturation();
    f["retriangulations"] = fluid_.retriangulations();
    f["triangulation_seconds"] = fluid_.triangulation_seconds();
    // Issue 16's budget: retriangulation rare enough that it stays under 10 % of the run.
    f["triangulation_wall_share"] = fluid_.triangulation_share();
    f["dem_dt_s"] = sys.settings.dt;
    f["dem_critical_dt_s"] = ex_.critical_wet;
    f["dem_critical_dt_dry_s"] = ex_.critical_dry;
    f["stiffness_in_time_step"] = cfg.boolean("fluid.stiffness_in_time_step");
    f["flow_substeps"] = fluid_.substeps();
    f["pores"] = fluid_.network().n_pores();
    Real pmean, v;
    fluid_.mean_pressure(pmean, v);
    f["mean_pore_pressure_final_Pa"] = pmean;
    f["pore_void_initial_m3"] = ex_.void0;
    f["pore_void_final_m3"] = v;
    f["liquid_mass_initial_kg"] = ex_.liquid_mass0;
    f["gas_mass_initial_kg"] = ex_.gas_mass0;
    f["liquid_mass_kg"] = fluid_.flow().total_liquid_mass();
    f["gas_mass_kg"] = fluid_.flow().total_gas_mass();
    if (fluid_.dim3()) {
      const auto& c = fluid_.c3();
      f["flow_scheme"] = c.params().implicit ? "implicit" : "explicit";
      f["pressure_forces"] = coupling::name(c.params().pressure_force);
      f["flow_steps"] = c.stats().flow_steps;
      f["flow_every_last"] = c.stats().flow_every;
      f["early_flow_steps"] = c.early_flow_steps();  // held cycles ended by hold_displacement / hold_strain
      f["throats"] = fluid_.network().n_channels();
      f["drained_pores"] = fluid_.drained_pores();
      const auto& s = c.stats();
      f["timing"] = {{"triangulation_seconds", s.t_triangulation}, {"network_update_seconds", s.t_update},
                     {"flow_seconds", s.t_flow}, {"forces_seconds", s.t_forces}};
    } else {
      const auto& st = fluid_.c2().stats();
      f["flow_stable_dt_s"] = st.last_stable_dt;
      f["flow_scheme"] = fluid_.c2().params().implicit_above > 0 ? "auto" : "explicit";
      f["implicit_above"] = fluid_.c2().params().implicit_above;
      f["implicit_flow_steps"] = st.implicit_steps;

      f["cavitations"] = st.cavitations;
      f["vapour_mass_kg_per_m"] = st.vapour_mass;
      // With sphere forces (force_height = diameter) the sample is a layer of spheres ~2 r thick,
      // while the axial stress divides by the discs' 1 m: the same peak per mean diameter.
      const bool layer = fluid_.c2().params().force_height == coupling::ForceHeight::Diameter;
      Real rm = 0;
      for (Real r : sys.particles.radius) rm += r;
      rm /= static_cast<Real>(sys.particles.size());
      f["force_height"] = layer ? "diameter" : "thickness";
      f["pressure_forces"] = coupling::name(fluid_.c2().params().pressure_force);
      f["remap"] = fluid_.c2().params().remap == porenet::RemapConserve::Mass ? "mass" : "pressure";
      f["remap_mass_change_kg_per_m"] = {{"liquid", st.remap_liquid_change},
                                         {"gas", st.remap_gas_change},
                                         {"liquid_largest_one", st.remap_liquid_change_max},
                                         {"liquid_relative", ex_.liquid_mass0 > 0 ? st.remap_liquid_change / ex_.liquid_mass0 : 0.0}};
      if (layer && out.no_peak.empty()) {
        j["layer"]["thickness_m"] = 2 * rm;
        j["layer"]["ucs_Pa"] = ucs_state().peak_stress / (2 * rm);
      }
    }
    write_pores("pores_final.csv");
  }
  std::string extra_report() const override {
    return fmt::format("max pore pressure {:.3f} MPa, {} retriangulations ({:.2g} % of this session's wall time)",
                       1e-6 * ex_.max_pore_pressure, fluid_.retriangulations(), 100 * fluid_.triangulation_share());
  }
  std::string test_title() const override { return "Saturated uniaxial compression"; }
  void extra_plots(std::vector<PlotJob>& jobs) const override {
    jobs.push_back(axial_strain_plot(opt.out_dir, "pore_pressure", test_title() + ": pore pressure",
                                     {"max_pore_pressure_Pa", "mean_pore_pressure_Pa"}, 1e-6, "pore pressure [MPa]"));
  }

  SatExtra ex_;
  double resume_time_ = 0;
  PoreFluid fluid_;
  PvdSeries pvd_;
};

// `fracflow check` and run: the sample's checks, and keys of the other dimension.
void validate(const Config& cfg) {
  dem::validate_dem_sample(cfg);
  const bool dim3 = cfg.integer("dem.dim") == 3;
  for (const auto& k : dim3 ? k2DOnly : k3DOnly)
    if (cfg.has(k)) cfg.fail(k, fmt::format("applies to {} samples only; this one has dem.dim = {}", dim3 ? "2D" : "3D", cfg.integer("dem.dim")));
  if (!dim3 && cfg.string("fluid.flow_scheme") == "implicit")
    cfg.fail("fluid.flow_scheme", "the 2D coupling steps the flow explicitly (sub-steps, one implicit step past "
                                  "fluid.implicit_above of them); use auto or explicit");
  if (!dim3 && cfg.string("fluid.flow_scheme") == "explicit" && cfg.has("fluid.implicit_above"))
    cfg.fail("fluid.implicit_above", "applies with fluid.flow_scheme = auto; explicit means sub-steps only");
  // Every pore would start cavitated and be held at that pressure (1e300 Pa: NaN grains at step 1).
  if (!dim3 && !(cfg.real("fluid.cavitation_pressure") < cfg.real("fluid.initial_pressure")))
    cfg.fail("fluid.cavitation_pressure",
             fmt::format("{} Pa is not below fluid.initial_pressure = {} Pa: every pore would start cavitated (water's "
                         "vapour pressure at 20 C is 2.34e3 Pa; 0 lets the liquid take any tension)",
                         cfg.real("fluid.cavitation_pressure"), cfg.real("fluid.initial_pressure")));
  // A vapour pressure far below any liquid's (1e-300 Pa) made each cavitated pore an ideal gas of
  // ~1e-305 kg/m^3 and the pressure solve stopped without converging (fuzzed, session 50); 1e-12 Pa ran.
  constexpr Real kLowestVapourPressure = 1e-3;  // Pa; glycerol ~0.01 Pa, mercury 0.17 Pa at 20-25 C
  if (!dim3 && cfg.real("fluid.cavitation_pressure") > 0 && cfg.real("fluid.cavitation_pressure") < kLowestVapourPressure)
    cfg.fail("fluid.cavitation_pressure",
             fmt::format("{} Pa is below the vapour pressure of any liquid a test uses (water 2.34e3 Pa, mercury 0.17 "
                         "Pa, glycerol ~0.01 Pa at 20-25 C): at least {} Pa, or 0 to switch cavitation off",
                         cfg.real("fluid.cavitation_pressure"), kLowestVapourPressure));
  if (!dim3) refuse_widening_aperture(cfg, "fluid");
  // Peng-Robinson water below its vapour pressure is steam: at 1e-300 Pa the EOS gave the gas root
  // (7e-306 kg/m^3) and the 3D run stopped at once blaming the time step (fuzzed, session 49). The 2D
  // coupling's cavitation floor must lie below the initial pressure (above); 3D models none.
  constexpr Real kWaterVapourPressure = 2.34e3;  // Pa at 20 C
  if (dim3 && cfg.string("fluid.liquid_eos") == "peng_robinson" && cfg.real("fluid.saturation") > 0 &&
      cfg.real("fluid.initial_pressure") < kWaterVapourPressure)
    cfg.fail("fluid.initial_pressure",
             fmt::format("{:.4g} Pa is below water's vapour pressure ({} Pa at 20 C): the Peng-Robinson water would "
                         "start as steam, and 3D samples model no cavitation; use 1e5 (atmospheric) or more",
                         cfg.real("fluid.initial_pressure"), kWaterVapourPressure));
  // A barotropic liquid no stiffer than the ideal gas beside it (an isothermal gas's modulus is its
  // pressure) is not a liquid: 1e-12 Pa was taken silently and no pore pressure ever built up; a modulus
  // in GPa where Pa are meant (2.2) does the same (fuzzed, session 49).
  if (cfg.string("fluid.liquid_eos") == "barotropic" &&
      !(cfg.real("fluid.liquid_bulk_modulus") > cfg.real("fluid.initial_pressure")))
    cfg.fail("fluid.liquid_bulk_modulus",
             fmt::format("{:.4g} Pa is not above fluid.initial_pressure = {:.4g} Pa: the liquid would be softer than the "
                         "gas beside it (an ideal gas's isothermal modulus is its pressure); water is 2.2e9 Pa (a modulus "
                         "in GPa where Pa are meant?)",
                         cfg.real("fluid.liquid_bulk_modulus"), cfg.real("fluid.initial_pressure")));
}

RunStatus run(const Config& cfg, const RunOptions& opt) {
  validate(cfg);
  return SaturatedUcsRun(cfg, opt).run();
}

}  // namespace

Driver saturated_ucs_driver() {
  return Driver{"saturated_ucs",
                "uniaxial compression of a bonded sample with water and gas in its pores (2D: seed 004 network; 3D: "
                "PFV-style network)",
                declare, run, validate};
}

}  // namespace ff::drivers
