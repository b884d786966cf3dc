// Moving-solid-cell schemes (lbm/moving_boundary.hpp) against Stokes-flow references, through the
// particle path (Solver::set_particles with a particle held fixed), set up as test_psm_drag.cpp:
//  - Stokes drag on a simple-cubic array of fixed spheres: Zick & Homsy (1982), J. Fluid Mech.
//    115:13, Table 2, F = 6 pi mu a K U with U the superficial (cell-averaged) velocity and
//    F = G tau_0 the force of the mean pressure gradient on one unit cell; the array is driven by
//    a body force g on the fluid cells, so at steady state the particle force is g N_fluid and
//    F_ZH = F_particle n^3 / N_fluid;
//  - torque on a sphere rotating in a periodic box: T = 8 pi mu a^3 Omega (Lamb 1932, Art. 334).
// Fast cases here; FRACFLOW_LONG_TESTS adds finer lattices and more fractions.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "lbm/solver.hpp"

using namespace ff;
using namespace ff::lbm;

namespace {

Solver<D3Q19, double> periodic_box_at_rest(int n, double tau, double gx, ParticleScheme scheme) {
  Grid g(3, n, n, n, {true, true, true});
  SolverSettings s;
  s.tau = tau;
  s.body_force = Vec3(gx, 0, 0);
  s.particle_scheme = scheme;
  Solver<D3Q19, double> sol(g, s);
  sol.finalize();
  sol.initialize([](int, int, int, double& rho, Vec3& u) {
    rho = 1;
    u = Vec3::Zero();
  });
  return sol;
}

struct DragResult {
  double K = 0, U = 0;
  long steps = 0;
};

// One sphere of solid fraction phi in a periodic box of n^3 cells; runs until U changes by less
// than 1e-5 (relative) over 200 steps.
DragResult zick_homsy_case(int n, double phi, double tau, ParticleScheme scheme) {
  const double nu = (tau - 0.5) / 3;
  const double a = std::cbrt(3 * phi / (4 * M_PI)) * n;
  auto sol = periodic_box_at_rest(n, tau, 1e-6 * std::pow(24.0 / n, 3), scheme);
  ParticleSet p;
  p.resize(1);
  p.radius[0] = a;
  p.position[0] = Vec3(0.5 * n - 0.5 + 0.13, 0.5 * n - 0.5 + 0.07, 0.5 * n - 0.5 - 0.11);  // off the lattice symmetry
  sol.set_particles(p);
  const double n_fluid = double(n) * n * n - double(sol.moving_boundary()->num_cells());
  auto superficial = [&]() {
    double jx = 0;
    for (int z = 0; z < n; ++z)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) jx += sol.density(x, y, z) * sol.velocity(x, y, z)[0];
    return jx / (double(n) * n * n);
  };
  DragResult r;
  double prev = 0;
  for (long t = 1; t <= 200000; ++t) {
    const bool sample = t % 200 == 0;
    sol.step(sample);
    if (!sample) continue;
    const double U = superficial();
    if (std::abs(U - prev) < 1e-5 * std::abs(U)) {
      r.steps = t;
      r.U = U;
      break;
    }
    prev = U;
  }
  const double F = sol.particle_forces()[0][0] * double(n) * n * n / n_fluid;
  r.K = F / (6 * M_PI * nu * a * r.U);
  return r;
}

double rotating_torque(int n, double a, double tau, ParticleScheme scheme, long* steps) {
  const double nu = (tau - 0.5) / 3;
  auto sol = periodic_box_at_rest(n, tau, 0.0, scheme);
  const double Omega = 1e-3;
  ParticleSet p;
  p.resize(1);
  p.radius[0] = a;
  p.position[0] = Vec3(0.5 * n + 0.21, 0.5 * n - 0.17, 0.5 * n + 0.09);
  p.omega[0] = Vec3(0, 0, Omega);
  sol.set_particles(p);
  double prev = 0;
  for (long t = 1; t <= 100000; ++t) {
    sol.step();
    if (t % 100 != 0) continue;
    const double T = -sol.particle_torques()[0][2] / (8 * M_PI * nu * a * a * a * Omega);
    if (std::abs(T - prev) < 1e-5 * std::abs(T)) {
      *steps = t;
      return T;
    }
    prev = T;
  }
  *steps = 0;
  return 0;
}

const ParticleScheme kSchemes[] = {ParticleScheme::StairwiseBounceBack, ParticleScheme::InterpolatedBounceBack};

}  // namespace

// Zick & Homsy (1982) Table 2, simple cubic, tau = 0.7, within 5% (issue 15's target). n = 24 here
// (a = 8.9 and 10.4 cells; measured at phi = 0.125, a = 7.4: stair-wise +1.7%, interpolated -0.8%),
// n = 40 from dilute to dense under the long label.
TEST(MovingBoundaryValidation, ZickHomsySimpleCubic) {
  struct Ref {
    double phi, K;
  };
#ifdef FRACFLOW_LONG_TESTS
  const int n = 40;
  const Ref refs[] = {{0.027, 2.008}, {0.064, 2.810}, {0.125, 4.292}, {0.216, 7.442}, {0.343, 15.4}, {0.45, 28.1}};
#else
  const int n = 24;
  const Ref refs[] = {{0.216, 7.442}, {0.343, 15.4}};
#endif
  for (ParticleScheme scheme : kSchemes)
    for (const Ref& ref : refs) {
      const DragResult r = zick_homsy_case(n, ref.phi, 0.7, scheme);
      const double err = r.K / ref.K - 1;
      const double a = std::cbrt(3 * ref.phi / (4 * M_PI)) * n;
      std::printf("%s Zick-Homsy n = %d phi = %.3f (a = %.2f): K = %.4f (ref %.3f, %+.2f%%), Re = %.3f, %ld steps\n",
                  particle_scheme_name(scheme), n, ref.phi, a, r.K, ref.K, 100 * err, 2 * a * r.U / (0.2 / 3), r.steps);
      EXPECT_GT(r.steps, 0) << "not steady";
      EXPECT_LT(std::abs(err), 0.05) << particle_scheme_name(scheme) << " phi = " << ref.phi;
    }
}

// Rotating sphere: torque against 8 pi mu a^3 Omega, tau = 0.7, a = 5 cells in 24^3 (phi = 0.038;
// the periodic images raise the torque by about 1-2%): tolerance 10% (the staircase of the
// stair-wise scheme is a slightly larger sphere, T ~ a^3: measured +6.5%; interpolated +2.7%),
// 5% at a = 8 in 48^3 under the long label.
TEST(MovingBoundaryValidation, RotatingSphereTorque) {
  for (ParticleScheme scheme : kSchemes) {
    long steps = 0;
#ifdef FRACFLOW_LONG_TESTS
    const int n = 48;
    const double a = 8, tol = 0.05;
#else
    const int n = 24;
    const double a = 5, tol = 0.10;
#endif
    const double ratio = rotating_torque(n, a, 0.7, scheme, &steps);
    std::printf("%s rotating sphere a = %.0f in %d^3: T / (8 pi mu a^3 Omega) = %.4f, %ld steps\n",
                particle_scheme_name(scheme), a, n, ratio, steps);
    EXPECT_GT(steps, 0) << "not steady";
    EXPECT_NEAR(ratio, 1.0, tol) << particle_scheme_name(scheme);
  }
}
