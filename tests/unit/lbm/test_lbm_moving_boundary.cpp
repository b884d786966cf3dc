// Moving solid cells (lbm/moving_boundary.hpp): stair-wise moving bounce-back (Ladd 1994, [S003]
// Sec. 2.3-2.4) and interpolated bounce-back with refill (Bouzidi et al. 2001, [S002] Sec. 3).
//  - action equals reaction in a closed periodic box with moving, spinning particles: the fluid's
//    momentum plus the impulse handed to the particles (links, covering, refill; Aidun, Lu & Ding
//    1998) is conserved to round-off, for both schemes; the mass that covering and refill move per
//    step is reported and bounded;
//  - a particle moving with a uniform flow feels no force (Galilean check of the moving-wall term);
//  - 1 and 2 threads give identical populations and forces; a resumed run continues bit-for-bit.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "lbm/solver.hpp"

using namespace ff;
using namespace ff::lbm;

namespace {

const ParticleScheme kSchemes[] = {ParticleScheme::StairwiseBounceBack, ParticleScheme::InterpolatedBounceBack};

// Fluid momentum and mass of the state before the next step, from the populations of the cells that
// are fluid now (AA pattern: even steps read g_q(x) from f[q][x], odd steps from f[opp q][x - c_q]).
template <class L, class T>
void fluid_totals(const Solver<L, T>& s, long double P[3], long double& M, double* max_drho = nullptr) {
  const Grid& g = s.grid();
  const auto& f = s.populations();
  const CellIndex N = g.padded_size();
  const bool odd = s.time_step() % 2 != 0;
  const auto* mb = s.moving_boundary();
  P[0] = P[1] = P[2] = 0;
  M = 0;
  for (int z = 0; z < g.nz; ++z)
    for (int y = 0; y < g.ny; ++y)
      for (int x = 0; x < g.nx; ++x) {
        const CellIndex i = g.index(x, y, z);
        if (s.is_solid(x, y, z) || (mb && mb->solid(i))) continue;
        long double m = 1.0L + (long double)f[i];
        for (int q = 1; q < L::Q; ++q) {
          const T v = odd ? f[L::opp[q] * N + g.neighbour(x, y, z, -L::c[q][0], -L::c[q][1], -L::c[q][2])]
                          : f[q * N + i];
          m += (long double)v;
          for (int a = 0; a < L::D; ++a) P[a] += (long double)(L::c[q][a]) * v;
        }
        M += m;
        if (max_drho) *max_drho = std::max(*max_drho, double(std::abs(m - 1.0L)));
      }
}

template <class L>
Solver<L, double> box(int nx, int ny, int nz, ParticleScheme scheme, bool walls_y = false) {
  Grid g(L::D, nx, ny, nz, {true, !walls_y, true});
  SolverSettings s;
  s.tau = 0.7;
  s.particle_scheme = scheme;
  Solver<L, double> sol(g, s);
  sol.finalize();
  sol.initialize([&](int x, int y, int z, double& rho, Vec3& u) {
    rho = 1.0 + 0.002 * std::sin(0.4 * x + 0.3 * y);
    u = Vec3(0.006 + 0.01 * std::sin(2 * M_PI * y / ny), 0.004 * std::cos(2 * M_PI * x / nx), L::D == 3 ? 0.003 * std::sin(0.2 * z) : 0.0);
  });
  return sol;
}

// a and b hold the same populations and particle loads, bit for bit.
template <class L>
void expect_identical(const Solver<L, double>& a, const Solver<L, double>& b, const std::string& what) {
  const auto& fa = a.populations();
  ASSERT_EQ(fa.size(), b.populations().size()) << what;
  for (std::size_t i = 0; i < fa.size(); ++i) ASSERT_EQ(fa[i], b.populations()[i]) << what << ", slot " << i;
  ASSERT_EQ(a.particle_forces().size(), b.particle_forces().size()) << what;
  for (std::size_t s = 0; s < a.particle_forces().size(); ++s)
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(a.particle_forces()[s][k], b.particle_forces()[s][k]) << what << ", particle " << s;
      ASSERT_EQ(a.particle_torques()[s][k], b.particle_torques()[s][k]) << what << ", particle " << s;
    }
}

