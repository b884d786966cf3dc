// `fracflow validate-hydrofrac`: the breakdown pressure of the hydrofrac driver over a sweep of
// sigma_h against Hubbert & Willis (1957) and Haimson & Fairhurst (1967), as one command. It
// measures the rock's tensile strength with the direct-tension driver on the same material,
// runs the borehole block at each sigma_h with the sleeve (non-penetrating), with penetration and
// with the lattice Boltzmann fluid (unless --no-lbm), and writes docs/validation/hydrofrac.md (src/drivers/hydrofrac/breakdown_theory.hpp)
// with a figure. Every run is an ordinary results folder under --out.
#include <fmt/chrono.h>
#include <fmt/format.h>
#include <sys/utsname.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>

#include "batch/run_case.hpp"
#include "commands.hpp"
#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "core/log.hpp"
#include "drivers/hydrofrac/breakdown_theory.hpp"
#include "io/plot.hpp"
#include "io/run_folder.hpp"

namespace fs = std::filesystem;
using namespace ff;

namespace {

struct Args {
  std::string out = "runs/validate_hydrofrac", doc = "docs/validation/hydrofrac.md";
  std::vector<double> sigma_h = {1e6, 2e6, 3e6, 4e6};
  double sigma_H = 4e6;
  double width = 30e-3, radius_min = 0.3e-3, radius_max = 0.45e-3, hole = 3.5e-3, ramp = 2e10;
  int seed = 1, threads = 1, packings = 3;
  bool overwrite = false;
  bool lbm = true;  // also the lattice Boltzmann fluid on every block
  // The LBM fluid (as examples/hydrofrac_2d_lbm.toml: a viscous lab oil, the smallest grain two cells
  // across); K_eff so that the pressures up to lbm_max_pressure stay within 10 % of density variation.
  double lbm_viscosity = 1e-2, lbm_bulk_modulus = 6.5e8, lbm_max_pressure = 60e6;
};

std::vector<std::string> lbm_sets(const Args& a) {
  return {"injection.fluid=\"lbm\"",
          "fluid.density=1000",
          fmt::format("fluid.viscosity={}", a.lbm_viscosity),
          fmt::format("fluid.bulk_modulus={}", a.lbm_bulk_modulus),
          "fluid.cells_per_radius=1.0",
          "fluid.scheme=\"interpolated\"",
          fmt::format("injection.max_pressure={}", a.lbm_max_pressure)};
}

// The coal-matrix material of the UCS/Brazilian examples (examples/ucs_2d.toml), 2D.
const char* kMaterial = R"(
[dem]
dim = 2
bond_law = "parallel"
[dem.group.matrix]
density = 1390
[dem.contact.matrix-matrix]
emod = 2.09e9
kratio = 14.65
friction = 0.4
[dem.bond.matrix-matrix]
emod = 2.09e9
kratio = 14.65
tensile_strength = 17.4e6
cohesion = 17.4e6
friction_angle = 4.0
[output]
vtk = false
progress_interval = 0
)";

std::string block_scenario(const Args& a) {
  return fmt::format(R"(driver = "hydrofrac"
title = "validate-hydrofrac block"
{}
[sample]
shape = "box"
width = {}
height = {}
radius_min = {}
radius_max = {}
porosity = 0.2
bond_gap = {}
seed = {}
[borehole]
radius = {}
[insitu]
sigma_H = {}
sigma_h = {}
[injection]
ramp_rate = {}
)",
                     kMaterial, a.width, a.width, a.radius_min, a.radius_max, a.radius_min / 2, a.seed, a.hole, a.sigma_H,
                     0.5 * a.sigma_H, a.ramp);
}

// A bar 14 x 28 grains-scaled like the block's grains (the Brazilian tests' bar at 0.4-0.6 mm).
std::string tension_scenario(const Args& a) {
  const double r = 0.5 * (a.radius_min + a.radius_max);
  return fmt::format(R"(driver = "direct_tension"
title = "validate-hydrofrac: tensile strength of the block's material"
{}
[sample]
shape = "box"
width = {}
height = {}
radius_min = {}
radius_max = {}
porosity = 0.2
bond_gap = {}
seed = {}
[direct_tension]
grip_velocity = 0.1
)",
                     kMaterial, 28 * r, 56 * r, a.radius_min, a.radius_max, a.radius_min / 2, a.seed);
}

