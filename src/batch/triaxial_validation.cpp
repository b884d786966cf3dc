#include "batch/triaxial_validation.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>

#include "batch/mohr_coulomb.hpp"
#include "core/error.hpp"
#include "core/log.hpp"
#include "io/plot.hpp"

namespace fs = std::filesystem;

namespace ff::batch {

const std::vector<LabTriaxialTest>& lab_table3() {
  // Zhao, Konietzky & Herbst (2021), Rock Mech. Rock Eng., doi:10.1007/s00603-021-02436-9, Table 3.
  static const std::vector<LabTriaxialTest> rows = {
      {"C1", 2.5, 25.94},  {"C11", 2.5, 28.92}, {"C13", 5.0, 41.44}, {"C15", 5.0, 30.34},
      {"C4", 7.5, 44.45},  {"C12", 7.5, 42.24}, {"C16", 7.5, 46.83}};
  return rows;
}

std::optional<double> lab_mean_peak_MPa(double sigma3_MPa) {
  double sum = 0;
  int n = 0;
  for (auto& r : lab_table3())
    if (std::abs(r.sigma3_MPa - sigma3_MPa) < 1e-3) sum += r.peak_differential_MPa, ++n;
  if (n == 0) return std::nullopt;
  return sum / n;
}

std::string validation_scenario(const ValidationSample& s, const std::string& driver, const std::string& voxels) {
  const bool coal = !voxels.empty();
  const double v = s.strain_rate * s.height_m / 2;  // each platen
  std::string t = fmt::format(
      "# Written by `fracflow validate-triaxial`: seed 000 Table 7 micro-parameters; the matrix values are the\n"
      "# starting point of the calibration, whose result the runs receive as --set overrides.\n"
      "driver = \"{}\"\ntitle = \"validation: {} {} x {} mm, {}\"\n\n"
      "[dem]\ndim = 3\nbond_law = \"parallel\"\n\n"
      "[dem.group.matrix]\ndensity = 1390\n",
      driver, coal ? "coal with inclusions" : "coal matrix", 1e3 * s.diameter_m, 1e3 * s.height_m, driver);
  if (coal) t += "[dem.group.inclusion]\ndensity = 1810\n";
  t += "\n[dem.contact.matrix-matrix]\nemod = 2.09e9\nkratio = 14.65\nfriction = 0.4\n"
       "[dem.bond.matrix-matrix]\nemod = 2.09e9\nkratio = 14.65\ntensile_strength = 17.4e6\ncohesion = 4.35e6\n"
       "friction_angle = 4.0\n";
  if (coal)
    t += "[dem.contact.inclusion-inclusion]\nemod = 2.84e9\nkratio = 2.44\nfriction = 0.4\n"
         "[dem.bond.inclusion-inclusion]\nemod = 2.84e9\nkratio = 2.44\ntensile_strength = 30.5e6\ncohesion = 12.2e6\n"
         "friction_angle = 7.0\n"
         "[dem.contact.matrix-inclusion]\nemod = 1.90e9\nkratio = 1.0\nfriction = 0.4\n"
         "[dem.bond.matrix-inclusion]\nemod = 1.90e9\nkratio = 1.0\ntensile_strength = 11.6e6\ncohesion = 5.8e6\n"
         "friction_angle = 8.0\n";
  t += fmt::format("\n[sample]\nshape = \"cylinder\"\ndiameter = {}\nheight = {}\nradius_min = {}\nradius_max = {}\n"
                   "porosity = 0.38\nseed = {}\nbond_gap = 0.05e-3\n",
                   s.diameter_m, s.height_m, s.radius_min_m, s.radius_max_m, s.seed);
  if (coal) {
    // make-sample centres the stack on the axis and starts it half a voxel above z = 0.
    const int nx = static_cast<int>(std::lround(s.diameter_m / s.voxel_size_m));
    const double x0 = -0.5 * (nx - 1) * s.voxel_size_m;
    t += fmt::format("default_group = \"matrix\"\n\n[sample.voxels]\nfolder = \"{}\"\norigin = [{}, {}, {}]\n"
                     "spacing = [{}, {}, {}]\n[sample.voxels.threshold.inclusion]\nmin = 151\nmax = 255\n"
                     "[sample.voxels.threshold.pore]\nmin = 1\nmax = 65\n",
                     voxels, x0, x0, 0.5 * s.voxel_size_m, s.voxel_size_m, s.voxel_size_m, s.voxel_size_m);
  }
  if (driver == "ucs")
    t += fmt::format("\n[ucs]\nplaten_velocity = {}\nplaten_friction = 0.1\nstop_fraction = 0.6\n", v);
  else
    t += fmt::format("\n[triaxial]\nconfining_pressure = 5e6\nlateral = \"membrane\"\nplaten_velocity = {}\n"
                     "platen_friction = 0.1\n\n[membrane]\nn_theta = 24\nlength_factor = 1.2\n",
                     v);
  return t;
}

TriaxialRunResult read_triaxial_result(const fs::path& dir, const std::string& label) {
  const fs::path file = dir / "summary.json";
  std::ifstream f(file);
  if (!f) throw Error(fmt::format("validation: cannot read '{}'", file.string()));
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(f);
  } catch (const std::exception& e) {
    throw Error(fmt::format("validation: '{}' is not valid JSON: {}", file.string(), e.what()));
  }
  if (j.value("driver", "") != "triaxial")
    throw Error(fmt::format("validation: '{}' is not the summary of a triaxial run", file.string()));
  TriaxialRunResult r;
  r.label = label;
  r.dir = dir;
  try {
    r.lateral = j.at("lateral").get<std::string>();
    r.sigma3_Pa = j.at("confining_pressure_Pa").get<double>();
    r.peak_differential_Pa = j.at("peak_differential_stress_Pa").get<double>();
    r.strain_at_peak = j.at("strain_at_peak").get<double>();
    r.confinement_at_peak_Pa = j.at("confinement_at_peak_Pa").get<double>();
    r.youngs_modulus_Pa = j.at("youngs_modulus_Pa").get<double>();
    r.poisson_ratio = j.at("poisson_ratio").get<double>();
    r.cracks_total = j.at("cracks").at("total").get<double>();
    r.cracks_tensile = j.at("cracks").at("tensile").get<double>();
    r.cracks_shear = j.at("cracks").at("shear").get<double>();
    r.largest_sphere_deviation = j.at("isotropic_stage").at("largest_sphere_deviation").get<double>();
    r.particles = j.at("sample").at("particles").get<int>();
    r.wall_time_s = j.value("wall_time_s", 0.0);
    if (j.contains("membrane")) {
      r.ring_radius_m = j["membrane"].at("ring_radius_m").get<std::vector<double>>();
      r.ring_z_m = j["membrane"].at("ring_z_m").get<std::vector<double>>();
    }
  } catch (const nlohmann::json::exception& e) {
    throw Error(fmt::format("validation: '{}' lacks a number the report needs: {}", file.string(), e.what()));
  }
  return r;
}

