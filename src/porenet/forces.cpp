#include "porenet/forces.hpp"

#include <cmath>
#include <fmt/format.h>

#include "core/error.hpp"
#include "porenet/reduce.hpp"

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
#pragma omp parallel for schedule(static) if (net.n_particles > kParallelMin)
  for (Index j = 0; j < net.n_particles; ++j) {
    Real sx = 0, sy = 0;
    for (Index e = net.pp_start[j]; e < net.pp_start[j + 1]; ++e) {
      Real dx, dy;
      arc_span_2d(net, p, j, e, dx, dy);
      // B26–B27: -P * 2 r * int_arc n dl.
      const Real w = -P[net.pp_pore[e]] * 2 * p.radius[j] * p.radius[j];
      sx += w * dy;
      sy += w * -dx;
    }
    fx[j] += sx;
    fy[j] += sy;
  }
}

void add_shear_forces(const Network2D& net, const Particles2D& p, std::span<const Real> P, std::span<Real> fx,
                      std::span<Real> fy) {
  check(net, p, P, fx, fy);
#pragma omp parallel for schedule(static) if (net.n_particles > kParallelMin)
  for (Index j = 0; j < net.n_particles; ++j) {
    Real sx = 0, sy = 0;
    for (Index e = net.pw_start[j]; e < net.pw_start[j + 1]; ++e) {
      const Index c = net.pw_ch[e];
      const Index a = net.ch_pore[2 * c], b = net.ch_pore[2 * c + 1];
      const Real L = net.ch_length[c];
      const Real tau = 0.5 * net.ch_aperture[c] * (P[a] - P[b]) / L;  // B25
      const Real lx = net.pore_cx[b] - net.pore_cx[a], ly = net.pore_cy[b] - net.pore_cy[a];
      const Real l = length_2d(lx, ly);
      if (l <= 0) continue;
      const Real w = tau * 2 * p.radius[j] * L / l;  // B28: tau I A_k, A_k = 2 r_j L
      sx += w * lx;
      sy += w * ly;
    }
    fx[j] += sx;
    fy[j] += sy;
  }
}

void void_gradient_2d(const Network2D& net, const Particles2D& p, Index j, Index e, Real& gx, Real& gy,
                      bool with_floors) {
  const Index k = net.pp_pore[e];
  const int c = net.pp_corner[e];
  const Index b = net.pore_v[3 * k + (c + 1) % 3], d = net.pore_v[3 * k + (c + 2) % 3];
  const Real xj = p.x[j], yj = p.y[j], xb = p.x[b], yb = p.y[b], xd = p.x[d], yd = p.y[d];
  // Triangle (j, b, d), counter-clockwise: dA/dx_j = (y_b - y_d, x_d - x_b) / 2.
  gx = 0.5 * (yb - yd);
  gy = 0.5 * (xd - xb);
  // The floors of network.cpp's void: the gradient of the void the flow uses, so that the fluid's work
  // on the grains is its own p dV. At the relative floor (a constant) a pore pushes no grain: its
  // pressure does not follow the grains there, and with the geometric gradient its pressure, raised by
  // inflow, did work it never stored (seed 004's study, S 0.5, packing 10: kinetic energy and the
  // largest pore pressure grew e-fold every ~8 us, whatever the time step, to 11 MPa at a platen
  // stress of 80 Pa). At the fraction floor (overlapping discs) V = phi x the triangle.
  const VoidFloor floor = with_floors ? void_floor_of(net, k) : VoidFloor::None;
  if (floor == VoidFloor::Relative) {
    gx = gy = 0;
    return;
  }
  if (floor == VoidFloor::Fraction) {
    gx *= net.params.min_void_fraction;
    gy *= net.params.min_void_fraction;
    return;
  }
  // Less the sectors theta_c r_c^2 / 2. The polar angle of a vector v turns by (-v_y, v_x) / |v|^2 per
  // unit move of its tip (and by minus that per move of its tail).
  const Real ux = xb - xj, uy = yb - yj, wx = xd - xj, wy = yd - yj;  // theta_j = angle(w) - angle(u)
  const Real uu = ux * ux + uy * uy, ww = wx * wx + wy * wy;
  const Real tjx = wy / ww - uy / uu, tjy = ux / uu - wx / ww;          // j is the tail of u and w
  const Real bx = xj - xb, by = yj - yb, bb = bx * bx + by * by;        // theta_b = angle(j - b) - angle(d - b)
  const Real dx = xj - xd, dy = yj - yd, dd = dx * dx + dy * dy;        // theta_d = angle(b - d) - angle(j - d)
  const Real rj = p.radius[j], rb = p.radius[b], rd = p.radius[d];
  gx -= 0.5 * (rj * rj * tjx - rb * rb * by / bb + rd * rd * dy / dd);
  gy -= 0.5 * (rj * rj * tjy + rb * rb * bx / bb - rd * rd * dx / dd);
}