void write_text(const fs::path& f, const std::string& t) {
  std::ofstream o(f);
  o << t;
  if (!o) throw Error(fmt::format("cannot write '{}'", f.string()));
}

nlohmann::json run_one(const fs::path& scenario, const std::vector<std::string>& sets, const fs::path& dir, int threads) {
  batch::InProcessRun r;
  r.out_dir = dir;
  r.threads = threads;
  log::info("validate-hydrofrac: running {}", dir.string());
  if (batch::run_in_process(scenario.string(), sets, r) != RunStatus::Finished)
    throw Error(fmt::format("validate-hydrofrac: the run {} stopped before its end ({}); nothing is reported, run "
                            "the command again with --overwrite",
                            dir.string(), stop_cause_or("an ABORT file")));
  std::ifstream f(dir / "summary.json");
  return nlohmann::json::parse(f);
}

double number_or_nan(const nlohmann::json& j) { return j.is_number() ? j.get<double>() : std::numeric_limits<double>::quiet_NaN(); }

int run_validate(const Args& a) {
  const fs::path out = a.out;
  // --overwrite replaces only a folder of ours (its marker), never the current directory or home.
  const FolderLock out_lock = prepare_batch_folder(out, a.overwrite, "validate-hydrofrac folder");
  const fs::path block = out / "block.toml", tension = out / "tension.toml";
  write_text(block, block_scenario(a));
  write_text(tension, tension_scenario(a));
  const auto jt = run_one(tension, {}, out / "tension", a.threads);
  if (!jt["tensile_strength_Pa"].is_number())
    throw Error(fmt::format("the direct-tension run in {} found no tensile strength", (out / "tension").string()));
  drivers::hydrofrac::SweepContext ctx;
  ctx.tensile_strength = jt["tensile_strength_Pa"];
  ctx.tension_run = fmt::format("`{}`, {} disks", (out / "tension").generic_string(), jt["sample"]["particles"].dump());
  std::vector<drivers::hydrofrac::BreakdownPoint> pts;
  std::string lbm_words;
  for (double sh : a.sigma_h) {
    drivers::hydrofrac::BreakdownPoint p;
    p.sigma_H = a.sigma_H;
    p.sigma_h = sh;
    p.packings = a.packings;
    std::vector<double> init, bd, pen, lbm_init, lbm_bd;
    for (int k = 0; k < a.packings; ++k) {
      const std::vector<std::string> sets = {fmt::format("insitu.sigma_h={}", sh), fmt::format("sample.seed={}", a.seed + k)};
      const auto js = run_one(block, sets, out / fmt::format("sleeve_sh{:g}MPa_seed{}", 1e-6 * sh, a.seed + k), a.threads);
      bd.push_back(number_or_nan(js["breakdown"]["pressure_Pa"]));
      init.push_back(number_or_nan(js["breakdown"]["initiation_pressure_Pa"]));
      if (k == 0) {
        p.sleeve_azimuth_deg = js["breakdown"].contains("fracture") ? number_or_nan(js["breakdown"]["fracture"]["azimuth_deg"])
                                                                   : std::numeric_limits<double>::quiet_NaN();
        p.particles = js["sample"]["particles"];
        p.wall_time_s = js["wall_time_s"];
      }
      auto sets_p = sets;
      sets_p.push_back("injection.penetration=true");
      const auto jp = run_one(block, sets_p, out / fmt::format("penetration_sh{:g}MPa_seed{}", 1e-6 * sh, a.seed + k), a.threads);
      pen.push_back(number_or_nan(jp["breakdown"]["pressure_Pa"]));
      if (k == 0) p.wall_time_s += number_or_nan(jp["wall_time_s"]);
      if (a.lbm) {
        auto sets_l = sets;
        for (const auto& x : lbm_sets(a)) sets_l.push_back(x);
        const auto jl = run_one(block, sets_l, out / fmt::format("lbm_sh{:g}MPa_seed{}", 1e-6 * sh, a.seed + k), a.threads);
        lbm_bd.push_back(number_or_nan(jl["breakdown"]["pressure_Pa"]));
        lbm_init.push_back(number_or_nan(jl["breakdown"]["initiation_pressure_Pa"]));
        if (k == 0) p.wall_time_s += number_or_nan(jl["wall_time_s"]);
        if (k == 0 && lbm_words.empty())
          lbm_words = fmt::format("nu = {:g} m^2/s, K_eff = {:.3g} Pa, dx = {:.3g} mm ({} x {} cells), tau = {:.3f}, {} DEM "
                                  "sub-steps per LBM step, interpolated bounce-back, closed faces",
                                  a.lbm_viscosity, number_or_nan(jl["lbm"]["bulk_modulus_eff_Pa"]),
                                  1e3 * number_or_nan(jl["lbm"]["dx_m"]), jl["lbm"]["lattice"][0].dump(),
                                  jl["lbm"]["lattice"][1].dump(), number_or_nan(jl["lbm"]["tau"]), jl["lbm"]["sub_steps"].dump());
      }
    }
    // Means (NaN when a packing found no breakdown: the point is then not fitted) and ranges.
    auto mean = [](const std::vector<double>& v) {
      double s = 0;
      for (double x : v) s += x;
      return s / static_cast<double>(v.size());
    };
    auto range = [](const std::vector<double>& v) { return *std::max_element(v.begin(), v.end()) - *std::min_element(v.begin(), v.end()); };
    p.sleeve_initiation = mean(init);
    p.sleeve_breakdown = mean(bd);
    p.penetrating_breakdown = mean(pen);
    p.initiation_range = range(init);
    p.breakdown_range = range(bd);
    p.penetrating_range = range(pen);
    if (a.lbm) {
      p.lbm_breakdown = mean(lbm_bd);
      p.lbm_initiation = mean(lbm_init);
      p.lbm_range = range(lbm_bd);
    }
    pts.push_back(p);
  }
  // The figure: DEM points and both theories against sigma_h.
  const fs::path doc = a.doc;
  const fs::path images = doc.parent_path() / "images";
  fs::create_directories(images);
  {
    std::ofstream c(out / "breakdown.csv");
    c << "sigma_h_Pa,initiation_sleeve_Pa,breakdown_sleeve_Pa,breakdown_penetration_Pa,hubbert_willis_Pa,"
         "haimson_fairhurst_eta0_Pa" << (a.lbm ? ",breakdown_lbm_Pa" : "") << "\n";
    for (const auto& p : pts) {
      c << p.sigma_h << "," << p.sleeve_initiation << "," << p.sleeve_breakdown << "," << p.penetrating_breakdown << ","
        << drivers::hydrofrac::hubbert_willis(p.sigma_H, p.sigma_h, ctx.tensile_strength) << ","
        << drivers::hydrofrac::haimson_fairhurst(p.sigma_H, p.sigma_h, ctx.tensile_strength, 0);
      if (a.lbm) c << "," << p.lbm_breakdown;
      c << "\n";
    }
  }
  PlotSpec spec;
  spec.title = fmt::format("Breakdown pressure, sigma_H = {:g} MPa, T = {:.2f} MPa (measured)", 1e-6 * a.sigma_H,
                           1e-6 * ctx.tensile_strength);
  spec.x = "sigma_h_Pa";
  spec.x_scale = 1e-6;
  spec.xlabel = "sigma_h [MPa]";
  spec.y = {"initiation_sleeve_Pa", "breakdown_sleeve_Pa", "breakdown_penetration_Pa", "hubbert_willis_Pa",
            "haimson_fairhurst_eta0_Pa"};
  if (a.lbm) spec.y.push_back("breakdown_lbm_Pa");
  spec.y_scale = 1e-6;
  spec.ylabel = "borehole pressure [MPa]";
  const bool figure = plot_series(out / "breakdown.csv", images / "hydrofrac_breakdown.png", spec);
  const auto t = std::time(nullptr);
  ctx.date = fmt::format("{:%Y-%m-%d %H:%M} UTC", fmt::gmtime(t));
  utsname u{};
  uname(&u);
  ctx.machine = fmt::format("{} {}, {} thread(s)", u.sysname, u.machine, a.threads);
  ctx.command = fmt::format("fracflow validate-hydrofrac --packings {} --sigma-H {:g} --sigma-h {}{}", a.packings, a.sigma_H, [&] {
    std::string s;
    for (double v : a.sigma_h) s += (s.empty() ? "" : ",") + fmt::format("{:g}", v);
    return s;
  }(), a.lbm ? "" : " --no-lbm");
  ctx.lbm_fluid = lbm_words;
  ctx.block = fmt::format("A {:.0f} mm square 2D block of about {} bonded disks (radii {:.2f}-{:.2f} mm), the coal-matrix "
                          "micro-parameters of examples/ucs_2d.toml.",
                          1e3 * a.width, pts.empty() ? 0L : pts.front().particles, 1e3 * a.radius_min, 1e3 * a.radius_max);
  ctx.ramp_rate = a.ramp;
  ctx.hole_radius = a.hole;
  ctx.grain_radius = 0.5 * (a.radius_min + a.radius_max);
  std::string text = drivers::hydrofrac::breakdown_report(pts, ctx);
  if (figure) text += "\n![breakdown pressure against sigma_h](images/hydrofrac_breakdown.png)\n";
  fs::create_directories(doc.parent_path().empty() ? fs::path(".") : doc.parent_path());
  write_text(doc, text);
  fmt::print("report in {}, runs in {}\n", doc.string(), out.string());
  return 0;
}

