// `fracflow validate-saturated`: seed 004's study (Krzaczek, Tejchman & Nitka 2024, Granular
// Matter 26:38) as one command. 2D concrete-like specimens of bonded discs with the seed's
// contact law (A1-A7, dem.contact_law = dem.bond_law = "cohesive") under uniaxial compression
// with the pore network (saturated_ucs driver) at liquid saturations 0, 0.5, 1 and several liquid
// viscosities, over a few packings; writes docs/validation/saturated_concrete.md with the strength
// table, the size of each effect, the maximum pore pressure against the vertical strain (the
// seed's graphical abstract), crack counts and pictures of pressure and cracks. The trends are
// measured and reported as found: nothing is fitted to the seed.
#include <fmt/chrono.h>
#include <fmt/format.h>
#include <sys/utsname.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <cstdint>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>

#include "batch/jobs.hpp"
#include "batch/run_case.hpp"
#include "commands.hpp"
#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "core/log.hpp"
#include "drivers/curve_peak.hpp"
#include "io/csv.hpp"
#include "io/run_folder.hpp"
#include "io/scenario.hpp"

namespace fs = std::filesystem;
using namespace ff;

namespace {

struct Args {
  std::string out = "runs/validate_saturated", doc = "docs/validation/saturated_concrete.md";
  std::vector<double> saturations = {0.0, 0.5, 1.0};
  std::vector<double> viscosities = {1e-3, 1e-1};
  // Platens 2 mm/s each (strain rate 0.2 1/s): at 20 mm/s the dry strength still depended on the
  // rate (15.6 against 17.0 kPa per m) and both waters stayed undrained (docs/saturated.md).
  double width = 10e-3, height = 20e-3, radius_min = 0.4e-3, radius_max = 0.6e-3, velocity = 0.002;
  double bond_gap = 0.5;  // x radius_min: neighbours this close are bonded (0.1: ~1.7 bonds per disc, brittle)
  double safety = 0.3;    // dem.time_step_safety (of the critical step with the pore fluid's stiffness)
  int seed = 7, threads = 1, packings = 3, jobs = 1;
  // fluid.liquid_placement of the partly saturated runs: at rest a wetting liquid holds the smallest
  // pores (capillarity); "uniform" (each pore half full) is the earlier study's.
  std::string placement = "smallest_pores_first";
  bool quick = false, overwrite = false, resume = false;
};

// The seed's law with concrete-like micro-parameters (module Ec, Ks/Kn, friction tan(mu_c),
// cohesion C and tension T of Nitka & Tejchman's cement matrix; docs/saturated.md), water in the
// pores, lateral faces drained, impermeable platens.
std::string scenario(const Args& a) {
  return fmt::format(R"(driver = "saturated_ucs"
title = "validate-saturated: seed 004 2D UCS, cohesive law A1-A7"
[dem]
dim = 2
contact_law = "cohesive"
bond_law = "cohesive"
local_damping = 0.08
time_step_safety = {}
[dem.group.matrix]
density = {}
[dem.contact.matrix-matrix]
ec = 11.3e9
nu_c = 0.2
friction = 0.3249
[dem.bond.matrix-matrix]
cohesion = 140e6
tension = 25e6
[sample]
shape = "box"
width = {}
height = {}
radius_min = {}
radius_max = {}
porosity = 0.2
bond_gap = {}
seed = {}
[ucs]
platen_velocity = {}
platen_friction = 0.1
max_strain = 0.01
[fluid]
drainage = "sides"
liquid_placement = "{}"
[output]
vtk = false
plots = false
progress_interval = 0
)",
                     a.safety, 2600 * 4 * 0.25 * (a.radius_min + a.radius_max) / 3, a.width, a.height, a.radius_min,
                     a.radius_max, a.bond_gap * a.radius_min, a.seed, a.velocity, a.placement);
}

void write_text(const fs::path& f, const std::string& t) {
  std::ofstream o(f);
  o << t;
  if (!o) throw Error(fmt::format("cannot write '{}'", f.string()));
}

// The strength is the peak of the quasi-static curve: rows whose unbalanced-force ratio is below
// this. In a saturated specimen the crack burst after the peak can drive pore pressures to 100+
// MPa and throw grains onto the platens for a row or two; that spike (unbalanced-force ratio
// 0.2-1.4) is a dynamic transient, not a strength, and it is not reproducible: the same packing
// gave 9.9 and 20.7 kPa for it after round-off changes, against 7.674 and 7.670 kPa for the
// quasi-static peak (docs/saturated.md, "Peak stress"). The rows excluded before the peak are the
// platens' start-up and small crack events (in the study's 15 runs: at most 0.94 x UCS but one, 1.01).
constexpr double kQuasiStatic = drivers::kQuasiStaticUnbalance;