// Three particles, two of them overlapping (bonded grains touch), moving and spinning fast enough
// to cover and uncover cells every few steps.
ParticleSet moving_set(int dim, double t) {
  ParticleSet p;
  p.resize(3);
  const double r[3] = {5.3, 4.1, 3.2};
  const Vec3 v[3] = {Vec3(0.03, 0.012, 0.006), Vec3(-0.015, 0.02, -0.01), Vec3(0.0, -0.025, 0.012)};
  const Vec3 X0[3] = {Vec3(12.3, 14.7, 10.2), Vec3(20.1, 16.2, 11.6), Vec3(30.4, 8.9, 13.1)};
  for (int s = 0; s < 3; ++s) {
    p.id[s] = 1000000000000ull + std::uint64_t(s);
    p.radius[s] = r[s];
    p.velocity[s] = v[s];
    p.position[s] = X0[s] + t * v[s];
    p.omega[s] = Vec3(0.004 * s, -0.003, 0.005 * (s + 1));
    if (dim == 2) p.position[s][2] = 0;
  }
  return p;
}

// Action equals reaction: P_fluid(t) + J(t) + sum_{k<t} F_k is constant, with P_fluid(t) the fluid
// momentum before step t (after the set of step t has covered and refilled cells), J(t) the
// momentum that change moved to the particles (part of F_t) and F_k the force on all particles of
// step k. Tolerance 1e-12 relative to the summed force magnitude (double-precision round-off).
template <class L>
void check_conservation(int nz, ParticleScheme scheme, int steps) {
  auto sol = box<L>(40, 28, nz, scheme);
  long double P[3], M;
  Vec3 invariant0 = Vec3::Zero(), sumF = Vec3::Zero();
  double mag = 0, worst = 0, added = 0, removed = 0, worst_net = 0;
  long changed = 0, covered = 0, uncovered = 0;
  double M0 = 0, cells0 = 0, Mend = 0, cells_end = 0;
  double max_drho_all = 0, worst_ratio = 0;
  for (int t = 0; t < steps; ++t) {
    double max_drho = 0;
    fluid_totals(sol, P, M, &max_drho);  // densities the covered cells carry away
    sol.set_particles(moving_set(L::D, double(t)));
    const MovingBoundaryStats& st = sol.moving_boundary()->stats();
    fluid_totals(sol, P, M, &max_drho);
    max_drho_all = std::max(max_drho_all, max_drho);
    const Vec3 inv = Vec3(double(P[0]), double(P[1]), double(P[2])) + st.impulse + sumF;
    if (t == 0) {
      invariant0 = inv;
      M0 = double(M);
      cells0 = double(st.solid_cells);
    } else {
      added += st.mass_added;
      removed += st.mass_removed;
      covered += st.covered;
      uncovered += st.uncovered;
      changed += st.covered + st.uncovered;
      // Mass beyond the volume change: each changed cell moves its rho - 1 (refill: the mean of
      // its neighbours'), so |net| <= max |rho - 1| * (changed cells).
      const double net = std::abs((st.mass_added - double(st.uncovered)) - (st.mass_removed - double(st.covered)));
      worst_net = std::max(worst_net, net);
      if (st.covered + st.uncovered > 0)
        worst_ratio = std::max(worst_ratio, net / (max_drho * double(st.covered + st.uncovered)));
      worst = std::max(worst, (inv - invariant0).norm() / std::max(mag, 1e-30));
    }
    EXPECT_EQ(st.unattributed, 0);
    sol.step();
    for (const Vec3& f : sol.particle_forces()) {
      sumF += f;
      mag += f.norm();
    }
    Mend = double(M);
    cells_end = double(st.solid_cells);
  }
  const std::string name = std::string(L::name) + " " + particle_scheme_name(scheme);
  const double drift = std::abs((Mend + cells_end) - (M0 + cells0)) / (M0 + cells0);
  std::printf("%s: max |P + J + sum F - const| / sum |F| = %.2e over %d steps; refill added %.4f, covering removed "
              "%.4f per step (%.2f / %.2f cells per step), net beyond the volume change at most %.2e per step "
              "(max |rho - 1| %.2e, ratio to the bound %.2f); fluid mass + solid cells drift %.2e relative\n",
              name.c_str(), worst, steps, added / (steps - 1), removed / (steps - 1), double(uncovered) / (steps - 1),
              double(covered) / (steps - 1), worst_net, max_drho_all, worst_ratio, drift);
  EXPECT_GT(changed, 100) << name;  // the particles do cover and uncover cells
  EXPECT_LT(worst, 1e-12) << name;
  // Refill at the neighbours' mean density: what a step's changes add beyond the volume change is
  // bounded by the density variations of the flow (|rho - 1| < 0.01 here) times the changed cells.
  EXPECT_LE(worst_ratio, 1.0 + 1e-9) << name;
  // The fluid mass plus one per solid cell changes only by the bounded mass above and by the
  // moving-wall term of overlapping and spinning particles (measured 0.7% after 300 steps in 2D, 0.1%
  // after 300 steps in 3D): a gross refill error (rho = 0 or 2) would move it by tens of percent.
  EXPECT_LT(drift, 0.02) << name;
}

}  // namespace

