// 3D PFV-style network (regular triangulation): void volumes, steady-flow mass balance and the
// permeability of a random sphere packing against Kozeny–Carman, k_KC = phi^3 d^2 / (180 (1 - phi)^2)
// (Carman 1937; c = 5, S0 = 6/d). Chareyre et al. (2012, Transp. Porous Media 94:595) report their
// PFV permeabilities close to Kozeny–Carman for such packings (PFV's throat length: the distance between
// the pores' power centres; hull pores on their centroids); the ratio here is printed and bounded to
// [0.5, 3] (measured 2026-11-29: 1.43 / 1.93 / 2.18 at porosity 0.40 / 0.44 / 0.48; with the centroids'
// distance, as before that day, 4.8 / 7.1 / 8.7, which the bound rejects).
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "box_network.hpp"
#include "geometry/packing.hpp"
#include "porenet/atan2_batch.hpp"
#include "porenet/flow.hpp"
#include "porenet/reduce.hpp"
#include "porenet/forces.hpp"

using namespace ff;
using namespace ff::porenet;

namespace {
using test_packings::box_spheres;
using test_packings::Spheres;
}  // namespace

TEST(PorenetNetwork3D, FourTouchingSpheresAndBoxFlow) {
  // Regular tetrahedron of edge 2 with unit spheres: void = V_tet - 4 Omega / 3, Omega = 0.5513 sr.
  std::vector<Real> x{0, 2, 1, 1}, y{0, 0, std::sqrt(3.0), 1 / std::sqrt(3.0)}, z{0, 0, 0, 2 * std::sqrt(2.0 / 3)},
      r{1, 1, 1, 1};
  const Network2D t = build_network_3d({x, y, z, r, {}});
  ASSERT_EQ(t.n_pores(), 1);
  const Real vtet = std::pow(2.0, 3) / (6 * std::sqrt(2.0));
  const Real omega = 3 * std::acos(1.0 / 3) - kPi;  // solid angle of a regular tetrahedron's corner
  EXPECT_NEAR(t.pore_void[0], vtet - 4 * omega / 3, 1e-12);

  std::vector<Real> ratios;
  for (const Real phi : {0.40, 0.44, 0.48}) {
    PackingSpec spec;
    spec.dim = 3;
    spec.container = PackingSpec::Container::Box;
    spec.box_lo = {0, 0, 0};
    spec.box_hi = {10e-3, 10e-3, 10e-3};
    spec.radius_min = 0.4e-3;
    spec.radius_max = 0.6e-3;
    spec.porosity = phi;
    spec.seed = 5;
    const Packing pk = dense_random_packing(spec);
    std::vector<Real> px, py, pz;
    for (const Vec3& c : pk.position) {
      px.push_back(c.x());
      py.push_back(c.y());
      pz.push_back(c.z());
    }
    const Network2D net = build_network_3d({px, py, pz, pk.radius, {}});
    SinglePhaseParams prm;
    prm.fluid = Eos::barotropic(1000, 1e5, 2.2e9);
    prm.solver = LinearSolver::ConjugateGradient;
    SinglePhaseFlow f(net, prm);
    const Real xlo = *std::min_element(px.begin(), px.end()), xhi = *std::max_element(px.begin(), px.end());
    Real xin = 0, xout = 0;
    int nin = 0, nout = 0;
    for (Index k = 0; k < net.n_pores(); ++k) {
      if (net.pore_cx[k] < xlo + 1e-3) {
        f.set_bc(k, PoreBc::Pressure, 1e5 + 100);
        xin += net.pore_cx[k];
        ++nin;
      } else if (net.pore_cx[k] > xhi - 1e-3) {
        f.set_bc(k, PoreBc::Pressure, 1e5);
        xout += net.pore_cx[k];
        ++nout;
      }
    }
    f.init(1e5);
    // Diffusion time of the box ~ L^2 mu phi / (k K) ~ 1e-7 s: 20 steps of 1e-5 s reach the steady state.
    // (Steps of 1e3 s would put dt G / S ~ 1e22 and the solver residual would swamp the smallest pores.)
    for (int n = 0; n < 20; ++n) f.step_implicit(1e-5);
    const Real Q = f.pressure_pores_inflow_rate(true) / 1000, Qout = -f.pressure_pores_inflow_rate(false) / 1000;
    EXPECT_LT(std::abs(Q - Qout) / Q, 1e-8);
    // Cross-section: the box face minus a wall layer of one radius (the hull of the centres).
    const Real A = (spec.box_hi.y() - 2 * 0.5e-3) * (spec.box_hi.z() - 2 * 0.5e-3);
    const Real k = Q * prm.mu * (xout / nout - xin / nin) / (A * 100);
    Real s3 = 0, s2 = 0;
    for (Real rr : pk.radius) {
      s3 += rr * rr * rr;
      s2 += rr * rr;
    }
    const Real d = 2 * s3 / s2, por = pk.achieved_porosity;
    const Real kkc = por * por * por * d * d / (180 * (1 - por) * (1 - por));
    ratios.push_back(k / kkc);
    std::printf("3D porosity %.3f (%zu spheres, %d pores, %d hidden): k = %.4e m^2, KC %.4e m^2, ratio %.3f, "
                "in/out %.1e\n", por, pk.radius.size(), net.n_pores(), net.hidden_particles, k, kkc, k / kkc,
                std::abs(Q - Qout) / Q);
  }
  const auto [lo, hi] = std::minmax_element(ratios.begin(), ratios.end());
  std::printf("3D k / k_KC from %.3f to %.3f\n", *lo, *hi);
  EXPECT_LT(*hi / *lo, 2.0);
  EXPECT_GT(*lo, 0.5);
  EXPECT_LT(*hi, 3.0);
}