struct Case {
  double saturation = 0, viscosity = 0;
  int seed = 0;
  fs::path dir;
  // ucs: the largest platen stress of the rows in equilibrium (kQuasiStatic); burst: the largest of all rows.
  double ucs = std::numeric_limits<double>::quiet_NaN(), strain_at_peak = 0, ucs_layer = 0, burst = 0, burst_ratio = 0;
  std::size_t peak_row = 0;
  double p_max_prepeak = 0, p_mean_at_peak = 0, strain_at_pmax = 0;
  double cracks_at_peak = 0, cracks_final = 0, tensile_final = 0, shear_final = 0, wall = 0;
  double steps = 0, implicit_steps = 0;  // DEM steps, and those whose flow was one implicit step
  long implicit_above = 0;                // the run's fluid.implicit_above (summary.json)
  long particles = 0, bonds = 0;
  enum class Source : std::uint8_t { Run, Continued, Read } source = Source::Run;  // Continued, Read: --resume
};

Case run_case(const fs::path& scen, const Args& a, double s, double mu, int seed, const fs::path& dir) {
  Case c;
  c.saturation = s;
  c.viscosity = mu;
  c.seed = seed;
  c.dir = dir;
  batch::InProcessRun r;
  r.out_dir = dir;
  r.threads = a.threads;
  const std::string what = fmt::format("S = {:g}, mu = {:g} Pa s, seed {}", s, mu, seed);
  if (stop_requested())  // a stop signal: the runs under way checkpoint, no new one starts
    throw InputError(fmt::format("validate-saturated: {} not started ({})", what, stop_signal_name()));
  RunStatus st = RunStatus::Finished;
  // --resume: a finished run (its summary.json written) is read as it is, an interrupted one continues
  // from its checkpoint, one stopped before its first checkpoint starts again.
  if (a.resume && fs::exists(dir / "summary.json")) {
    log::info("validate-saturated: {}: finished before, read from {}", what, dir.string());
    c.source = Case::Source::Read;
  } else if (a.resume && fs::exists(dir / "checkpoint")) {
    log::info("validate-saturated: {}: continuing from {}/checkpoint", what, dir.string());
    st = batch::resume_in_process(dir, r);
    c.source = Case::Source::Continued;
  } else {
    if (a.resume && fs::exists(dir)) {
      if (!fs::exists(dir / ".fracflow"))
        throw InputError(fmt::format("--resume: '{}' is not a run of this study (no .fracflow marker); move it away",
                                     dir.string()));
      fs::remove_all(dir);  // the study's own run, stopped before it wrote a checkpoint
    }
    log::info("validate-saturated: {}", what);
    st = batch::run_in_process(scen.string(),
                               {fmt::format("fluid.saturation={}", s), fmt::format("fluid.liquid_viscosity={}", mu),
                                fmt::format("sample.seed={}", seed)},
                               r);
  }
  if (st != RunStatus::Finished)
    throw InputError(fmt::format("validate-saturated: the run {} ({}) stopped before its end{}; continue the study "
                                 "with the same options and --resume",
                                 dir.string(), what,
                                 stop_requested() ? " (" + stop_signal_name() + ", after a checkpoint)" : std::string()));
  std::ifstream f(dir / "summary.json");
  const auto j = nlohmann::json::parse(f);
  if (j["ucs_Pa"].is_number()) c.ucs = j["ucs_Pa"];
  if (j.contains("layer") && j["layer"].contains("ucs_Pa")) c.ucs_layer = j["layer"]["ucs_Pa"];
  c.wall = j.value("wall_time_s", 0.0);
  c.steps = j.value("steps", 0.0);
  if (j.contains("fluid")) {
    c.implicit_steps = j["fluid"].value("implicit_flow_steps", 0.0);
    c.implicit_above = j["fluid"].value("implicit_above", 0L);
  }
  if (j.contains("sample")) {
    c.particles = j["sample"].value("particles", 0L);
    c.bonds = j["sample"].value("bonds", 0L);
  }
  const CsvTable cols = read_csv(dir / "series.csv");
  const auto& stress = cols.column("axial_stress_Pa");
  const auto& strain = cols.column("axial_strain");
  for (double v : stress) c.burst = std::max(c.burst, v);
  const auto qs = drivers::quasi_static_peak(cols, "axial_stress_Pa");
  if (!qs)
    throw Error(fmt::format("validate-saturated: {} has no row near equilibrium (unbalanced-force ratio < {})",
                            (dir / "series.csv").string(), kQuasiStatic));
  const std::size_t peak = qs->row;
  // The layer strength scales as the driver's (the same factor: the mean layer thickness).
  if (c.ucs > 0) c.ucs_layer *= qs->stress / c.ucs;
  c.burst_ratio = c.burst / qs->stress;
  c.ucs = qs->stress;
  c.peak_row = peak;
  c.strain_at_peak = qs->strain;
  const auto& p_max = cols.column("max_pore_pressure_Pa");
  for (std::size_t k = 0; k <= peak && k < stress.size(); ++k) {
    if (p_max[k] > c.p_max_prepeak) {
      c.p_max_prepeak = p_max[k];
      c.strain_at_pmax = strain[k];
    }
  }
  c.p_mean_at_peak = cols.column("mean_pore_pressure_Pa")[peak];
  c.cracks_at_peak = cols.column("cracks_total")[peak];
  c.cracks_final = cols.column("cracks_total").back();
  c.tensile_final = cols.column("cracks_tensile").back();
  c.shear_final = cols.column("cracks_shear").back();
  return c;
}

