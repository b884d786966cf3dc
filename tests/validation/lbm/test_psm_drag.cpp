// Partially saturated cells (lbm/psm.hpp) against Stokes-flow references:
//  - Stokes drag on a simple-cubic array of fixed spheres: Zick & Homsy (1982), J. Fluid Mech.
//    115:13, Table 2, F = 6 pi mu a K U with U the superficial (cell-averaged) velocity;
//  - torque on a sphere rotating in a periodic box: T = 8 pi mu a^3 Omega (Lamb 1932, Art. 334;
//    the periodic images raise it by O(phi), about 1% at phi = 0.019, measured).
// The array is driven by a body force g on the fluid; in Zick & Homsy's problem the mean pressure
// gradient G also pushes on the sphere, F_ZH = G tau_0 = F_fluid / (1 - phi) with F_fluid = G V_f the
// force through the fluid (measured here as the PSM force on the particle).
// Fast cases here; FRACFLOW_LONG_TESTS adds finer lattices and more fractions.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "lbm/solver.hpp"

using namespace ff;
using namespace ff::lbm;

namespace {

// A D3Q19 periodic box of n^3 cells, fluid at rest, relaxation time tau, body force gx along x.
Solver<D3Q19, double> periodic_box_at_rest(int n, double tau, double gx) {
  Grid g(3, n, n, n, {true, true, true});
  SolverSettings s;
  s.tau = tau;
  s.body_force = Vec3(gx, 0, 0);
  Solver<D3Q19, double> sol(g, s);
  sol.finalize();
  sol.initialize([](int, int, int, double& rho, Vec3& u) {
    rho = 1;
    u = Vec3::Zero();
  });
  return sol;
}

struct DragResult {
  double K = 0;     // Zick & Homsy's drag coefficient
  double U = 0;     // superficial velocity
  long steps = 0;
};

// One sphere of solid fraction phi in a periodic box of n^3 cells, body force along x; runs until
// U changes by less than 1e-5 (relative) over 200 steps.
DragResult zick_homsy_case(int n, double phi, double tau) {
  const double nu = (tau - 0.5) / 3;
  const double a = std::cbrt(3 * phi / (4 * M_PI)) * n;
  // Stokes flow: U grows like n^2 at a fixed force, so the force falls like n^-3 (Reynolds number
  // 2 a U / nu below 0.25 for every case here).
  auto sol = periodic_box_at_rest(n, tau, 1e-6 * std::pow(24.0 / n, 3));
  ParticleSet p;
  p.resize(1);
  p.radius[0] = a;
  p.position[0] = Vec3(0.5 * n - 0.5 + 0.13, 0.5 * n - 0.5 + 0.07, 0.5 * n - 0.5 - 0.11);  // off the lattice symmetry
  sol.set_particles(p);
  auto superficial = [&]() {
    double jx = 0;
    for (int z = 0; z < n; ++z)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) jx += sol.density(x, y, z) * sol.velocity(x, y, z)[0];
    return jx / (double(n) * n * n);
  };
  DragResult r;
  double prev = 0;
  const long max_steps = 200000;
  for (long t = 1; t <= max_steps; ++t) {
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
  const double F = sol.particle_forces()[0][0] / (1 - phi);
  r.K = F / (6 * M_PI * nu * a * r.U);
  return r;
}

// Sphere of radius a spinning at Omega about z in a periodic box of n^3 cells; runs until the
// torque changes by less than 1e-5 (relative) over 100 steps.
struct TorqueResult {
  double ratio = 0;  // T / (8 pi mu a^3 Omega)
  long steps = 0;
};

TorqueResult rotating_torque(int n, double a, double tau) {
  const double nu = (tau - 0.5) / 3;
  auto sol = periodic_box_at_rest(n, tau, 0.0);
  const double Omega = 1e-3;
  ParticleSet p;
  p.resize(1);
  p.radius[0] = a;
  p.position[0] = Vec3(0.5 * n + 0.21, 0.5 * n - 0.17, 0.5 * n + 0.09);
  p.omega[0] = Vec3(0, 0, Omega);
  sol.set_particles(p);
  TorqueResult r;
  double prev = 0;
  for (long t = 1; t <= 100000; ++t) {
    sol.step();
    if (t % 100 != 0) continue;
    const double T = -sol.particle_torques()[0][2] / (8 * M_PI * nu * a * a * a * Omega);
    if (std::abs(T - prev) < 1e-5 * std::abs(T)) {
      r.ratio = T;
      r.steps = t;
      break;
    }
    prev = T;
  }
  return r;
}

}  // namespace

// Zick & Homsy (1982) Table 2, simple cubic, tau = 0.7. Tolerance 5% (issue 15's target). PSM's
// drag is low by an error that falls like 1/a^2 (measured at phi = 0.125, tau = 0.7: -7.1%, -2.8%,
// -1.4% at a = 5.0, 7.4, 9.9 cells; at tau = 1: -11.4%, -5.1%, -2.8%): n = 24 (a = 6.0 to 10.4 cells; phi = 0.45, a = 11.4, measured -4.5%)
// here, n = 40 (a = 5.5 to 19 cells) under the long label.
TEST(PsmValidation, ZickHomsySimpleCubic) {
  struct Ref {
    double phi, K;
  };
#ifdef FRACFLOW_LONG_TESTS
  const int n = 40;
  const Ref refs[] = {{0.027, 2.008}, {0.064, 2.810}, {0.125, 4.292}, {0.216, 7.442}, {0.343, 15.4}, {0.45, 28.1}};
#else
  const int n = 24;
  const Ref refs[] = {{0.064, 2.810}, {0.125, 4.292}, {0.216, 7.442}, {0.343, 15.4}};
#endif
  for (const Ref& ref : refs) {
    const DragResult r = zick_homsy_case(n, ref.phi, 0.7);
    const double err = r.K / ref.K - 1;
    const double a = std::cbrt(3 * ref.phi / (4 * M_PI)) * n;
    std::printf("Zick-Homsy n = %d phi = %.3f: K = %.4f (ref %.3f, %+.2f%%), U = %.3e, Re = %.3f, %ld steps\n", n,
                ref.phi, r.K, ref.K, 100 * err, r.U, 2 * a * r.U / (0.2 / 3), r.steps);
    EXPECT_GT(r.steps, 0) << "not steady";
    EXPECT_LT(std::abs(err), 0.05) << "phi = " << ref.phi;
  }
}

// Rotating sphere: torque against 8 pi mu a^3 Omega, tau = 0.7. The PSM torque is low by the same
// resolution error as the drag (measured: -7.3% at a = 4 in 24^3, -8.3% at a = 4 in 32^3 (the
// periodic images add ~1% at phi = 0.019), -1.8% at a = 6 in 32^3): tolerance 10% at a = 4 cells
// here, 5% at a = 8 cells in 48^3 (phi = 0.019) under the long label.
TEST(PsmValidation, RotatingSphereTorque) {
#ifdef FRACFLOW_LONG_TESTS
  const int n = 48;
  const double a = 8, tol = 0.05;
#else
  const int n = 24;
  const double a = 4, tol = 0.10;
#endif
  const TorqueResult r = rotating_torque(n, a, 0.7);
  std::printf("rotating sphere a = %.1f in %d^3: T / (8 pi mu a^3 Omega) = %.4f, %ld steps\n", a, n, r.ratio, r.steps);
  EXPECT_GT(r.steps, 0) << "not steady";
  EXPECT_NEAR(r.ratio, 1.0, tol);
}