// The patch force per unit pressure (forces.cpp) reads the vector the last geometry update stored for
// each pore corner (network3d.cpp). Check it against the direct integral, computed here
// from the positions for each pore corner and face (-int_patch n dA = sum_f n_f theta_f R^2 / 2, n_f
// the face's outward normal, theta_f the face's angle at the sphere), after every sphere of a packing
// has moved by up to 5 % of the smallest radius (update_network_3d, topology kept). Tolerance 1e-12
// of theta R^2 (round-off of the two orders of evaluation).
TEST(PorenetNetwork3D, PatchForcesFollowTheUpdatedGeometry) {
  Spheres pk = box_spheres({5e-3, 5e-3, 5e-3}, 0.42, 3);
  auto &x = pk.x, &y = pk.y, &z = pk.z;
  Network2D net = build_network_3d({x, y, z, pk.r, {}});
  ASSERT_GT(net.n_pores(), 500);
  for (std::size_t j = 0; j < x.size(); ++j) {  // a deterministic jitter
    x[j] += 2e-5 * std::sin(1.3 * static_cast<Real>(j));
    y[j] += 2e-5 * std::cos(0.7 * static_cast<Real>(j));
    z[j] += 2e-5 * std::sin(2.1 * static_cast<Real>(j) + 0.4);
  }
  const Particles3D p{x, y, z, pk.r, {}};
  update_network_3d(net, p);
  Real worst = 0;
  long checked = 0;
  for (Index j = 0; j < net.n_particles; ++j)
    for (Index e = net.pp_start[j]; e < net.pp_start[j + 1]; ++e) {
      const Index k = net.pp_pore[e];
      const int c = net.pp_corner[e];
      const Vec3 o(x[j], y[j], z[j]);
      Vec3 expect = Vec3::Zero();
      for (int f = 0; f < 3; ++f) {  // the faces through j: (j, a, b), the fourth corner d
        auto corner = [&](int q) {
          const Index w = net.pore_v[4 * k + (c + 1 + q) % 4];
          return Vec3(x[w], y[w], z[w]);
        };
        const Vec3 a = corner(f) - o, b = corner((f + 1) % 3) - o, d = corner((f + 2) % 3) - o;
        Vec3 n = a.cross(b).normalized();
        if (n.dot(d) > 0) n = -n;
        const Real th = std::atan2(a.cross(b).norm(), a.dot(b));
        expect += 0.5 * th * pk.r[j] * pk.r[j] * n;
      }
      Real got[3];
      unit_patch_force_3d(net, e, got);
      const Real scale = pk.r[j] * pk.r[j];
      worst = std::max(worst, (Vec3(got[0], got[1], got[2]) - expect).norm() / scale);
      ++checked;
    }
  std::printf("%ld pore corners: largest |a - a_direct| / R^2 = %.2e\n", checked, worst);
  EXPECT_LT(worst, 1e-12);
}