BulgeProfile bulge_profile(const TriaxialRunResult& r, double R0) {
  BulgeProfile b;
  if (r.ring_radius_m.empty()) return b;
  // The band between the platens: the sample height shrinks with the axial strain, the platens
  // stay centred on the sample's mid-height (both move at the same speed).
  double zmin = HUGE_VAL, zmax = -HUGE_VAL;
  for (double z : r.ring_z_m) zmin = std::min(zmin, z), zmax = std::max(zmax, z);
  const double mid = 0.5 * (zmin + zmax);
  std::vector<std::pair<double, double>> band;  // (z, expansion)
  double lo = HUGE_VAL, hi = -HUGE_VAL;
  // Rings whose height lies within the loaded band: the sleeve is 20% longer than the sample,
  // so the outer rings beyond the platens are left out by keeping the middle 1/1.2 of the sleeve.
  const double half_band = 0.5 * (zmax - zmin) / 1.2;
  for (std::size_t k = 0; k < r.ring_radius_m.size(); ++k) {
    if (std::abs(r.ring_z_m[k] - mid) > half_band + 1e-12) continue;
    band.emplace_back(r.ring_z_m[k], (r.ring_radius_m[k] - R0) / R0);
    lo = std::min(lo, r.ring_z_m[k]);
    hi = std::max(hi, r.ring_z_m[k]);
  }
  if (band.empty()) return b;
  b.max_expansion = -HUGE_VAL;
  b.min_expansion = HUGE_VAL;
  for (auto& [z, e] : band) {
    b.mean_expansion += e / static_cast<double>(band.size());
    if (e > b.max_expansion) b.max_expansion = e, b.z_of_max_fraction = hi > lo ? (z - lo) / (hi - lo) : 0.5;
    b.min_expansion = std::min(b.min_expansion, e);
  }
  return b;
}

