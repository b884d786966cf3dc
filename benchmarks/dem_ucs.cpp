// ucs-cylinder benchmark (issue 2, item 11; honest lines: issue 13, item 8): the DEM engine timed
// on a bonded sample compressed between two platens. The sample is either built by genesis (a
// 25 mm x 50 mm cylinder of spheres with radii uniform in [0.4, 0.6] mm, about 28,000 particles;
// --small: 12.5 mm x 25 mm) or read from a packing file (--packing FILE), so that fracflow can
// be timed on exactly the packing a peer code (ESyS-Particle, YADE) uses; --write-packing FILE
// exports the sample for the peers in the same format.
//
// Packing file (src/dem/packing_file.hpp): plain text, SI units, '#' starts a comment, blank
// lines ignored; one particle per line `x y z r` (centre and radius, metres); then optionally a
// line `bonds` followed by one bond per line `i j` (0-based indices in the order of the particle
// lines). Without a `bonds` line the bonds are installed between every pair whose gap is at most
// sample.bond_gap (--bond-gap), by the same function genesis uses (DemSystem::install_bonds).
// With a packing file there is no genesis: the particles are placed as given (in the spatial
// memory order genesis uses, unless --keep-order), the platens at the packing's extent along z.
//
// What the figures mean. From one loaded state (platens at 0.05 m/s each, 200 steps, so every
// bond and contact is active), each thread count 1, 2, 4, ... up to --max-threads starts from a
// copy of that state, runs 20 warm-up steps and then --steps timed steps in blocks of 50. A
// block's figure is particles x steps / wall seconds (particle-steps/s). Printed per thread
// count: the MEDIAN block first (the figure to quote: a fair middle on a shared machine), the
// best block beside it (the least disturbed block; an upper bound, up to 44% above the median
// at 2 threads on the project's shared 2-core machines), and the speed-up over 1 thread as the
// ratio of the medians. The program checks that every thread count ends with bit-identical
// positions and prints the share of each stage of the step over all timed blocks. With
// --membrane, the same sample is also stepped inside a flexible membrane (issue 4, item 9) on 1
// thread, interleaving 50-step blocks with and without it; the added step time is the median of
// the per-pair time ratios (the ratio of the best blocks beside it).
//
// Arguments are checked: an unknown option, a missing value or a value that is not a number in
// range is an error (exit code 2); a bad packing file is an error naming the line (exit code 1).
#include <fmt/core.h>
#include <omp.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.hpp"
#include "dem/dem_params.hpp"
#include "dem/packing_file.hpp"
#include "dem/presets.hpp"
#include "dem/sample_builder.hpp"
#include "drivers/driver.hpp"
#include "io/scenario.hpp"
#include "dem/diagnostics.hpp"
#include "dem/membrane/membrane_boundary.hpp"

using namespace ff;