// The vectorised atan2 of the 3D geometry (porenet/atan2_batch.cpp): within 4.5e-16 (2 ulp at pi)
// of libm's atan2 for y >= 0 over all octants, the edge cases exact (0, pi/2, pi; 0 for y = x = 0),
// and the same bits whether an element is computed in the vector body of a long batch or alone
// (the scalar remainder): the result does not depend on how the geometry is blocked or threaded.
TEST(PorenetNetwork3D, VectorisedAtan2MatchesLibmAndDoesNotDependOnTheBatch) {
  std::vector<Real> y, x;
  for (int i = 0; i < 4000; ++i) {
    const Real a = 0.5 + 0.5 * std::sin(0.37 * i), b = std::cos(0.91 * i + 0.2);  // y in [0, 1], x in [-1, 1]
    y.push_back(i % 3 == 0 ? a * 1e-9 : a);
    x.push_back(i % 5 == 0 ? b * 1e7 : b);
  }
  const Real special_y[] = {0, 0, 1, 0, 1, 1, 2.5e-300, 1e300};
  const Real special_x[] = {1, -1, 0, 0, 1, -1, -1, 1e-300};
  y.insert(y.end(), std::begin(special_y), std::end(special_y));
  x.insert(x.end(), std::begin(special_x), std::end(special_x));
  const int n = static_cast<int>(y.size());
  std::vector<Real> batch(static_cast<std::size_t>(n));
  atan2_nonneg(y.data(), x.data(), batch.data(), n);
  Real worst = 0;
  for (int i = 0; i < n; ++i) {
    const Real ref = y[i] == 0 && x[i] == 0 ? 0.0 : std::atan2(y[i], x[i]);
    worst = std::max(worst, std::abs(batch[i] - ref));
    Real alone;
    atan2_nonneg(&y[i], &x[i], &alone, 1);
    ASSERT_EQ(alone, batch[i]) << "y " << y[i] << " x " << x[i];
  }
  EXPECT_LT(worst, 4.5e-16);
  EXPECT_EQ(batch[n - 8], 0.0);
  EXPECT_EQ(batch[n - 7], kPi);
  EXPECT_EQ(batch[n - 6], kPi / 2);
  EXPECT_EQ(batch[n - 5], 0.0);
}

// The geometry update runs over blocks of pores and throats in parallel (above kParallelMin): 1 and 2
// threads give the same bits (voids, patch vectors, conductances) on a network large enough to split.
TEST(PorenetNetwork3D, GeometryUpdateIsTheSameOnOneAndTwoThreads) {
  Spheres pk = box_spheres({10e-3, 10e-3, 8e-3}, 0.42, 4);
  auto &x = pk.x, &y = pk.y, &z = pk.z;
  for (std::size_t j = 0; j < x.size(); ++j) x[j] += 1e-5 * std::sin(3.1 * y[j] / 1e-3);
  Network2D one = build_network_3d({x, y, z, pk.r, {}});
  ASSERT_GT(one.n_pores(), kParallelMin);  // both loops split (throats ~2x the pores)
  Network2D two = one;
  for (auto& v : x) v += 3e-6;  // a move that changes every pore's shape a little
  for (std::size_t j = 0; j < y.size(); ++j) y[j] += 2e-6 * std::cos(static_cast<Real>(j));
  const int before = omp_get_max_threads();
  omp_set_num_threads(1);
  update_network_3d(one, {x, y, z, pk.r, {}});
  omp_set_num_threads(2);
  update_network_3d(two, {x, y, z, pk.r, {}});
  omp_set_num_threads(before);
  EXPECT_EQ(one.pore_void, two.pore_void);
  EXPECT_EQ(one.pore_patch, two.pore_patch);
  EXPECT_EQ(one.ch_cond, two.ch_cond);
  EXPECT_EQ(one.ch_aperture, two.ch_aperture);
}