DifferentialFit fit_differential(const std::vector<TriaxialRunResult>& runs) {
  DifferentialFit f;
  if (runs.size() < 2) return f;
  std::vector<double> s3, q;
  for (auto& r : runs) s3.push_back(r.sigma3_Pa), q.push_back(r.peak_differential_Pa);
  const LineFit line = fit_line(s3, q);
  if (!(line.sxx > 0)) return f;
  return {line.intercept, line.slope, line.r_squared};
}

namespace {

std::string mpa(double pa) { return fmt::format("{:.2f}", 1e-6 * pa); }
std::string yes_no(bool ok) { return ok ? "**pass**" : "**FAIL**"; }

// The calibration targets and results out of calibrate's calibration.json.
struct CalibrationNumbers {
  bool present = false, converged = false;
  double E = 0, nu = 0, ucs = 0, b = 0;
  int runs = 0;
};
CalibrationNumbers calibration_numbers(const nlohmann::json& c) {
  CalibrationNumbers n;
  if (!c.is_object() || !c.contains("final_measured")) return n;
  n.present = true;
  n.converged = c.value("converged", false);
  const auto& m = c["final_measured"];
  n.E = m.value("youngs_modulus_Pa", 0.0);
  n.nu = m.value("poisson_ratio", 0.0);
  n.ucs = m.value("ucs_Pa", 0.0);
  n.b = m.value("slope_b", 0.0);
  n.runs = c.contains("iterations") ? static_cast<int>(c["iterations"].size()) : 0;
  return n;
}

}  // namespace

