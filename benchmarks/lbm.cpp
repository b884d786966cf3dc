// LBM throughput: million fluid-cell updates per second (MLUPS) of the solver's step, against
// a memory-bandwidth roofline a reader can trust.
//
// Cases, each in D2Q9 (2000^2) and D3Q19 (128^3), double and single precision, BGK and TRT; the
// population arrays (139-353 MB) are 4.3-11 times the 32 MB L3 of the project's machines, so
// no row can be served partly from the cache (at 1000^2 the D2Q9 arrays were 35 and 70 MB).
// --quick runs lattices that fit in the cache; the table says so.
//   box      fully periodic, every cell a bulk cell: the kernel alone;
//   channel  what real runs look like: no-slip walls on the side faces, a lattice of solid
//            cylinders (2D) or spheres (3D) with Bouzidi links covering 10-15% of the cells,
//            a Zou-He velocity inlet on x- and a pressure outlet on x+. Fluid cells next to a
//            wall, a solid or an open face take the general boundary path; the table gives
//            their share ("bdry %").
//
// Roofline. A cell update reads the Q populations of a cell and writes them back to the same
// slots (AA pattern, in place): 2 Q sizeof(real) bytes, every cache line read once and written
// once, no write-allocate read, no non-temporal stores. The kernel with exactly that traffic
// is the in-place update a[i] = s a[i] + t (16 bytes per element), so the roofline is the
// best in-place bandwidth divided by 2 Q sizeof(real), and "% roof" should stay at or below
// 100%. Two more bandwidths are printed for reference: the STREAM triad a[i] = b[i] + s c[i]
// (counted as 24 bytes like STREAM, although the write-allocate read of a[] makes it move 32:
// an in-place kernel can beat it, which is why the old fractions of this program read
// 107-267%) and a copy with non-temporal stores (16 bytes counted and moved).
//
// Timing. The machines this project runs on are shared, so every figure comes from many short
// blocks (about 0.1 s of LBM steps, three passes over the arrays for the bandwidths), and the
// configurations are interleaved: each round runs one block of every configuration in turn,
// so a noisy period hits them all alike. The median block is the figure; the best block
// (closest to an idle machine) is printed beside it. Compare rows of one run only. Holding every
// configuration at once costs memory: about 5.5 GB (--quick: 1.2 GB, mostly the 768 MB of bandwidth arrays).
//
// Usage: lbm [--quick] [--threads 1,2] [--repeat 3]
#include <omp.h>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "lbm/solver.hpp"

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define FF_BENCH_CLONES __attribute__((target_clones("default", "arch=x86-64-v3", "arch=x86-64-v4")))
#else
#define FF_BENCH_CLONES
#endif

using namespace ff;
using namespace ff::lbm;
using Clock = std::chrono::steady_clock;

namespace {

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Median and best of a set of rates (higher is better).
struct Stats {
  double median = 0, best = 0;
  int n = 0;
};
Stats stats(std::vector<double> v) {
  Stats s;
  s.n = int(v.size());
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  s.median = v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
  s.best = v.back();
  return s;
}

// ------------------------------------------------------------------ memory bandwidth

// The loops are cloned like the LBM kernel (bulk_sweep.cpp), so both use the same vector width.
FF_BENCH_CLONES void triad_range(double* a, const double* b, const double* c, double s, std::int64_t lo,
                                 std::int64_t hi) {
  for (std::int64_t i = lo; i < hi; ++i) a[i] = b[i] + s * c[i];
}
FF_BENCH_CLONES void inplace_range(double* a, double s, double t, std::int64_t lo, std::int64_t hi) {
  for (std::int64_t i = lo; i < hi; ++i) a[i] = s * a[i] + t;
}
// Copy with non-temporal (streaming) stores: the written lines bypass the caches and are not
// read first. lo and hi are multiples of 2, the arrays 64-byte aligned.
void nt_copy_range(double* a, const double* b, std::int64_t lo, std::int64_t hi) {
#if defined(__SSE2__)
  for (std::int64_t i = lo; i < hi; i += 2) _mm_stream_pd(a + i, _mm_load_pd(b + i));
  _mm_sfence();
#else
  for (std::int64_t i = lo; i < hi; ++i) a[i] = b[i];  // no streaming stores on this target
#endif
}

struct DoubleArray {
  double* p = nullptr;
  explicit DoubleArray(std::int64_t n) : p(static_cast<double*>(std::aligned_alloc(64, std::size_t(n) * 8))) {
    if (!p) {
      std::fprintf(stderr, "out of memory\n");
      std::exit(1);
    }
  }
  ~DoubleArray() { std::free(p); }
  DoubleArray(const DoubleArray&) = delete;
  DoubleArray& operator=(const DoubleArray&) = delete;
};

class Bandwidth {
 public:
  static constexpr std::int64_t kN = 32'000'000;  // 256 MB per array: far beyond any cache
  enum Kernel { Triad, NtCopy, InPlace, kKernels };
  static constexpr double kBytes[kKernels] = {24, 16, 16};  // counted per element

