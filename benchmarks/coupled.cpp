// Coupled DEM-LBM step (issue 15, item 7): the time of one coupled step split into its parts, for
// each particle scheme (PSM, stair-wise and interpolated moving bounce-back), on 1 and 2 threads.
// "psm-r" is the PSM with lbm::SolverSettings::psm_refresh = 0.02 cells (fractions kept while the
// particles stay that close to where they were computed; velocities taken every step).
//
// Cases (hydrofrac-like: a round block of bonded rock with a borehole, fully periodic lattice):
//   2D  D2Q9,  1000 x 1000 cells, about 10,000 bonded disks (hexagonal packing, spacing 9 cells,
//       radii 0.47-0.495 of it: disks about 9 cells across), a borehole of 3 spacings;
//   3D  D3Q19, 96^3 cells, about 20,000 bonded spheres (simple cubic, spacing 2.6 cells, radii
//       0.45-0.485 of it: spheres about 2.4 cells across), a borehole along z.
// --quick: 200^2 with about 400 disks and 32^3 with about 700 spheres, a few steps (seconds).
// Motion: the block turns as a rigid body about the borehole axis (bonds unstrained), with the rim
// moving `slow` 0.002 cells per LBM step (bonded rock under load: few cells change per step) or
// `fast` 0.05 cells per step (every particle's rim cells change within a few steps), both with
// moving walls (the particles' velocities in the fluid's walls, the set handed over every step); or
// `creep`, the hydrofrac LBM fluid's own mode (coupling/hydrofrac/lbm_load.cpp): quasi-static walls
// (zero wall velocities), the rim moving 1e-4 cells per step (the rock's creep measured there), the
// set handed to the fluid again only once a particle has moved 0.02 cells (CouplerSettings::
// wall_motion = 0, set_refresh = 0.02). The DEM runs its full step (contacts, bonds, integration)
// n_sub times per LBM step.
//
// The split (ms per coupled step, median over blocks; creep: the mean over all blocks, so that the
// rebuilds every ~200 steps count):
//   LBM   the stream-collide of the same lattice with no particles (a second solver, its blocks
//         interleaved with the coupled ones, so a noisy period hits both alike);
//   DEM   the n_sub DEM steps (DemLbmCoupler::times.dem);
//   coup  everything the particles add: the coupler's own work (particle set, solid fractions or
//         links, covering and refill, force conversion, dry-side pressure; times.coupling) plus
//         the difference between the LBM step with particles (times.lbm: PSM update inside the
//         sweep, or the bounce-back post-pass) and LBM;
//   set   the part of coup before the LBM step (times.coupling alone);
//   c/L   coup / LBM: the target is c/L <= 1.
// "cells" is the cells the set covers (PSM: cells with a solid fraction; bounce-back: solid cells),
// "chg" the cells that changed between solid and fluid per step, "links" the fluid-solid links
// (bounce-back schemes) and "sets" the sets handed over per 100 steps (every step but in creep).
// Every configuration is run with the same number of steps on each thread count; "hash" combines
// the DEM positions and the fluid populations at the end, and `same` says whether 1 and 2 threads
// gave bit-identical results.
//
// Usage: coupled [--quick] [--threads 1,2] [--steps N] [--block N] [--dim 2|3] [--scheme psm|psm-r|stair|interp]
//                [--motion slow|fast|creep] [--sub N]
#include <fmt/core.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "coupling/dem_lbm_coupler.hpp"
#include "coupling/fluid_spec.hpp"
#include "dem/diagnostics.hpp"
#include "dem/dem_system.hpp"
#include "lbm/solver.hpp"

using namespace ff;
using Clock = std::chrono::steady_clock;

