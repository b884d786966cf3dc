// Fluid forces on the grains (seed 004 Eqs. B25–B28), as per-particle arrays.
//  - pressure (B26–B27): F_P,j = -sum_i P_i n A_k with A_k = 2 r_j e_k: the fluid in pore i pushes on
//    the arc of disc j inside that triangle, over a height 2 r_j (the seed's cylinder section). The
//    arc is integrated exactly (the limit of the seed's discretised edges e_k):
//    int_arc n dl = R_j rot(-90°)(u_2 - u_1), u_1, u_2 the unit vectors from the centre to the two
//    other corners (counter-clockwise). A disc surrounded by pores at one pressure gets zero net force.
//  - channel shear (B25, B28): tau = (h/2) (P_i - P_j) / L on both walls of each channel, acting
//    along the centre line in the flow direction over A_k = 2 r_j L.
// Forces are added to fx, fy [N] (one entry per particle); each particle sums its own pores and
// channels in CSR order, so the result is independent of the thread count.
#pragma once
#include <array>
#include <cmath>
#include <span>

#include "porenet/network.hpp"

namespace ff::porenet {

void add_pressure_forces(const Network2D& net, const Particles2D& particles, std::span<const Real> pore_pressure,
                         std::span<Real> fx, std::span<Real> fy);
// u2 - u1 for disc j's pore-corner entry e (net.pp_pore[e]): u1, u2 the unit vectors from j's centre to
// the triangle's other two corners (counter-clockwise). int_arc n dl = R rot(-90 deg)(u2 - u1), so the
// arc's chord is R |u2 - u1| (add_pressure_forces; the coupling's fluid stiffness).
inline void arc_span_2d(const Network2D& net, const Particles2D& p, Index j, Index e, Real& dx, Real& dy) {
  const Index k = net.pp_pore[e];
  const int c = net.pp_corner[e];
  const Index b = net.pore_v[3 * k + (c + 1) % 3], d = net.pore_v[3 * k + (c + 2) % 3];
  Real u1x = p.x[b] - p.x[j], u1y = p.y[b] - p.y[j];
  Real u2x = p.x[d] - p.x[j], u2y = p.y[d] - p.y[j];
  const Real l1 = length_2d(u1x, u1y), l2 = length_2d(u2x, u2y);
  u1x /= l1, u1y /= l1, u2x /= l2, u2y /= l2;
  dx = u2x - u1x;
  dy = u2y - u1y;
}

// The energy-consistent alternative to B26-B27 (coupling::PressureForce::VoidGradient): grain j feels
// P_i 2 r_j g_ij from pore i, g_ij = d(void per unit depth)/d(x_j), the void being the triangle less the
// three disc sectors, with network.cpp's floors (zero at the relative floor, phi x the triangle's at the
// fraction floor). The fluid's work on the grains is then sum_i P_i dV_i: a pore whose pressure follows
// its void is a conservative spring (the arc force is not, unless the pore is equilateral with equal
// discs). Zero net force on an interior grain at uniform pressure where no pore around it is at a floor
// (the triangles around it tile, and each neighbour's two angles beside it sum to a fixed angle); a
// floored pore's share is missing from that sum, as its void no longer changes with the grains.
// with_floors = false: the triangle's geometric gradient everywhere (what a floored pore will push with
// once it opens: the bound the time step's fluid stiffness takes).
void void_gradient_2d(const Network2D& net, const Particles2D& p, Index j, Index e, Real& gx, Real& gy,
                      bool with_floors = true);
void add_pressure_forces_void_gradient(const Network2D& net, const Particles2D& particles,
                                       std::span<const Real> pore_pressure, std::span<Real> fx, std::span<Real> fy);

void add_shear_forces(const Network2D& net, const Particles2D& particles, std::span<const Real> pore_pressure,
                      std::span<Real> fx, std::span<Real> fy);

// 3D (PFV-style integration over the sphere surface; forces.cpp): pressure on the spherical patches of
// each sphere inside its tetrahedra, added to fx, fy, fz [N]. Both read the patch forces per unit
// pressure of the network's last geometry (build_network_3d or update_network_3d at these positions).
void add_pressure_forces_3d(const Network2D& net, const Particles3D& particles, std::span<const Real> pore_pressure,
                            std::span<Real> fx, std::span<Real> fy, std::span<Real> fz);
// 3D channel shear (the analogue of B25 and B28 for a throat of fluid area A_f and wetted perimeter
// sum_k theta_k R_k): Poiseuille flow through the throat pulls its wall with tau = R_h (P_a - P_b) / L,
// R_h = A_f / sum theta R, over the wall area sum theta R x L, i.e. A_f (P_a - P_b) in all; sphere k takes
// its wetted arc's share, along the facet's normal from pore a to pore b (net.ch_shear). With the patch
// pressure forces the grains of a fixed packing in steady flow take 0.81 of the Darcy drag (0.70 without;
// test_network3d, ShearAndPressureForcesCarryThePressureDrop; docs/porenet.md section 6). Added to fx, fy,
// fz [N]; one pass over the throats in order (the same sums on any thread count).
void add_shear_forces_3d(const Network2D& net, const Particles3D& particles, std::span<const Real> pore_pressure,
                         std::span<Real> fx, std::span<Real> fy, std::span<Real> fz);
// With walls (BoxWalls): the force [N] the pore pressures exert on each wall, along d_w (outward), sum
// over its pores of P_k times the pore's area on the wall. Channel shear on the walls is not included.
std::array<Real, 6> wall_pressure_forces_3d(const Network2D& net, std::span<const Real> pore_pressure);
// The force per unit pressure [m^2] on the sphere of pore-corner entry e (pore net.pp_pore[e]):
// sum_f n_f theta_f R^2 / 2 (forces.cpp); add_pressure_forces_3d sums P_k times it.
void unit_patch_force_3d(const Network2D& net, Index e, Real out[3]);

}  // namespace ff::porenet