std::vector<ValidationCheck> validation_checks(const ValidationReport& r) {
  std::vector<ValidationCheck> out;
  const auto c = calibration_numbers(r.calibration);
  if (c.present) {
    const bool ok = std::abs(c.E / kMatrixE_Pa - 1) < 0.05 && std::abs(c.nu - kMatrixNu) < 0.03 &&
                    std::abs(c.ucs / kMatrixUcs_Pa - 1) < 0.05;
    out.push_back({"matrix calibration to Table 5 (E, nu, UCS)",
                   fmt::format("E {:.3f} GPa ({:+.1f}%), nu {:.3f}, UCS {:.2f} MPa ({:+.1f}%)", 1e-9 * c.E,
                               100 * (c.E / kMatrixE_Pa - 1), c.nu, 1e-6 * c.ucs, 100 * (c.ucs / kMatrixUcs_Pa - 1)),
                   "E and UCS within 5%, nu within 0.03", ok});
  }
  // Isotropic stage: measurement spheres against the boundary stresses.
  if (!r.c1.empty()) {
    double worst = 0;
    for (auto& x : r.c1) worst = std::max(worst, x.largest_sphere_deviation);
    for (auto& x : r.c4) worst = std::max(worst, x.largest_sphere_deviation);
    out.push_back({"isotropic stage: measurement spheres vs applied stresses", fmt::format("largest deviation {:.1f}%", 100 * worst),
                   "within 5%", worst <= 0.05});
  }
  if (r.c1.size() >= 2) {
    bool rising = true;
    for (std::size_t k = 1; k < r.c1.size(); ++k) rising = rising && r.c1[k].peak_differential_Pa > r.c1[k - 1].peak_differential_Pa;
    std::string peaks;
    for (auto& x : r.c1) peaks += (peaks.empty() ? "" : ", ") + mpa(x.peak_differential_Pa);
    out.push_back({"C1: peak differential stress rises with sigma3", peaks + " MPa", "strictly rising", rising});
    const auto f = fit_differential(r.c1);
    out.push_back({"C1: slope b of peak differential stress vs sigma3 (Eq. 1)",
                   fmt::format("{:.2f} ({:+.0f}% of {:.2f})", f.slope, 100 * (f.slope / kLabSlope - 1), kLabSlope),
                   "within 30% of 3.54", std::abs(f.slope / kLabSlope - 1) <= 0.30});
  }
  for (auto& x : r.c1) {
    const auto lab = lab_mean_peak_MPa(1e-6 * x.sigma3_Pa);
    if (!lab) continue;
    const double e = 1e-6 * x.peak_differential_Pa / *lab - 1;
    out.push_back({fmt::format("C1 at sigma3 = {:g} MPa: peak vs Table 3 mean", 1e-6 * x.sigma3_Pa),
                   fmt::format("{} vs {:.2f} MPa ({:+.0f}%)", mpa(x.peak_differential_Pa), *lab, 100 * e), "within 20%",
                   std::abs(e) <= 0.20});
  }
  for (auto& l : r.laterals) {
    if (l.lateral != "particle_membrane") continue;
    for (auto& x : r.c1)
      if (std::abs(x.sigma3_Pa - l.sigma3_Pa) < 1) {
        out.push_back({fmt::format("sigma3 = {:g} MPa: flexible membrane stronger than the particle membrane (Fig. 15)",
                                   1e-6 * x.sigma3_Pa),
                       fmt::format("{} vs {} MPa ({:+.1f}%)", mpa(x.peak_differential_Pa), mpa(l.peak_differential_Pa),
                                   100 * (x.peak_differential_Pa / l.peak_differential_Pa - 1)),
                       "flexible at least 5% higher (seed 000: 'significantly lower' with the particle membrane)",
                       x.peak_differential_Pa > 1.05 * l.peak_differential_Pa});
      }
  }
  if (!r.c1.empty()) {
    // "Visibly uneven": the largest ring expansion at least twice the smallest one (a uniform
    // cylinder would give the same expansion on every ring).
    const auto& x = r.c1.back();
    const auto b = bulge_profile(x, 0.5 * r.sample.diameter_m);
    const bool uneven = b.max_expansion > 0 && b.max_expansion >= 2 * std::max(b.min_expansion, 0.0);
    out.push_back({fmt::format("C1 at sigma3 = {:g} MPa: uneven bulge of the flexible membrane", 1e-6 * x.sigma3_Pa),
                   fmt::format("ring expansion {:.2f}% to {:.2f}% of R0 (largest at {:.0f}% of the height)",
                               100 * b.min_expansion, 100 * b.max_expansion, 100 * b.z_of_max_fraction),
                   "largest >= 2 x smallest", uneven});
  }
  if (!r.c1.empty() && r.c1.size() == r.c4.size()) {
    int stronger = 0;
    double sum1 = 0, sum4 = 0;
    std::string diffs;
    for (std::size_t k = 0; k < r.c1.size(); ++k) {
      stronger += r.c1[k].peak_differential_Pa > r.c4[k].peak_differential_Pa;
      sum1 += r.c1[k].peak_differential_Pa, sum4 += r.c4[k].peak_differential_Pa;
      diffs += (diffs.empty() ? "" : ", ") + fmt::format("{:+.2f}", 1e-6 * (r.c1[k].peak_differential_Pa - r.c4[k].peak_differential_Pa));
    }
    out.push_back({"C1 (inclusion-rich) stronger than C4 (inclusion-poor)",
                   fmt::format("C1 - C4 = {} MPa; stronger at {} of {} pressures", diffs, stronger, r.c1.size()),
                   "C1 stronger on average (seed 000: by 1.79-3.05 MPa)", sum1 > sum4});
  }
  return out;
}

namespace {

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
    const auto iq = std::find(cols.begin(), cols.end(), "differential_stress") - cols.begin();
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

