// ucs-cylinder benchmark (issue 2, item 11): a 25 mm x 50 mm cylinder of bonded spheres with
// radii uniform in [0.4, 0.6] mm (about 30,000 particles), compressed between platens.
// Prints the genesis time and one line per thread count: `threads N: X particle-steps/s`,
// all measured from the same bonded state in this one run, and checks that every thread
// count gives bit-identical positions. The steps run in blocks of 50; the figure is the best
// block (the one least disturbed by other work on a shared machine), the median follows.
// With --membrane, the same sample is also stepped inside a flexible membrane (issue 4, item 9)
// on 1 thread, interleaving blocks with and without it, and the added step time is printed.
#include <fmt/core.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>

#include "dem/dem_params.hpp"
#include "dem/presets.hpp"
#include "dem/sample_builder.hpp"
#include "drivers/driver.hpp"
#include "io/scenario.hpp"

using namespace ff;

int main(int argc, char** argv) {
  long steps = 300;
  int max_threads = 0;  // 0: every core
  double diameter = 25e-3, height = 50e-3;
  bool membrane = false;
  int membrane_n_theta = 48;                  // units around the sleeve (scenario default: 24)
  double radius_min = 0.4e-3, radius_max = 0.6e-3;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--steps") && i + 1 < argc) steps = std::atol(argv[++i]);
    if (!std::strcmp(argv[i], "--small")) { diameter = 12.5e-3; height = 25e-3; }
    if (!std::strcmp(argv[i], "--max-threads") && i + 1 < argc) max_threads = std::atoi(argv[++i]);
    if (!std::strcmp(argv[i], "--membrane")) membrane = true;
    if (!std::strcmp(argv[i], "--membrane-n-theta") && i + 1 < argc) membrane_n_theta = std::atoi(argv[++i]);
    if (!std::strcmp(argv[i], "--radius-min") && i + 1 < argc) radius_min = std::atof(argv[++i]);
    if (!std::strcmp(argv[i], "--radius-max") && i + 1 < argc) radius_max = std::atof(argv[++i]);
  }
  const Driver& ucs = find_driver("ucs");
  ParamTable table = parameter_table(ucs);
  const std::string text = "driver = \"ucs\"\n" + std::string(dem::kCoalMatrixTable7Toml) +
                           fmt::format("[sample]\ndiameter = {}\nheight = {}\nradius_min = {}\nradius_max = {}\n"
                                       "porosity = 0.38\n",
                                       diameter, height, radius_min, radius_max);
  Config cfg = load_scenario(table, "<benchmark>", text, {});
  omp_set_num_threads(omp_get_num_procs());
  dem::DemSystem base;
  base.settings = dem::build_settings(cfg);
  base.materials = dem::build_materials(cfg);
  const auto t0 = std::chrono::steady_clock::now();
  const dem::SampleInfo info = dem::build_sample(cfg, base);
  const double genesis = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  dem::add_platens(base, info, 0.1);
  base.settings.dt = 0.8 * base.critical_time_step();
  base.walls[0].velocity.z() = 0.05;
  base.walls[1].velocity.z() = -0.05;
  base.run(200);  // load the sample a little so every contact and bond is active
  fmt::print("ucs-cylinder benchmark: {} particles, {} bonds, {} contacts touching; genesis {:.1f} s\n",
             base.particles.size(), base.intact_bonds(), base.contacts_touching(), genesis);
  std::vector<Vec3> reference;
  double rate1 = 0;
  const int maxthreads = max_threads > 0 ? max_threads : omp_get_num_procs();
  for (int threads = 1; threads <= maxthreads; threads *= 2) {
    omp_set_num_threads(threads);
    dem::DemSystem sys = base;
    sys.stage_times = {};
    sys.run(20);  // warm-up
    const long block = std::min(steps, 50L);
    std::vector<double> rates;
    for (long done = 0; done < steps; done += block) {
      const auto a = std::chrono::steady_clock::now();
      sys.run(block);
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count();
      rates.push_back(static_cast<double>(sys.particles.size()) * static_cast<double>(block) / s);
    }
    std::sort(rates.begin(), rates.end());
    const double rate = rates.back(), median = rates[rates.size() / 2];
    bool same = true;
    if (reference.empty()) reference = sys.particles.pos;
    else same = std::memcmp(reference.data(), sys.particles.pos.data(), reference.size() * sizeof(Vec3)) == 0;
    if (threads == 1) rate1 = rate;
    fmt::print("threads {}: {:.3g} particle-steps/s (best of {} blocks; median {:.3g}){}{}\n", threads, rate, rates.size(),
               median, threads > 1 ? fmt::format(", speed-up {:.2f}", rate / rate1) : std::string(),
               same ? "" : "  (RESULTS DIFFER FROM 1 THREAD!)");
    const auto& t = sys.stage_times;
    const double tot = t.neighbors + t.contacts + t.bonds + t.walls + t.integrate;
    fmt::print("  stages: neighbours {:.0f}%, contacts {:.0f}%, bonds {:.0f}%, walls {:.0f}%, gather+integrate {:.0f}%\n",
               100 * t.neighbors / tot, 100 * t.contacts / tot, 100 * t.bonds / tot, 100 * t.walls / tot,
               100 * t.integrate / tot);
  }
  if (membrane) {
    // Membrane of n_theta x N_z square units around the sample at 5 MPa; blocks with and without it
    // alternate so both see the same machine load. Overhead = best-block time ratio - 1.
    omp_set_num_threads(1);
    dem::DemSystem plain = base, wrapped = base;
    const Real R = 0.5 * diameter;
    // Clearance 0.1% of R: closes in ~200 steps at v_max.
    dem::MembraneSettings m = dem::membrane_around_cylinder(R, base.walls[0].point.z(), base.walls[1].point.z(), membrane_n_theta, 0,
                                                            1e-3, 1.2);
    m.pressure = 5e6;
    m.v_max = 1.0;
    m.r_min = 0.9 * R;
    wrapped.membrane.emplace(m);
    wrapped.rebuild_neighbors();
    plain.run(20);
    wrapped.run(400);  // the membrane closes its clearance and touches the sample
    // Best blocks show the per-step cost; the totals include the rebuilds a block may hold.
    double best_plain = 1e300, best_wrapped = 1e300, total_plain = 0, total_wrapped = 0;
    const long nb_plain = plain.neighbor_builds(), nb_wrapped = wrapped.neighbor_builds();
    const long mb_wrapped = wrapped.membrane_builds();
    wrapped.stage_times = {};
    for (long done = 0; done < steps; done += 50) {
      auto a = std::chrono::steady_clock::now();
      plain.run(50);
      const double tp = std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count();
      a = std::chrono::steady_clock::now();
      wrapped.run(50);
      const double tw = std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count();
      best_plain = std::min(best_plain, tp), best_wrapped = std::min(best_wrapped, tw);
      total_plain += tp, total_wrapped += tw;
    }
    int touching = 0;
    for (std::size_t k = 0; k < wrapped.membrane->element_count(); ++k) touching += wrapped.membrane->contacts(k) > 0;
    // The membrane's own stage (its candidate searches, contact forces, servo and vertex update)
    // against the rest of the same steps: what it adds to a step of the same confined sample,
    // free of the A/B difference that the confined sample has more contacts than the free one.
    const auto& t = wrapped.stage_times;
    const double rest = t.neighbors + t.contacts + t.bonds + t.walls + t.integrate;
    fmt::print("membrane: {} triangles ({} touching the sample), {} candidates; step time +{:.1f}% on 1 thread "
               "(best of {} blocks each, interleaved), +{:.1f}% in total over the {} steps (neighbour rebuilds: {} "
               "without, {} with the membrane; membrane candidate rebuilds {})\n",
               wrapped.membrane->element_count(), touching, wrapped.membrane->candidate_particles().size(),
               100 * (best_wrapped / best_plain - 1), (steps + 49) / 50, 100 * (total_wrapped / total_plain - 1), steps,
               plain.neighbor_builds() - nb_plain, wrapped.neighbor_builds() - nb_wrapped,
               wrapped.membrane_builds() - mb_wrapped);
    fmt::print("membrane stage: {:.1f}% of the wrapped sample's step time, i.e. +{:.1f}% over the rest of its step\n",
               100 * t.membrane / (rest + t.membrane), 100 * t.membrane / rest);
  }
  return 0;
}
