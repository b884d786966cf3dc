// The markdown report of the triaxial validation and its figures (docs/validation/triaxial.md),
// written from a ValidationReport; the checks themselves are in triaxial_validation.cpp.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "batch/run_case.hpp"
#include "batch/triaxial_validation.hpp"
#include "core/error.hpp"
#include "core/log.hpp"
#include "io/plot.hpp"

namespace fs = std::filesystem;

namespace ff::batch {

namespace {

std::string yes_no(bool ok) { return ok ? "**pass**" : "**FAIL**"; }

// Differential stress against axial strain of several runs on one strain grid (NaN where a run
// has no data), for one figure.
void write_curves_csv(const fs::path& csv, const std::vector<std::pair<std::string, const TriaxialRunResult*>>& runs) {
  std::vector<std::vector<double>> e(runs.size()), q(runs.size());
  double emax = 0;
  for (std::size_t k = 0; k < runs.size(); ++k) {
    std::ifstream f(runs[k].second->dir / "series.csv");
    std::string line;
    std::getline(f, line);
    std::vector<std::string> cols;
    for (std::size_t a = 0, b; a <= line.size(); a = b + 1) {
      b = line.find(',', a);
      if (b == std::string::npos) b = line.size();
      cols.push_back(line.substr(a, b - a));
    }
    const auto ie = std::find(cols.begin(), cols.end(), "axial_strain") - cols.begin();
    const auto iq = std::find(cols.begin(), cols.end(), "differential_stress_Pa") - cols.begin();
    if (ie >= static_cast<long>(cols.size()) || iq >= static_cast<long>(cols.size())) continue;
    while (std::getline(f, line)) {
      std::vector<double> v;
      for (std::size_t a = 0, b; a <= line.size(); a = b + 1) {
        b = line.find(',', a);
        if (b == std::string::npos) b = line.size();
        v.push_back(std::strtod(line.c_str() + a, nullptr));
      }
      if (static_cast<long>(v.size()) <= std::max(ie, iq)) continue;
      e[k].push_back(v[ie]);
      q[k].push_back(v[iq]);
    }
    if (!e[k].empty()) emax = std::max(emax, e[k].back());
  }
  std::ofstream out(csv);
  out << "axial_strain";
  for (auto& r : runs) out << "," << r.first;
  out << "\n";
  const int n = 300;
  for (int i = 0; i <= n; ++i) {
    const double x = emax * i / n;
    out << fmt::format("{}", x);
    for (std::size_t k = 0; k < runs.size(); ++k) {
      const auto& ek = e[k];
      double y = std::nan("");
      if (!ek.empty() && x >= ek.front() && x <= ek.back()) {
        const auto it = std::upper_bound(ek.begin(), ek.end(), x);
        const std::size_t j = it == ek.end() ? ek.size() - 1 : static_cast<std::size_t>(it - ek.begin());
        if (j == 0) y = q[k][0];
        else {
          const double w = ek[j] > ek[j - 1] ? (x - ek[j - 1]) / (ek[j] - ek[j - 1]) : 1.0;
          y = q[k][j - 1] + w * (q[k][j] - q[k][j - 1]);
        }
      }
      out << fmt::format(",{}", y);
    }
    out << "\n";
  }
}

// Differential stress against axial strain of several runs in one figure: img/NAME.csv + .png.
PlotJob curves_figure(const fs::path& img, const std::string& name, const std::string& title,
                      const std::vector<std::pair<std::string, const TriaxialRunResult*>>& runs) {
  write_curves_csv(img / (name + ".csv"), runs);
  PlotJob j{img / (name + ".csv"), img / (name + ".png"), {}};
  j.spec.title = title;
  j.spec.x = "axial_strain";
  j.spec.x_scale = 100;
  j.spec.xlabel = "axial strain [%]";
  for (auto& p : runs) j.spec.y.push_back(p.first);
  j.spec.y_scale = 1e-6;
  j.spec.ylabel = "differential stress [MPa]";
  return j;
}

}  // namespace

void write_validation_report(const ValidationReport& r, const fs::path& doc) {
  const fs::path img = doc.parent_path() / "images";
  fs::create_directories(img);
  const auto checks = validation_checks(r);
  std::vector<PlotJob> jobs;
  // Curves and profiles of the first packing (the others only enter the peak statistics).
  const auto c1_first = runs_of_packing(r.c1, r.sample.seed), c4_first = runs_of_packing(r.c4, r.sample.seed);
  const auto lat_first = runs_of_packing(r.laterals, r.sample.seed);

  // Figure: C1 stress-strain curves at the three pressures (seed 000 Figs. 15-17).
  if (!c1_first.empty()) {
    std::vector<std::pair<std::string, const TriaxialRunResult*>> runs;
    for (auto* x : c1_first) runs.emplace_back(fmt::format("C1 sigma3 = {:g} MPa", 1e-6 * x->sigma3_Pa), x);
    for (auto* x : c4_first) runs.emplace_back(fmt::format("C4 sigma3 = {:g} MPa", 1e-6 * x->sigma3_Pa), x);
    jobs.push_back(curves_figure(img, "triaxial_curves", "Triaxial compression, flexible membrane: C1-like and C4-like samples", runs));
  }
  // Figure: the lateral boundaries compared at the first pressure (seed 000 Fig. 15).
  if (!lat_first.empty() && !c1_first.empty()) {
    std::vector<std::pair<std::string, const TriaxialRunResult*>> runs = {{"flexible membrane", c1_first.front()}};
    for (auto* x : lat_first)
      runs.emplace_back(x->lateral == "particle_membrane" ? "particle membrane" : x->lateral == "rigid_cylinder" ? "rigid cylinder" : x->lateral, x);
    jobs.push_back(curves_figure(img, "triaxial_laterals",
                                 fmt::format("C1, sigma3 = {:g} MPa: lateral boundary compared", 1e-6 * c1_first.front()->sigma3_Pa),
                                 runs));
  }
  // Figure: peaks against sigma3 with the laboratory tests (seed 000 Fig. 6).
  if (!r.c1.empty()) {
    {
      std::ofstream f(img / "triaxial_peaks.csv");
      f << "sigma3_MPa,C1 simulated (mean of packings),C4 simulated (mean of packings),C1 fit\n";
      const auto fit = fit_differential(r.c1);
      const auto p1 = peaks_by_pressure(r.c1), p4 = peaks_by_pressure(r.c4);
      for (std::size_t k = 0; k < p1.size(); ++k)
        f << fmt::format("{},{},{},{}\n", 1e-6 * p1[k].sigma3_Pa, 1e-6 * p1[k].mean_Pa,
                         k < p4.size() ? 1e-6 * p4[k].mean_Pa : std::nan(""),
                         1e-6 * (fit.intercept_Pa + fit.slope * p1[k].sigma3_Pa));
      std::ofstream l(img / "triaxial_lab_table3.csv");
      l << "sigma3_MPa,peak_differential_MPa\n";
      for (auto& t : lab_table3()) l << fmt::format("{},{}\n", t.sigma3_MPa, t.peak_differential_MPa);
    }
    PlotJob j{img / "triaxial_peaks.csv", img / "triaxial_peaks.png", {}};
    j.spec.title = "Peak differential stress against confinement";
    j.spec.x = "sigma3_MPa";
    j.spec.xlabel = "confining pressure sigma3 [MPa]";
    j.spec.y = {"C1 simulated (mean of packings)", "C4 simulated (mean of packings)", "C1 fit"};
    j.spec.ylabel = "peak differential stress [MPa]";
    j.spec.reference_csv = img / "triaxial_lab_table3.csv";
    j.spec.ref_x = "sigma3_MPa";
    j.spec.ref_y = "peak_differential_MPa";
    j.spec.ref_label = "laboratory (Table 3)";
    jobs.push_back(j);
  }
  // Figure: the final membrane profile (radius of each ring against height).
  if (!c1_first.empty() && !c1_first.front()->ring_radius_m.empty()) {
    std::ofstream f(img / "triaxial_bulge.csv");
    f << "z_mm";
    for (auto* x : c1_first) f << fmt::format(",sigma3 = {:g} MPa", 1e-6 * x->sigma3_Pa);
    f << "\n";
    const double R0 = 0.5 * r.sample.diameter_m;
    const auto& z0 = c1_first.front()->ring_z_m;
    for (std::size_t k = 0; k < z0.size(); ++k) {
      f << fmt::format("{}", 1e3 * z0[k]);
      for (auto* x : c1_first)
        f << fmt::format(",{}", k < x->ring_radius_m.size() ? 100 * (x->ring_radius_m[k] - R0) / R0 : std::nan(""));
      f << "\n";
    }
    f.close();
    PlotJob j{img / "triaxial_bulge.csv", img / "triaxial_bulge.png", {}};
    j.spec.title = "C1: flexible membrane at the end of the run (mean radius of each ring)";
    j.spec.x = "z_mm";
    j.spec.xlabel = "height z [mm] (ring of the initial sleeve)";
    for (auto* x : c1_first) j.spec.y.push_back(fmt::format("sigma3 = {:g} MPa", 1e-6 * x->sigma3_Pa));
    j.spec.ylabel = "radial expansion (r - R0)/R0 [%]";
    jobs.push_back(j);
  }
  // Seed 000 Fig. 21: one run's stress and crack counts, drawn by the driver.
  if (c1_first.size() >= 2) {
    const auto src = c1_first[1]->dir / "plots" / "stress_strain_cracks.png";
    std::error_code ec;
    if (fs::exists(src)) fs::copy_file(src, img / "triaxial_c1_stress_cracks.png", fs::copy_options::overwrite_existing, ec);
  }
  const int drawn = plot_series(jobs);
  if (drawn < static_cast<int>(jobs.size()))
    log::warn("validation report: {} of {} figures drawn (python3 with matplotlib needed)", drawn, jobs.size());

  // The markdown.
  std::string md;
  int passed = 0;
  for (auto& c : checks) passed += c.passed;
  md += "# Triaxial validation: coal with inclusions in a flexible membrane (seed 000)\n\n";
  md += fmt::format("Produced by `{}` on {} ({}; {:.0f} min of wall time). Do not edit by hand: run the command again.\n\n",
                    r.command, r.date, r.machine, r.wall_time_s / 60);
  md += fmt::format("**{} of {} checks pass.**\n\n", passed, checks.size());
  md += "| check | measured | required | result |\n|---|---|---|---|\n";
  for (auto& c : checks) md += fmt::format("| {} | {} | {} | {} |\n", c.what, c.measured, c.required, yes_no(c.passed));
  const auto& s = r.sample;
  const int parts = r.c1.empty() ? 0 : r.c1.front().particles;
  md += fmt::format(
      "\n## Set-up\n\n"
      "- Samples: {:g} x {:g} mm cylinders (Table 3's lab samples are ~25 x 50 mm), particle radii {:g}-{:g} mm "
      "({} spheres in the C1 sample; seed 000 uses 0.5 mm, 34,608 spheres), porosity 0.38; {} packings of each sample "
      "(packing seeds {} to {}) at each pressure, whose peaks are averaged: one packing of ~4,000 spheres scatters by "
      "~1 MPa.\n"
      "- Groups from synthetic segmented voxel stacks (`fracflow make-sample c1|c4 --seed {} --voxel-size {:g}e-3`): "
      "C1-like (~20% inclusions in vertical veins) and C4-like (~10%, isolated near the surface); seed 000 Table 2 / Fig. 4.\n"
      "- Micro-parameters: the coal matrix calibrated by `fracflow calibrate` (below) on a matrix-only sample of "
      "the same size and particles; inclusions and the matrix-inclusion interface from seed 000 Table 7 ({}).\n"
      "- Loading: isotropic stage to sigma3 (platens and membrane servo-controlled), then both platens at {:g} m/s "
      "(axial strain rate {:g}/s; quasi-static in the DEM sense, far faster than the lab) until the differential "
      "stress falls below 60% of its peak or 6% strain. Flexible membrane: 2 x 24 triangles around, square units, "
      "sleeve 1.2 x the sample height.\n",
      1e3 * s.diameter_m, 1e3 * s.height_m, 1e3 * s.radius_min_m, 1e3 * s.radius_max_m, parts, s.packings, s.seed,
      s.seed + static_cast<unsigned>(std::max(s.packings, 1)) - 1, s.seed, 1e3 * s.voxel_size_m,
      r.inclusions == "table7" ? "as printed"
                               : "scaled: Table 7's values times the factors the calibration applied to the matrix's "
                                 "emod, kratio and strengths, with the calibrated bond friction angle, so that the "
                                 "contrasts between matrix, inclusions and interface stay those of Table 7 (this code's "
                                 "bonded-particle model gives E ~ 0.95 GPa at Table 7's matrix values, not PFC's 2.37 GPa)",
      s.strain_rate * s.height_m / 2, s.strain_rate);

  const auto cal = calibration_numbers(r.calibration);
  if (cal.present) {
    const std::string why = r.calibration.value("stop_reason", std::string());
    md += "\n## Calibration of the coal matrix (seed 000 Table 5 averages; Eq. 1 slope)\n\n";
    md += cal.converged ? fmt::format("Converged after {} iterations.", cal.runs)
                        : fmt::format("**Not converged** after {} iterations; iteration {} is used.{}", cal.runs,
                                      r.calibration.value("chosen_iteration", 0), why.empty() ? "" : " Stop: " + why + ".");
    md += " Each iteration is one UCS run; b (triaxial runs at the two outer pressures) is measured beside the runs "
          "that come near E, nu and UCS, and the bond friction angle moves only after a run with all three in "
          "tolerance (docs/batch.md).\n\n";
    md += "| iteration | emod [GPa] | kratio | tensile / cohesion [MPa] | bond friction angle [deg] | E [GPa] | nu | UCS [MPa] | b |\n"
          "|---|---|---|---|---|---|---|---|---|\n";
    for (auto& it : r.calibration.value("iterations", nlohmann::json::array())) {
      const auto& p = it["parameters"];
      auto get = [&](const char* k) {
        for (auto& [key, v] : p.items())
          if (key.size() >= std::string(k).size() && key.compare(key.size() - std::string(k).size(), std::string::npos, k) == 0 &&
              key.rfind("dem.bond.", 0) == 0)
            return v.get<double>();
        return std::nan("");
      };
      const bool b_measured = it.value("slope_measured", it.value("slope_b", 0.0) > 0);
      md += fmt::format("| {} | {:.4g} | {:.4g} | {:.4g} / {:.4g} | {:.3g} | {:.3f} | {:.3f} | {:.2f} | {} |\n",
                        it.value("iteration", 0), 1e-9 * get(".emod"), get(".kratio"), 1e-6 * get(".tensile_strength"),
                        1e-6 * get(".cohesion"), get(".friction_angle"), 1e-9 * json_number(it, {"youngs_modulus_Pa"}),
                        json_number(it, {"poisson_ratio"}), 1e-6 * json_number(it, {"ucs_Pa"}),
                        b_measured ? fmt::format("{:.2f}", it.value("slope_b", 0.0)) : std::string("-"));
    }
    md += fmt::format("\nTargets: E = 2.37 GPa, nu = 0.35, UCS = 14.97 MPa (Table 5), b = {:.2f} (Eq. 1, the slope of "
                      "the peak differential stress against sigma3).\n",
                      r.calibration.value("targets", nlohmann::json::object()).value("slope_b", 0.0));
  }

  if (!r.inclusion_sets.empty()) {
    md += "\nInclusion and interface parameters of the runs:";
    for (auto& x : r.inclusion_sets) md += " `" + x + "`";
    md += "\n";
  }

  auto run_table = [&](const std::vector<TriaxialRunResult>& runs, bool with_lab) {
    std::string t = "| sample | packing | lateral | sigma3 [MPa] | peak q [MPa] | lab mean [MPa] | strain at peak [%] | confinement at peak "
                    "[MPa] | E [GPa] | nu | cracks (tensile / shear) | isotropic stage: spheres vs boundary | particles | wall time [s] |\n"
                    "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (auto& x : runs) {
      const auto lab = with_lab ? lab_mean_peak_MPa(1e-6 * x.sigma3_Pa) : std::nullopt;
      t += fmt::format("| {} | {} | {} | {:g} | {} | {} | {:.2f} | {} | {:.2f} | {:.2f} | {:.0f} ({:.0f} / {:.0f}) | {:.1f}% | {} | {:.0f} |\n",
                       x.label, x.packing_seed, lateral_label(x), 1e-6 * x.sigma3_Pa, mpa(x.peak_differential_Pa),
                       lab ? fmt::format("{:.2f}", *lab) : "-", 100 * x.strain_at_peak, mpa(x.confinement_at_peak_Pa),
                       1e-9 * x.youngs_modulus_Pa, x.poisson_ratio, x.cracks_total, x.cracks_tensile, x.cracks_shear,
                       100 * x.largest_sphere_deviation, x.particles, x.wall_time_s);
    }
    return t;
  };
  std::vector<TriaxialRunResult> all = r.c1;
  all.insert(all.end(), r.c4.begin(), r.c4.end());
  md += "\n## Runs\n\n" + run_table(all, true);
  {  // the peaks over the packings at each pressure
    const auto p1 = peaks_by_pressure(r.c1), p4 = peaks_by_pressure(r.c4);
    md += "\nPeak differential stress over the packings (mean +- sample standard deviation):\n\n"
          "| sigma3 [MPa] | C1 [MPa] | C4 [MPa] | C1 - C4 [MPa] | lab mean (Table 3) [MPa] | seed 000's C1 - C4 [MPa] |\n"
          "|---|---|---|---|---|---|\n";
    for (std::size_t k = 0; k < p1.size(); ++k) {
      const auto lab = lab_mean_peak_MPa(1e-6 * p1[k].sigma3_Pa);
      const bool has4 = k < p4.size();
      const double s3 = 1e-6 * p1[k].sigma3_Pa;
      // Seed 000 Sec. 6 quotes the C1 - C4 difference at 2.5 and 5 MPa.
      const std::string seed_diff = std::abs(s3 - 2.5) < 1e-6 ? "1.79" : std::abs(s3 - 5) < 1e-6 ? "3.05" : "-";
      md += fmt::format("| {:g} | {} +- {} ({}) | {} | {} | {} | {} |\n", s3, mpa(p1[k].mean_Pa), mpa(p1[k].sd_Pa), p1[k].runs,
                        has4 ? fmt::format("{} +- {} ({})", mpa(p4[k].mean_Pa), mpa(p4[k].sd_Pa), p4[k].runs) : "-",
                        has4 ? fmt::format("{:+.2f}", 1e-6 * (p1[k].mean_Pa - p4[k].mean_Pa)) : "-",
                        lab ? fmt::format("{:.2f}", *lab) : "-", seed_diff);
    }
  }
  if (r.c1.size() >= 2) {
    const auto f1 = fit_differential(r.c1);
    md += fmt::format("\nC1 fit: peak q = {:.2f} + {:.3f} sigma3 MPa (R^2 = {:.4f}); laboratory Eq. 1: {:.2f} + {:.3f} sigma3 "
                      "(R^2 = 0.8671).",
                      1e-6 * f1.intercept_Pa, f1.slope, f1.r_squared, kLabIntercept_MPa, kLabSlope);
    if (r.c4.size() >= 2) {
      const auto f4 = fit_differential(r.c4);
      md += fmt::format(" C4 fit: {:.2f} + {:.3f} sigma3.", 1e-6 * f4.intercept_Pa, f4.slope);
    }
    md += " In Mohr-Coulomb terms sigma1 = a + (b + 1) sigma3.\n";
  }
  if (!r.laterals.empty()) {
    std::vector<TriaxialRunResult> cmp;
    for (auto& x : r.c1)
      if (std::abs(x.sigma3_Pa - r.laterals.front().sigma3_Pa) < 1) cmp.push_back(x);
    cmp.insert(cmp.end(), r.laterals.begin(), r.laterals.end());
    md += "\n## Lateral boundary compared (seed 000 Fig. 15)\n\n" + run_table(cmp, true);
    md += "\nThe particle membrane's forces have fixed magnitudes (pressure x initial tributary area), so the pressure it "
          "applies per unit of actual area falls only as far as the sleeve's mean radius grows; the flexible membrane "
          "recomputes each triangle's force from its current area, and the rigid cylinder cannot bulge unevenly. The "
          "particle membrane's 'confinement at peak' (total force over the lateral area at the spheres' mean radius) and "
          "its lateral strain (nu) read off because its spheres sink into the hollows of the sample surface (docs/dem.md).\n";
  }
  if (!r.friction.empty()) {
    md += "\n## Friction of the lateral boundary\n\n"
          "The runs above have frictionless lateral boundaries (membrane.friction = 0: pure pressure, as a rubber sleeve "
          "that moves with the sample). Below, the same C1 packings with every boundary contact taking the particle's own "
          "contact friction (membrane.friction = -1, mu = 0.4 as in Table 7), as PFC wall elements would:\n\n" +
          run_table(r.friction, true);
    if (const auto f = compare_friction_runs(r.friction))
      md += fmt::format(
          "\nMeans: flexible membrane {} MPa, particle membrane {} MPa ({:+.1f}%). The flexible membrane's elements move only "
          "along their normals, so friction holds the sample's surface where the sample shortens and bulges: the sleeve "
          "carries axial load, which raises the peak as seed 000's Fig. 15 shows, while the particle membrane's spheres "
          "move with the surface and add almost nothing. The same friction spoils the isotropic stage (measurement "
          "spheres against the applied stresses, column above), which seed 000 reports consistent, and a latex sleeve "
          "cannot carry axial load; so the validation runs keep the frictionless boundary (docs/dem.md).\n",
          mpa(f->flexible.mean_Pa), mpa(f->particle.mean_Pa), 100 * (f->flexible.mean_Pa / f->particle.mean_Pa - 1));
  }
  if (!r.isotropic_fine.empty()) {
    const auto& x0 = r.isotropic_fine.front();
    md += fmt::format(
        "\n## Isotropic stage at seed resolution (measurement spheres)\n\n"
        "The C1 sample rebuilt with particle radii {:g}-{:g} mm ({} spheres; seed 000: 0.5 mm, 34,608), taken through the "
        "isotropic stage only. Three measurement spheres of radius 0.6 R on the axis at 1/4, 1/2 and 3/4 of the height; "
        "stress by PFC's formula with each sphere's own porosity (METHODS.md 1.7). In the coarse runs above a sphere "
        "holds ~300 particles and reads the denser core: their deviations are in the runs table.\n\n"
        "| sigma3 [MPa] | platens [MPa] | membrane [MPa] | spheres: axial [MPa] | spheres: lateral [MPa] | particles per "
        "sphere | porosity in the spheres | largest deviation | wall time [s] |\n|---|---|---|---|---|---|---|---|---|\n",
        1e3 * r.sample.fine_radius_min_m, 1e3 * r.sample.fine_radius_max_m, x0.particles);
    for (auto& x : r.isotropic_fine) {
      std::string ax, lat, n, por;
      for (auto& m : x.spheres) {
        const std::string sep = ax.empty() ? "" : " / ";
        ax += sep + mpa(m.axial_Pa), lat += sep + mpa(m.lateral_Pa), n += sep + std::to_string(m.particles);
        por += sep + fmt::format("{:.3f}", m.porosity);
      }
      md += fmt::format("| {:g} | {} | {} | {} | {} | {} | {} | {:.1f}% | {:.0f} |\n", 1e-6 * x.sigma3_Pa, mpa(x.platen_Pa),
                        mpa(x.confinement_Pa), ax, lat, n, por, 100 * x.largest_deviation, x.wall_time_s);
    }
  }
  md += "\n## Figures\n\n"
        "![C1 and C4 stress-strain curves](images/triaxial_curves.png)\n\n"
        "![Peak differential stress against confinement, with the laboratory tests](images/triaxial_peaks.png)\n\n";
  if (!r.laterals.empty()) md += "![Lateral boundaries compared](images/triaxial_laterals.png)\n\n";
  md += "![Final membrane profile](images/triaxial_bulge.png)\n\n"
        "![C1 stress and cracks against strain (seed 000 Fig. 21)](images/triaxial_c1_stress_cracks.png)\n\n"
        "The runs' folders hold VTK series for ParaView (`vtk/membrane.pvd`: the bulging membrane, `vtk/cracks.pvd`: "
        "cracks coloured by type, `vtk/contacts.pvd`: the force network).\n";
  std::ofstream f(doc);
  f << md;
  if (!f) throw Error(fmt::format("validation: cannot write '{}'", doc.string()));
}

}  // namespace ff::batch
