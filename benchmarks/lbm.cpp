// LBM throughput: million lattice-cell updates per second (MLUPS) of the fused stream-collide
// step for D2Q9 at 1000^2 and D3Q19 at 128^3 (fully periodic, so every cell is a bulk cell),
// on 1 and 2 threads, in double and single precision, against the memory-bandwidth roofline.
//
// Roofline: each update reads and writes Q populations, 2 Q sizeof(real) bytes; the bandwidth
// is this program's own STREAM-style triad a[i] = b[i] + s c[i], counted as 24 bytes per
// iteration like STREAM (the write-allocate read of a[] is not counted, so an in-place LBM
// kernel, which has no write-allocate traffic, can exceed 100% of this figure).
//
// Timing: the best of many short blocks (lbm_mlups), because the machines this project runs on
// are shared; compare figures taken in one run.
//
// Usage: lbm [--quick] [--threads 1,2] [--repeat 3]
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "lbm/solver.hpp"

using namespace ff;
using namespace ff::lbm;
using Clock = std::chrono::steady_clock;

namespace {

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Best triad bandwidth [GB/s] over 10 x `repeat` passes (about 35 ms each) with `threads` threads.
double triad_bandwidth(int threads, int repeat) {
  const std::int64_t n = 40'000'000;  // 3 x 320 MB: far beyond any cache
  std::unique_ptr<double[]> a(new double[n]), b(new double[n]), c(new double[n]);
#pragma omp parallel for num_threads(threads) schedule(static)
  for (std::int64_t i = 0; i < n; ++i) {  // first touch by the threads that use the pages
    a[i] = 0;
    b[i] = 1;
    c[i] = 2;
  }
  double best = 0;
  const double s = 0.5;
  for (int r = 0; r < 10 * repeat + 1; ++r) {
    const auto t0 = Clock::now();
#pragma omp parallel for num_threads(threads) schedule(static)
    for (std::int64_t i = 0; i < n; ++i) a[i] = b[i] + s * c[i];
    const double t = seconds_since(t0);
    if (r > 0) best = std::max(best, 24.0 * double(n) / t * 1e-9);
  }
  if (a[n / 2] != 2.0) std::fprintf(stderr, "triad check failed\n");
  return best;
}

struct Result {
  double mlups = 0;
  std::size_t bytes_per_update = 0;
};

// Best MLUPS over timed blocks of about kBlockSeconds (an even number of steps: both AA
// halves), `repeat` x `seconds` of blocks in all. Short blocks and the best of many: on a shared
// machine most blocks overlap other work, and the best one approximates an idle machine.
template <class L, class T>
Result lbm_mlups(int n, CollisionModel m, int threads, int repeat, double seconds) {
  constexpr double kBlockSeconds = 0.1;
  omp_set_num_threads(threads);
  Grid g(L::D, n, n, L::D == 3 ? n : 1, {true, true, true});
  SolverSettings st;
  st.collision = m;
  st.tau = 0.8;
  Solver<L, T> s(g, st);
  s.finalize();
  const double k = 2 * M_PI / n;
  s.initialize([&](int x, int y, int z, double&, Vec3& u) {
    u = Vec3(0.02 * std::sin(k * y), 0.02 * std::sin(k * (x + z)), L::D == 3 ? 0.01 * std::cos(k * x) : 0.0);
  });
  const double cells = double(s.num_fluid_cells());
  // Calibrate the step count on a short run.
  auto t0 = Clock::now();
  for (int i = 0; i < 4; ++i) s.step();
  const double per_step = seconds_since(t0) / 4;
  const int steps = std::max(2, 2 * int(0.5 * kBlockSeconds / per_step));  // even: both AA halves
  const int blocks = std::max(repeat, int(repeat * seconds / (steps * per_step)));
  Result r;
  r.bytes_per_update = 2 * L::Q * sizeof(T);
  for (int b = 0; b < blocks; ++b) {
    t0 = Clock::now();
    for (int i = 0; i < steps; ++i) s.step();
    r.mlups = std::max(r.mlups, cells * steps / seconds_since(t0) * 1e-6);
  }
  s.step(true);
  if (!(s.max_speed() < 1)) std::fprintf(stderr, "warning: the benchmark flow became unstable\n");
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  int repeat = 3;
  std::vector<int> thread_counts = {1, 2};
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--quick")) quick = true;
    else if (!std::strcmp(argv[i], "--repeat") && i + 1 < argc) repeat = std::max(1, std::atoi(argv[++i]));
    else if (!std::strcmp(argv[i], "--threads") && i + 1 < argc) {
      thread_counts.clear();
      for (char* t = std::strtok(argv[++i], ","); t; t = std::strtok(nullptr, ",")) thread_counts.push_back(std::atoi(t));
    } else {
      std::printf("usage: %s [--quick] [--threads 1,2] [--repeat 3]\n", argv[0]);
      return 2;
    }
  }
  const double seconds = quick ? 0.3 : 1.5;
  const int n2 = quick ? 400 : 1000, n3 = quick ? 64 : 128;
  std::printf("fracflow LBM benchmark: fused stream-collide (AA pattern), periodic box, tau = 0.8\n");
  std::printf("bytes per cell update = 2 Q sizeof(real); roofline = triad bandwidth / bytes per update\n\n");
  std::printf("%-7s %-9s %-6s %-4s %7s %9s %11s %9s\n", "threads", "lattice", "real", "coll", "MLUPS", "GB/s",
              "roofline", "fraction");
  for (int t : thread_counts) {
    const double bw_before = triad_bandwidth(t, repeat);
    struct Row {
      std::string lattice, real, coll;
      Result r;
    };
    std::vector<Row> rows;
    auto add = [&](const char* lat, const char* real, const char* coll, Result r) { rows.push_back({lat, real, coll, r}); };
    const std::string l2 = "D2Q9/" + std::to_string(n2), l3 = "D3Q19/" + std::to_string(n3);
    add(l2.c_str(), "double", "BGK", lbm_mlups<D2Q9, double>(n2, CollisionModel::Bgk, t, repeat, seconds));
    add(l2.c_str(), "double", "TRT", lbm_mlups<D2Q9, double>(n2, CollisionModel::Trt, t, repeat, seconds));
    add(l2.c_str(), "float", "BGK", lbm_mlups<D2Q9, float>(n2, CollisionModel::Bgk, t, repeat, seconds));
    add(l3.c_str(), "double", "BGK", lbm_mlups<D3Q19, double>(n3, CollisionModel::Bgk, t, repeat, seconds));
    add(l3.c_str(), "double", "TRT", lbm_mlups<D3Q19, double>(n3, CollisionModel::Trt, t, repeat, seconds));
    add(l3.c_str(), "float", "BGK", lbm_mlups<D3Q19, float>(n3, CollisionModel::Bgk, t, repeat, seconds));
    // Bandwidth measured before and after; the better one is the machine's (others may share it).
    const double bw = std::max(bw_before, triad_bandwidth(t, repeat));
    for (auto& row : rows) {
      const double gbs = row.r.mlups * 1e6 * double(row.r.bytes_per_update) * 1e-9;
      const double roof = bw * 1e9 / double(row.r.bytes_per_update) * 1e-6;
      std::printf("%-7d %-9s %-6s %-4s %7.1f %9.2f %11.1f %8.0f%%\n", t, row.lattice.c_str(), row.real.c_str(),
                  row.coll.c_str(), row.r.mlups, gbs, roof, 100 * row.r.mlups / roof);
    }
    std::printf("%-7d triad bandwidth %.2f GB/s (STREAM counting, 24 bytes per iteration)\n\n", t, bw);
    std::fflush(stdout);
  }
  return 0;
}
