// Uniaxial compression of a partially saturated 2D bonded-disc specimen (seed 004, Krzaczek,
// Tejchman & Nitka 2024): the UCS driver's sample, platens and measurements, with the pore network
// and two-phase flow of src/coupling/porenet stepped inside each DEM step. Extra series columns:
// the largest and the mean pore pressure, the liquid saturation and the retriangulations.
#include "drivers/saturated/saturated_ucs_driver.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "core/log.hpp"
#include "coupling/porenet/dem_porenet.hpp"
#include "dem/dem_params.hpp"
#include "dem/diagnostics.hpp"
#include "dem/sample_builder.hpp"
#include "drivers/dem_results.hpp"
#include "drivers/dem_run_loop.hpp"
#include "drivers/ucs/ucs_driver.hpp"
#include "drivers/ucs/ucs_measure.hpp"
#include "io/plot.hpp"

namespace fs = std::filesystem;

namespace ff::drivers {

namespace {

void declare(ParamTable& t) {
  declare_ucs_params(t);
  t.real("fluid.saturation", 1.0, "-", "initial liquid saturation of the pores (0: dry, gas only; 1: liquid only)")
      .range(0, 1);
  t.real("fluid.liquid_viscosity", 1e-3, "Pa s", "dynamic viscosity of the liquid (water: 1e-3)").positive();
  t.real("fluid.gas_viscosity", 1.8e-5, "Pa s", "dynamic viscosity of the gas (air: 1.8e-5)").positive();
  t.string("fluid.liquid_eos", "barotropic",
           "liquid equation of state: barotropic (constant bulk modulus) or peng_robinson (PR + Peneloux water, seed 004 "
           "B10-B22; ~3.3x stiffer than real water)")
      .one_of({"barotropic", "peng_robinson"});
  t.real("fluid.liquid_bulk_modulus", 2.2e9, "Pa", "bulk modulus of the barotropic liquid (water: 2.2e9)").positive();
  t.string("fluid.gas_eos", "ideal", "gas equation of state: ideal (air) or peng_robinson (PR air)")
      .one_of({"ideal", "peng_robinson"});
  t.real("fluid.initial_pressure", 1e5, "Pa", "initial pore pressure, also the ambient pressure outside").positive();
  t.string("fluid.drainage", "sides",
           "pores held at the ambient pressure: sides (hull pores at the free lateral faces; platens impermeable) or "
           "closed (undrained sample)")
      .one_of({"sides", "closed"});
  t.real("fluid.aperture_h0", 1e-6, "m", "Eq. B1 contact/bond channel aperture at zero normal stress").positive();
  t.real("fluid.aperture_hinf", 1e-7, "m", "Eq. B1 aperture at infinite normal stress").positive();
  t.real("fluid.aperture_gamma", 0.01, "-", "Eq. B2 reduction factor of pore-to-pore channel apertures").positive();
  t.real("fluid.min_void_relative", 0.05, "-",
         "floor of a pore's void volume as a fraction of the mean cell (slivers set the explicit flow step)")
      .open_range(0, 1);
  t.real("fluid.retriangulation_tolerance", 0.25, "-",
         "retriangulate when a particle has moved this fraction of the mean radius since the last triangulation")
      .positive();
  t.boolean("fluid.shear_forces", true, "add the channel shear forces (B25, B28) to the pressure forces (B26-B27)");
  t.real("fluid.cavitation_pressure", 2.34e3, "Pa",
         "absolute pressure below which a pore's liquid cavitates (vapour fills the rest of its void at this pressure; "
         "water at 20 C: 2.34e3); 0 = the liquid takes any tension")
      .non_negative();
  t.string("fluid.force_height", "auto",
           "wetted height of a grain in B27/B28, to match the height its contacts and bonds act over: thickness (1 m "
           "discs: linear/parallel laws), diameter (the seed's 2 r_j: spheres in one layer, its cohesive law A1-A7), "
           "auto (diameter with dem.contact_law = cohesive, else thickness)")
      .one_of({"auto", "thickness", "diameter"});
}

const std::vector<std::string> kColumns = {
    "step", "time_s", "axial_strain", "axial_stress_Pa", "lateral_strain", "volumetric_strain", "cracks_tensile",
    "cracks_shear", "cracks_total", "intact_bonds", "kinetic_energy_J", "unbalanced_force_ratio",
    "max_pore_pressure_Pa", "mean_pore_pressure_Pa", "saturation", "retriangulations", "flow_substeps"};

struct SatState {
  Real peak_stress = 0, strain_at_peak = 0;
  long peak_row = 0, rows = 0, cracks_written = 0, vtk_index = 0;
  Real next_vtk_strain = 0, h0 = 0;
  int finished = 0;
  Real max_pore_pressure = 0, strain_at_max_pressure = 0;
};

coupling::PorenetCouplingParams coupling_params(const Config& cfg) {
  coupling::PorenetCouplingParams p;
  const Real T = 293.15;
  p.fluid.liquid = cfg.string("fluid.liquid_eos") == "peng_robinson"
                       ? porenet::Eos::water_pr(T)
                       : porenet::Eos::barotropic(1000, cfg.real("fluid.initial_pressure"),
                                                  cfg.real("fluid.liquid_bulk_modulus"));
  p.fluid.gas = cfg.string("fluid.gas_eos") == "peng_robinson" ? porenet::Eos::air_pr(T)
                                                                : porenet::Eos::ideal_gas(T, 28.9586);
  p.fluid.mu_liquid = cfg.real("fluid.liquid_viscosity");
  p.fluid.mu_gas = cfg.real("fluid.gas_viscosity");
  p.initial_pressure = p.ambient_pressure = cfg.real("fluid.initial_pressure");
  p.saturation = cfg.real("fluid.saturation");
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
  return p;
}

}  // namespace
}  // namespace ff::drivers