double mean_of(const std::vector<const Case*>& v, double Case::*m) {
  double s = 0;
  for (auto* c : v) s += c->*m;
  return v.empty() ? std::numeric_limits<double>::quiet_NaN() : s / static_cast<double>(v.size());
}
double range_of(const std::vector<const Case*>& v, double Case::*m) {
  if (v.empty()) return 0;
  double lo = v[0]->*m, hi = lo;
  for (auto* c : v) lo = std::min(lo, c->*m), hi = std::max(hi, c->*m);
  return hi - lo;
}

// The pictures: max pore pressure against vertical strain (the seed's graphical abstract),
// stress-strain curves, and the pore pressure at the peak with the cracks (matplotlib).
const char* kPictures = R"PY(
import csv, json, sys, os
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.collections import PolyCollection
cases = json.load(open(sys.argv[1])); img = sys.argv[2]; prefix = sys.argv[3]
def series(d):
    rows = list(csv.DictReader(open(os.path.join(d, "series.csv"))))
    return {k: [float(r[k]) for r in rows] for k in rows[0]}
def label(c): return "dry (S = 0)" if c["s"] == 0 else "S = %g, mu = %g Pa s" % (c["s"], c["mu"])
first = [c for c in cases if c["first"]]
fig, ax = plt.subplots(figsize=(6.4, 4.2))
for c in first:
    if c["s"] == 0: continue
    s = series(c["dir"]); k = c["peak_row"]
    ax.plot([100 * e for e in s["axial_strain"][:k + 1]], [1e-6 * p for p in s["max_pore_pressure_Pa"][:k + 1]], label=label(c))
ax.set_xlabel("vertical normal strain [%]"); ax.set_ylabel("maximum pore pressure [MPa]")
ax.set_title("Maximum pore pressure up to the peak stress"); ax.grid(alpha=0.3); ax.legend(fontsize=8)
fig.tight_layout(); fig.savefig(os.path.join(img, prefix + "_pmax_strain.png"), dpi=120); plt.close(fig)
fig, ax = plt.subplots(figsize=(6.4, 4.2))
for c in first:
    s = series(c["dir"])
    ax.plot([100 * e for e in s["axial_strain"]], [1e-6 * p for p in s["axial_stress_Pa"]], label=label(c))
