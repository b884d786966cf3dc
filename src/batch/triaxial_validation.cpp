#include "batch/triaxial_validation.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>

#include "batch/mohr_coulomb.hpp"
#include "batch/run_case.hpp"
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

std::string lateral_label(const TriaxialRunResult& r) {
  if (r.boundary_friction == 0) return r.lateral;
  return r.boundary_friction < 0 ? r.lateral + ", friction of the particles" : fmt::format("{}, friction {:g}", r.lateral, r.boundary_friction);
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
  // Present but null (no peak, no elastic fit: the run's summary says why) reads as NaN.
  auto number = [&](const char* key) {
    const auto& v = j.at(key);
    return v.is_null() ? std::nan("") : v.get<double>();
  };
  try {
    r.lateral = j.at("lateral").get<std::string>();
    r.sigma3_Pa = j.at("confining_pressure_Pa").get<double>();
    r.peak_differential_Pa = number("peak_differential_stress_Pa");
    r.strain_at_peak = number("strain_at_peak");
    r.confinement_at_peak_Pa = number("confinement_at_peak_Pa");
    r.youngs_modulus_Pa = number("youngs_modulus_Pa");
    r.poisson_ratio = number("poisson_ratio");
    r.cracks_total = j.at("cracks").at("total").get<double>();
    r.cracks_tensile = j.at("cracks").at("tensile").get<double>();
    r.cracks_shear = j.at("cracks").at("shear").get<double>();
    r.largest_sphere_deviation = j.at("isotropic_stage").at("largest_sphere_deviation").get<double>();
    r.particles = j.at("sample").at("particles").get<int>();
    r.wall_time_s = j.value("wall_time_s", 0.0);
    if (j.contains("parameters")) {
      r.packing_seed = j["parameters"].value("sample.seed", 0u);
      r.boundary_friction = j["parameters"].value("membrane.friction", 0.0);
    }
    if (j.contains("membrane")) {
      r.ring_radius_m = j["membrane"].at("ring_radius_m").get<std::vector<double>>();
      r.ring_z_m = j["membrane"].at("ring_z_m").get<std::vector<double>>();
    }
  } catch (const nlohmann::json::exception& e) {
    throw Error(fmt::format("validation: '{}' lacks a number the report needs: {}", file.string(), e.what()));
  }
  return r;
}

