#include "porenet/forces.hpp"

#include <cmath>
#include <fmt/format.h>

#include "core/error.hpp"

namespace ff::porenet {
namespace {
void check(const Network2D& net, const Particles2D& p, std::span<const Real> pp, std::span<Real> fx,
           std::span<Real> fy) {
  if (net.dim != 2) throw InputError("porenet: the B26-B28 grain forces are implemented for 2D networks only");
  const auto n = static_cast<std::size_t>(net.n_particles);
  if (p.x.size() != n || fx.size() != n || fy.size() != n || pp.size() != static_cast<std::size_t>(net.n_pores()))
    throw InputError(fmt::format("porenet: force arrays sized {} / {} / {} particles and {} pressures; the network "
                                 "has {} particles and {} pores", p.x.size(), fx.size(), fy.size(), pp.size(), n,
                                 net.n_pores()));
}
}  // namespace

void add_pressure_forces(const Network2D& net, const Particles2D& p, std::span<const Real> P, std::span<Real> fx,
                         std::span<Real> fy) {
  check(net, p, P, fx, fy);
#pragma omp parallel for schedule(static)
  for (Index j = 0; j < net.n_particles; ++j) {
    Real sx = 0, sy = 0;
    for (Index e = net.pp_start[j]; e < net.pp_start[j + 1]; ++e) {
      const Index k = net.pp_pore[e];
      const int c = net.pp_corner[e];
      const Index b = net.pore_v[3 * k + (c + 1) % 3], d = net.pore_v[3 * k + (c + 2) % 3];
      Real u1x = p.x[b] - p.x[j], u1y = p.y[b] - p.y[j];
      Real u2x = p.x[d] - p.x[j], u2y = p.y[d] - p.y[j];
      const Real l1 = std::hypot(u1x, u1y), l2 = std::hypot(u2x, u2y);
      u1x /= l1, u1y /= l1, u2x /= l2, u2y /= l2;
      // B26–B27: -P * 2 r * int_arc n dl.
      const Real w = -P[k] * 2 * p.radius[j] * p.radius[j];
      sx += w * (u2y - u1y);
      sy += w * (u1x - u2x);
    }
    fx[j] += sx;
    fy[j] += sy;
  }
}

void add_shear_forces(const Network2D& net, const Particles2D& p, std::span<const Real> P, std::span<Real> fx,
                      std::span<Real> fy) {
  check(net, p, P, fx, fy);
#pragma omp parallel for schedule(static)
  for (Index j = 0; j < net.n_particles; ++j) {
    Real sx = 0, sy = 0;
    for (Index e = net.pw_start[j]; e < net.pw_start[j + 1]; ++e) {
      const Index c = net.pw_ch[e];
      const Index a = net.ch_pore[2 * c], b = net.ch_pore[2 * c + 1];
      const Real L = net.ch_length[c];
      const Real tau = 0.5 * net.ch_aperture[c] * (P[a] - P[b]) / L;  // B25
      const Real lx = net.pore_cx[b] - net.pore_cx[a], ly = net.pore_cy[b] - net.pore_cy[a];
      const Real l = std::hypot(lx, ly);
      if (l <= 0) continue;
      const Real w = tau * 2 * p.radius[j] * L / l;  // B28: tau I A_k, A_k = 2 r_j L
      sx += w * lx;
      sy += w * ly;
    }
    fx[j] += sx;
    fy[j] += sy;
  }
}

}  // namespace ff::porenet