namespace {

struct Options {
  long steps = 300;
  int max_threads = 0;  // 0: every core
  double diameter = 25e-3, height = 50e-3;
  bool small = false;
  bool membrane = false;
  bool energy = false;  // energy bookkeeping on in the timed steps (DemSettings::track_energy)
  int membrane_n_theta = 48;  // units around the sleeve (scenario default: 24)
  double radius_min = 0.4e-3, radius_max = 0.6e-3;
  double bond_gap = 0.05e-3;  // sample.bond_gap default (seed 000)
  bool bond_gap_set = false;
  std::string packing, write_packing;
  bool keep_order = false;
  bool radius_set = false;
};

constexpr long kBlock = 50;

void print_help() {
  const Options d;
  fmt::print(
      "Usage: dem_ucs [options]\n"
      "Times the DEM engine (particle-steps/s) on a bonded sample compressed between two platens, on\n"
      "1, 2, 4, ... threads, from one loaded state; checks that every thread count gives bit-identical\n"
      "positions.\n"
      "\n"
      "Options [default]:\n"
      "  --steps N             timed steps per thread count, in blocks of {} [{}]\n"
      "  --max-threads N       time 1, 2, 4, ... threads up to N [every core: {}]\n"
      "  --small               genesis of a {:g} mm x {:g} mm cylinder instead of {:g} mm x {:g} mm [off]\n"
      "  --radius-min X        smallest radius of genesis, m [{:g}]\n"
      "  --radius-max X        largest radius of genesis, m [{:g}]\n"
      "  --bond-gap X          sample.bond_gap, m: bonds between pairs whose gap is at most X (genesis,\n"
      "                        and a packing file without a bond list) [{:g}]\n"
      "  --packing FILE        time the packing in FILE instead of a genesis sample (format below) [none]\n"
      "  --keep-order          with --packing: keep the file's particle order in memory instead of the\n"
      "                        spatial order genesis uses [off]\n"
      "  --write-packing FILE  write the sample (particles and bond list, before any step) as a\n"
      "                        packing file, e.g. for a peer code [none]\n"
      "  --membrane            also time a flexible membrane at 5 MPa around the genesis sample, on\n"
      "                        1 thread (not with --packing) [off]\n"
      "  --membrane-n-theta N  membrane units around the sleeve [{}]\n"
      "  --energy              energy bookkeeping on in the timed steps, as in the DEM drivers [off]\n"
      "  -h, --help            print this text and exit\n"
      "\n"
      "What the figures mean: the sample is loaded for 200 steps (platens at 0.05 m/s each); each\n"
      "thread count starts from a copy of that state, runs 20 warm-up steps, then the timed steps in\n"
      "blocks of {}. A block's figure is particles x steps / wall seconds. `threads N:` prints the\n"
      "MEDIAN block first (quote this one), the best block beside it (least disturbed by other work;\n"
      "an upper bound, on a shared machine well above the median), and the speed-up over 1 thread as\n"
      "the ratio of the medians. `stages:` is each stage's share of the timed steps. --membrane\n"
      "prints the added step time as the median ratio of interleaved block pairs (best blocks beside).\n"
      "\n"
      "Packing file: plain text, SI units; '#' starts a comment, blank lines are ignored.\n"
      "  x y z r      one particle per line: centre and radius, m (r > 0)\n"
      "  bonds        optional: this word alone on a line, then\n"
      "  i j          one bond per line: 0-based indices of two particle lines\n"
      "Without a `bonds` line the bonds are installed by the --bond-gap rule, as after genesis; a\n"
      "`bonds` line with no pair below it means no bonds. The particles keep their positions and\n"
      "radii (group `matrix`, coal Table 7 properties); the platens touch the packing's extent along\n"
      "z. Errors (missing file, a bad line with its number, r <= 0, a bond index out of range) stop\n"
      "the program with exit code 1; bad arguments with exit code 2.\n",
      kBlock, d.steps, omp_get_num_procs(), d.diameter * 500, d.height * 500, d.diameter * 1e3, d.height * 1e3,
      d.radius_min, d.radius_max, d.bond_gap, d.membrane_n_theta, kBlock);
}

[[noreturn]] void usage_error(const std::string& what) {
  fmt::print(stderr, "dem_ucs: {}\n(dem_ucs --help lists the options)\n", what);
  std::exit(2);
}

long parse_integer(const std::string& opt, const char* text, long lo) {
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(text, &end, 10);
  if (*text == '\0' || *end != '\0' || errno == ERANGE)
    usage_error(fmt::format("{}: '{}' is not an integer", opt, text));
  if (v < lo) usage_error(fmt::format("{}: {} is below the least value {}", opt, v, lo));
  return v;
}

double parse_real(const std::string& opt, const char* text, bool allow_zero) {
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(text, &end);
  if (*text == '\0' || *end != '\0' || errno == ERANGE || !std::isfinite(v))
    usage_error(fmt::format("{}: '{}' is not a number", opt, text));
  if (v < 0 || (!allow_zero && v == 0))
    usage_error(fmt::format("{}: {} must be {}", opt, text, allow_zero ? "zero or positive" : "positive"));
  return v;
}

Options parse_args(int argc, char** argv) {
  Options o;
  bool membrane_n_set = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> const char* {
      if (i + 1 >= argc) usage_error(fmt::format("{} needs a value", a));
      return argv[++i];
    };
    if (a == "-h" || a == "--help") {
      print_help();
      std::exit(0);
    } else if (a == "--steps") {
      o.steps = parse_integer(a, value(), 1);
    } else if (a == "--max-threads") {
      o.max_threads = static_cast<int>(parse_integer(a, value(), 1));
    } else if (a == "--small") {
      o.small = true;
      o.diameter = 12.5e-3;
      o.height = 25e-3;
    } else if (a == "--radius-min") {
      o.radius_min = parse_real(a, value(), false);
      o.radius_set = true;
    } else if (a == "--radius-max") {
      o.radius_max = parse_real(a, value(), false);
      o.radius_set = true;
    } else if (a == "--bond-gap") {
      o.bond_gap = parse_real(a, value(), true);
      o.bond_gap_set = true;
    } else if (a == "--packing") {
      o.packing = value();
    } else if (a == "--keep-order") {
      o.keep_order = true;
    } else if (a == "--write-packing") {
      o.write_packing = value();
    } else if (a == "--membrane") {
      o.membrane = true;
    } else if (a == "--energy") {
      o.energy = true;
    } else if (a == "--membrane-n-theta") {
      o.membrane_n_theta = static_cast<int>(parse_integer(a, value(), 3));
      membrane_n_set = true;
    } else {
      usage_error(fmt::format("unknown argument '{}'", a));
    }
  }
  if (o.radius_min > o.radius_max)
    usage_error(fmt::format("--radius-min {:g} is above --radius-max {:g}", o.radius_min, o.radius_max));
  if (!o.packing.empty()) {
    if (o.small) usage_error("--small sets the genesis sample's size; a --packing file has its own");
    if (o.radius_set) usage_error("--radius-min/--radius-max set the genesis radii; a --packing file has its own");
    if (o.membrane) usage_error("--membrane wraps the genesis cylinder (axis at x = y = 0); it is not available with --packing");
  } else if (o.keep_order) {
    usage_error("--keep-order applies to a --packing file only");
  }
  if (membrane_n_set && !o.membrane) usage_error("--membrane-n-theta applies with --membrane only");
  return o;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double seconds_since(std::chrono::steady_clock::time_point a) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count();
}

