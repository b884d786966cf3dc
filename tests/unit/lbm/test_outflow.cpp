// Outflow faces (zero-gradient extrapolation and the convective condition of Yang 2013,
// Comput. Math. Appl. 65:160-171; Lou, Guo & Shi 2013, Phys. Rev. E 87:063301):
//  * the in-place solver against a plain two-lattice push reference with the same boundary rules,
//    every step (both halves of the AA pattern, bulk and boundary donors, a solid donor, wall
//    corners and edges; D2Q9 and D3Q19, float and double);
//  * plane Poiseuille flow: profile and pressure gradient dp/dx = -12 mu U_mean / H^2
//    (White, Viscous Fluid Flow, 3rd ed., Eq. 3-38; [S003] Eq. 14 for the profile);
//  * reflection of a plane acoustic pulse and of an advected vortex at the outlet;
//  * checkpoint/restart and thread-count independence, bit for bit.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "core/error.hpp"
#include "lbm/solver.hpp"

using namespace ff;
using namespace ff::lbm;

namespace {

using Kind = FaceCondition::Kind;
using Outflow = FaceCondition::Outflow;

FaceCondition outflow_face(Outflow o, double U = 0, bool density_free = true) {
  FaceCondition c;
  c.kind = Kind::Outflow;
  c.outflow = o;
  c.convective_velocity = U;
  c.outflow_density_free = density_free;
  return c;
}

// ---------------------------------------------------------------- two-lattice reference

// Box nx x ny x nz: x- wall, x+ outflow, walls on y (and z in 3D), one solid cell one layer inside
// the outlet (its outflow node has a solid donor and bounces its unknowns back). Push streaming
// into a second array; half-way bounce-back; then the outflow rule on the streamed values.
template <class L, class T>
struct Reference {
  int nx, ny, nz;
  Outflow kind;
  double Uset;
  bool density_free;
  Relax<T> r;
  std::vector<T> f, fn, gs;   // pre-collision, streamed, post-collision: [q * n + cell]
  std::vector<T> prev, un;    // convective state per outflow node (node = y + ny * z)
  std::vector<T> drho, ux;    // moments of the last step
  int sx, sy, sz;             // the solid cell
  Reference(int nx_, int ny_, int nz_, Outflow k, double U, bool free)
      : nx(nx_), ny(ny_), nz(nz_), kind(k), Uset(U), density_free(free) {
    const double fa[3] = {0, 0, 0};
    r = make_relax<T>(CollisionModel::Trt, 0.7, 3.0 / 16, fa);
    const std::size_t n = cells();
    f.assign(L::Q * n, T(0));
    fn = gs = f;
    prev.assign(L::Q * std::size_t(ny) * nz, T(0));
    un.assign(std::size_t(ny) * nz, T(0));
    drho.assign(n, T(0));
    ux.assign(n, T(0));
    sx = nx - 2, sy = ny / 2, sz = nz / 2;
  }
  std::size_t cells() const { return std::size_t(nx) * ny * nz; }
  std::size_t id(int x, int y, int z) const { return std::size_t(x) + std::size_t(nx) * (y + std::size_t(ny) * z); }
  bool solid(int x, int y, int z) const { return x == sx && y == sy && z == sz; }
  void init(const std::function<void(int, int, int, double&, Vec3&)>& fn0) {
    const std::size_t n = cells();
    for (int z = 0; z < nz; ++z)
      for (int y = 0; y < ny; ++y)
        for (int x = 0; x < nx; ++x) {
          double rho = 1;
          Vec3 u = Vec3::Zero();
          if (!solid(x, y, z)) fn0(x, y, z, rho, u);
          const T uu[3] = {T(u[0]), T(u[1]), T(L::D == 3 ? u[2] : 0.0)};
          T geq[L::Q];
          equilibrium<L, T>(T(rho), uu, geq);
          for (int q = 0; q < L::Q; ++q) f[q * n + id(x, y, z)] = geq[q];
          // A solid donor's node bounces back g*_o(x, t-1): at t = 0 the initial g_q itself.
          for (int q = 0; q < L::Q; ++q) gs[L::opp[q] * n + id(x, y, z)] = geq[q];
          if (x == nx - 1) {
            un[y + std::size_t(ny) * z] = uu[0];
            for (int q = 0; q < L::Q; ++q) prev[q * std::size_t(ny) * nz + y + std::size_t(ny) * z] = geq[q];
          }
        }
  }
  void step() {
    const std::size_t n = cells(), nn = std::size_t(ny) * nz;
    // The face's convective speed from the previous step's outflow speeds, in node order.
    double sum = 0;
    long count = 0;
    for (int z = 0; z < nz; ++z)
      for (int y = 0; y < ny; ++y)
        if (!solid(nx - 1, y, z)) {
          sum += double(un[y + std::size_t(ny) * z]);
          ++count;
        }
    const T U = T(Uset > 0 ? Uset : std::max(0.0, sum / double(count)));
    // The outflow rule on the gathered populations (before the collision, as the solver does).
    for (int z = 0; z < nz; ++z)
      for (int y = 0; y < ny; ++y) {
        if (solid(nx - 1, y, z)) continue;
        const std::size_t c = id(nx - 1, y, z), k = y + std::size_t(ny) * z;
        // The donor's unknowns shifted to the node's own density (solver.cpp, apply_outflow).
        T delta = 0;
        if (density_free && !solid(nx - 2, y, z)) {
          T known = f[c], unknown = 0, drho_d = f[id(nx - 2, y, z)], W = 0;
          for (int q = 1; q < L::Q; ++q) {
            drho_d += f[q * n + id(nx - 2, y, z)];
            if (L::c[q][0] < 0) {
              unknown += f[q * n + id(nx - 2, y, z)];
              W += T(L::w[q]);
            } else {
              known += f[q * n + c];
            }
          }
          delta = (known + unknown - drho_d) / (T(1) - W);
        }
        for (int q = 0; q < L::Q; ++q) {
          if (L::c[q][0] >= 0) continue;
          const T d = solid(nx - 2, y, z) ? gs[L::opp[q] * n + c] : f[q * n + id(nx - 2, y, z)] + T(L::w[q]) * delta;
          if (kind == Outflow::Convective) {
            T& p = prev[q * nn + k];
            f[q * n + c] = (p + U * d) / (T(1) + U);
            p = f[q * n + c];
          } else {
            f[q * n + c] = d;
          }
        }
      }
    for (int z = 0; z < nz; ++z)
      for (int y = 0; y < ny; ++y)
        for (int x = 0; x < nx; ++x) {
          if (solid(x, y, z)) continue;
          const std::size_t c = id(x, y, z);
          T g[L::Q], d, u[3];
          for (int q = 0; q < L::Q; ++q) g[q] = f[q * n + c];
          collide<L, T, CollisionModel::Trt, false>(g, r, d, u);
          for (int q = 0; q < L::Q; ++q) gs[q * n + c] = g[q];
          drho[c] = d;
          ux[c] = u[0];
          if (x == nx - 1) un[y + std::size_t(ny) * z] = u[0];  // outward speed (n = -e_x)
        }
    for (int z = 0; z < nz; ++z)
      for (int y = 0; y < ny; ++y)
        for (int x = 0; x < nx; ++x) {
          if (solid(x, y, z)) continue;
          const std::size_t c = id(x, y, z);
          for (int q = 0; q < L::Q; ++q) {
            const int X = x + L::c[q][0], Y = y + L::c[q][1], Z = z + L::c[q][2];
            if (X >= nx) continue;  // leaves through the outlet
            const bool out = X < 0 || Y < 0 || Y >= ny || (L::D == 3 && (Z < 0 || Z >= nz));
            if (out || solid(X, Y, Z)) fn[L::opp[q] * n + c] = gs[q * n + c];
            else fn[q * n + id(X, Y, Z)] = gs[q * n + c];
          }
        }
    std::swap(f, fn);
  }
};

template <class L, class T>
double reference_difference(Outflow kind, double U, bool density_free) {
  const int nx = 9, ny = 7, nz = L::D == 3 ? 5 : 1;
  auto init = [](int x, int y, int z, double& rho, Vec3& u) {
    rho = 1 + 0.01 * std::sin(0.7 * x + 0.3 * y + 0.5 * z);
    u = Vec3(0.05 + 0.02 * std::cos(0.5 * y + 0.2 * x), 0.01 * std::sin(0.4 * x + z), 0.01 * std::cos(0.3 * x + y));
  };
  Reference<L, T> ref(nx, ny, nz, kind, U, density_free);
  ref.init(init);
  Grid g(L::D, nx, ny, nz, {false, false, L::D == 2});
  SolverSettings st;
  st.tau = 0.7;
  Solver<L, T> s(g, st);
  s.set_face(1, outflow_face(kind, U, density_free));
  const int id = s.add_object("block", WallScheme::HalfwayBounceBack, Vec3::Zero());
  s.set_solid(ref.sx, ref.sy, ref.sz, id);
  s.finalize();
  s.initialize(init);
  double worst = 0;
  for (int t = 0; t < 30; ++t) {
    s.step(true);
    ref.step();
    for (int z = 0; z < nz; ++z)
      for (int y = 0; y < ny; ++y)
        for (int x = 0; x < nx; ++x) {
          if (ref.solid(x, y, z)) continue;
          const std::size_t c = ref.id(x, y, z);
          worst = std::max(worst, std::abs(s.density(x, y, z) - 1.0 - double(ref.drho[c])));
          worst = std::max(worst, std::abs(s.velocity(x, y, z)[0] - double(ref.ux[c])));
        }
  }
  return worst;
}

// ---------------------------------------------------------------- plane Poiseuille

struct PoiseuilleResult {
  double profile_mid = 0, profile_out = 0;  // RMS error / u_max at mid-channel and at the outlet node
  double shape_out = 0;                     // RMS error of u / <u> at the outlet node (compressibility removed)
  double gradient = 0;                      // relative error of dp/dx against 12 mu U_mean / H^2
  double mass_before = 0, mass_rise = 0;    // mean density at step 5000 and its rise over 1000 steps
};

template <class L, class T>
PoiseuilleResult poiseuille(const FaceCondition& outlet) {
  const int H = 16, Lx = 48, nz = L::D == 3 ? 2 : 1;
  const double tau = 0.8, nu = (tau - 0.5) / 3, umax = 0.01;
  Grid g(L::D, Lx, H, nz, {false, false, true});
  SolverSettings st;
  st.tau = tau;
  Solver<L, T> s(g, st);
  PoiseuilleResult res;
  // Walls half-way at y = -1/2 and H - 1/2 (TRT, Lambda = 3/16: exactly there).
  auto prof = [&](int, int y, int) {
    const double yy = y + 0.5;
    return Vec3(4 * umax * yy * (H - yy) / (H * H), 0, 0);
  };
  FaceCondition in;
  in.kind = Kind::Velocity;
  in.profile = prof;
  s.set_face(0, in);
  s.set_face(1, outlet);
  s.finalize();
  s.initialize([&](int x, int y, int z, double& r, Vec3& u) { r = 1; u = prof(x, y, z); });
  for (int i = 0; i < 6000; ++i) {
    s.step(i == 4999 || i == 5999);
    if (i == 4999) res.mass_before = s.total_mass() / (Lx * H * nz);
  }
  res.mass_rise = s.total_mass() / (Lx * H * nz) - res.mass_before;
  auto rms = [&](int x, bool normalise) {
    double mean = 0;
    for (int y = 0; y < H; ++y) mean += s.velocity(x, y, 0)[0] / H;
    double e2 = 0;
    for (int y = 0; y < H; ++y) {
      const double ua = prof(0, y, 0)[0], u = s.velocity(x, y, 0)[0];
      const double e = normalise ? u / mean - ua / (2 * umax / 3) : (u - ua) / umax;
      e2 += e * e;
    }
    return std::sqrt(e2 / H);
  };
  res.profile_mid = rms(Lx / 2, false);
  res.profile_out = rms(Lx - 1, false);
  res.shape_out = rms(Lx - 1, true);
  // Mean pressure p = c_s^2 rho over two cross-sections; mu = rho nu, U_mean from the local flux.
  const int x1 = Lx / 4, x2 = 3 * Lx / 4;
  double p1 = 0, p2 = 0, rho = 0, um = 0;
  for (int y = 0; y < H; ++y) {
    p1 += s.density(x1, y, 0) / (3.0 * H);
    p2 += s.density(x2, y, 0) / (3.0 * H);
    rho += s.density(Lx / 2, y, 0) / H;
    um += s.velocity(Lx / 2, y, 0)[0] / H;
  }
  const double dpdx = (p2 - p1) / (x2 - x1), expected = -12 * rho * nu * um / (H * H);
  res.gradient = std::abs(dpdx / expected - 1);
  return res;
}

// ---------------------------------------------------------------- acoustic pulse

// Reflected fraction of a plane, right-running pressure pulse (Gaussian in rho', u' = c_s rho'/rho_0)
// riding on a mean flow u0 in a channel with periodic sides and a velocity inlet: the amplitude of
// the left-running Riemann variable (rho' - u'/c_s)/2 that comes back to a probe after the pulse hit
// the outlet, over the right-running amplitude that passed it. Waves from the inlet are right-running
// and arrive later than the window; the initial pulse has no left-running part.
double reflection(const FaceCondition& outlet, bool print_series = false) {
  const int nx = 400, ny = 2, x0 = 80, xp = 200;
  const double u0 = 0.05, eps = 1e-3, w = 10, cs = std::sqrt(1.0 / 3);
  Grid g(2, nx, ny, 1, {false, true, true});
  SolverSettings st;
  st.tau = 0.55;
  Solver<D2Q9, double> s(g, st);
  FaceCondition in;
  in.kind = Kind::Velocity;
  in.velocity = Vec3(u0, 0, 0);
  s.set_face(0, in);
  s.set_face(1, outlet);
  s.finalize();
  s.initialize([&](int x, int, int, double& r, Vec3& u) {
    const double d = eps * std::exp(-0.5 * (x - x0) * (x - x0) / (w * w));
    r = 1 + d;
    u = Vec3(u0 + cs * d, 0, 0);
  });
  // Arrivals at the probe (steps): incoming ~190, reflected ~890, the inlet's echo of it ~1590.
  const int t_in = 600, t_end = 1300;
  double a_in = 0, a_out = 0, jm0 = 0;
  for (int t = 0; t < t_end; ++t) {
    s.step(true);
    const double rho = s.density(xp, 0, 0), u = s.velocity(xp, 0, 0)[0];
    const double jp = 0.5 * ((rho - 1) + (u - u0) / cs), jm = 0.5 * ((rho - 1) - (u - u0) / cs);
    if (t < t_in) a_in = std::max(a_in, std::abs(jp));
    if (t == t_in) jm0 = jm;
    if (t >= t_in) a_out = std::max(a_out, std::abs(jm - jm0));
    if (print_series && t % 50 == 0) std::printf("  t %4d  J+ %+.3e  J- %+.3e\n", t, jp, jm);
  }
  return a_out / a_in;
}

// ---------------------------------------------------------------- advected vortex

// A Gaussian vortex (stream function C exp(-r^2 / 2R^2), with its pressure field
// p - p0 = -rho C^2 / (2 R^2) exp(-r^2 / R^2)) carried by a uniform flow u0 out through the outlet.
// Returns the largest |u - u0| left in the channel after the vortex has gone, over its peak speed,
// and sets `finite` if nothing blew up on the way.
double vortex_residual(const FaceCondition& outlet, bool& finite) {
  const int nx = 120, ny = 60;
  const double u0 = 0.08, R = 5, C = 0.02 * R * std::exp(0.5);  // peak swirl 0.02 at r = R
  const double xc = 50, yc = 30;
  Grid g(2, nx, ny, 1, {false, true, true});
  SolverSettings st;
  st.tau = 0.56;
  Solver<D2Q9, double> s(g, st);
  FaceCondition in;
  in.kind = Kind::Velocity;
  in.velocity = Vec3(u0, 0, 0);
  s.set_face(0, in);
  s.set_face(1, outlet);
  s.finalize();
  s.initialize([&](int x, int y, int, double& r, Vec3& u) {
    const double dx = x - xc, dy = y - yc, e = std::exp(-0.5 * (dx * dx + dy * dy) / (R * R));
    u = Vec3(u0 - C * dy / (R * R) * e, C * dx / (R * R) * e, 0);
    r = 1 - 3 * C * C / (2 * R * R) * e * e;
  });
  finite = true;
  const int steps = 2000;  // the vortex reaches the outlet after ~900 steps and has left by ~1200
  for (int t = 0; t < steps; ++t) {
    s.step(t % 100 == 99);
    if (t % 100 == 99 && !std::isfinite(s.max_speed())) {
      finite = false;
      return 1e9;
    }
  }
  double m = 0;
  for (int y = 0; y < ny; ++y)
    for (int x = 0; x < nx; ++x) {
      const Vec3 u = s.velocity(x, y, 0);
      m = std::max(m, std::hypot(u[0] - u0, u[1]));
    }
  return m / 0.02;
}

// ---------------------------------------------------------------- restart and threads

// A channel with walls and an obstacle near a convective (or zero-gradient) outlet, driven by a
// velocity inlet: enough happens at the outlet in a few dozen steps.
template <class L, class T>
Solver<L, T> busy_channel(const FaceCondition& outlet, int nx, int ny, int nz) {
  Grid g(L::D, nx, ny, nz, {false, false, false});
  SolverSettings st;
  st.tau = 0.6;
  Solver<L, T> s(g, st);
  FaceCondition in;
  in.kind = Kind::Velocity;
  in.velocity = Vec3(0.05, 0, 0);
  s.set_face(0, in);
  s.set_face(1, outlet);
  const int id = s.add_object("sphere", WallScheme::Bouzidi, Vec3(nx - 6, ny / 2.0, nz / 2.0));
  if (L::D == 3) s.add_shape(id, Sphere{Vec3(nx - 6, ny / 2.0, nz / 2.0), 2.6});
  else s.add_shape(id, Circle{Vec3(nx - 6, ny / 2.0, 0), 2.6});
  s.finalize();
  s.initialize([&](int x, int y, int z, double& r, Vec3& u) {
    r = 1 + 0.002 * std::sin(0.4 * x + 0.7 * y + z);
    u = Vec3(0.05 + 0.01 * std::cos(0.3 * y + 0.2 * z), 0.01 * std::sin(0.5 * x), L::D == 3 ? 0.005 : 0.0);
  });
  return s;
}

template <class L, class T>
void expect_restart_identical(const FaceCondition& outlet, int N) {
  auto a = busy_channel<L, T>(outlet, 20, 10, 8);
  for (int i = 0; i < 2 * N; ++i) a.step();
  auto b = busy_channel<L, T>(outlet, 20, 10, 8);
  for (int i = 0; i < N; ++i) b.step();
  const std::vector<T> saved(b.populations().begin(), b.populations().end());
  const long at = b.time_step();
  auto c = busy_channel<L, T>(outlet, 20, 10, 8);  // a fresh solver, then the checkpoint
  c.restore(saved, at);
  for (int i = 0; i < N; ++i) c.step();
  ASSERT_EQ(c.time_step(), a.time_step());
  EXPECT_TRUE(std::equal(a.populations().begin(), a.populations().end(), c.populations().begin()))
      << L::name << " N = " << N;
}

}  // namespace

