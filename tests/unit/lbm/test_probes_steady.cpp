// Probe interpolation (drivers/flow/probes.hpp) and the steady-state criterion
// (drivers/flow/steady.hpp) on synthetic fields and series: no solver involved.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "drivers/flow/probes.hpp"
#include "drivers/flow/steady.hpp"

using ff::Vec3;
using ff::drivers::probe_stencil;
using ff::drivers::ProbeStencil;

namespace {

// An n x n lattice (cell centres at integer coordinates) with a solid disk of radius r at c.
struct DiskLattice {
  int n;
  Vec3 c;
  double r;
  std::vector<std::uint8_t> solid;
  DiskLattice(int n_, Vec3 c_, double r_) : n(n_), c(c_), r(r_), solid(std::size_t(n_) * n_) {
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) solid[std::size_t(x) + std::size_t(n) * y] = (Vec3(x, y, 0) - c).norm() <= r;
  }
  template <class F>
  double apply(const ProbeStencil& s, F f) const {
    double v = 0;
    for (std::size_t k = 0; k < s.node.size(); ++k)
      v += s.weight[k] * f(double(s.node[k] % std::size_t(n)), double(s.node[k] / std::size_t(n)));
    return v;
  }
};

}  // namespace

TEST(FlowProbes, BilinearInTheBulkIsExactForBilinearFields) {
  const DiskLattice l(30, Vec3(15, 15, 0), 4);
  const Vec3 p(3.3, 7.8, 0);
  const ProbeStencil s = probe_stencil(p, l.n, l.n, 1, l.solid);
  EXPECT_EQ(s.method, "bilinear");
  auto f = [](double x, double y) { return 2 + 0.5 * x - 1.5 * y + 0.25 * x * y; };
  EXPECT_NEAR(l.apply(s, f), f(p.x(), p.y()), 1e-12);
}

TEST(FlowProbes, LeastSquaresOnASolidSurfaceIsExactForQuadratics) {
  // Points on the surface of a disk (as the DFG probes at its front and back) and half a cell
  // from a domain face: the fit uses fluid nodes only, so the solid's values never enter.
  const DiskLattice l(40, Vec3(20.3, 19.6, 0), 6.2);
  auto f = [](double x, double y) { return 1.0 - 0.3 * x + 0.7 * y + 0.05 * x * x - 0.02 * x * y + 0.08 * y * y; };
  for (int k = 0; k < 16; ++k) {
    const double a = 2 * M_PI * k / 16;
    const Vec3 p = l.c + l.r * Vec3(std::cos(a), std::sin(a), 0);
    const ProbeStencil s = probe_stencil(p, l.n, l.n, 1, l.solid);
    EXPECT_NE(s.method.find("quadratic least squares"), std::string::npos) << s.method;
    for (auto i : s.node) EXPECT_EQ(l.solid[i], 0);
    EXPECT_NEAR(l.apply(s, f), f(p.x(), p.y()), 1e-10) << "angle " << a;
  }
  const Vec3 wall(12.4, -0.5, 0);  // on the lower face of the domain
  EXPECT_NEAR(l.apply(probe_stencil(wall, l.n, l.n, 1, l.solid), f), f(wall.x(), wall.y()), 1e-10);
}

TEST(FlowProbes, LeastSquaresIsThirdOrderForSmoothFields) {
  // f = sin(2x) cos(3y) + exp(x/2) around a disk of radius 1 (physical), probes on its
  // surface, lattice spacing h = 1/N: the quadratic fit's error falls as h^3.
  std::vector<double> err;
  for (int N : {8, 16, 32}) {
    const double h = 1.0 / N;
    const int n = 6 * N;
    const Vec3 c(3.0 * N + 0.17, 3.0 * N - 0.29, 0);  // lattice units
    const DiskLattice l(n, c, N);
    auto f = [&](double x, double y) {
      const double X = (x - c.x()) * h, Y = (y - c.y()) * h;
      return std::sin(2 * X) * std::cos(3 * Y) + std::exp(X / 2);
    };
    double e = 0;
    for (int k = 0; k < 12; ++k) {
      const double a = 2 * M_PI * (k + 0.13) / 12;
      const Vec3 p = c + N * Vec3(std::cos(a), std::sin(a), 0);
      e = std::max(e, std::abs(l.apply(probe_stencil(p, n, n, 1, l.solid), f) - f(p.x(), p.y())));
    }
    err.push_back(e);
    std::printf("surface probes, D = %d cells: max error %.3g (field amplitude ~2)\n", 2 * N, e);
  }
  // Measured: 5.2e-2, 4.2e-3, 5.7e-4 at D = 16, 32, 64 cells (ratios 12 and 7.3; h^3 gives 8).
  EXPECT_LT(err[0], 0.1);
  EXPECT_GT(err[0] / err[1], 5.0);
  EXPECT_GT(err[1] / err[2], 5.0);
}

TEST(FlowProbes, ThinLatticeDropsTheTermsItCannotFit) {
  // One z plane (a D3Q19 run whose sample holds one plane, or a lattice one cell deep).
  const DiskLattice l(20, Vec3(10, 10, 0), 3);
  const ProbeStencil s = probe_stencil(Vec3(13.0, 10.0, 0), l.n, l.n, 1, l.solid);
  double sum = 0;
  for (double w : s.weight) sum += w;
  EXPECT_NEAR(sum, 1.0, 1e-12);  // reproduces constants
}

TEST(FlowSteady, AcousticRingingAveragesOutAndSheddingDoesNot) {
  using ff::drivers::steady_drift;
  const long w = 40;  // samples per window = one period of the slowest acoustic mode
  // Steady value 5.6 approached with time constant 1 window, ringing +-2% at the acoustic
  // periods (4L/c and 4L/3c) decaying slowly: the drift reaches 1e-4 and the window mean is then
  // within 1e-4 of 5.6.
  auto ringing = [&](long i) {
    const double t = double(i) / w;
    return 5.6 * (1 + 0.3 * std::exp(-t) + 0.02 * std::exp(-t / 20) * (std::sin(2 * M_PI * t) + 0.5 * std::sin(6 * M_PI * t)));
  };
  long stop = -1;
  for (long n = 1; n < 40 * w; ++n)
    if (steady_drift(ringing, n, w) < 1e-4) {
      stop = n;
      break;
    }
  ASSERT_GT(stop, 0) << "never steady";
  double mean = 0;
  for (long i = stop - w; i < stop; ++i) mean += ringing(i) / w;
  EXPECT_LT(std::abs(mean - 5.6) / 5.6, 1e-4) << "stopped after " << double(stop) / w << " windows";
  // A vortex street: Cd oscillating +-0.3% at a period unrelated to the window never stops at
  // 1e-4, although its mean does not change.
  auto shedding = [&](long i) { return 3.2 * (1 + 0.003 * std::sin(2 * M_PI * i / 13.7)); };
  for (long n = 4 * w; n < 40 * w; n += 7) EXPECT_GT(steady_drift(shedding, n, w), 1e-4) << n;
}
