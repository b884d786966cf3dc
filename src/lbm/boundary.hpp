// Boundary conditions evaluated link by link (walls) or node by node (open faces), in the
// shifted populations g = f - w of collision.hpp. Each function fills the unknown incoming
// population(s) of one fluid cell before it collides.
//
// Link notation: q is the incoming direction whose source x - c_q is solid, so the link
// from the fluid node x into the wall points along c_o, o = opp(q); delta is the fraction
// of that link on the fluid side (|x - x_w| / |x - x_b|).
#pragma once
#include <cstdint>

#include "lbm/collision.hpp"
#include "lbm/grid.hpp"

namespace ff::lbm {

// How a solid object's cut links are treated.
enum class WallScheme : std::uint8_t {
  HalfwayBounceBack,  // stair-wise wall mid-link ([S003] Eq. 8; Ladd 1994 moving-wall term)
  Bouzidi,            // Bouzidi, Firdaouss & Lallemand (2001) linear interpolation
  Yu,                 // Yu, Mei, Luo & Shyy (2003), as printed in [S002] Eq. 7
};

// One fluid->solid link of a boundary cell.
struct Link {
  std::int32_t cell = 0;       // index into the boundary-cell list
  std::uint8_t q = 0;          // incoming direction (its source is solid)
  WallScheme scheme = WallScheme::HalfwayBounceBack;
  bool has_second = false;     // x + c_q is a fluid node (needed by the interpolated schemes)
  std::int16_t object = 0;     // solid object hit by the link
  float delta = 0.5f;          // wall distance fraction along the link
};

// How an open node fills its unknown populations.
enum class OpenKind : std::uint8_t { Velocity, Pressure, ZeroGradient, Convective };

// A fluid cell next to an open (velocity, pressure or outflow) face.
template <class T>
struct OpenNode {
  std::int8_t axis = 0;     // normal axis
  std::int8_t sign = 1;     // inward normal n = sign * e_axis
  bool pressure = false;    // true: prescribed density; false: prescribed velocity
  OpenKind kind = OpenKind::Velocity;
  T rho = 1;                // prescribed density (pressure nodes)
  T u[3] = {0, 0, 0};       // prescribed velocity (tangential part only for pressure nodes)
  // Outflow nodes only. The donor is the fluid cell x + n one layer inward: `donor` is the row of
  // its pre-collision populations in the solver's donor buffer, -1 if that cell is solid.
  // `ghost` is the open ghost cell x - n, whose otherwise unused slots hold the convective state.
  std::int8_t face = 0;
  bool density_free = true;  // the unknowns carry the node's density, not the donor's (solver.cpp)
  std::int32_t donor = -1;
  std::int64_t ghost = 0;
};

// Everything the non-bulk path needs about one fluid cell.
struct BoundaryCell {
  CellIndex cell = 0;
  int x = 0, y = 0, z = 0;
  std::uint32_t link_mask = 0;  // bit q: f_q comes from a solid node (a Link exists)
  std::uint32_t open_mask = 0;  // bit q: f_q comes from an open face (Zou-He unknown)
  std::int32_t first_link = 0;  // links of this cell: [first_link, first_link + num_links)
  std::int32_t num_links = 0;
  std::int32_t open = -1;       // index of its OpenNode, -1 if none
  std::int32_t capture = -1;    // outflow donor: row of the donor buffer that receives its
                                //   pre-collision populations, -1 if none
  bool outflow = false;         // on an outflow face: updated after every other boundary cell
};

// Reflected population for a wall link ([S003] Eq. 8 / METHODS §4.5-4.6).
//   A = g*_o(x, t)        population that hit the wall
//   B = g*_q(x, t)        post-collision population leaving the wall at x (interpolated schemes)
//   C = g*_o(x + c_q, t)  = the streamed g_o(x, t+1)      (interpolated schemes, if has_second)
//   mw = 6 w_q rho_w (c_q . u_w): the moving-wall momentum term
template <class T>
inline T reflect(WallScheme s, T delta, bool has_second, T A, T B, T C, T mw) {
  if (s == WallScheme::HalfwayBounceBack || !has_second) return A + mw;
  if (s == WallScheme::Bouzidi) {
    // Bouzidi et al. (2001) with the moving-wall term of Lallemand & Luo (2003).
    if (delta < T(0.5)) return T(2) * delta * A + (T(1) - T(2) * delta) * C + mw;
    const T inv2d = T(0.5) / delta;
    return inv2d * A + (T(2) * delta - T(1)) * inv2d * B + inv2d * mw;
  }
  // Yu et al. (2003), [S002] Eq. 7: the wall value is interpolated between x and x_b and
  // then combined with the second fluid node; the moving term sits inside 1/(1+delta), as
  // in Yu et al.'s own derivation (checked with the Couette test in tests/unit/lbm).
  return ((T(1) - delta) * C + delta * A + delta * B + mw) / (T(1) + delta);
}

// Zou & He (1997) velocity/pressure condition in the general form of Hecht & Harting (2010):
// unknowns g_q (c_q . n > 0) = g_o + 6 w_q rho c_q.u + sum_t c_qt N_t, with N_t chosen so the
// tangential momentum equals rho u_t exactly. On D2Q9 this reduces to METHODS §4.5.
// Every population with c_q . n <= 0 must already be set (streamed or bounced).
// incompressible: momentum rho_0 u with rho_0 = 1 (He & Luo 1997), so sum = rho - u.n.
template <class L, class T>
void zou_he(T* g, const OpenNode<T>& nd, bool incompressible = false) {
  const int a = nd.axis, s = nd.sign;
  T k0 = 0, kneg = 0;
  for (int q = 0; q < L::Q; ++q) {
    const int cn = L::c[q][a] * s;
    if (cn == 0) k0 += g[q];
    else if (cn < 0) kneg += g[q];
  }
  T rho, u[3] = {nd.u[0], nd.u[1], nd.u[2]};
  const T sum = T(1) + k0 + T(2) * kneg;  // = rho (1 - u.n) in shifted populations
  if (incompressible) {
    if (nd.pressure) {
      rho = nd.rho;
      u[a] = T(s) * (rho - sum);
    } else {
      rho = sum + T(s) * u[a];
    }
  } else if (nd.pressure) {
    rho = nd.rho;
    u[a] = T(s) * (T(1) - sum / rho);
  } else {
    rho = sum / (T(1) - T(s) * u[a]);
  }
  const T rho_u = incompressible ? T(1) : rho;  // multiplies the momentum terms
  // Bounce-back of the non-equilibrium part plus the equilibrium difference.
  for (int q = 0; q < L::Q; ++q) {
    if (L::c[q][a] * s <= 0) continue;
    const T cu = L::c[q][0] * u[0] + L::c[q][1] * u[1] + L::c[q][2] * u[2];
    g[q] = g[L::opp[q]] + T(6 * L::w[q]) * rho_u * cu;
  }
  // Transverse momentum correction.
  for (int t = 0; t < 3; ++t) {
    if (t == a || (L::D == 2 && t == 2)) continue;
    T have = 0, nt = 0;
    for (int q = 0; q < L::Q; ++q) {
      have += L::c[q][t] * g[q];
      if (L::c[q][a] * s > 0) nt += T(L::c[q][t] * L::c[q][t]);
    }
    const T X = (rho_u * u[t] - have) / nt;
    for (int q = 0; q < L::Q; ++q)
      if (L::c[q][a] * s > 0) g[q] += L::c[q][t] * X;
  }
}

}  // namespace ff::lbm