  Bandwidth() : a_(kN), b_(kN), c_(kN) {
#pragma omp parallel for schedule(static)
    for (std::int64_t i = 0; i < kN; ++i) {  // first touch
      a_.p[i] = 0;
      b_.p[i] = 1;
      c_.p[i] = 1;
    }
  }
  // One timed pass of kernel k on `threads` threads [GB/s, counted bytes].
  double pass(Kernel k, int threads) {
    const auto t0 = Clock::now();
#pragma omp parallel num_threads(threads)
    {
      const std::int64_t nt = omp_get_num_threads(), id = omp_get_thread_num();
      const std::int64_t lo = (kN / 8 * id / nt) * 8, hi = (kN / 8 * (id + 1) / nt) * 8;
      if (k == Triad) triad_range(a_.p, b_.p, c_.p, 0.5, lo, hi);
      else if (k == NtCopy) nt_copy_range(c_.p, b_.p, lo, hi);  // c = b = 1: the triad's input stays put
      else inplace_range(b_.p, 0.5, 0.5, lo, hi);  // b = 1 is its fixed point
    }
    return kBytes[k] * double(kN) / seconds_since(t0) * 1e-9;
  }
  bool check() const { return a_.p[kN / 2] == 1.5 && b_.p[kN / 3] == 1.0 && c_.p[kN - 1] == 1.0; }