TEST(LbmOutflow, MatchesTwoLatticeReference) {
  // Every step, both AA halves: the in-place solver equals the push reference (same collision,
  // same rules) to round-off; a wrong slot of either AA half shows at the 1e-3 level.
  for (bool free : {true, false})
    for (Outflow k : {Outflow::ZeroGradient, Outflow::Convective})
      for (double U : {0.0, 0.1}) {
        if (k == Outflow::ZeroGradient && U > 0) continue;
        EXPECT_LT((reference_difference<D2Q9, double>(k, U, free)), 1e-14) << int(k) << " U " << U << " " << free;
        EXPECT_LT((reference_difference<D3Q19, double>(k, U, free)), 1e-14) << int(k) << " U " << U << " " << free;
        EXPECT_LT((reference_difference<D2Q9, float>(k, U, free)), 1e-6) << int(k) << " U " << U << " " << free;
        EXPECT_LT((reference_difference<D3Q19, float>(k, U, free)), 1e-6) << int(k) << " U " << U << " " << free;
      }
}

TEST(LbmOutflow, PoiseuilleChannel) {
  // Parabolic Zou-He inlet, outflow outlet, H = 16, L = 48, tau 0.8, u_max 0.01, 6000 steps.
  // Tolerances: profile RMS 0.5% of u_max (the LBM's weak compressibility alone changes u by
  // ~0.2% along this channel), profile shape at the outlet node 0.3%, dp/dx 1%, and a steady
  // mass: mean density change over the last 1000 steps below 1e-5 (the plain copy: 3e-2).
  auto check = [](auto tag, auto real, const FaceCondition& out, const char* name) {
    using L = decltype(tag);
    using T = decltype(real);
    const PoiseuilleResult r = poiseuille<L, T>(out);
    std::printf("  %s %s %s: profile mid %.2e, outlet %.2e, outlet shape %.2e, dp/dx error %.2e, density rise "
                "%.1e per 1000 steps\n",
                L::name.data(), sizeof(T) == 4 ? "float" : "double", name, r.profile_mid, r.profile_out, r.shape_out,
                r.gradient, r.mass_rise);
    EXPECT_LT(r.profile_mid, 5e-3) << L::name << " " << name;
    EXPECT_LT(r.profile_out, 5e-3) << L::name << " " << name;
    EXPECT_LT(r.shape_out, 3e-3) << L::name << " " << name;
    EXPECT_LT(r.gradient, 1e-2) << L::name << " " << name;
    EXPECT_LT(std::abs(r.mass_rise), 1e-5) << L::name << " " << name;
  };
  check(D2Q9{}, double{}, outflow_face(Outflow::ZeroGradient), "zero-gradient");
  check(D2Q9{}, double{}, outflow_face(Outflow::Convective), "convective");
  check(D2Q9{}, float{}, outflow_face(Outflow::Convective), "convective");
  check(D3Q19{}, double{}, outflow_face(Outflow::ZeroGradient), "zero-gradient");
  check(D3Q19{}, double{}, outflow_face(Outflow::Convective), "convective");
  check(D3Q19{}, float{}, outflow_face(Outflow::ZeroGradient), "zero-gradient");
}