IsotropicStageResult read_isotropic_stage(const fs::path& dir) {
  const fs::path file = dir / "summary.json";
  std::ifstream f(file);
  if (!f) throw Error(fmt::format("validation: cannot read '{}'", file.string()));
  IsotropicStageResult r;
  r.dir = dir;
  try {
    const nlohmann::json j = nlohmann::json::parse(f);
    const auto& iso = j.at("isotropic_stage");
    r.sigma3_Pa = j.at("confining_pressure_Pa").get<double>();
    r.platen_Pa = iso.at("platen_stress_Pa").get<double>();
    r.confinement_Pa = iso.at("confinement_Pa").get<double>();
    r.largest_deviation = iso.at("largest_sphere_deviation").get<double>();
    for (const auto& m : iso.at("measurement_spheres"))
      r.spheres.push_back({m.at("axial_Pa").get<double>(), m.at("lateral_Pa").get<double>(), m.value("porosity", std::nan("")),
                           m.at("particles").get<int>()});
    r.particles = j.at("sample").at("particles").get<int>();
    r.wall_time_s = j.value("wall_time_s", 0.0);
  } catch (const std::exception& e) {
    throw Error(fmt::format("validation: '{}' lacks the isotropic stage the report needs: {}", file.string(), e.what()));
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

namespace {
// Mean and sample standard deviation (0 for fewer than two values).
struct MeanSd {
  double mean = 0, sd = 0;
};
MeanSd mean_sd(const std::vector<double>& v) {
  MeanSd m;
  if (v.empty()) return m;
  double sum = 0, ss = 0;
  for (double x : v) sum += x;
  m.mean = sum / static_cast<double>(v.size());
  for (double x : v) ss += (x - m.mean) * (x - m.mean);
  m.sd = v.size() > 1 ? std::sqrt(ss / static_cast<double>(v.size() - 1)) : 0;
  return m;
}
}  // namespace

std::optional<FrictionComparison> compare_friction_runs(const std::vector<TriaxialRunResult>& runs) {
  std::vector<TriaxialRunResult> fw, pm;
  FrictionComparison c;
  for (auto& x : runs) {
    (x.lateral == "membrane" ? fw : pm).push_back(x);
    c.largest_sphere_deviation = std::max(c.largest_sphere_deviation, x.largest_sphere_deviation);
  }
  const auto a = peaks_by_pressure(fw), b = peaks_by_pressure(pm);
  if (a.size() != 1 || b.size() != 1) return std::nullopt;
  c.flexible = a[0];
  c.particle = b[0];
  return c;
}

std::vector<PeakStats> peaks_by_pressure(const std::vector<TriaxialRunResult>& runs) {
  std::vector<PeakStats> out;
  std::vector<std::vector<double>> peaks;
  for (auto& r : runs) {
    std::size_t k = 0;
    while (k < out.size() && std::abs(out[k].sigma3_Pa - r.sigma3_Pa) > 1) ++k;
    if (k == out.size()) out.push_back({r.sigma3_Pa, 0, 0, 0}), peaks.emplace_back();
    peaks[k].push_back(r.peak_differential_Pa);
  }
  for (std::size_t k = 0; k < out.size(); ++k) {
    const MeanSd m = mean_sd(peaks[k]);
    out[k].mean_Pa = m.mean;
    out[k].sd_Pa = m.sd;
    out[k].runs = static_cast<int>(peaks[k].size());
  }
  std::sort(out.begin(), out.end(), [](const PeakStats& a, const PeakStats& b) { return a.sigma3_Pa < b.sigma3_Pa; });
  return out;
}

std::vector<const TriaxialRunResult*> runs_of_packing(const std::vector<TriaxialRunResult>& runs, unsigned seed) {
  std::vector<const TriaxialRunResult*> out;
  for (auto& r : runs)
    if (r.packing_seed == seed) out.push_back(&r);
  return out;
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

std::string mpa(double pa) { return fmt::format("{:.2f}", 1e-6 * pa); }

CalibrationNumbers calibration_numbers(const nlohmann::json& c) {
  CalibrationNumbers n;
  if (!c.is_object() || !c.contains("final_measured")) return n;
  n.present = true;
  n.converged = c.value("converged", false);
  const auto& m = c["final_measured"];
  n.E = json_number(m, {"youngs_modulus_Pa"});  // NaN when null: the check below then fails
  n.nu = json_number(m, {"poisson_ratio"});
  n.ucs = json_number(m, {"ucs_Pa"});
  n.b = m.value("slope_b", 0.0);
  n.runs = c.contains("iterations") ? static_cast<int>(c["iterations"].size()) : 0;
  return n;
}

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
  // Isotropic stage: measurement spheres against the boundary stresses, at seed 000's
  // resolution where it was run (a sphere in the coarse validation samples holds ~300
  // particles, whose stress scatters by several percent), else in the runs themselves.
  if (!r.isotropic_fine.empty()) {
    double worst = 0;
    int fewest = 1 << 30;
    for (auto& x : r.isotropic_fine) {
      worst = std::max(worst, x.largest_deviation);
      for (auto& m : x.spheres) fewest = std::min(fewest, m.particles);
    }
    out.push_back({fmt::format("isotropic stage at seed resolution (C1, {} spheres): measurement spheres vs applied stresses",
                               r.isotropic_fine.front().particles),
                   fmt::format("largest deviation {:.1f}% (>= {} particles per measurement sphere)", 100 * worst, fewest),
                   "within 5%", worst <= 0.05});
  } else if (!r.c1.empty()) {
    double worst = 0;
    for (auto& x : r.c1) worst = std::max(worst, x.largest_sphere_deviation);
    for (auto& x : r.c4) worst = std::max(worst, x.largest_sphere_deviation);
    out.push_back({"isotropic stage: measurement spheres vs applied stresses", fmt::format("largest deviation {:.1f}%", 100 * worst),
                   "within 5%", worst <= 0.05});
  }
  const auto p1 = peaks_by_pressure(r.c1), p4 = peaks_by_pressure(r.c4);
  const bool several = !p1.empty() && p1.front().runs > 1;
  const std::string over = several ? fmt::format(" (mean of {} packings)", p1.front().runs) : "";
  if (p1.size() >= 2) {
    bool rising = true;
    for (std::size_t k = 1; k < p1.size(); ++k) rising = rising && p1[k].mean_Pa > p1[k - 1].mean_Pa;
    std::string peaks;
    for (auto& x : p1) peaks += (peaks.empty() ? "" : ", ") + mpa(x.mean_Pa);
    out.push_back({"C1: peak differential stress rises with sigma3" + over, peaks + " MPa", "strictly rising", rising});
    const auto f = fit_differential(r.c1);
    out.push_back({"C1: slope b of peak differential stress vs sigma3 (Eq. 1)",
                   fmt::format("{:.2f} ({:+.0f}% of {:.2f})", f.slope, 100 * (f.slope / kLabSlope - 1), kLabSlope),
                   "within 30% of 3.54", std::abs(f.slope / kLabSlope - 1) <= 0.30});
  }
  for (auto& x : p1) {
    const auto lab = lab_mean_peak_MPa(1e-6 * x.sigma3_Pa);
    if (!lab) continue;
    const double e = 1e-6 * x.mean_Pa / *lab - 1;
    out.push_back({fmt::format("C1 at sigma3 = {:g} MPa: peak vs Table 3 mean{}", 1e-6 * x.sigma3_Pa, over),
                   fmt::format("{} vs {:.2f} MPa ({:+.0f}%)", mpa(x.mean_Pa), *lab, 100 * e), "within 20%",
                   std::abs(e) <= 0.20});
  }
  std::vector<TriaxialRunResult> particle;
  for (auto& l : r.laterals)
    if (l.lateral == "particle_membrane") particle.push_back(l);
  const auto pp = peaks_by_pressure(particle);
  // The same comparison with frictional boundary contacts, quoted beside the check (not judged).
  std::string with_friction;
  if (const auto f = compare_friction_runs(r.friction))
    with_friction = fmt::format("; with frictional contacts (membrane.friction = -1): {} vs {} MPa ({:+.1f}%), but the "
                                "isotropic stage then reads up to {:.0f}% off (below)",
                                mpa(f->flexible.mean_Pa), mpa(f->particle.mean_Pa),
                                100 * (f->flexible.mean_Pa / f->particle.mean_Pa - 1), 100 * f->largest_sphere_deviation);
  for (auto& l : pp)
    for (auto& x : p1)
      if (std::abs(x.sigma3_Pa - l.sigma3_Pa) < 1) {
        const std::string n = l.runs > 1 ? fmt::format(" (means of {} packings)", l.runs) : "";
        out.push_back({fmt::format("sigma3 = {:g} MPa: flexible membrane stronger than the particle membrane (Fig. 15){}",
                                   1e-6 * x.sigma3_Pa, n),
                       fmt::format("{} vs {} MPa ({:+.1f}%){}", mpa(x.mean_Pa), mpa(l.mean_Pa), 100 * (x.mean_Pa / l.mean_Pa - 1),
                                   with_friction),
                       "flexible at least 5% higher (seed 000: 'significantly lower' with the particle membrane)",
                       x.mean_Pa > 1.05 * l.mean_Pa});
      }
  if (!r.c1.empty()) {
    // "Visibly uneven": the largest ring expansion at least twice the smallest one (a uniform
    // cylinder would give the same expansion on every ring). The first packing at the highest pressure.
    const auto first = runs_of_packing(r.c1, r.sample.seed);
    const auto& x = first.empty() ? r.c1.back() : *first.back();
    const auto b = bulge_profile(x, 0.5 * r.sample.diameter_m);
    const bool uneven = b.max_expansion > 0 && b.max_expansion >= 2 * std::max(b.min_expansion, 0.0);
    out.push_back({fmt::format("C1 at sigma3 = {:g} MPa: uneven bulge of the flexible membrane", 1e-6 * x.sigma3_Pa),
                   fmt::format("ring expansion {:.2f}% to {:.2f}% of R0 (largest at {:.0f}% of the height)",
                               100 * b.min_expansion, 100 * b.max_expansion, 100 * b.z_of_max_fraction),
                   "largest >= 2 x smallest", uneven});
  }
  if (!p1.empty() && p1.size() == p4.size()) {
    // Differences of the means at each pressure, and over all runs the mean C1 - C4 difference
    // with its standard error (same packing seeds on both samples, so the pairs are matched).
    std::string diffs;
    int stronger = 0;
    for (std::size_t k = 0; k < p1.size(); ++k) {
      stronger += p1[k].mean_Pa > p4[k].mean_Pa;
      diffs += (diffs.empty() ? "" : ", ") + fmt::format("{:+.2f}", 1e-6 * (p1[k].mean_Pa - p4[k].mean_Pa));
    }
    std::vector<double> d;
    for (auto& a : r.c1)
      for (auto& b : r.c4)
        if (a.packing_seed == b.packing_seed && std::abs(a.sigma3_Pa - b.sigma3_Pa) < 1)
          d.push_back(a.peak_differential_Pa - b.peak_differential_Pa);
    const MeanSd m = mean_sd(d);
    const double mean = m.mean, se = d.empty() ? 0 : m.sd / std::sqrt(static_cast<double>(d.size()));
    out.push_back({"C1 (inclusion-rich) stronger than C4 (inclusion-poor)" + over,
                   fmt::format("C1 - C4 = {} MPa; stronger at {} of {} pressures; over all {} pairs {:+.2f} +- {:.2f} MPa "
                               "(mean +- standard error)",
                               diffs, stronger, p1.size(), d.size(), 1e-6 * mean, 1e-6 * se),
                   "C1 stronger on average (seed 000: by 1.79-3.05 MPa)", mean > 0});
  }
  return out;
}

}  // namespace ff::batch