 private:
  DoubleArray a_, b_, c_;
};

// ------------------------------------------------------------------ LBM cases

struct Case {
  std::string kind, lattice, real, coll;
  double solid_share = 0, boundary_share = 0;  // of all cells / of fluid cells
  double fluid_cells = 0;
  std::size_t bytes_per_update = 0;
  double population_bytes = 0;  // the arrays a step streams through
  int steps = 2;  // per block, even: both halves of the AA pattern
  virtual ~Case() = default;
  virtual void run(int steps) = 0;
  virtual bool stable() = 0;  // samples once; false if the flow blew up (NaN or u > 1)
  // Block length for about `block_seconds` on the current thread count.
  void calibrate(double block_seconds) {
    run(2);  // warm the caches and the thread pool
    const auto t0 = Clock::now();
    run(4);
    const double per_step = seconds_since(t0) / 4;
    steps = std::max(2, 2 * int(0.5 * block_seconds / per_step));
  }
  double block() {  // MLUPS of one block
    const auto t0 = Clock::now();
    run(steps);
    return fluid_cells * steps / seconds_since(t0) * 1e-6;
  }
};

template <class L, class T>
struct CaseImpl : Case {
  std::unique_ptr<Solver<L, T>> s;
  void run(int n) override {
    for (int i = 0; i < n; ++i) s->step();
  }
  bool stable() override {
    s->step(true);
    s->step(true);  // even number of steps in all
    return s->max_speed() < 1;
  }
};

template <class L, class T>
std::unique_ptr<Case> make_case(bool channel, int n, CollisionModel m) {
  auto c = std::make_unique<CaseImpl<L, T>>();
  c->kind = channel ? "channel" : "box";
  c->lattice = std::string(L::D == 2 ? "D2Q9 " : "D3Q19 ") + std::to_string(n) + (L::D == 2 ? "^2" : "^3");
  c->real = sizeof(T) == 8 ? "double" : "float";
  c->coll = m == CollisionModel::Trt ? "TRT" : "BGK";
  c->bytes_per_update = 2 * L::Q * sizeof(T);
  const int nz = L::D == 3 ? n : 1;
  const Grid g(L::D, n, n, nz, {!channel, !channel, !channel});
  SolverSettings st;
  st.collision = m;
  st.tau = 0.8;
  c->s = std::make_unique<Solver<L, T>>(g, st);
  Solver<L, T>& s = *c->s;
  const double u0 = 0.05;  // inflow speed, lattice units (Ma 0.087)
  if (channel) {
    FaceCondition in, out;  // the other faces stay no-slip walls
    in.kind = FaceCondition::Kind::Velocity;
    in.velocity = Vec3(u0, 0, 0);
    out.kind = FaceCondition::Kind::Pressure;
    out.density = 1;
    s.set_face(0, in);
    s.set_face(1, out);
    // Square array of cylinders (r 10, pitch 40) or cubic array of spheres (r 6.5, pitch 17),
    // clear of the walls, from 1/8 to 7/8 of the length.
    const double r = L::D == 2 ? 10 : 6.5, pitch = L::D == 2 ? 40 : 17;
    const int nxs = int((0.75 * n) / pitch), nts = int((n - 2) / pitch);
    const double x0 = 0.5 * (n - (nxs - 1) * pitch), t0 = 0.5 * (n - 1 - (nts - 1) * pitch);
    for (int i = 0; i < nxs; ++i)
      for (int j = 0; j < nts; ++j)
        for (int k = 0; k < (L::D == 3 ? nts : 1); ++k) {
          const Vec3 ctr(x0 + i * pitch, t0 + j * pitch, L::D == 3 ? t0 + k * pitch : 0.0);
          const int id = s.add_object("solid", WallScheme::Bouzidi, ctr);
          if constexpr (L::D == 2) s.add_shape(id, Circle{ctr, r});
          else s.add_shape(id, Sphere{ctr, r});
        }
  }
  s.finalize();
  const double k = 2 * M_PI / n;
  s.initialize([&](int x, int y, int z, double&, Vec3& u) {
    if (channel) u = Vec3(u0, 0, 0);
    else u = Vec3(0.02 * std::sin(k * y), 0.02 * std::sin(k * (x + z)), L::D == 3 ? 0.01 * std::cos(k * x) : 0.0);
  });
  c->fluid_cells = double(s.num_fluid_cells());
  c->population_bytes = double(s.populations().size() * sizeof(T));
  c->solid_share = 1 - c->fluid_cells / double(g.interior_size());
  c->boundary_share = double(s.num_boundary_cells()) / c->fluid_cells;
  return c;
}

// Size of the last-level cache [bytes] from sysfs (0 if unknown). sysconf's figure is wrong on
// some VMs (320 MB on the project's 32 MB Zen 4 VM).
double l3_bytes() {
  std::ifstream f("/sys/devices/system/cpu/cpu0/cache/index3/size");
  double v = 0;
  std::string unit;
  if (!(f >> v)) return 0;
  std::getline(f, unit);
  if (!unit.empty() && (unit[0] == 'K' || unit[0] == 'k')) v *= 1024;
  else if (!unit.empty() && unit[0] == 'M') v *= 1024 * 1024;
  return v;
}

std::string load_average() {
  std::ifstream f("/proc/loadavg");
  std::string a, b, c;
  if (!(f >> a >> b >> c)) return "n/a";
  return a + " " + b + " " + c;
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  int repeat = 3;
  std::vector<int> thread_counts = {1, 2};
  std::string command = argv[0];
  for (int i = 1; i < argc; ++i) command += std::string(" ") + argv[i];
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--quick")) quick = true;
    else if (!std::strcmp(argv[i], "--repeat") && i + 1 < argc) repeat = std::max(1, std::atoi(argv[++i]));
    else if (!std::strcmp(argv[i], "--threads") && i + 1 < argc) {
      thread_counts.clear();
      for (char* t = std::strtok(argv[++i], ","); t; t = std::strtok(nullptr, ","))
        thread_counts.push_back(std::max(1, std::atoi(t)));
    } else {
      std::printf(
          "usage: %s [--quick] [--threads 1,2] [--repeat 3]\n"
          "  --quick     smaller lattices (D2Q9 400^2, D3Q19 64^3) and fewer, shorter blocks\n"
          "  --threads   thread counts to run, comma-separated\n"
          "  --repeat    multiplies the number of timed blocks per figure (15 x repeat, quick: 3 x repeat)\n",
          argv[0]);
      return 2;
    }
  }
  const double block_seconds = quick ? 0.05 : 0.1;
  const int rounds = (quick ? 3 : 15) * repeat;
  const int n2 = quick ? 400 : 2000, n3 = quick ? 64 : 128;

  char date[64];
  const std::time_t now = std::time(nullptr);
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  std::printf("fracflow LBM benchmark, %s, `%s`, load average before: %s\n", date, command.c_str(),
              load_average().c_str());
  std::printf("Every figure: median of %d interleaved blocks (~%.2f s of LBM steps; bandwidths: %d array passes), "
              "best block beside it.\n\n",
              rounds, block_seconds, 3 * rounds);

  Bandwidth bw;
  std::vector<std::unique_ptr<Case>> cases;
  for (bool channel : {false, true}) {
    cases.push_back(make_case<D2Q9, double>(channel, n2, CollisionModel::Bgk));
    cases.push_back(make_case<D2Q9, double>(channel, n2, CollisionModel::Trt));
    cases.push_back(make_case<D2Q9, float>(channel, n2, CollisionModel::Bgk));
    cases.push_back(make_case<D3Q19, double>(channel, n3, CollisionModel::Bgk));
    cases.push_back(make_case<D3Q19, double>(channel, n3, CollisionModel::Trt));
    cases.push_back(make_case<D3Q19, float>(channel, n3, CollisionModel::Bgk));
  }
  const int nc = int(cases.size());

