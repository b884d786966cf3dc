// What a hydrofrac run reports when it ends (HydrofracRun::finish): summary.json (breakdown,
// fracture, borehole, in-situ and pressurised elastic state against Kirsch, the fluid's budgets) and
// the plots of pressure, cracks, injected volume and the fracture pattern.
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>

#include "core/log.hpp"
#include "drivers/dem_results.hpp"
#include "drivers/hydrofrac/hydrofrac_run.hpp"
#include "drivers/run_record.hpp"
#include "drivers/summary_values.hpp"
#include "fracflow/version.hpp"
#include "io/json_out.hpp"
#include "io/plot.hpp"

namespace ff::drivers::hydrofrac {

nlohmann::json HydrofracRun::circles_json(const std::vector<CircleRecord>& cs) const {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& c : cs) {
    const Real t = std::atan2(c.y, c.x), co = std::cos(t), si = std::sin(t);
    auto polar = [&](Real xx, Real yy, Real xy) {
      return std::array<Real, 3>{xx * co * co + yy * si * si + 2 * xy * si * co, xx * si * si + yy * co * co - 2 * xy * si * co,
                                 (yy - xx) * si * co + xy * (co * co - si * si)};
    };
    const auto m = polar(c.xx, c.yy, c.xy), k = polar(c.k_xx, c.k_yy, c.k_xy);
    nlohmann::json j = {{"kind", c.far ? "interior" : "near_hole"},
                        {"r_over_a", c.r_over_a},
                        {"azimuth_deg", c.angle_deg},
                        {"x_m", c.x},
                        {"y_m", c.y},
                        {"radius_m", c.radius},
                        {"particles", c.particles},
                        {"porosity", c.porosity},
                        {"pressure_Pa", c.pressure},
                        {"measured_Pa", {{"xx", c.xx}, {"yy", c.yy}, {"xy", c.xy}, {"rr", m[0]}, {"tt", m[1]}, {"rt", m[2]}}},
                        {"kirsch_Pa", {{"xx", c.k_xx}, {"yy", c.k_yy}, {"xy", c.k_xy}, {"rr", k[0]}, {"tt", k[1]}, {"rt", k[2]}}}};
    if (sys.settings.dim == 3) j["measured_Pa"]["zz"] = c.zz;
    a.push_back(j);
  }
  return a;
}