ax.set_xlabel("vertical normal strain [%]"); ax.set_ylabel("axial stress [MPa per m of disc thickness]")
ax.set_title("Stress-strain curves (first packing)"); ax.grid(alpha=0.3); ax.legend(fontsize=8)
fig.tight_layout(); fig.savefig(os.path.join(img, prefix + "_stress_strain.png"), dpi=120); plt.close(fig)
pics = [c for c in first if c["picture"]]
fig, axs = plt.subplots(1, len(pics), figsize=(3.2 * len(pics), 5.2), squeeze=False)
for ax, c in zip(axs[0], pics):
    tri, pr = [], []
    for r in csv.DictReader(open(os.path.join(c["dir"], "pores_at_peak.csv"))):
        tri.append([(1e3 * float(r["x%d_m" % i]), 1e3 * float(r["y%d_m" % i])) for i in range(3)])
        pr.append(1e-6 * float(r["pressure_Pa"]))
    pc = PolyCollection(tri, array=pr, cmap="viridis", edgecolors="none")
    ax.add_collection(pc); fig.colorbar(pc, ax=ax, shrink=0.6, label="pore pressure [MPa]")
    xs, ys, cs = [], [], []
    if os.path.exists(os.path.join(c["dir"], "cracks.csv")):
        for r in csv.DictReader(open(os.path.join(c["dir"], "cracks.csv"))):
            xs.append(1e3 * float(r["x_m"])); ys.append(1e3 * float(r["y_m"]))
            cs.append("red" if r["mode"] == "tensile" else "orange")
    ax.scatter(xs, ys, s=6, c=cs, marker="x", linewidths=0.8)
    ax.set_aspect("equal"); ax.autoscale_view(); ax.set_xlabel("x [mm]"); ax.set_ylabel("y [mm]")
    ax.set_title(label(c) + "\npressure at the largest stress, all cracks", fontsize=8)
fig.tight_layout(); fig.savefig(os.path.join(img, prefix + "_pressure_cracks.png"), dpi=120); plt.close(fig)
)PY";

// The options that shape the results and differ from the defaults, as typed: the report's command
// line, so that it can be run again as it stands.
std::string nondefault_options(const Args& a) {
  const Args d;
  auto list = [](const std::vector<double>& v) {
    std::string s;
    for (double x : v) s += s.empty() ? fmt::format("{:g}", x) : fmt::format(",{:g}", x);
    return s;
  };
  std::string s;
  if (a.quick) s += " --quick";
  if (a.saturations != d.saturations) s += " --saturations " + list(a.saturations);
  if (a.viscosities != d.viscosities) s += " --viscosities " + list(a.viscosities);
  if (!a.quick && a.width != d.width) s += fmt::format(" --width {:g}", a.width);
  if (!a.quick && a.height != d.height) s += fmt::format(" --height {:g}", a.height);
  if (a.velocity != d.velocity) s += fmt::format(" --velocity {:g}", a.velocity);
  if (a.placement != d.placement) s += " --liquid-placement " + a.placement;
  if (a.seed != d.seed) s += fmt::format(" --seed {}", a.seed);
  if (a.bond_gap != d.bond_gap) s += fmt::format(" --bond-gap {:g}", a.bond_gap);
  if (a.safety != d.safety) s += fmt::format(" --time-step-safety {:g}", a.safety);
  if (!a.quick && a.packings != d.packings) s += fmt::format(" --packings {}", a.packings);
  return s;
}