TEST(LbmOutflow, PlainCopyIsAMassSource) {
  // Why the copied populations take the node's density (solver.cpp, apply_outflow): with the plain
  // copy the node receives the donor's density, and the density drop drho = 36 mu U_mean / H^2 per
  // cell of Poiseuille flow makes the whole lattice gain about drho / 3 per step (docs/lbm.md). The
  // outlet's own kink lowers the drop across the last cell, so the rate is checked to 30%.
  const PoiseuilleResult r = poiseuille<D2Q9, double>(outflow_face(Outflow::ZeroGradient, 0, false));
  const double nu = 0.1, U = 2.0 / 3 * 0.01, drho = 36 * nu * U / (16 * 16);
  std::printf("  plain copy: density rise %.3e per step, drho / 3 = %.3e\n", r.mass_rise / 1000, drho / 3);
  EXPECT_NEAR(r.mass_rise / 1000, drho / 3 * r.mass_before, 0.3 * drho / 3);
}

TEST(LbmOutflow, AcousticReflection) {
  // Plane pulse on a mean flow 0.05, periodic sides (see reflection()). Bounds from the measured
  // figures (docs/lbm.md) with margin; a pressure face reflects all but the viscous loss.
  FaceCondition p;
  p.kind = Kind::Pressure;
  p.density = 1;
  const double cs = std::sqrt(1.0 / 3);
  const double rp = reflection(p);
  const double rz = reflection(outflow_face(Outflow::ZeroGradient));
  const double rc = reflection(outflow_face(Outflow::Convective));
  const double rs = reflection(outflow_face(Outflow::Convective, 0.05 + cs));
  const double rz0 = reflection(outflow_face(Outflow::ZeroGradient, 0, false));
  const double rs0 = reflection(outflow_face(Outflow::Convective, 0.05 + cs, false));
  std::printf("  reflected fraction: pressure %.3f, zero-gradient %.3f, convective (U = mean) %.3f, "
              "convective (U = u0 + c_s) %.3f; plain copy: zero-gradient %.3f, convective (U = u0 + c_s) %.3f\n",
              rp, rz, rc, rs, rz0, rs0);
  EXPECT_GT(rp, 0.8);
  EXPECT_LT(rp, 1.0);
  EXPECT_GT(rz, 0.8);  // the density-free copy reflects much like a pressure face
  EXPECT_LT(rc, 0.3);
  EXPECT_LT(rs, 0.35);
  EXPECT_LT(rz0, 0.3);
  EXPECT_LT(rs0, 0.02);
}