TEST(MovingBoundary, ActionEqualsReaction2D) {
  for (ParticleScheme s : kSchemes) check_conservation<D2Q9>(1, s, 300);
}
TEST(MovingBoundary, ActionEqualsReaction3D) {
  for (ParticleScheme s : kSchemes) check_conservation<D3Q19>(24, s, 120);
}

// A particle carried by a uniform flow at the same velocity leaves the flow uniform, and the links
// exchange no momentum: in f^eq(rho, U) the moving-wall term turns g*_o into exactly g*_q, and a
// closed staircase has as many links along c as along -c. Its force is then only the momentum of
// the cells it covers minus that of the cells it refills, rho U (covered - uncovered) with rho = 1
// (Aidun et al. 1998), which averages to zero. Tolerance: 1e-12 of the force scale 6 pi mu a U
// (round-off).
TEST(MovingBoundary, ComovingParticleExchangesNoMomentum) {
  for (ParticleScheme s : kSchemes) {
    Grid g(2, 48, 40, 1, {true, true, true});
    SolverSettings st;
    st.tau = 0.8;
    st.particle_scheme = s;
    Solver<D2Q9, double> sol(g, st);
    sol.finalize();
    const Vec3 U(0.02, -0.013, 0);
    sol.initialize([&](int, int, int, double& rho, Vec3& u) {
      rho = 1;
      u = U;
    });
    ParticleSet p;
    p.resize(1);
    p.radius[0] = 6.3;
    p.velocity[0] = U;
    double worst_link = 0, worst_change = 0;
    long changed = 0;
    for (int t = 0; t < 200; ++t) {
      p.position[0] = Vec3(20.2, 19.7, 0) + double(t) * U;
      sol.set_particles(p);
      const MovingBoundaryStats st_change = sol.moving_boundary()->stats();
      sol.step(true);
      const Vec3 expected = double(st_change.covered - st_change.uncovered) * U;
      worst_change = std::max(worst_change, (st_change.impulse - expected).norm());
      worst_link = std::max(worst_link, (sol.particle_forces()[0] - st_change.impulse).norm());
      if (t > 0) changed += st_change.covered + st_change.uncovered;
    }
    double du = 0;
    for (int y = 0; y < 40; ++y)
      for (int x = 0; x < 48; ++x) du = std::max(du, (sol.velocity(x, y, 0) - U).norm());
    const double scale = 6 * M_PI * (0.3 / 3) * 6.3 * U.norm();
    std::printf("%s comoving: links' force %.2e, change impulse - rho U (cov - uncov) %.2e (of 6 pi mu a U), %ld cells "
                "changed, max |u - U| = %.2e\n",
                particle_scheme_name(s), worst_link / scale, worst_change / scale, changed, du);
    EXPECT_GT(changed, 20);
    EXPECT_LT(worst_link / scale, 1e-12) << particle_scheme_name(s);
    EXPECT_LT(worst_change / scale, 1e-12) << particle_scheme_name(s);
    EXPECT_LT(du, 1e-12) << particle_scheme_name(s);
  }
}