int run_validate(Args a) {
  if (a.quick) {
    a.packings = 1;
    a.width = 8e-3;
    a.height = 16e-3;
  }
  const fs::path out = a.out;
  const fs::path scen = out / "specimen.toml";
  if (a.resume && a.overwrite) throw InputError("--resume continues the study in --out; --overwrite replaces it: not both");
  FolderLock out_lock;  // one study per folder at a time
  if (a.resume) {
    if (!fs::exists(scen))
      throw InputError(fmt::format("--resume: '{}' holds no study (no specimen.toml)", out.string()));
    if (read_text_file(scen.string()) != scenario(a))
      throw InputError(fmt::format("--resume: the study in '{}' was started with other options (its specimen.toml "
                                   "differs from what these options give: width, height, velocity, bond gap, time "
                                   "step safety, --quick); give the same options, or a new --out",
                                   out.string()));
    out_lock = FolderLock::acquire(out);
  } else {
    if (!a.overwrite && fs::is_directory(out) && !fs::is_empty(out))
      throw InputError(fmt::format("'{}' exists; pass --overwrite to replace it, or --resume to continue it",
                                   out.string()));
    // --overwrite replaces only a folder of ours (its marker), never the current directory or home.
    out_lock = prepare_batch_folder(out, a.overwrite, "validate-saturated study folder");
    write_text(scen, scenario(a));
  }
  const auto t0 = std::chrono::steady_clock::now();
  struct Spec {
    double s, mu;
    int seed;
  };
  std::vector<Spec> specs;
  for (int k = 0; k < a.packings; ++k)
    for (double s : a.saturations) {
      // Dry: the liquid's viscosity plays no part; one run.
      const std::vector<double> mus = s == 0 ? std::vector<double>{a.viscosities.front()} : a.viscosities;
      for (double mu : mus) specs.push_back({s, mu, a.seed + k});
    }
  // --jobs cases at a time, each run in this process (batch::run_in_process); the report keeps this order.
  std::vector<Case> cases(specs.size());
  std::vector<std::exception_ptr> failed(specs.size());
  batch::run_jobs(specs.size(), a.jobs, [&](std::size_t k) {
    const Spec& c = specs[k];
    try {
      cases[k] = run_case(scen, a, c.s, c.mu, c.seed, out / fmt::format("S{:g}_mu{:g}_seed{}", c.s, c.mu, c.seed));
    } catch (...) {
      failed[k] = std::current_exception();
    }
  });
  for (const auto& e : failed)
    if (e) std::rethrow_exception(e);
  const double total_wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  auto group = [&](double s, double mu) {
    std::vector<const Case*> v;
    for (const auto& c : cases)
      if (c.saturation == s && (s == 0 || c.viscosity == mu)) v.push_back(&c);
    return v;
  };
  // Effects as paired ratios: each case against the dry run (or the lower viscosity) of the SAME
  // packing, then the mean and range over packings; the packings differ far more than the fluid does.
  auto ucs_of = [&](double s, double mu, int seed) {
    for (const auto& c : cases)
      if (c.seed == seed && c.saturation == s && (s == 0 || c.viscosity == mu)) return c.ucs;
    return std::numeric_limits<double>::quiet_NaN();
  };
  struct Ratio {
    double mean = 0, lo = 0, hi = 0;
  };
  auto paired = [&](double s1, double mu1, double s0, double mu0) {
    Ratio r{0, std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
    for (int k = 0; k < a.packings; ++k) {
      const double q = ucs_of(s1, mu1, a.seed + k) / ucs_of(s0, mu0, a.seed + k) - 1;
      r.mean += q / a.packings;
      r.lo = std::min(r.lo, q);
      r.hi = std::max(r.hi, q);
    }
    return r;
  };
  std::string md;
  md += "# Seed 004: partially saturated concrete under uniaxial compression (2D)\n\n";
  long n_read = 0, n_continued = 0;
  for (const auto& c : cases)
    n_read += c.source == Case::Source::Read, n_continued += c.source == Case::Source::Continued;
  const std::string resumed =
      a.resume ? fmt::format("; continued with --resume: {} run(s) read as finished before, {} continued from their "
                             "checkpoints (the runs' own wall times are in the table below)",
                             n_read, n_continued)
               : std::string();
  md += fmt::format("Generated by `fracflow validate-saturated{}` on {} ({} thread(s) per run, {} run(s) at a time, {:.0f} s "
                    "in all{}). Do not edit by hand.\n\n",
                    nondefault_options(a),
                    fmt::format("{:%Y-%m-%d %H:%M} UTC", fmt::gmtime(std::time(nullptr))),
                    a.threads, std::min<int>(a.jobs, static_cast<int>(specs.size())), total_wall, resumed);
  const Case& c0 = cases.front();
  md += fmt::format(
      "**Specimen.** {:.0f} x {:.0f} mm box of {} bonded discs (radii {:.2f}-{:.2f} mm, {} cohesive bonds), "
      "{} packing(s) (sample.seed {}..{}), neighbours closer than {:.3f} mm bonded. Seed 004's DEM law (Appendix A, "
      "A1-A7; `dem.contact_law = dem.bond_law = "
      "\"cohesive\"`, src/dem/bond/cohesive_bond.hpp): Ec = 11.3 GPa, Ks/Kn = 0.2, tan(mu_c) = 0.325 (18 deg), "
      "C = 140 MPa, T = 25 MPa, alpha_d = 0.08. Platens {:g} m/s each (strain rate {:.2g} 1/s), lateral faces "
      "drained at 0.1 MPa, platens impermeable. Pore network of seed 004 (B1-B28): water as a barotropic liquid "
      "(K = 2.2 GPa), air as an ideal gas; B1 h0 = 1 um, h_inf = 0.1 um, B2 gamma = 0.01; forces over the spheres' "
      "height 2 r (as the law's forces are those of spheres): channel shear (B25, B28) and the pore pressure as "
      "p dV/dx on each grain, the gradient of the pore's void (`fluid.pressure_forces = void_gradient`: seed 004's "
      "B26-B27 arc force is not the gradient of the void, and with it the saturated specimens fluttered, kinetic "
      "energy growing before the first crack; docs/saturated.md, \"Pressure forces\"); a retriangulation carries the "
      "pores' pressures over (`fluid.remap = pressure`; conserving the mass instead moved every pore by 1.5-8 MPa). "
      "Partial saturation: `fluid.liquid_placement = {}`{}.\n\n",
      1e3 * a.width, 1e3 * a.height, c0.particles, 1e3 * a.radius_min, 1e3 * a.radius_max, c0.bonds, a.packings, a.seed,
      a.seed + a.packings - 1, 1e3 * a.bond_gap * a.radius_min, a.velocity, 2 * a.velocity / a.height,
      a.placement,
      a.placement == "uniform" ? " (every pore holds the saturation's fraction of liquid)"
                               : " (capillary equilibrium of a wetting liquid: the smallest pores liquid-full up to the "
                                 "saturation, the largest gas only)");
  md += fmt::format(
      "**Stress units.** The driver divides the platen force by width x 1 m (fracflow's discs are 1 m thick); the "
      "seed's forces are those of spheres in one layer, so the strength per layer of mean thickness 2 r is also "
      "given (column *UCS layer*). Ratios do not depend on this. The discs' density is the spheres' (2600 kg/m3) "
      "per 1 m of disc, 2600 x 4 r/3, so that masses match the sphere forces. Time step {} x the critical step that "
      "counts the pore fluid's stiffness on each grain (`fluid.stiffness_in_time_step`; a liquid-full pore adds "
      "about two contact stiffnesses per face, so the saturated specimens' step is the shorter). The flow: explicit "
      "sub-steps within each DEM step (seed 004's scheme), or one backward-Euler step where more than "
      "`fluid.implicit_above` = {} would be needed (the share of such DEM steps is in the runs' table). Interpretation "
      "and the checks behind it: docs/saturated.md.\n\n",
      a.safety, c0.implicit_above);
  md += fmt::format(
      "**Strength.** UCS is the largest platen stress among the rows of `series.csv` near equilibrium (unbalanced-force "
      "ratio below {:g}; the rows excluded before the peak are the platens' start-up and small crack events, in the "
      "study's 15 runs at most 0.94 x UCS but one row at 1.01 x UCS). A saturated specimen's crack burst can drive pore "
      "pressures above 100 MPa and throw grains onto the platens for a row or two (unbalanced-force ratio 0.2-1.4): "
      "that spike is a dynamic transient, and it does not repeat (the same packing gave 9.9 and 20.7 kPa for it after "
      "round-off changes in the network code, against 7.674 and 7.670 kPa for the quasi-static peak). The largest "
      "stress of all rows is in the runs' table.\n\n",
      kQuasiStatic);
  md += "## Strength by saturation and viscosity\n\n";
  md += "| S | mu [Pa s] | UCS, 1 m discs [kPa] (range) | UCS layer [MPa] | vs dry (paired) | strain at peak [%] | max p before peak "
        "[MPa] | mean p at peak [MPa] | cracks at peak | cracks final (tensile/shear) | runs |\n";
  md += "|---|---|---|---|---|---|---|---|---|---|---|\n";
  struct Row {
    double s, mu, ucs;
  };
  std::vector<Row> rows;
  for (double s : a.saturations) {
    const std::vector<double> mus = s == 0 ? std::vector<double>{a.viscosities.front()} : a.viscosities;
    for (double mu : mus) {
      const auto g = group(s, mu);
      const double u = mean_of(g, &Case::ucs);
      rows.push_back({s, mu, u});
      md += fmt::format("| {:g} | {} | {:.3f} ({:.3f}) | {:.3f} | {:+.1f} % | {:.4f} | {:.3f} | {:.3f} | {:.0f} | {:.0f} "
                        "({:.0f}/{:.0f}) | {} |\n",
                        s, s == 0 ? std::string("-") : fmt::format("{:g}", mu), 1e-3 * u, 1e-3 * range_of(g, &Case::ucs),
                        1e-6 * mean_of(g, &Case::ucs_layer), 100 * paired(s, mu, 0, 0).mean, 100 * mean_of(g, &Case::strain_at_peak),
                        1e-6 * mean_of(g, &Case::p_max_prepeak), 1e-6 * mean_of(g, &Case::p_mean_at_peak),
                        mean_of(g, &Case::cracks_at_peak), mean_of(g, &Case::cracks_final), mean_of(g, &Case::tensile_final),
                        mean_of(g, &Case::shear_final), g.size());
    }
  }
  // The size of each effect, and whether the seed's trends hold (measured, as found).
  md += "\n## Size of each effect\n\n";
  bool dry_strongest = true, falls_with_s = true, falls_with_mu = true;
  md += "Paired: each packing's run against the same packing's dry run (or lower viscosity); mean [min, max] over "
        "the packings.\n\n";
  for (double mu : a.viscosities) {
    double prev = 0;
    for (double s : a.saturations) {
      if (s == 0) continue;
      const Ratio r = paired(s, mu, 0, 0);
      md += fmt::format("- saturation 0 -> {:g} at mu = {:g} Pa s: UCS {:+.1f} % [{:+.1f}, {:+.1f}]\n", s, mu, 100 * r.mean,
                        100 * r.lo, 100 * r.hi);
      if (r.mean >= 0) dry_strongest = false;
      if (r.mean >= prev) falls_with_s = false;
      prev = r.mean;
    }
  }
  for (double s : a.saturations) {
    if (s == 0) continue;
    for (std::size_t k = 1; k < a.viscosities.size(); ++k) {
      const Ratio r = paired(s, a.viscosities[k], s, a.viscosities[k - 1]);
      md += fmt::format("- viscosity {:g} -> {:g} Pa s at S = {:g}: UCS {:+.1f} % [{:+.1f}, {:+.1f}]\n", a.viscosities[k - 1],
                        a.viscosities[k], s, 100 * r.mean, 100 * r.lo, 100 * r.hi);
      if (r.mean >= 0) falls_with_mu = false;
    }
  }
  double noise = 0;
  for (double s : a.saturations)
    for (double mu : a.viscosities) {
      const auto g = group(s, mu);
      const double m = mean_of(g, &Case::ucs);
      if (g.size() > 1) noise = std::max(noise, range_of(g, &Case::ucs) / m);
    }
  md += fmt::format("- packing-to-packing range of the UCS itself (largest over the cases, relative to the mean): {}\n\n",
                    a.packings > 1 ? fmt::format("{:.2f} %", 100 * noise)
                    : a.quick      ? std::string("one packing only (--quick)")
                                   : std::string("one packing only (--packings 1)"));
  md += fmt::format("Seed 004's trends (paired means; a difference smaller than the paired range is not resolved): dry "
                    "specimen the strongest: **{}**; strength falls as saturation rises: **{}**; strength falls as "
                    "viscosity rises: **{}**.\n\n",
                    dry_strongest ? "yes" : "no", falls_with_s ? "yes" : "no", falls_with_mu ? "yes" : "no");
  // Pictures.
  const fs::path doc = a.doc;
  const fs::path images = doc.parent_path() / "images";
  fs::create_directories(images);
  nlohmann::json jc = nlohmann::json::array();
  for (const auto& c : cases) {
    const bool first = c.seed == a.seed;
    const bool picture = first && (c.saturation == 0 || (c.saturation == a.saturations.back() &&
                                                         (c.viscosity == a.viscosities.front() || c.viscosity == a.viscosities.back())));
    jc.push_back({{"s", c.saturation}, {"mu", c.viscosity}, {"dir", fs::absolute(c.dir).string()}, {"first", first},
                  {"picture", picture}, {"peak_row", c.peak_row}});
  }
  write_text(out / "cases.json", jc.dump(1));
  write_text(out / "pictures.py", kPictures);
  const std::string cmd = fmt::format("/usr/bin/python3 '{}' '{}' '{}' saturated > '{}' 2>&1", (out / "pictures.py").string(),
                                      (out / "cases.json").string(), images.string(), (out / "pictures.log").string());
  const bool pictures = std::system(cmd.c_str()) == 0;
  if (!pictures) log::warn("validate-saturated: the pictures failed; see {}", (out / "pictures.log").string());
  md += "## Figures\n\n";
  if (pictures) {
    md += "Maximum pore pressure against vertical normal strain up to the peak stress (seed 004's graphical abstract):\n\n"
          "![max pore pressure against strain](images/saturated_pmax_strain.png)\n\n"
          "![stress-strain curves](images/saturated_stress_strain.png)\n\n"
          "Pore pressure at the largest platen stress of the run (the driver's `pores_at_peak.csv`: after a burst "
          "where the last column of the runs' table is above 1) and the cracks of the whole run (x: tensile red, "
          "shear orange):\n\n"
          "![pore pressure and cracks](images/saturated_pressure_cracks.png)\n\n";
  } else {
    md += "(the pictures could not be drawn: /usr/bin/python3 with matplotlib is needed)\n\n";
  }
  md += "## Runs\n\n| case | UCS, 1 m discs [kPa] | max p before peak [MPa] at strain [%] | cracks final | DEM steps "
        "| implicit flow steps [%] | wall [s] (since the run's last start: after a stop, the resumed part) "
        "| largest stress of all rows [kPa] (/ UCS) |\n|---|---|---|---|---|---|---|---|\n";
  for (const auto& c : cases)
    md += fmt::format("| `{}` | {:.3f} | {:.3f} at {:.4f} | {:.0f} | {:.0f} | {:.1f} | {:.1f} | {:.3f} ({:.2f}) |\n",
                      c.dir.filename().string(), 1e-3 * c.ucs, 1e-6 * c.p_max_prepeak, 100 * c.strain_at_pmax,
                      c.cracks_final, c.steps, c.steps > 0 ? 100 * c.implicit_steps / c.steps : 0.0, c.wall,
                      1e-3 * c.burst, c.burst_ratio);
  utsname u{};
  uname(&u);
  md += fmt::format("\nMachine: {} {}. Runs under `{}`.\n", u.sysname, u.machine, out.generic_string());
  fs::create_directories(doc.parent_path().empty() ? fs::path(".") : doc.parent_path());
  write_text(doc, md);
  fmt::print("report in {}, runs in {}\n", doc.string(), out.string());
  return 0;
}

const bool registered = ff::cli::register_command({"validate-saturated", [](CLI::App& app) {
  auto a = std::make_shared<Args>();
  auto* sub = app.add_subcommand("validate-saturated",
                                 "seed 004's study: UCS of 2D bonded concrete-like specimens (cohesive law A1-A7) at liquid "
                                 "saturations and viscosities with the pore network; writes docs/validation/saturated_concrete.md");
  sub->add_option("--out,-o", a->out, "folder of all the runs")->capture_default_str();
  sub->add_option("--doc", a->doc, "the markdown report to write (figures in its folder/images)")->capture_default_str();
  sub->add_option("--saturations", a->saturations, "liquid saturations (0 first: the dry reference)")
      ->delimiter(',')
      ->capture_default_str();
  sub->add_option("--viscosities", a->viscosities, "liquid viscosities [Pa s], increasing")->delimiter(',')->capture_default_str();
  sub->add_option("--width", a->width, "specimen width [m]")->check(CLI::PositiveNumber)->capture_default_str();
  sub->add_option("--height", a->height, "specimen height [m]")->check(CLI::PositiveNumber)->capture_default_str();
  sub->add_option("--velocity", a->velocity, "platen velocity, each [m/s]")->check(CLI::PositiveNumber)->capture_default_str();
  sub->add_option("--liquid-placement", a->placement,
                  "where a saturation below 1 puts the water (fluid.liquid_placement): uniform or smallest_pores_first")
      ->check(CLI::IsMember({"uniform", "smallest_pores_first"}))
      ->capture_default_str();
  sub->add_option("--seed", a->seed, "first packing seed")->capture_default_str();
  sub->add_option("--bond-gap", a->bond_gap, "neighbours closer than this x radius_min are bonded (sample.bond_gap)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  sub->add_option("--time-step-safety", a->safety,
                  "dem.time_step_safety: fraction of the critical step (with the pore fluid's stiffness) used")
      ->check(CLI::Range(1e-3, 1.0))
      ->capture_default_str();
  sub->add_option("--packings", a->packings, "packings per case; the report gives their mean and range")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  sub->add_option("--threads,-t", a->threads, "OpenMP threads per run")->check(CLI::PositiveNumber)->capture_default_str();
  sub->add_option("--jobs,-j", a->jobs, "runs at a time")->check(CLI::PositiveNumber)->capture_default_str();
  sub->add_flag("--quick", a->quick, "one packing of a 8 x 16 mm specimen (a smoke run)");
  sub->add_flag("--overwrite", a->overwrite, "replace an existing --out folder");
  sub->add_flag("--resume", a->resume,
                "continue the study in --out (same options): finished runs are read, interrupted ones continue from "
                "their checkpoints, the rest run");
  return ff::cli::Command::Run([a] {
    if (a->saturations.empty() || a->saturations.front() != 0)
      throw InputError("validate-saturated: --saturations must start with 0 (the dry reference)");
    if (a->viscosities.empty()) throw InputError("validate-saturated: --viscosities needs at least one value");
    return run_validate(*a);
  });
}});

}  // namespace