namespace ff {
template <> struct is_checkpoint_pod<drivers::SatState> : std::true_type {};
}  // namespace ff

namespace ff::drivers {
namespace {

void make_plots(const fs::path& out, const Config& cfg) {
  if (!cfg.boolean("output.plots")) return;
  fs::create_directories(out / "plots");
  std::vector<PlotJob> jobs = {
      axial_strain_plot(out, "stress_strain_cracks", "Saturated uniaxial compression: stress and cracks",
                        {"axial_stress_Pa"}, 1e-6, "axial stress [MPa]"),
      axial_strain_plot(out, "pore_pressure", "Saturated uniaxial compression: pore pressure",
                        {"max_pore_pressure_Pa", "mean_pore_pressure_Pa"}, 1e-6, "pore pressure [MPa]")};
  jobs[0].spec.y2 = {"cracks_total", "cracks_tensile", "cracks_shear"};
  jobs[0].spec.y2label = "number of cracks";
  plot_series(jobs);
}

class SaturatedUcsRun final : public DemRun {
 public:
  SaturatedUcsRun(const Config& c, const RunOptions& o)
      : DemRun(c, o, {"ucs", "stress", "axial_stress_Pa", "ucs.platen_velocity or ucs.max_strain"}) {}

 private:
  DemLoopCounters counters() override {
    return {&st_.rows, &st_.peak_row, &st_.peak_stress, &st_.strain_at_peak, &st_.cracks_written, &st_.vtk_index,
            &st_.next_vtk_strain, &st_.finished};
  }
  void set_up() override {
    info = dem::build_sample(cfg, sys);
    if (info.dim != 2) throw InputError("saturated_ucs: dem.dim must be 2 (the seed 004 network is 2D)");
    dem::add_platens(sys, info, cfg.real("ucs.platen_friction"));
    dem::choose_time_step(cfg, sys);
    const Real v = cfg.real("ucs.platen_velocity");
    sys.walls[0].velocity[info.axis] = v;
    sys.walls[1].velocity[info.axis] = -v;
    gauge_.init(sys, info);
    st_.h0 = gauge_.initial_height();
    fluid_.init(sys, coupling_params(cfg));
    log::info("pore network: {} pores, {} channels ({} pairs); DEM step {:.3g} s, flow stable step {:.3g} s",
              fluid_.network().n_pores(), fluid_.network().n_channels(), fluid_.pairs().size(), sys.settings.dt,
              fluid_.flow().stable_dt());
  }
  void save_after_dem(CheckpointWriter& w) const override {
    w.put_value("ucs.state", st_);
    w.put_value("ucs.sample", sample_record(info));
    w.put("ucs.gauge", gauge_.particles());
    fluid_.save(w);
  }
  void load_after_dem(CheckpointReader& r) override {
    st_ = r.get_value<SatState>("ucs.state");
    info = sample_info(r.get_value<SampleRecord>("ucs.sample"));
    std::vector<Index> g;
    r.get("ucs.gauge", g);
    gauge_.restore(std::move(g), st_.h0);
    fluid_.load(r, sys, coupling_params(cfg));
  }
  void ready() override { columns = kColumns; }
  double planned_steps() const override {
    return cfg.real("ucs.max_strain") * st_.h0 / (2 * cfg.real("ucs.platen_velocity") * sys.settings.dt);
  }
  void advance(long steps) override {
    for (long s = 0; s < steps; ++s) {
      fluid_.step(sys);
      const Real pm = fluid_.max_pressure();
      if (pm > st_.max_pore_pressure) st_.max_pore_pressure = pm;
    }
  }
  DemRowReport measure() override {
    const CompressionState m = gauge_.measure(sys, info);
    const auto& net = fluid_.network();
    const auto p = fluid_.flow().pressure();
    Real pv = 0, v = 0;
    for (Index i = 0; i < net.n_pores(); ++i) {
      pv += p[i] * net.pore_void[i];
      v += net.pore_void[i];
    }
    row = {static_cast<double>(sys.step_count), sys.time, m.axial_strain, m.axial_stress, m.lateral_strain,
           m.volumetric_strain, static_cast<double>(sys.cracks.tensile), static_cast<double>(sys.cracks.shear),
           static_cast<double>(sys.cracks.total()), static_cast<double>(intact_bonds(sys)), kinetic_energy(sys),
           max_unbalanced_force_ratio(sys), fluid_.max_pressure(), pv / v, fluid_.flow().saturation(),
           static_cast<double>(fluid_.stats().retriangulations), static_cast<double>(fluid_.stats().last_substeps)};
    if (m.axial_stress >= st_.peak_stress) write_pores("pores_at_peak.csv");
    status.clear();
    fmt::format_to(std::back_inserter(status), "strain {:.3f}%  stress {:.3f} MPa  p_max {:.3f} MPa  cracks {}",
                   100 * m.axial_strain, 1e-6 * m.axial_stress, 1e-6 * fluid_.max_pressure(), sys.cracks.total());
    return {true, m.axial_strain, m.axial_stress, m.lateral_strain};
  }
  // The pore field for pictures: triangle corners and pressure, liquid fraction.
  void write_pores(const std::string& name) const {
    const auto& net = fluid_.network();
    const auto p = fluid_.flow().pressure();
    const auto a = fluid_.flow().liquid_fraction();
    std::ofstream f(opt.out_dir / name);
    f << "x0_m,y0_m,x1_m,y1_m,x2_m,y2_m,pressure_Pa,liquid_fraction\n";
    for (Index i = 0; i < net.n_pores(); ++i) {
      for (int k = 0; k < 3; ++k) {
        const auto& q = sys.particles.pos[static_cast<std::size_t>(net.pore_v[3 * i + k])];
        f << fmt::format("{:.9g},{:.9g},", q.x(), q.y());
      }
      f << fmt::format("{:.9g},{:.6g}\n", p[i], a[i]);
    }
  }
  void summarize(nlohmann::json& j, const DemOutcome& out) override {
    j["ucs_Pa"] = out.no_peak.empty() ? nlohmann::json(st_.peak_stress) : nlohmann::json(nullptr);
    if (!out.no_peak.empty()) j["peak"]["largest_stress_Pa"] = st_.peak_stress;
    put_elastic_fit(j, out.fit, "least squares on the pre-peak curve between 20% and 50% of the peak stress");
    j["fluid"]["max_pore_pressure_Pa"] = st_.max_pore_pressure;
    j["fluid"]["saturation_initial"] = cfg.real("fluid.saturation");
    j["fluid"]["saturation_final"] = fluid_.flow().saturation();
    j["fluid"]["retriangulations"] = fluid_.stats().retriangulations;
    j["fluid"]["dem_dt_s"] = sys.settings.dt;
    j["fluid"]["flow_stable_dt_s"] = fluid_.stats().last_stable_dt;
    j["fluid"]["flow_substeps"] = fluid_.stats().last_substeps;
    j["fluid"]["pores"] = fluid_.network().n_pores();
    j["fluid"]["cavitations"] = fluid_.stats().cavitations;
    j["fluid"]["vapour_mass_kg_per_m"] = fluid_.stats().vapour_mass;
    // With sphere forces (force_height = diameter) the sample is a layer of spheres ~2 r thick,
    // while the axial stress divides by the discs' 1 m: the same peak per mean diameter.
    const bool layer = fluid_.params().force_height == coupling::ForceHeight::Diameter;
    Real rm = 0;
    for (Real r : sys.particles.radius) rm += r;
    rm /= static_cast<Real>(sys.particles.size());
    j["fluid"]["force_height"] = layer ? "diameter" : "thickness";
    if (layer && out.no_peak.empty()) {
      j["layer"]["thickness_m"] = 2 * rm;
      j["layer"]["ucs_Pa"] = st_.peak_stress / (2 * rm);
    }
    write_pores("pores_final.csv");
  }
  void plots() override { make_plots(opt.out_dir, cfg); }
  void report(const DemOutcome& out) override {
    log::info("{}, max pore pressure {:.3f} MPa, cracks {} ({} tensile, {} shear), {} retriangulations; {}",
              out.no_peak.empty() ? fmt::format("UCS {:.3f} MPa at axial strain {:.3f}%", 1e-6 * st_.peak_stress,
                                                100 * st_.strain_at_peak)
                                  : std::string("no UCS"),
              1e-6 * st_.max_pore_pressure, sys.cracks.total(), sys.cracks.tensile, sys.cracks.shear,
              fluid_.stats().retriangulations, out.stop_reason);
  }

  SatState st_;
  CompressionGauge gauge_;
  coupling::DemPorenetCoupling fluid_;
};

RunStatus run(const Config& cfg, const RunOptions& opt) { return SaturatedUcsRun(cfg, opt).run(); }

}  // namespace

Driver saturated_ucs_driver() {
  return Driver{"saturated_ucs",
                "uniaxial compression of a 2D bonded sample with water and gas in its pores (seed 004 pore network)",
                declare, run, dem::validate_dem_sample};
}

}  // namespace ff::drivers