  // Figure: C1 stress-strain curves at the three pressures (seed 000 Figs. 15-17).
  if (!r.c1.empty()) {
    std::vector<std::pair<std::string, const TriaxialRunResult*>> runs;
    for (auto& x : r.c1) runs.emplace_back(fmt::format("C1 sigma3 = {:g} MPa", 1e-6 * x.sigma3_Pa), &x);
    for (auto& x : r.c4) runs.emplace_back(fmt::format("C4 sigma3 = {:g} MPa", 1e-6 * x.sigma3_Pa), &x);
    jobs.push_back(curves_figure(img, "triaxial_curves", "Triaxial compression, flexible membrane: C1-like and C4-like samples", runs));
  }
  // Figure: the lateral boundaries compared at the first pressure (seed 000 Fig. 15).
  if (!r.laterals.empty() && !r.c1.empty()) {
    std::vector<std::pair<std::string, const TriaxialRunResult*>> runs = {{"flexible membrane", &r.c1.front()}};
    for (auto& x : r.laterals) runs.emplace_back(x.lateral == "particle_membrane" ? "particle membrane" : x.lateral == "rigid_cylinder" ? "rigid cylinder" : x.lateral, &x);
    jobs.push_back(curves_figure(img, "triaxial_laterals",
                                 fmt::format("C1, sigma3 = {:g} MPa: lateral boundary compared", 1e-6 * r.c1.front().sigma3_Pa),
                                 runs));
  }
  // Figure: peaks against sigma3 with the laboratory tests (seed 000 Fig. 6).
  if (!r.c1.empty()) {
    {
      std::ofstream f(img / "triaxial_peaks.csv");
      f << "sigma3_MPa,C1 simulated,C4 simulated,C1 fit\n";
      const auto fit = fit_differential(r.c1);
      for (std::size_t k = 0; k < r.c1.size(); ++k)
        f << fmt::format("{},{},{},{}\n", 1e-6 * r.c1[k].sigma3_Pa, 1e-6 * r.c1[k].peak_differential_Pa,
                         k < r.c4.size() ? 1e-6 * r.c4[k].peak_differential_Pa : std::nan(""),
                         1e-6 * (fit.intercept_Pa + fit.slope * r.c1[k].sigma3_Pa));
      std::ofstream l(img / "triaxial_lab_table3.csv");
      l << "sigma3_MPa,peak_differential_MPa\n";
      for (auto& t : lab_table3()) l << fmt::format("{},{}\n", t.sigma3_MPa, t.peak_differential_MPa);
    }
    PlotJob j{img / "triaxial_peaks.csv", img / "triaxial_peaks.png", {}};
    j.spec.title = "Peak differential stress against confinement";
    j.spec.x = "sigma3_MPa";
    j.spec.xlabel = "confining pressure sigma3 [MPa]";
    j.spec.y = {"C1 simulated", "C4 simulated", "C1 fit"};
    j.spec.ylabel = "peak differential stress [MPa]";
    j.spec.reference_csv = img / "triaxial_lab_table3.csv";
    j.spec.ref_x = "sigma3_MPa";
    j.spec.ref_y = "peak_differential_MPa";
    j.spec.ref_label = "laboratory (Table 3)";
    jobs.push_back(j);
  }
  // Figure: the final membrane profile (radius of each ring against height).
  if (!r.c1.empty() && !r.c1.front().ring_radius_m.empty()) {
    std::ofstream f(img / "triaxial_bulge.csv");
    f << "z_mm";
    for (auto& x : r.c1) f << fmt::format(",sigma3 = {:g} MPa", 1e-6 * x.sigma3_Pa);
    f << "\n";
    const double R0 = 0.5 * r.sample.diameter_m;
    const auto& z0 = r.c1.front().ring_z_m;
    for (std::size_t k = 0; k < z0.size(); ++k) {
      f << fmt::format("{}", 1e3 * z0[k]);
      for (auto& x : r.c1)
        f << fmt::format(",{}", k < x.ring_radius_m.size() ? 100 * (x.ring_radius_m[k] - R0) / R0 : std::nan(""));
      f << "\n";
    }
    f.close();
    PlotJob j{img / "triaxial_bulge.csv", img / "triaxial_bulge.png", {}};
    j.spec.title = "C1: flexible membrane at the end of the run (mean radius of each ring)";
    j.spec.x = "z_mm";
    j.spec.xlabel = "height z [mm] (ring of the initial sleeve)";
    for (auto& x : r.c1) j.spec.y.push_back(fmt::format("sigma3 = {:g} MPa", 1e-6 * x.sigma3_Pa));
    j.spec.ylabel = "radial expansion (r - R0)/R0 [%]";
    jobs.push_back(j);
  }
  // Seed 000 Fig. 21: one run's stress and crack counts, drawn by the driver.
  if (r.c1.size() >= 2) {
    const auto src = r.c1[1].dir / "plots" / "stress_strain_cracks.png";
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
      "({} spheres in the C1 sample; seed 000 uses 0.5 mm, 34,608 spheres), porosity 0.38, packing seed {}.\n"
      "- Groups from synthetic segmented voxel stacks (`fracflow make-sample c1|c4 --seed {} --voxel-size {:g}e-3`): "
      "C1-like (~20% inclusions in vertical veins) and C4-like (~10%, isolated near the surface); seed 000 Table 2 / Fig. 4.\n"
      "- Micro-parameters: the coal matrix calibrated by `fracflow calibrate` (below) on a matrix-only sample of "
      "the same size and particles; inclusions and the matrix-inclusion interface from seed 000 Table 7 ({}).\n"
      "- Loading: isotropic stage to sigma3 (platens and membrane servo-controlled), then both platens at {:g} m/s "
      "(axial strain rate {:g}/s; quasi-static in the DEM sense, far faster than the lab) until the differential "
      "stress falls below 60% of its peak or 6% strain. Flexible membrane: 2 x 24 triangles around, square units, "
      "sleeve 1.2 x the sample height.\n",
      1e3 * s.diameter_m, 1e3 * s.height_m, 1e3 * s.radius_min_m, 1e3 * s.radius_max_m, parts, s.seed, s.seed,
      1e3 * s.voxel_size_m,
      r.inclusions == "table7" ? "as printed"
                               : "scaled: Table 7's values times the factors the calibration applied to the matrix's "
                                 "emod, kratio and strengths, with the calibrated bond friction angle, so that the "
                                 "contrasts between matrix, inclusions and interface stay those of Table 7 (this code's "
                                 "bonded-particle model gives E ~ 0.95 GPa at Table 7's matrix values, not PFC's 2.37 GPa)",
      s.strain_rate * s.height_m / 2, s.strain_rate);