TEST(LbmOutflow, VortexLeavesThroughOutlet) {
  // Bound: after the vortex has left, no disturbance above 2% of its peak speed remains.
  FaceCondition p;
  p.kind = Kind::Pressure;
  p.density = 1;
  bool fp, fz, fc;
  const double rp = vortex_residual(p, fp);
  const double rz = vortex_residual(outflow_face(Outflow::ZeroGradient), fz);
  const double rc = vortex_residual(outflow_face(Outflow::Convective), fc);
  std::printf("  residual max |u - u0| / peak after the vortex left: pressure %.4f, zero-gradient %.4f, "
              "convective %.4f\n",
              rp, rz, rc);
  EXPECT_TRUE(fp && fz && fc);
  EXPECT_LT(rz, 0.02);
  EXPECT_LT(rc, 0.02);
}

TEST(LbmOutflow, RestartIsBitIdentical) {
  // 2N steps == N steps, populations into a fresh solver, N more; N even and odd (AA parity).
  for (int N : {10, 11}) {
    expect_restart_identical<D2Q9, double>(outflow_face(Outflow::Convective), N);
    expect_restart_identical<D2Q9, float>(outflow_face(Outflow::Convective, 0.07), N);
    expect_restart_identical<D3Q19, double>(outflow_face(Outflow::Convective), N);
    expect_restart_identical<D3Q19, float>(outflow_face(Outflow::ZeroGradient), N);
  }
}