void HydrofracRun::finish(const std::string& stop) {
  vtk();
  const hydrofrac::FluidState f = fluid_->state();
  nlohmann::json j;
  j["fracflow_version"] = kVersion;
  j["driver"] = "hydrofrac";
  j["title"] = cfg.string("title");
  j["stop_reason"] = stop;
  const bool rate_mode = cfg.string("injection.mode") == "rate";
  j["injection"] = {{"fluid", cfg.string("injection.fluid")},
                    {"mode", cfg.string("injection.mode")},
                    {"penetration", cfg.string("injection.fluid") == "sleeve" && cfg.boolean("injection.penetration")},
                    {"final_pressure_Pa", f.pressure},
                    {"injected_volume_m3", f.injected_volume},
                    {"borehole_volume_m3", f.borehole_volume},
                    {"wall_particles", f.wetted_particles},
                    {"wetted_cracks", f.wetted_cracks},
                    {"peak_pressure_Pa", st_.peak_pressure},
                    {"start_time_s", st_.injection_time}};
  if (sys.settings.dim == 2) j["injection"]["note"] = "2D: volumes and rates per metre of thickness";
  nlohmann::json bd;
  bd["definition"] = rate_mode ? "first pressure peak followed by a drop of injection.peak_drop once a crack has reached the hole"
                               : fmt::format("pressure when the fracture connected to the hole first reached {} m beyond its wall "
                                             "(injection.breakdown_length)",
                                             breakdown_length_ > 0 ? breakdown_length_ : hole_.radius);
  if (st_.breakdown_found) {
    bd["pressure_Pa"] = st_.breakdown_pressure;
    bd["time_s"] = st_.breakdown_time;
    bd["cracks"] = st_.breakdown_cracks;
    bd["fracture"] = {{"connected_cracks", st_.bd_connected},
                      {"length_m", st_.bd_length},
                      {"extent_beyond_wall_m", st_.bd_extent},
                      {"azimuth_deg", st_.bd_azimuth},
                      {"anisotropy", st_.bd_anisotropy},
                      {"normal_azimuth_deg", st_.bd_normal_azimuth}};
  } else {
    bd["pressure_Pa"] = nullptr;
    bd["reason"] = fmt::format("no breakdown before the run stopped: {}", stop);
  }
  bd["initiation_pressure_Pa"] = st_.initiation_found ? nlohmann::json(st_.initiation_pressure) : nlohmann::json(nullptr);
  bd["initiation_definition"] = "pressure at the first series row with a crack connected to the hole";
  j["breakdown"] = bd;
  j["fracture"] = {{"connected_cracks", shape_.cracks},
                   {"length_m", shape_.length},
                   {"extent_beyond_wall_m", extent_},
                   {"azimuth_deg", shape_.azimuth_deg},
                   {"anisotropy", shape_.anisotropy},
                   {"normal_azimuth_deg", shape_.normal_azimuth_deg},
                   {"definition", "cracks connected to the hole through broken bonds: principal axis of sum d d^T about the "
                                  "axis (azimuth from x = sigma_H), tip-to-tip length along it, largest distance minus the "
                                  "effective hole radius; normal_azimuth_deg: normal to the principal axis of the cracks' "
                                  "normals sum n n^T"}};
  j["borehole"] = {{"radius_m", hole_.radius},
                   {"effective_radius_m", st_.effective_radius},
                   {"centre_m", {hole_.centre.x(), hole_.centre.y()}},
                   {"perforation_length_m", hole_.perforation_length},
                   {"perforation_azimuth_deg",
                    hole_.perforation_length > 0 ? cfg.real("borehole.perforation_azimuth") : 0.0},
                   {"natural_fracture_bonds", joints_.size()}};
  j["insitu"] = {{"targets_Pa", {{"sigma_H", targets_.x()}, {"sigma_h", targets_.y()}}},
                 {"equilibrium_reached", st_.equilibrium != 0},
                 {"steps", st_.insitu_steps},
                 {"tolerance", cfg.real("insitu.tolerance")}};
  if (sys.settings.dim == 3) j["insitu"]["targets_Pa"]["sigma_v"] = targets_.z();
  j["elastic_state"] = {
      {"method", "measurement circles (2D) / spheres (3D) with PFC's porosity correction against Kirsch's solution averaged over "
                 "the same region (a = effective hole radius, far field = the in-situ targets, compression positive)"},
      {"insitu", circles_json(insitu_)}};
  if (!probe_.empty()) j["elastic_state"]["pressurised"] = circles_json(probe_);
  if (lbm_) {
    const auto& in = lbm_->info();
    const hydrofrac::LbmBudget b = lbm_->budget();
    j["lbm"] = {{"scheme", cfg.string("fluid.scheme")},
                {"dt_lbm_s", in.scales.dt()},
                {"dt_dem_s", in.dem_dt},
                {"sub_steps", in.stride},
                {"tau", in.scales.units.tau()},
                {"mach_reference", in.scales.mach},
                {"max_mach", b.max_mach},
                {"bulk_modulus_eff_Pa", in.scales.bulk_modulus},
                {"dx_m", in.scales.units.dx()},
                {"lattice", {in.n[0], in.n[1], in.n[2]}},
                {"lbm_steps", b.lbm_steps},
                {"particle_set_changes", b.set_changes},
                {"mass_budget_m3",
                 {{"injected", b.injected},
                  {"lattice_change", b.lattice_change},
                  {"drained", b.drained},
                  {"covering_refill", b.covering_refill},
                  {"residual", b.residual},
                  {"definition", "volumes at the reference density: lattice_change = injected + drained + covering_refill + "
                                 "residual; drained is what the drained faces added (negative: outflow; 0 with closed faces), "
                                 "the residual what the bounce-back walls created or destroyed"}}},
                {"faces", cfg.string("fluid.faces")}};
    log::info("hydrofrac: LBM mass budget over {} LBM steps ({} new particle sets; m^3 at rho_f): injected {:.4g}, lattice "
              "change {:.4g}, drained {:.4g}, covering and refill {:.4g}, residual (walls) {:.4g}; largest Mach number {:.3g}",
              b.lbm_steps, b.set_changes, b.injected, b.lattice_change, b.drained, b.covering_refill, b.residual, b.max_mach);
  }
  if (net_) {
    const auto& in = net_->info();
    const hydrofrac::NetworkBudget b = net_->budget();
    const double wall = control_.run_wall_s();  // (the timings are checkpointed: every session's)
    j["network"] = {{"pores", in.pores},
                    {"channels", in.channels},
                    {"hole_pores", in.hole_pores},
                    {"dt_flow_s", in.dt_flow},
                    {"dt_dem_s", in.dt_dem},
                    {"flow_every", in.flow_every},
                    {"predict_pressures", net_->predicting()},
                    {"dt_explicit_s", in.dt_explicit},
                    {"spring_period_s", in.t_spring},
                    {"flow_steps", b.flow_steps},
                    {"retriangulations", b.retriangulations},
                    {"max_cg_iterations", b.max_cg_iterations},
                    {"max_substeps", b.max_substeps},
                    {"cavitations", b.cavitations},
                    {"vapour_volume_m3", b.vapour_volume},
                    {"wall_s", {{"network_update", b.t_sync}, {"flow", b.t_flow}, {"forces", b.t_forces},
                                {"rest_dem_and_output", wall - b.t_sync - b.t_flow - b.t_forces}}},
                    // Issue 16's budget: retriangulation rare enough to stay under 10 % of the run. The
                    // updates that retriangulated, over this process's wall time.
                    {"retriangulation_wall_share", control_.elapsed_s() > 0 ? b.t_triangulation / control_.elapsed_s() : 0.0},
                    {"mass_budget_kg",
                     {{"injected", b.injected_mass},
                      {"pore_mass_start", b.pore_mass0},
                      {"pore_mass_end", b.pore_mass},
                      {"remap_change", b.remap_change},
                      {"residual", b.residual},
                      {"definition", "(pore_mass_end - pore_mass_start) - injected - remap_change (the mass the "
                                     "retriangulations added: network.remap = pressure); rate mode: injected = rho Q t (a "
                                     "closed block: the residual is the scheme's mass error; drained faces: plus what the "
                                     "hull pores exchanged with the far field); ramp mode: injected is defined as the "
                                     "change (residual 0)"}}},
                    {"faces", net_->drained_faces() ? "drained" : "closed"},
                    {"walls", net_->walls()},
                    {"crack_channels", net_->crack_channels()},
                    {"preconditioner", net_->amg() ? "amg" : "dic"}};
    log::info("hydrofrac: network mass budget over {} flow steps ({} retriangulations; kg{}): injected {:.6g}, pores "
              "{:.6g} -> {:.6g}, residual {:.3g}; wall time: network update {:.1f} s (retriangulations {:.1f} s in this "
              "session), flow {:.1f} s, forces {:.1f} s of {:.1f} s",
              b.flow_steps, b.retriangulations, sys.settings.dim == 2 ? " per m" : "", b.injected_mass, b.pore_mass0,
              b.pore_mass, b.residual, b.t_sync, b.t_triangulation, b.t_flow, b.t_forces, wall);
  }
  j["cracks"] = cracks_json(sys);
  j["sample"] = sample_json(sys, info);
  j["time_step_s"] = sys.settings.dt;
  j["steps"] = sys.step_count;
  j["wall_time_s"] = control_.run_wall_s();  // every session of the run
  j["threads"] = opt.threads;
  j["parameters"] = params_json(cfg);
  add_run_record(j, opt);
  write_json_atomic(opt.out_dir / "summary.json", j);
  plots();
  st_.finished = 1;
  checkpoint();
  log::info("hydrofrac: {}; breakdown {}, cracks {} ({} tensile, {} shear), {} connected: fracture {:.3g} m long at {:.1f} deg "
            "from sigma_H",
            stop,
            st_.breakdown_found ? fmt::format("{:.3f} MPa", 1e-6 * st_.breakdown_pressure) : std::string("not reached"),
            sys.cracks.total(), sys.cracks.tensile, sys.cracks.shear, shape_.cracks, shape_.length, shape_.azimuth_deg);
}