int run(const Options& o) {
  const double diameter = o.diameter;
  const long steps = o.steps;
  const Driver& ucs = find_driver("ucs");
  ParamTable table = parameter_table(ucs);
  const std::string text = "driver = \"ucs\"\n" + std::string(dem::kCoalMatrixTable7Toml) +
                           fmt::format("[sample]\ndiameter = {}\nheight = {}\nradius_min = {}\nradius_max = {}\n"
                                       "porosity = 0.38\nbond_gap = {}\n",
                                       o.diameter, o.height, o.radius_min, o.radius_max, o.bond_gap);
  Config cfg = load_scenario(table, "<benchmark>", text, {});
  omp_set_num_threads(omp_get_num_procs());
  dem::DemSystem base;
  base.settings = dem::build_settings(cfg);
  base.materials = dem::build_materials(cfg);
  dem::SampleInfo info;
  std::string origin;
  if (o.packing.empty()) {
    const auto t0 = std::chrono::steady_clock::now();
    info = dem::build_sample(cfg, base);
    origin = fmt::format("genesis of a {:g} mm x {:g} mm cylinder, radii {:g}-{:g} mm, in {:.1f} s", o.diameter * 1e3,
                         o.height * 1e3, o.radius_min * 1e3, o.radius_max * 1e3, seconds_since(t0));
  } else {
    const auto t0 = std::chrono::steady_clock::now();
    const dem::PackingFile pk = dem::read_packing_file(o.packing);
    info = dem::place_packing(pk, cfg, base, 0, !o.keep_order);
    origin = fmt::format("packing {} ({} order, bonds {}; box {:.4g} x {:.4g} x {:.4g} mm, box porosity {:.3f}, {} floaters), "
                         "read and placed in {:.2f} s",
                         o.packing, o.keep_order ? "file" : "spatial",
                         pk.has_bond_list ? "from the file's list" : fmt::format("by bond_gap {:g} m", o.bond_gap),
                         info.width * 1e3, info.area / info.width * 1e3, info.height * 1e3, info.porosity,
                         info.floaters, seconds_since(t0));
  }
  if (!o.write_packing.empty()) {
    dem::PackingFile out;
    out.pos = base.particles.pos;
    out.radius = base.particles.radius;
    out.has_bond_list = true;
    for (std::size_t b = 0; b < base.bonds.i.size(); ++b)
      if (!base.bonds.broken[b]) out.bonds.emplace_back(base.bonds.i[b], base.bonds.j[b]);
    dem::write_packing_file(o.write_packing, out,
                            fmt::format("fracflow benchmarks/dem_ucs sample: {} particles, {} bonds\nfrom {}",
                                        out.pos.size(), out.bonds.size(), origin));
    fmt::print("wrote {} ({} particles, {} bonds)\n", o.write_packing, out.pos.size(), out.bonds.size());
  }
  dem::add_platens(base, info, 0.1);
  base.settings.dt = 0.8 * critical_time_step(base);
  base.walls[0].velocity.z() = 0.05;
  base.walls[1].velocity.z() = -0.05;
  base.run(200);  // load the sample a little so every contact and bond is active
  if (o.energy) {
    base.settings.track_energy = true;
    dem::start_energy_tracking(base);
  }
  fmt::print("{}: {} particles, {} bonds, {} contacts touching; {}\n", o.packing.empty() ? "ucs-cylinder benchmark" : "packing benchmark",
             base.particles.size(), intact_bonds(base), contacts_touching(base), origin);
  if (base.particles.size() < base.settings.parallel_min)
    fmt::print("note: fewer particles than DemSettings::parallel_min = {}: the engine's loops run on one thread "
               "whatever the thread count\n",
               base.settings.parallel_min);
  std::vector<Vec3> reference;
  double median1 = 0;
  const int maxthreads = o.max_threads > 0 ? o.max_threads : omp_get_num_procs();
  for (int threads = 1; threads <= maxthreads; threads *= 2) {
    omp_set_num_threads(threads);
    dem::DemSystem sys = base;
    sys.run(20);  // warm-up
    sys.stage_times = {};
    std::vector<double> rates;
    long full = 0;  // blocks of kBlock steps (a shorter last block holds the rest of --steps)
    for (long done = 0; done < steps;) {
      const long n = std::min(kBlock, steps - done);
      const auto a = std::chrono::steady_clock::now();
      sys.run(n);
      const double s = seconds_since(a);
      rates.push_back(static_cast<double>(sys.particles.size()) * static_cast<double>(n) / s);
      full += n == kBlock;
      done += n;
    }
    const double med = median(rates), best = *std::max_element(rates.begin(), rates.end());
    bool same = true;
    if (reference.empty()) reference = sys.particles.pos;
    else same = std::memcmp(reference.data(), sys.particles.pos.data(), reference.size() * sizeof(Vec3)) == 0;
    if (threads == 1) median1 = med;
    const std::string blocks = static_cast<long>(rates.size()) == full
                                   ? fmt::format("{} blocks of {} steps", rates.size(), kBlock)
                                   : fmt::format("{} blocks of <= {} steps", rates.size(), kBlock);
    fmt::print("threads {}: {:.3g} particle-steps/s (median of {}; best block {:.3g}){}{}\n", threads, med, blocks, best,
               threads > 1 ? fmt::format(", speed-up {:.2f} (ratio of medians)", med / median1) : std::string(),
               same ? "" : "  (RESULTS DIFFER FROM 1 THREAD!)");
    const auto& t = sys.stage_times;
    const double tot = t.neighbors + t.contacts + t.bonds + t.walls + t.integrate;
    fmt::print("  stages: neighbours {:.0f}%, contacts {:.0f}%, bonds {:.0f}%, walls {:.0f}%, gather+integrate {:.0f}%\n",
               100 * t.neighbors / tot, 100 * t.contacts / tot, 100 * t.bonds / tot, 100 * t.walls / tot,
               100 * t.integrate / tot);
  }
  if (o.membrane) {
    // Membrane of n_theta x N_z square units around the sample at 5 MPa; blocks with and without it
    // alternate so both see the same machine load. Overhead: median of the per-pair time ratios - 1
    // (the best-block ratio beside it).
    omp_set_num_threads(1);
    dem::DemSystem plain = base, wrapped = base;
    const Real R = 0.5 * diameter;
    // Clearance 0.1% of R: closes in ~200 steps at v_max.
    dem::MembraneSettings m = dem::membrane_around_cylinder(R, base.walls[0].point.z(), base.walls[1].point.z(),
                                                            o.membrane_n_theta, 0, 1e-3, 1.2);
    m.pressure = 5e6;
    m.v_max = 1.0;
    m.r_min = 0.9 * R;
    dem::attach_membrane(wrapped, m);
    wrapped.rebuild_neighbors();
    plain.run(20);
    wrapped.run(400);  // the membrane closes its clearance and touches the sample
    // Block ratios show the per-step cost; the totals include the rebuilds a block may hold.
    double best_plain = 1e300, best_wrapped = 1e300, total_plain = 0, total_wrapped = 0;
    std::vector<double> ratios;
    const long nb_plain = plain.neighbor_builds(), nb_wrapped = wrapped.neighbor_builds();
    const long mb_wrapped = dem::membrane_boundary(wrapped)->builds();
    wrapped.stage_times = {};
    for (long done = 0; done < steps;) {
      const long n = std::min(kBlock, steps - done);
      auto a = std::chrono::steady_clock::now();
      plain.run(n);
      const double tp = seconds_since(a);
      a = std::chrono::steady_clock::now();
      wrapped.run(n);
      const double tw = seconds_since(a);
      if (n == kBlock || ratios.empty()) {
        best_plain = std::min(best_plain, tp), best_wrapped = std::min(best_wrapped, tw);
        ratios.push_back(tw / tp);
      }
      total_plain += tp, total_wrapped += tw;
      done += n;
    }
    int touching = 0;
    for (std::size_t k = 0; k < dem::membrane_of(wrapped)->element_count(); ++k) touching += dem::membrane_of(wrapped)->contacts(k) > 0;
    // The membrane's own stage (its candidate searches, contact forces, servo and vertex update)
    // against the rest of the same steps: what it adds to a step of the same confined sample,
    // free of the A/B difference that the confined sample has more contacts than the free one.
    const auto& t = wrapped.stage_times;
    const double rest = t.neighbors + t.contacts + t.bonds + t.walls + t.integrate;
    fmt::print("membrane: {} triangles ({} touching the sample), {} candidates; step time +{:.1f}% on 1 thread "
               "(median of {} interleaved block pairs; best blocks +{:.1f}%), +{:.1f}% in total over the {} steps "
               "(neighbour rebuilds: {} without, {} with the membrane; membrane candidate rebuilds {})\n",
               dem::membrane_of(wrapped)->element_count(), touching, dem::membrane_of(wrapped)->candidate_particles().size(),
               100 * (median(ratios) - 1), ratios.size(), 100 * (best_wrapped / best_plain - 1),
               100 * (total_wrapped / total_plain - 1), steps, plain.neighbor_builds() - nb_plain,
               wrapped.neighbor_builds() - nb_wrapped, dem::membrane_boundary(wrapped)->builds() - mb_wrapped);
    fmt::print("membrane stage: {:.1f}% of the wrapped sample's step time, i.e. +{:.1f}% over the rest of its step\n",
               100 * t.boundaries / (rest + t.boundaries), 100 * t.boundaries / rest);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse_args(argc, argv);
  try {
    return run(o);
  } catch (const Error& e) {
    fmt::print(stderr, "dem_ucs: error: {}\n", e.what());
    return 1;
  }
}