TEST(LbmOutflow, ResultsDoNotDependOnThreadCount) {
  // Large enough for the parallel bulk (> 16384 cells) and both boundary passes (> 2048 cells).
  const int saved = omp_get_max_threads();
  for (Outflow k : {Outflow::ZeroGradient, Outflow::Convective}) {
    std::vector<double> pop[2];
    for (int t = 0; t < 2; ++t) {
      omp_set_num_threads(t + 1);
      auto s = busy_channel<D3Q19, double>(outflow_face(k), 24, 50, 50);
      for (int i = 0; i < 9; ++i) s.step();
      pop[t].assign(s.populations().begin(), s.populations().end());
    }
    EXPECT_TRUE(pop[0] == pop[1]) << int(k);
  }
  omp_set_num_threads(saved);
}

TEST(LbmOutflow, RefusesBadFaces) {
  Grid g(2, 2, 8, 1, {false, true, true});
  Solver<D2Q9, double> s(g, SolverSettings{});
  s.set_face(1, outflow_face(Outflow::ZeroGradient));
  EXPECT_THROW(s.finalize(), InputError);  // fewer than 3 cells along x
  EXPECT_THROW(s.set_face(1, outflow_face(Outflow::Convective, -0.1)), InputError);
  Grid g2(2, 8, 8, 1, {false, false, true});
  Solver<D2Q9, double> s2(g2, SolverSettings{});
  s2.set_face(1, outflow_face(Outflow::ZeroGradient));
  FaceCondition p;
  p.kind = Kind::Pressure;
  s2.set_face(3, p);
  EXPECT_THROW(s2.finalize(), InputError);  // open-face crossing at (7, 7)
}