  struct PerThreads {
    int threads;
    Stats bw[Bandwidth::kKernels];
    std::vector<Stats> mlups;
  };
  std::vector<PerThreads> results;
  bool ok = true;
  for (int t : thread_counts) {
    omp_set_num_threads(t);
    for (auto& c : cases) c->calibrate(block_seconds);
    std::vector<std::vector<double>> bw_samples(Bandwidth::kKernels), lbm_samples(nc);
    for (int k = 0; k < Bandwidth::kKernels; ++k) bw.pass(Bandwidth::Kernel(k), t);  // warm-up
    // Round r runs every configuration once, starting at a rotating position.
    const int nconf = Bandwidth::kKernels + nc;
    for (int r = 0; r < rounds; ++r)
      for (int j = 0; j < nconf; ++j) {
        const int c = (j + r) % nconf;
        if (c < Bandwidth::kKernels)  // passes are short (10-30 ms): three, for a sharper best
          for (int k = 0; k < 3; ++k) bw_samples[c].push_back(bw.pass(Bandwidth::Kernel(c), t));
        else lbm_samples[c - Bandwidth::kKernels].push_back(cases[c - Bandwidth::kKernels]->block());
      }
    PerThreads p;
    p.threads = t;
    for (int k = 0; k < Bandwidth::kKernels; ++k) p.bw[k] = stats(bw_samples[k]);
    for (int c = 0; c < nc; ++c) p.mlups.push_back(stats(lbm_samples[c]));
    results.push_back(p);
    std::fprintf(stderr, "%d thread(s) done\n", t);
  }
  for (auto& c : cases)
    if (!c->stable()) {
      std::fprintf(stderr, "warning: the %s %s %s %s flow became unstable\n", c->kind.c_str(), c->lattice.c_str(),
                   c->real.c_str(), c->coll.c_str());
      ok = false;
    }
  if (!bw.check()) {
    std::fprintf(stderr, "bandwidth kernels: wrong results\n");
    ok = false;
  }

  std::printf("Memory bandwidth, GB/s, median (best): triad counts 24 B per element as STREAM does (it moves 32: the\n"
              "write-allocate read of a[]), nt-copy a[i] = b[i] with non-temporal stores 16 B, in-place\n"
              "a[i] = s a[i] + t 16 B (read and write back, the LBM step's traffic).\n\n");
  std::printf("| threads | triad | nt-copy | in-place |\n|---|---|---|---|\n");
  for (auto& p : results) {
    std::printf("| %d |", p.threads);
    for (int k = 0; k < Bandwidth::kKernels; ++k) std::printf(" %.1f (%.1f) |", p.bw[k].median, p.bw[k].best);
    std::printf("\n");
  }
  const double l3 = l3_bytes();
  std::printf("\nLBM: MLUPS = million fluid-cell updates per second. A cell update moves 2 Q sizeof(real) bytes,\n"
              "read and written back in place (AA pattern, no write-allocate), so the roofline is the best in-place\n"
              "bandwidth / (2 Q sizeof(real)) and %% roof = MLUPS / roofline (median; best block in brackets).\n"
              "solid %% = solid share of the cells; bdry %% = share of the fluid cells on the boundary path;\n"
              "MB = the population array (\"in L3\": it fits in the %.0f MB last-level cache, so that row is not\n"
              "memory-bound and its %% roof is no roofline fraction; it can exceed 100%%).\n\n",
              l3 / 1048576);
  std::printf("| threads | case | lattice | real | coll. | solid %% | bdry %% | MB | MLUPS median | MLUPS best | GB/s "
              "median | roofline MLUPS | %% roof |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (auto& p : results) {
    const double inplace = p.bw[Bandwidth::InPlace].best;
    for (int c = 0; c < nc; ++c) {
      const Case& k = *cases[c];
      const Stats& m = p.mlups[c];
      const double roof = inplace * 1e3 / double(k.bytes_per_update);
      const bool in_cache = k.population_bytes <= l3;
      std::printf("| %d | %s | %s | %s | %s | %.1f | %.1f | %.0f%s | %.1f | %.1f | %.1f | %.1f | %.0f%% (%.0f%%) |\n",
                  p.threads, k.kind.c_str(), k.lattice.c_str(), k.real.c_str(), k.coll.c_str(), 100 * k.solid_share,
                  100 * k.boundary_share, k.population_bytes / 1048576, in_cache ? " in L3" : "", m.median, m.best, m.median * double(k.bytes_per_update) * 1e-3, roof,
                  100 * m.median / roof, 100 * m.best / roof);
    }
  }
  std::printf("\n%d blocks per figure; load average after: %s\n", rounds, load_average().c_str());
  return ok ? 0 : 1;
}