// Channel shear in 3D (add_shear_forces_3d) with the patch pressure forces, in a steady flow along x
// through a fixed packing (10 x 6 x 6 mm, inlet and outlet bands 1 mm deep at 1e5 + 100 Pa and 1e5 Pa).
// On the interior spheres of the middle slab (x 2.5 mm or more from the ends, no hull pore around them),
// in the measured pressure gradient G = dp/dx:
//  - the pressure forces alone are Archimedes' force in a gradient, -G sum V_s (a body in a linear
//    pressure field), within 10 %;
//  - with the shear they come closer to the whole Darcy drag, -G times the slab's total volume
//    sum V_s / (1 - n) (the fluid's momentum balance: what the gradient pushes through the pores, the
//    grains hold; n the network's porosity): measured 2026-11-29 0.81 of it (pressure alone 0.70), the
//    shear 15 % of the total where n = 0.36 would give 36 %: the throats' A_f (P_a - P_b) sums over the
//    network's own pressure drops, and the throats of sliver tetrahedra, whose power centres lie far
//    apart, take small ones. Asserted: within 25 % of the Darcy drag and closer to it than without.
TEST(PorenetNetwork3D, ShearAndPressureForcesCarryThePressureDrop) {
  Spheres pk = box_spheres({10e-3, 6e-3, 6e-3}, 0.42, 7);
  const Network2D net = build_network_3d({pk.x, pk.y, pk.z, pk.r, {}});
  SinglePhaseParams prm;
  prm.fluid = Eos::barotropic(1000, 1e5, 2.2e9);
  prm.solver = LinearSolver::ConjugateGradient;
  SinglePhaseFlow f(net, prm);
  const Real xlo = *std::min_element(pk.x.begin(), pk.x.end()), xhi = *std::max_element(pk.x.begin(), pk.x.end());
  for (Index k = 0; k < net.n_pores(); ++k) {
    if (net.pore_cx[k] < xlo + 1e-3)
      f.set_bc(k, PoreBc::Pressure, 1e5 + 100);
    else if (net.pore_cx[k] > xhi - 1e-3)
      f.set_bc(k, PoreBc::Pressure, 1e5);
  }
  f.init(1e5);
  for (int n = 0; n < 20; ++n) f.step_implicit(1e-5);
  std::vector<Real> P(f.pressure().begin(), f.pressure().end());
  for (Real& p : P) p -= 1e5;  // gauge
  // The gradient: least squares of p against x over the pores between the bands, weighted by their void.
  Real sw = 0, sx = 0, sp = 0, sxx = 0, sxp = 0, sum_void = 0, sum_cell = 0;
  for (Index k = 0; k < net.n_pores(); ++k) {
    sum_void += net.pore_void[k];
    sum_cell += net.pore_cell[k];
    if (net.pore_cx[k] < xlo + 1e-3 || net.pore_cx[k] > xhi - 1e-3) continue;
    const Real w = net.pore_void[k], x = net.pore_cx[k], p = P[static_cast<std::size_t>(k)];
    sw += w, sx += w * x, sp += w * p, sxx += w * x * x, sxp += w * x * p;
  }
  const Real G = (sw * sxp - sx * sp) / (sw * sxx - sx * sx);
  const Real porosity = sum_void / sum_cell;
  const std::size_t n = pk.x.size();
  std::vector<Real> px(n, 0), py(n, 0), pz(n, 0), qx(n, 0), qy(n, 0), qz(n, 0);
  const Particles3D view{pk.x, pk.y, pk.z, pk.r, {}};
  add_pressure_forces_3d(net, view, P, px, py, pz);
  add_shear_forces_3d(net, view, P, qx, qy, qz);
  std::vector<char> hull(n, 0);
  for (Index k = 0; k < net.n_pores(); ++k)
    if (net.pore_hull[k])
      for (int c = 0; c < 4; ++c) hull[static_cast<std::size_t>(net.pore_v[4 * k + c])] = 1;
  Real Fp = 0, Fs = 0, Vs = 0, Fside = 0;
  int count = 0;
  for (std::size_t j = 0; j < n; ++j) {
    if (hull[j] || pk.x[j] < xlo + 2.5e-3 || pk.x[j] > xhi - 2.5e-3) continue;
    Fp += px[j];
    Fs += qx[j];
    Fside += std::hypot(py[j] + qy[j], pz[j] + qz[j]);
    Vs += 4.0 / 3 * kPi * pk.r[j] * pk.r[j] * pk.r[j];
    ++count;
  }
  const Real archimedes = -G * Vs, darcy = -G * Vs / (1 - porosity);
  std::printf("3D channel shear: %zu spheres, %d interior in the slab, G %.5g Pa/m, porosity %.3f: pressure forces %.5g N "
              "(Archimedes %.5g, ratio %.4f); with shear %.5g N (Darcy drag %.5g, ratio %.4f); shear share %.3f; "
              "sideways sum of |F| %.3g of it\n", n, count, G, porosity, Fp, archimedes, Fp / archimedes, Fp + Fs,
              darcy, (Fp + Fs) / darcy, Fs / (Fp + Fs), Fside / (Fp + Fs));
  ASSERT_GT(count, 30);
  ASSERT_LT(G, 0);
  EXPECT_NEAR(Fp / archimedes, 1.0, 0.1);
  EXPECT_NEAR((Fp + Fs) / darcy, 1.0, 0.25);
  EXPECT_LT(std::abs((Fp + Fs) / darcy - 1), std::abs(Fp / darcy - 1));
}