// 1 and 2 threads give identical populations and forces (3D lattice above the parallel thresholds,
// particles touching the walls: boundary-cell path, > 8192 links and solid cells: parallel post-pass); a run resumed
// at step 9 from the populations and the last step's particle set continues bit-for-bit.
TEST(MovingBoundary, ThreadsAndResumeBitIdentical) {
  for (ParticleScheme scheme : kSchemes) {
    auto set_at = [](long t) {
      ParticleSet p;
      p.resize(6);
      for (int s = 0; s < 6; ++s) {
        p.id[s] = std::uint64_t(7 * s + 1);
        p.radius[s] = 7.6 + 0.3 * s;
        p.velocity[s] = Vec3(0.04 * std::sin(s + 1.0), 0.03 * std::cos(s + 1.0), 0.02 * std::sin(2.0 * s));
        p.omega[s] = Vec3(0.002 * (s % 3 - 1), 0.003, -0.002 * (s % 2));
        p.position[s] = Vec3(6.0 + 11.0 * (s % 3), s < 3 ? 3.5 : 18.0, 6.0 + 5.0 * s) + double(t) * p.velocity[s];
      }
      return p;
    };
    auto run = [&](int threads, long steps, const Solver<D3Q19, double>* from) {
      omp_set_num_threads(threads);
      Solver<D3Q19, double> sol = box<D3Q19>(40, 28, 36, scheme, true);
      if (from) {
        sol.restore(std::vector<double>(from->populations().begin(), from->populations().end()), from->time_step());
        sol.restore_particles(set_at(from->time_step() - 1));
      }
      for (long t = sol.time_step(); t < steps; ++t) {
        sol.set_particles(set_at(t));
        sol.step();
      }
      return sol;
    };
    const int saved = omp_get_max_threads();
    auto a = run(1, 20, nullptr);
    auto b = run(2, 20, nullptr);
    auto half = run(1, 9, nullptr);
    auto c = run(2, 20, &half);
    omp_set_num_threads(saved);
    ASSERT_GT(a.moving_boundary()->num_links(), 8192u);  // the parallel post-pass
    ASSERT_GT(a.moving_boundary()->num_cells(), 8192u);
    ASSERT_GT(a.moving_boundary()->stats().covered + a.moving_boundary()->stats().uncovered, 0);
    expect_identical(a, b, std::string(particle_scheme_name(scheme)) + " threads");
    expect_identical(a, c, std::string(particle_scheme_name(scheme)) + " resume");
    std::printf("%s: 1/2 threads and resume identical (%zu links, %zu solid cells)\n", particle_scheme_name(scheme),
                a.moving_boundary()->num_links(), a.moving_boundary()->num_cells());
  }
}