void add_pressure_forces_void_gradient(const Network2D& net, const Particles2D& p, std::span<const Real> P,
                                       std::span<Real> fx, std::span<Real> fy) {
  check(net, p, P, fx, fy);
#pragma omp parallel for schedule(static) if (net.n_particles > kParallelMin)
  for (Index j = 0; j < net.n_particles; ++j) {
    Real sx = 0, sy = 0;
    for (Index e = net.pp_start[j]; e < net.pp_start[j + 1]; ++e) {
      Real gx, gy;
      void_gradient_2d(net, p, j, e, gx, gy);
      const Real w = P[net.pp_pore[e]] * 2 * p.radius[j];  // over the seed's height 2 r_j, as B27
      sx += w * gx;
      sy += w * gy;
    }
    fx[j] += sx;
    fy[j] += sy;
  }
}

}  // namespace ff::porenet

namespace ff::porenet {

// Sphere j at a corner of tetrahedron k: the pressure on the spherical patch inside the tetrahedron,
// p times the patch force per unit pressure that the last geometry update stored (network3d.cpp,
// pore_geometry_3d: the cone's faces, n_f theta_f R^2 / 2 each). A face between two pores gets
// opposite normals from them: an interior sphere at uniform pressure feels no net force.
void unit_patch_force_3d(const Network2D& net, Index e, Real out[3]) {
  const Real* a = &net.pore_patch[12 * static_cast<std::size_t>(net.pp_pore[e]) + 3 * net.pp_corner[e]];
  out[0] = a[0];
  out[1] = a[1];
  out[2] = a[2];
}

void add_shear_forces_3d(const Network2D& net, const Particles3D& p, std::span<const Real> P, std::span<Real> fx,
                         std::span<Real> fy, std::span<Real> fz) {
  const auto n = static_cast<std::size_t>(net.n_particles);
  if (net.dim != 3) throw InputError("porenet: add_shear_forces_3d needs a 3D network");
  if (p.x.size() != n || fx.size() != n || fy.size() != n || fz.size() != n ||
      P.size() != static_cast<std::size_t>(net.n_pores()) ||
      net.ch_shear.size() != 3 * static_cast<std::size_t>(net.n_channels()))
    throw InputError(fmt::format("porenet: add_shear_forces_3d: {} particles, {} pores, {} throats; arrays of sizes "
                                 "{}/{}/{}, {}, {}", n, net.n_pores(), net.n_channels(), p.x.size(), fx.size(),
                                 fy.size(), P.size(), net.ch_shear.size()));
  for (Index c = 0; c < net.n_channels(); ++c) {
    const Index a = net.ch_pore[2 * c], b = net.ch_pore[2 * c + 1];
    const Real dp = P[static_cast<std::size_t>(a)] - P[static_cast<std::size_t>(b)];
    if (dp == 0) continue;
    const Index* v = &net.ch_part[3 * static_cast<std::size_t>(c)];
    // The facet's plane: spanned by the edges from its first sphere; an edge to a wall (walls sort last)
    // runs along the wall's axis.
    Real u[3], t[3];
    for (int j = 1; j < 3; ++j) {
      Real* e = j == 1 ? u : t;
      if (net.is_wall_vertex(v[j])) {
        e[0] = e[1] = e[2] = 0;
        e[(v[j] - net.n_particles) / 2] = 1;
      } else {
        e[0] = p.x[v[j]] - p.x[v[0]];
        e[1] = p.y[v[j]] - p.y[v[0]];
        e[2] = p.z[v[j]] - p.z[v[0]];
      }
    }
    const Real ux = u[0], uy = u[1], uz = u[2], wx = t[0], wy = t[1], wz = t[2];
    Real nx = uy * wz - uz * wy, ny = uz * wx - ux * wz, nz = ux * wy - uy * wx;
    const Real len = std::sqrt(nx * nx + ny * ny + nz * nz);
    if (!(len > 0)) continue;
    // Oriented from pore a to pore b (their centroids lie on either side of the shared facet).
    const Real side = nx * (net.pore_cx[b] - net.pore_cx[a]) + ny * (net.pore_cy[b] - net.pore_cy[a]) +
                      nz * (net.pore_cz[b] - net.pore_cz[a]);
    const Real s = (side < 0 ? -dp : dp) / len;
    for (int k = 0; k < 3; ++k) {
      if (net.is_wall_vertex(v[k])) continue;  // a wall's share is not applied (ch_shear holds none)
      const Real w = s * net.ch_shear[3 * static_cast<std::size_t>(c) + k];
      const auto j = static_cast<std::size_t>(v[k]);
      fx[j] += w * nx;
      fy[j] += w * ny;
      fz[j] += w * nz;
    }
  }
}

void add_pressure_forces_3d(const Network2D& net, const Particles3D& p, std::span<const Real> P, std::span<Real> fx,
                            std::span<Real> fy, std::span<Real> fz) {
  const auto n = static_cast<std::size_t>(net.n_particles);
  if (net.dim != 3) throw InputError("porenet: add_pressure_forces_3d needs a 3D network");
  if (p.x.size() != n || fx.size() != n || fy.size() != n || fz.size() != n ||
      P.size() != static_cast<std::size_t>(net.n_pores()))
    throw InputError(fmt::format("porenet: 3D force arrays sized {} / {} particles and {} pressures; the network has "
                                 "{} particles and {} pores", p.x.size(), fx.size(), P.size(), n, net.n_pores()));
#pragma omp parallel for schedule(static) if (net.n_particles > kParallelMin)
  for (Index j = 0; j < net.n_particles; ++j) {
    Real s[3] = {0, 0, 0};
    for (Index e = net.pp_start[j]; e < net.pp_start[j + 1]; ++e) {
      Real a[3];
      unit_patch_force_3d(net, e, a);
      const Real Pk = P[net.pp_pore[e]];
      for (int q = 0; q < 3; ++q) s[q] += Pk * a[q];
    }
    fx[j] += s[0];
    fy[j] += s[1];
    fz[j] += s[2];
  }
}

std::array<Real, 6> wall_pressure_forces_3d(const Network2D& net, std::span<const Real> P) {
  if (P.size() != static_cast<std::size_t>(net.n_pores()))
    throw InputError(fmt::format("porenet: {} pressures for {} pores", P.size(), net.n_pores()));
  std::array<Real, 6> f{};
  for (int w = 0; w < net.n_walls; ++w)
    for (Index e = net.wp_start[w]; e < net.wp_start[w + 1]; ++e) {
      const Real* a = &net.pore_patch[12 * static_cast<std::size_t>(net.wp_pore[e]) + 3 * net.wp_corner[e]];
      f[static_cast<std::size_t>(w)] += P[static_cast<std::size_t>(net.wp_pore[e])] * std::abs(a[w / 2]);
    }
  return f;
}

}  // namespace ff::porenet