namespace {

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

double mean(const std::vector<double>& v) {
  double s = 0;
  for (const double x : v) s += x;
  return v.empty() ? 0 : s / double(v.size());
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

struct Options {
  bool quick = false;
  std::vector<int> threads = {1, 2};
  long steps = 0, block = 0;  // 0: the mode's default
  int dim = 0;                // 0: both
  std::string scheme, motion;
  long sub = 4;
};

[[noreturn]] void usage(const std::string& what) {
  fmt::print(stderr,
             "coupled: {}\nUsage: coupled [--quick] [--threads 1,2] [--steps N] [--block N] [--dim 2|3]\n"
             "               [--scheme psm|psm-r|stair|interp] [--motion slow|fast|creep] [--sub N]\n",
             what);
  std::exit(2);
}

long to_long(const char* opt, const char* s, long lo) {
  char* end = nullptr;
  const long v = std::strtol(s, &end, 10);
  if (*s == '\0' || *end != '\0' || v < lo) usage(fmt::format("{}: '{}' is not an integer >= {}", opt, s, lo));
  return v;
}

// 64-bit FNV-1a over raw bytes.
std::uint64_t fnv(const void* data, std::size_t n, std::uint64_t h = 1469598103934665603ull) {
  const auto* b = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ull;
  return h;
}

// ------------------------------------------------------------------ the rock

struct Rock {
  dem::DemSystem dem;
  int n = 0;          // lattice cells per axis
  double dx = 1e-4;   // m
  Vec3 centre;        // lattice units
};

dem::DemSystem empty_system(int dim) {
  dem::DemSystem s;
  s.settings.dim = dim;
  s.settings.local_damping = 0;  // the fluid's drag is the only damping
  s.materials.group_names = {"rock"};
  s.materials.density = {2600};
  dem::LinearContact::Params lc;
  lc.emod = 1e9;
  lc.kratio = 2;
  lc.fric = 0.5;
  s.materials.contact_params<dem::LinearContact>() = {lc};
  s.materials.contact_params<dem::HertzMindlinContact>() = {dem::HertzMindlinContact::Params{}};
  dem::ParallelBond::Material pb;
  pb.emod = 1e9;
  pb.kratio = 2;
  pb.ten = 1e7;
  pb.coh = 2e7;
  s.materials.bond_params<dem::ParallelBond>() = {pb};
  s.materials.bond_params<dem::RotationalBond>().resize(1);
  s.materials.set_bond_law<dem::ParallelBond>();
  return s;
}

// Deterministic radii in [a, b] spacing units (no RNG state shared between cases).
double radius_factor(std::size_t k, double a, double b) {
  const double u = double((k * 2654435761ull) % 1000) / 999.0;
  return a + (b - a) * u;
}

Rock make_rock(int dim, bool quick) {
  Rock r;
  r.dem = empty_system(dim);
  auto& p = r.dem.particles;
  const double dx = r.dx;
  if (dim == 2) {
    r.n = quick ? 200 : 1000;
    const double s = 9.0;  // hexagonal spacing, cells
    const double c = 0.5 * (r.n - 1), R = 0.48 * r.n, hole = 3 * s;
    r.centre = Vec3(c, c, 0);
    const double hy = s * std::sqrt(3.0) / 2;
    for (int j = -int(R / hy) - 1; j <= int(R / hy) + 1; ++j)
      for (int i = -int(R / s) - 2; i <= int(R / s) + 2; ++i) {
        const double x = (i + 0.5 * (j & 1)) * s, y = j * hy;
        const double d = std::hypot(x, y);
        if (d > R - 0.5 * s || d < hole) continue;
        const std::size_t k = p.size();
        p.resize(k + 1);
        p.pos[k] = Vec3(c + x, c + y, 0) * dx;
        p.radius[k] = radius_factor(k, 0.47, 0.495) * s * dx;
        p.set_mass_from_density(k, 2600, 2);
      }
    r.dem.settings.skin = 0.1 * s * dx;
    r.dem.install_bonds(0.08 * s * dx);
  } else {
    r.n = quick ? 32 : 96;
    const double s = 2.6;  // simple cubic spacing, cells
    const double c = 0.5 * (r.n - 1), R = 0.46 * r.n, hole = 2 * s;
    r.centre = Vec3(c, c, c);
    const int m = int(R / s) + 1;
    for (int k3 = -m; k3 <= m; ++k3)
      for (int j = -m; j <= m; ++j)
        for (int i = -m; i <= m; ++i) {
          const Vec3 d(i * s, j * s, k3 * s);
          if (d.norm() > R - 0.5 * s || std::hypot(d.x(), d.y()) < hole) continue;
          const std::size_t k = p.size();
          p.resize(k + 1);
          p.pos[k] = (r.centre + d) * dx;
          p.radius[k] = radius_factor(k, 0.45, 0.485) * s * dx;
          p.set_mass_from_density(k, 2600, 3);
        }
    r.dem.settings.skin = 0.1 * s * dx;
    r.dem.install_bonds(0.12 * s * dx);
  }
  r.dem.initialise();
  return r;
}

// ------------------------------------------------------------------ one configuration

struct Result {
  double lbm = 0, lbm_part = 0, set = 0, coup = 0, dem = 0;
  double cells = 0, changed = 0, links = 0, sets = 0;
  std::uint64_t hash = 0;
  long sub = 0;
};

// psm-r: the PSM keeping its solid fractions while every particle stays within this many cells of
// where they were computed (lbm::SolverSettings::psm_refresh; the hydrofrac driver re-hands its set
// after the same distance).
constexpr double kPsmRefresh = 0.02;

lbm::ParticleScheme scheme_of(const std::string& s) {
  if (s == "psm" || s == "psm-r") return lbm::ParticleScheme::Psm;
  if (s == "stair") return lbm::ParticleScheme::StairwiseBounceBack;
  return lbm::ParticleScheme::InterpolatedBounceBack;
}

template <class L>
Result run_config(const Rock& rock, const std::string& scheme, const std::string& motion, int threads, const Options& o,
                  long steps, long block) {
  omp_set_num_threads(threads);
  dem::DemSystem dem = rock.dem;
  dem.settings.dt = coupling::coupled_dem_time_step(dem, 0.5);  // half the critical step
  const double dx = rock.dx;
  // A model fluid with tau = 0.8 at an LBM step of n_sub DEM steps.
  coupling::FluidSpec fs;
  fs.density = 1000;
  fs.dx = dx;
  fs.time_step = double(o.sub) * dem.settings.dt;
  fs.viscosity = 0.3 * dx * dx / (3 * fs.time_step);
  const coupling::FluidScales sc = coupling::derive_scales(fs);
  const int n = rock.n;
  lbm::Grid g(L::D, n, n, L::D == 3 ? n : 1, {true, true, true});
  lbm::SolverSettings st;
  st.tau = sc.units.tau();
  st.particle_scheme = scheme_of(scheme);
  if (scheme == "psm-r") st.psm_refresh = kPsmRefresh;
  lbm::Solver<L, double> fluid(g, st), bare(g, st);
  for (auto* f : {&fluid, &bare}) {
    f->finalize();
    // A gentle shear flow, so that the fluid moves (creep's walls are at rest) and the hash checks
    // more than a fluid at rest.
    f->initialize([n](int x, int y, int, double& rho, Vec3& u) {
      rho = 1;
      u = 1e-3 * Vec3(std::sin(2 * M_PI * y / n), std::sin(2 * M_PI * x / n), 0);
    });
  }
  // Rigid rotation about the borehole axis: rim speed U cells per LBM step.
  const bool creep = motion == "creep";
  const double U = motion == "fast" ? 0.05 : creep ? 1e-4 : 0.002;
  double rim = 0;
  for (const Vec3& x : dem.particles.pos) rim = std::max(rim, std::hypot(x.x() / dx - rock.centre.x(), x.y() / dx - rock.centre.y()));
  const double w = U / rim / sc.dt();  // rad/s
  for (std::size_t i = 0; i < dem.particles.size(); ++i) {
    const Vec3 arm = dem.particles.pos[i] - rock.centre * dx;
    dem.particles.vel[i] = Vec3(-w * arm.y(), w * arm.x(), 0);
    dem.particles.omega[i] = Vec3(0, 0, w);
  }
  coupling::CouplerSettings cs;
  cs.buoyancy = false;
  if (creep) {
    cs.wall_motion = 0;
    cs.set_refresh = kPsmRefresh;
  }
  coupling::DemLbmCoupler<L, double> cp(dem, fluid, sc, cs);
  for (int k = 0; k < 2; ++k) {  // warm-up: the first set covers every cell
    cp.step();
    bare.step();
  }
  Result r;
  r.sub = cp.sub_steps();
  std::vector<double> vl, vp, vs, vc, vd;
  double cells = 0, changed = 0, links = 0;
  const long sets0 = cp.handovers();
  for (long done = 0; done < steps;) {
    const long nb = std::min(block, steps - done);
    const coupling::CouplerTimes t0 = cp.times;
    for (long k = 0; k < nb; ++k) {
      const long h0 = cp.handovers();
      cp.step();
      if (const auto* mb = fluid.moving_boundary()) {
        if (cp.handovers() > h0) changed += double(mb->stats().covered + mb->stats().uncovered);
        cells += double(mb->num_cells());
        links += double(mb->num_links());
      } else if (const auto* ps = fluid.psm()) {
        cells += double(ps->num_cells());
      }
    }
    const auto c0 = Clock::now();
    for (long k = 0; k < nb; ++k) bare.step();
    const double tb = seconds_since(c0) / double(nb);
    const double tl = (cp.times.lbm - t0.lbm) / double(nb), ts = (cp.times.coupling - t0.coupling) / double(nb);
    vl.push_back(tb);
    vp.push_back(tl);
    vs.push_back(ts);
    vc.push_back(ts + tl - tb);
    vd.push_back((cp.times.dem - t0.dem) / double(nb));
    done += nb;
  }
  auto pick = [&](const std::vector<double>& v) { return creep ? mean(v) : median(v); };
  r.lbm = pick(vl);
  r.lbm_part = pick(vp);
  r.set = pick(vs);
  r.coup = pick(vc);
  r.dem = pick(vd);
  r.cells = cells / double(steps);
  r.changed = changed / double(steps);
  r.links = links / double(steps);
  r.sets = 100.0 * double(cp.handovers() - sets0) / double(steps);
  const auto& P = dem.particles.pos;
  r.hash = fnv(P.data(), P.size() * sizeof(Vec3));
  const auto& f = fluid.populations();
  r.hash = fnv(f.data(), f.size() * sizeof(double), r.hash);
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> const char* {
      if (i + 1 >= argc) usage(a + ": missing value");
      return argv[++i];
    };
    if (a == "--quick") o.quick = true;
    else if (a == "--threads") {
      o.threads.clear();
      std::string s = value();
      for (std::size_t p = 0; p <= s.size();) {
        const std::size_t q = std::min(s.find(',', p), s.size());
        o.threads.push_back(int(to_long("--threads", s.substr(p, q - p).c_str(), 1)));
        p = q + 1;
      }
    } else if (a == "--steps") o.steps = to_long("--steps", value(), 1);
    else if (a == "--block") o.block = to_long("--block", value(), 1);
    else if (a == "--sub") o.sub = to_long("--sub", value(), 1);
    else if (a == "--dim") {
      o.dim = int(to_long("--dim", value(), 2));
      if (o.dim != 2 && o.dim != 3) usage("--dim: 2 or 3");
    } else if (a == "--scheme") {
      o.scheme = value();
      if (o.scheme != "psm" && o.scheme != "psm-r" && o.scheme != "stair" && o.scheme != "interp")
        usage("--scheme: psm, psm-r, stair or interp");
    } else if (a == "--motion") {
      o.motion = value();
      if (o.motion != "slow" && o.motion != "fast" && o.motion != "creep") usage("--motion: slow, fast or creep");
    } else if (a == "-h" || a == "--help") {
      fmt::print(
          "Usage: coupled [--quick] [--threads 1,2] [--steps N] [--block N] [--dim 2|3]\n"
          "               [--scheme psm|psm-r|stair|interp] [--motion slow|fast|creep] [--sub N]\n"
          "Times the coupled DEM-LBM step of a bonded block with a borehole (2D: 1000^2 D2Q9, ~10,000 disks;\n"
          "3D: 96^3 D3Q19, ~18,500 spheres; --quick: small lattices) for each particle scheme, split into\n"
          "LBM (the same lattice without particles), coup (everything the particles add), set (its part\n"
          "before the LBM step) and DEM (n_sub = --sub DEM steps [4]); ms per step, median of blocks of\n"
          "--block steps. `same` compares a hash of positions and populations with the first thread count.\n");
      return 0;
    } else {
      usage("unknown option " + a);
    }
  }
  // creep re-hands its set every ~200 steps: its rows run long enough to include rebuilds.
  auto steps_of = [&](const std::string& m) { return o.steps ? o.steps : m == "creep" ? (o.quick ? 8 : 400) : (o.quick ? 4 : 20); };
  auto block_of = [&](const std::string& m) { return o.block ? o.block : m == "creep" ? (o.quick ? 4 : 50) : (o.quick ? 2 : 5); };
  fmt::print("coupled DEM-LBM step, ms per coupled step (median of blocks of {} steps, {} steps per row; creep: mean of "
             "blocks of {}, {} steps){}\n",
             block_of("slow"), steps_of("slow"), block_of("creep"), steps_of("creep"), o.quick ? ", --quick lattices" : "");
  fmt::print("coup = coupler work + (LBM step with particles - LBM step without); c/L = coup / LBM (target <= 1)\n");
  for (int dim : {2, 3}) {
    if (o.dim && dim != o.dim) continue;
    const auto t0 = Clock::now();
    const Rock rock = make_rock(dim, o.quick);
    fmt::print("\n{}D: {} lattice {}^{} cells, {} bonded particles, {} bonds (built in {:.1f} s)\n", dim,
               dim == 2 ? "D2Q9" : "D3Q19", rock.n, dim, rock.dem.particles.size(), rock.dem.bonds.size(),
               seconds_since(t0));
    fmt::print("{:<7} {:<5} {:>3} {:>4} {:>8} {:>8} {:>8} {:>8} {:>8} {:>9} {:>6} {:>9} {:>8} {:>9} {:>6}  {:<16} {}\n",
               "scheme", "move", "thr", "sub", "LBM", "coup", "set", "DEM", "total", "LBM+part", "c/L", "cells", "chg",
               "links", "sets", "hash", "same");
    for (const std::string scheme : {"psm", "psm-r", "stair", "interp"}) {
      if (!o.scheme.empty() && scheme != o.scheme) continue;
      for (const std::string motion : {"slow", "fast", "creep"}) {
        if (!o.motion.empty() && motion != o.motion) continue;
        std::uint64_t first = 0;
        for (std::size_t ti = 0; ti < o.threads.size(); ++ti) {
          const long steps = steps_of(motion), block = block_of(motion);
          const Result r = dim == 2 ? run_config<lbm::D2Q9>(rock, scheme, motion, o.threads[ti], o, steps, block)
                                    : run_config<lbm::D3Q19>(rock, scheme, motion, o.threads[ti], o, steps, block);
          if (ti == 0) first = r.hash;
          fmt::print("{:<7} {:<5} {:>3} {:>4} {:>8.2f} {:>8.2f} {:>8.2f} {:>8.2f} {:>8.2f} {:>9.2f} {:>6.2f} {:>9.0f} "
                     "{:>8.0f} {:>9.0f} {:>6.1f}  {:016x} {}\n",
                     scheme, motion, o.threads[ti], r.sub, 1e3 * r.lbm, 1e3 * r.coup, 1e3 * r.set, 1e3 * r.dem,
                     1e3 * (r.lbm + r.coup + r.dem), 1e3 * r.lbm_part, r.coup / r.lbm, r.cells, r.changed, r.links,
                     r.sets, r.hash,
                     ti == 0 ? "-" : (r.hash == first ? "yes" : "NO"));
          std::fflush(stdout);
        }
      }
    }
  }
  return 0;
}