// Links that stood for two steps are applied inside the bulk sweep, by lattice row (the row index);
// before that, and with SolverSettings::links_in_sweep = false, after it, particle by particle. Both
// must give the same populations and loads bit for bit (each particle's load is summed per node row
// in the same order), on 1 and 2 threads (other row blocks, other rows left to the pass after the
// sweep). Particles at rest and creeping ones (1e-5 cells per step: no cell changes, the Bouzidi
// fractions and the moving-wall term change every step), overlapping pairs, one across the periodic
// x edge; 2D and 3D, both bounce-back schemes.
template <class L>
void check_links_in_sweep(ParticleScheme scheme) {
  const int nz = L::D == 3 ? 30 : 1;
  auto set_at = [&](long t) {
    ParticleSet p;
    p.resize(7);
    for (int s = 0; s < 7; ++s) {
      p.id[s] = std::uint64_t(3 * s + 2);
      p.radius[s] = 4.3 + 0.45 * s;
      p.velocity[s] = s % 3 == 0 ? Vec3::Zero() : Vec3(1e-5 * (s - 3), 7e-6, L::D == 3 ? -5e-6 : 0.0);
      p.omega[s] = s % 3 == 0 ? Vec3::Zero() : Vec3(0, 0, 2e-6 * s);
      p.position[s] = Vec3(1.5 + 9.3 * s, 9.0 + 3.0 * (s % 2) + 0.2 * s, L::D == 3 ? 8.0 + 2.1 * s : 0.0) +
                      double(t) * p.velocity[s];
    }
    return p;
  };
  auto run = [&](int threads, bool in_sweep) {
    omp_set_num_threads(threads);
    Grid g(L::D, 64, 26, nz, {true, false, true});
    SolverSettings st;
    st.tau = 0.7;
    st.particle_scheme = scheme;
    st.links_in_sweep = in_sweep;
    Solver<L, double> sol(g, st);
    sol.finalize();
    sol.initialize([&](int x, int y, int z, double& rho, Vec3& u) {
      rho = 1.0 + 0.002 * std::sin(0.4 * x + 0.3 * y);
      u = Vec3(0.02 * std::sin(M_PI * y / 26.0), 0.004 * std::cos(2 * M_PI * x / 64.0), L::D == 3 ? 0.003 * std::sin(0.2 * z) : 0.0);
    });
    bool used = false;
    for (long t = 0; t < 14; ++t) {
      sol.set_particles(set_at(t));
      used = used || sol.moving_boundary()->rows_ready();
      sol.step();
    }
    EXPECT_EQ(used, in_sweep);
    return sol;
  };
  const int saved = omp_get_max_threads();
  auto after = run(1, false);
  auto sweep1 = run(1, true);
  auto sweep2 = run(2, true);
  omp_set_num_threads(saved);
  EXPECT_EQ(after.moving_boundary()->stats().covered + after.moving_boundary()->stats().uncovered, 0);
  expect_identical(after, sweep1, std::string(particle_scheme_name(scheme)) + " in the sweep");
  expect_identical(after, sweep2, std::string(particle_scheme_name(scheme)) + " in the sweep, 2 threads");
  double fmax = 0;
  for (const Vec3& F : after.particle_forces()) fmax = std::max(fmax, F.norm());
  EXPECT_GT(fmax, 1e-4);  // the fluid loads the particles (the comparison is not of zeros)
}

TEST(MovingBoundary, LinksInTheSweepGiveTheSameResultsAsAfterIt) {
  for (ParticleScheme scheme : kSchemes) {
    check_links_in_sweep<D2Q9>(scheme);
    check_links_in_sweep<D3Q19>(scheme);
  }
}

// Bad input names the scheme and the particle, and leaves the current set as it was.
TEST(MovingBoundary, BadParticleInput) {
  auto sol = box<D2Q9>(30, 20, 1, ParticleScheme::StairwiseBounceBack);
  ParticleSet p = moving_set(2, 0);
  sol.set_particles(p);
  const std::size_t cells = sol.moving_boundary()->num_cells(), links = sol.moving_boundary()->num_links();
  p.radius[1] = -1;
  try {
    sol.set_particles(p);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("stairwise_bounce_back particle 1"), std::string::npos) << e.what();
  }
  EXPECT_EQ(sol.moving_boundary()->num_cells(), cells);
  EXPECT_EQ(sol.moving_boundary()->num_links(), links);
  p.radius[1] = 4.1;
  sol.set_particles(p);  // the same set again: nothing changes
  EXPECT_EQ(sol.moving_boundary()->stats().covered + sol.moving_boundary()->stats().uncovered, 0);
  EXPECT_EQ(sol.moving_boundary()->num_cells(), cells);
}
