// Sample genesis timing (issue 13, item 7): builds the dem_ucs sample (coal matrix, seed 000
// Table 7; cylinder of spheres with radii uniform in [0.4, 0.6] mm at porosity 0.38) by
// dem::build_sample and prints the wall time of genesis with what it reached: particles,
// porosity, equilibrium criterion (met or not), coordination numbers and locked-in stress.
// Sizes: --size 2k (12.5 x 25 mm, ~3.5k spheres), 25k (25 x 50 mm, ~28k, the dem_ucs default),
// 100k (40 x 80 mm, ~115k); or --diameter/--height. Threads: --threads N (default: every core).
#include <fmt/core.h>
#include <omp.h>

#include <chrono>
#include <ctime>
#include <cstdlib>
#include <string>

#include "core/error.hpp"
#include "dem/dem_params.hpp"
#include "dem/presets.hpp"
#include "dem/sample_builder.hpp"
#include "drivers/driver.hpp"
#include "io/scenario.hpp"

using namespace ff;

namespace {

[[noreturn]] void usage(int code) {
  fmt::print(code ? stderr : stdout,
             "Usage: genesis [--size 2k|25k|100k] [--diameter D --height H] [--porosity P] [--seed S]\n"
             "               [--threads N] [--set key=value ...]\n"
             "Times dem::build_sample on the dem_ucs cylinder (default --size 25k: 25 mm x 50 mm, radii\n"
             "0.4-0.6 mm, porosity 0.38) and prints what the genesis reached.\n");
  std::exit(code);
}

double number(const char* s, const std::string& opt) {
  char* end = nullptr;
  const double v = std::strtod(s, &end);
  if (end == s || *end != '\0' || !(v > 0)) {
    fmt::print(stderr, "genesis: {} needs a positive number, not '{}'\n", opt, s);
    usage(2);
  }
  return v;
}

}  // namespace

int main(int argc, char** argv) {
  double diameter = 25e-3, height = 50e-3, porosity = 0.38;
  long seed = 1;
  int threads = omp_get_num_procs();
  std::vector<std::string> overrides;
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    if (a == "-h" || a == "--help") usage(0);
    if (k + 1 >= argc) {
      fmt::print(stderr, "genesis: {} needs a value\n", a);
      usage(2);
    }
    const char* v = argv[++k];
    if (a == "--size") {
      const std::string s = v;
      if (s == "2k") diameter = 12.5e-3, height = 25e-3;
      else if (s == "25k") diameter = 25e-3, height = 50e-3;
      else if (s == "100k") diameter = 40e-3, height = 80e-3;
      else {
        fmt::print(stderr, "genesis: --size is 2k, 25k or 100k, not '{}'\n", s);
        usage(2);
      }
    } else if (a == "--diameter") diameter = number(v, a);
    else if (a == "--height") height = number(v, a);
    else if (a == "--porosity") porosity = number(v, a);
    else if (a == "--seed") seed = static_cast<long>(number(v, a));
    else if (a == "--threads") threads = static_cast<int>(number(v, a));
    else if (a == "--set") overrides.emplace_back(v);
    else {
      fmt::print(stderr, "genesis: unknown option '{}'\n", a);
      usage(2);
    }
  }
  try {
    const Driver& ucs = find_driver("ucs");
    ParamTable table = parameter_table(ucs);
    const std::string text = "driver = \"ucs\"\n" + std::string(dem::kCoalMatrixTable7Toml) +
                             fmt::format("[sample]\ndiameter = {}\nheight = {}\nporosity = {}\nseed = {}\n", diameter,
                                         height, porosity, seed);
    Config cfg = load_scenario(table, "<genesis benchmark>", text, overrides);
    omp_set_num_threads(threads);
    dem::DemSystem sys;
    sys.settings = dem::build_settings(cfg);
    sys.materials = dem::build_materials(cfg);
    const auto t0 = std::chrono::steady_clock::now();
    const std::clock_t c0 = std::clock();
    const dem::SampleInfo info = dem::build_sample(cfg, sys);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double cpu = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;  // all threads
    const auto n = static_cast<double>(sys.particles.size());
    fmt::print("genesis: {:g} x {:g} mm, {} threads: {} particles in {:.2f} s ({:.2f} s CPU; packing {:.2f} s, cycling {:.2f} s, {} steps); "
               "porosity {:.4f} (asked {:g}); equilibrium {} ({:.3g}, tolerance {:g}); bonds/particle {:.2f}, "
               "touching contacts/particle {:.2f}; locked-in stress {:.3g} Pa; {} floaters\n",
               diameter * 1e3, height * 1e3, threads, sys.particles.size(), s, cpu, info.packing_seconds,
               info.genesis_seconds - info.packing_seconds, info.genesis_steps, info.porosity, porosity,
               info.equilibrium_reached ? "reached" : "NOT reached", info.unbalanced_force_ratio,
               cfg.real("sample.genesis_tolerance"), 2.0 * static_cast<double>(info.bonds) / n,
               info.coordination_contacts, info.locked_in_stress, info.floaters);
  } catch (const std::exception& e) {
    fmt::print(stderr, "genesis: {}\n", e.what());
    return 1;
  }
  return 0;
}