const bool registered = ff::cli::register_command({"validate-hydrofrac", [](CLI::App& app) {
  auto a = std::make_shared<Args>();
  auto* sub = app.add_subcommand("validate-hydrofrac",
                                 "breakdown pressures of a sweep over sigma_h against Hubbert-Willis and Haimson-Fairhurst "
                                 "(tensile strength measured by direct tension); writes docs/validation/hydrofrac.md");
  sub->add_option("--out,-o", a->out, "folder of all the runs")->capture_default_str();
  sub->add_option("--doc", a->doc, "the markdown report to write (figure in its folder/images)")->capture_default_str();
  sub->add_option("--sigma-h", a->sigma_h, "minimum horizontal stresses of the sweep [Pa]")->delimiter(',')->capture_default_str();
  sub->add_option("--sigma-H", a->sigma_H, "maximum horizontal stress, fixed [Pa]")->check(CLI::PositiveNumber)->capture_default_str();
  sub->add_option("--width", a->width, "block side [m]")->check(CLI::PositiveNumber)->capture_default_str();
  sub->add_option("--radius-min", a->radius_min, "smallest grain radius [m]")->check(CLI::PositiveNumber)->capture_default_str();
  sub->add_option("--radius-max", a->radius_max, "largest grain radius [m]")->check(CLI::PositiveNumber)->capture_default_str();
  sub->add_option("--hole", a->hole, "borehole radius [m]")->check(CLI::PositiveNumber)->capture_default_str();
  sub->add_option("--ramp", a->ramp, "pressure ramp rate [Pa/s]")->check(CLI::PositiveNumber)->capture_default_str();
  sub->add_option("--seed", a->seed, "first packing seed")->capture_default_str();
  sub->add_option("--packings", a->packings, "packings (seeds) per sigma_h; the report gives their mean and range")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  sub->add_option("--threads,-t", a->threads, "OpenMP threads per run")->check(CLI::PositiveNumber)->capture_default_str();
  sub->add_flag("--overwrite", a->overwrite, "replace an existing --out folder");
  sub->add_flag("!--no-lbm", a->lbm, "skip the lattice Boltzmann fluid's runs (by default every block is also fractured by "
                                     "the LBM fluid of examples/hydrofrac_2d_lbm.toml)");
  return ff::cli::Command::Run([a] { return run_validate(*a); });
}});

}  // namespace