TEST(LbmOutflow, EveryFaceAndDirectionAgree) {
  // The same flow through each of the six faces (D3Q19, walls on the other four; a velocity inlet
  // opposite): the lattice's cube symmetries map the runs onto each other, so every sampled
  // velocity must agree to round-off (1e-13) with the x+ run, over both AA halves.
  for (Outflow k : {Outflow::ZeroGradient, Outflow::Convective}) {
    std::vector<double> ref;
    for (int a = 0; a < 3; ++a)
      for (int s : {1, -1}) {
        const int L = 10, nb = 6, nc = 5, b = a == 0 ? 1 : 0, c = a == 2 ? 1 : 2;
        int n[3];
        n[a] = L;
        n[b] = nb;
        n[c] = nc;
        Grid g(3, n[0], n[1], n[2], {false, false, false});
        SolverSettings st;
        st.tau = 0.7;
        Solver<D3Q19, double> sol(g, st);
        FaceCondition in;
        in.kind = Kind::Velocity;
        Vec3 uin = Vec3::Zero();
        uin[a] = s * 0.03;
        in.velocity = uin;
        sol.set_face(2 * a + (s > 0 ? 0 : 1), in);
        sol.set_face(2 * a + (s > 0 ? 1 : 0), outflow_face(k));
        sol.finalize();
        // Canonical coordinates: X along the flow from the inlet, Y and Z across.
        auto canon = [&](int x, int y, int z) {
          const int p[3] = {x, y, z};
          return std::array<int, 3>{s > 0 ? p[a] : L - 1 - p[a], p[b], p[c]};
        };
        sol.initialize([&](int x, int y, int z, double& r, Vec3& u) {
          const auto C = canon(x, y, z);
          r = 1 + 0.002 * std::sin(0.5 * C[0] + 0.3 * C[1] * C[1] + 0.2 * C[2]);
          u = Vec3::Zero();
          u[a] = s * (0.03 + 0.01 * std::cos(0.4 * C[1] + 0.7 * C[2]));
          u[b] = 0.005 * std::sin(0.6 * C[0] + C[2]);
          u[c] = 0.004 * std::cos(0.5 * C[0] + C[1]);
        });
        const std::size_t per_step = std::size_t(L) * nb * nc * 3;
        std::vector<double> out(2 * per_step);  // the last two steps: an even and an odd one
        double worst = 0;
        for (int t = 0; t < 41; ++t) {
          sol.step(true);
          if (t < 39) continue;
          for (int z = 0; z < n[2]; ++z)
            for (int y = 0; y < n[1]; ++y)
              for (int x = 0; x < n[0]; ++x) {
                const auto C = canon(x, y, z);
                const Vec3 u = sol.velocity(x, y, z);
                const double uc[3] = {s * u[a], u[b], u[c]};
                for (int i = 0; i < 3; ++i) {
                  const std::size_t at =
                      std::size_t(t - 39) * per_step + 3 * (std::size_t(C[0]) + L * (std::size_t(C[1]) + nb * C[2])) + i;
                  out[at] = uc[i];
                  if (!ref.empty()) worst = std::max(worst, std::abs(out[at] - ref[at]));
                }
              }
        }
        if (ref.empty()) ref = out;
        EXPECT_LT(worst, 1e-13) << "outflow on face " << face_name(2 * a + (s > 0 ? 1 : 0)) << " kind " << int(k);
      }
  }
}