void HydrofracRun::plots() {
  if (!cfg.boolean("output.plots")) return;
  const fs::path out = opt.out_dir;
  fs::create_directories(out / "plots");
  // Outline of the hole (and the block) for the fracture picture; the cracks are the markers.
  const fs::path outline = out / "plots" / "outline.csv";
  {
    std::ofstream o(outline);
    o << "x_m,y_m\n";
    const Real a = st_.effective_radius;
    for (int k = 0; k <= 72; ++k)
      o << hole_.centre.x() + a * std::cos(2 * kPi * k / 72) << "," << hole_.centre.y() + a * std::sin(2 * kPi * k / 72) << "\n";
    const auto& W = sys.walls;
    o << "nan,nan\n";
    for (int k : {0, 1, 3, 2, 0}) {
      const Real x = W[k % 2 ? 1 : 0].point.x(), y = W[k / 2 ? 3 : 2].point.y();
      o << x << "," << y << "\n";
    }
  }
  PlotJob p{out / "series.csv", out / "plots" / "pressure_cracks.png", {}};
  p.spec.title = "Hydraulic fracturing: borehole pressure and cracks";
  p.spec.x = "time_s";
  p.spec.x_scale = 1e3;
  p.spec.xlabel = "time [ms]";
  p.spec.y = {"pressure_Pa"};
  p.spec.y_scale = 1e-6;
  p.spec.ylabel = "borehole pressure [MPa]";
  p.spec.y2 = {"cracks_total", "cracks_tensile", "cracks_shear", "cracks_connected"};
  p.spec.y2label = "number of cracks";
  PlotJob v{out / "series.csv", out / "plots" / "injected_volume.png", {}};
  v.spec.title = "Injected volume";
  v.spec.x = "time_s";
  v.spec.x_scale = 1e3;
  v.spec.xlabel = "time [ms]";
  v.spec.y = {"injected_volume_m3"};
  v.spec.y_scale = 1e6;
  v.spec.ylabel = sys.settings.dim == 2 ? "injected volume [cm^3 per m]" : "injected volume [cm^3]";
  PlotJob c{outline, out / "plots" / "fracture_pattern.png", {}};
  c.spec.title = "Cracks (circles) around the borehole";
  c.spec.x = "x_m";
  c.spec.x_scale = 1e3;
  c.spec.xlabel = "x (sigma_H) [mm]";
  c.spec.y = {"y_m"};
  c.spec.y_scale = 1e3;
  c.spec.ylabel = "y (sigma_h) [mm]";
  c.spec.reference_csv = out / "cracks.csv";
  c.spec.ref_x = "x_m";
  c.spec.ref_y = "y_m";
  c.spec.ref_label = "cracks";
  c.spec.y_labels = {"block and borehole"};
  c.spec.equal_aspect = true;
  const std::vector<PlotJob> jobs = {p, v, c};
  plot_series(jobs);
}

}  // namespace ff::drivers::hydrofrac