  const auto cal = calibration_numbers(r.calibration);
  if (cal.present) {
    md += fmt::format("\n## Calibration of the coal matrix (seed 000 Table 5 averages; Eq. 1 slope)\n\n"
                      "{} after {} iterations (each one UCS run and triaxial runs at the two outer pressures).\n\n",
                      cal.converged ? "Converged" : "**Not converged**; the closest iteration is used,", cal.runs);
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
      md += fmt::format("| {} | {:.4g} | {:.4g} | {:.4g} / {:.4g} | {:.3g} | {:.3f} | {:.3f} | {:.2f} | {:.2f} |\n",
                        it.value("iteration", 0), 1e-9 * get(".emod"), get(".kratio"), 1e-6 * get(".tensile_strength"),
                        1e-6 * get(".cohesion"), get(".friction_angle"), 1e-9 * it.value("youngs_modulus_Pa", 0.0),
                        it.value("poisson_ratio", 0.0), 1e-6 * it.value("ucs_Pa", 0.0), it.value("slope_b", 0.0));
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
    std::string t = "| sample | lateral | sigma3 [MPa] | peak q [MPa] | lab mean [MPa] | strain at peak [%] | confinement at peak "
                    "[MPa] | E [GPa] | nu | cracks (tensile / shear) | isotropic stage: spheres vs boundary | particles | wall time [s] |\n"
                    "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (auto& x : runs) {
      const auto lab = with_lab ? lab_mean_peak_MPa(1e-6 * x.sigma3_Pa) : std::nullopt;
      t += fmt::format("| {} | {} | {:g} | {} | {} | {:.2f} | {} | {:.2f} | {:.2f} | {:.0f} ({:.0f} / {:.0f}) | {:.1f}% | {} | {:.0f} |\n",
                       x.label, x.lateral, 1e-6 * x.sigma3_Pa, mpa(x.peak_differential_Pa),
                       lab ? fmt::format("{:.2f}", *lab) : "-", 100 * x.strain_at_peak, mpa(x.confinement_at_peak_Pa),
                       1e-9 * x.youngs_modulus_Pa, x.poisson_ratio, x.cracks_total, x.cracks_tensile, x.cracks_shear,
                       100 * x.largest_sphere_deviation, x.particles, x.wall_time_s);
    }
    return t;
  };
  std::vector<TriaxialRunResult> all = r.c1;
  all.insert(all.end(), r.c4.begin(), r.c4.end());
  md += "\n## Runs\n\n" + run_table(all, true);
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
    std::vector<TriaxialRunResult> cmp = {r.c1.front()};
    cmp.insert(cmp.end(), r.laterals.begin(), r.laterals.end());
    md += "\n## Lateral boundary compared (seed 000 Fig. 15)\n\n" + run_table(cmp, true);
    md += "\nThe particle membrane's forces have fixed magnitudes (pressure x initial tributary area), so the pressure it "
          "applies per unit of actual area falls only as far as the sleeve's mean radius grows; the flexible membrane "
          "recomputes each triangle's force from its current area, and the rigid cylinder cannot bulge unevenly. The "
          "particle membrane's 'confinement at peak' (total force over the lateral area at the spheres' mean radius) and "
          "its lateral strain (nu) read off because its spheres sink into the hollows of the sample surface (docs/dem.md).\n";
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
