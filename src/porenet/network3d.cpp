// 3D pore network from a regular triangulation (PFV style); see network.hpp.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Regular_triangulation_3.h>
#include <CGAL/Regular_triangulation_cell_base_3.h>
#include <CGAL/Regular_triangulation_vertex_base_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fmt/format.h>
#include <limits>

#include "core/error.hpp"
#include "porenet/atan2_batch.hpp"
#include "porenet/reduce.hpp"
#include "porenet/network.hpp"

namespace ff::porenet {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vbb = CGAL::Regular_triangulation_vertex_base_3<Kernel>;
using Vb = CGAL::Triangulation_vertex_base_with_info_3<Index, Kernel, Vbb>;
using Cb = CGAL::Regular_triangulation_cell_base_3<Kernel>;
using Tds = CGAL::Triangulation_data_structure_3<Vb, Cb>;
using Regular = CGAL::Regular_triangulation_3<Kernel, Tds>;

struct V3 {
  Real x, y, z;
};
V3 sub(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
Real dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
Real norm(V3 a) { return std::sqrt(dot(a, a)); }

// The geometry runs over blocks of pores or throats: a first loop gathers the atan2 arguments of the
// block, atan2_nonneg evaluates them in one vectorised call, a second loop uses the angles.
constexpr Index kGeometryBlock = 64;

// Pores [k0, k1): volume, void (METHODS §5.2; the floors), centroid, and each corner sphere's patch
// force per unit pressure (pore_patch; forces.cpp). Sphere j at corner c: the patch inside the
// tetrahedron and the three plane sectors of the faces through j (angle theta at j, area theta R^2/2)
// close a cone, so -int_patch n dA = sum_f n_f theta_f R^2 / 2, n_f the face's outward unit normal.
// The solid angle at corner i is Omega_i = 2 atan2(|u . (v x w)|, |u||v||w| + (u.v)|w| + (u.w)|v| +
// (v.w)|u|) with u, v, w the edges from it (Van Oosterom & Strackee 1983, IEEE Trans. Biomed. Eng.
// 30:125).
void pore_geometry_3d(Network2D& net, const Particles3D& p, Index k0, Index k1) {
  // Per pore: 4 solid angles, then the angles at the first two corners of each face (the third is pi
  // minus them).
  constexpr int kArgs = 12;
  Real ys[kArgs * kGeometryBlock], xs[kArgs * kGeometryBlock], th[kArgs * kGeometryBlock];
  Real normal[12 * kGeometryBlock], vol[kGeometryBlock];
  for (Index k = k0; k < k1; ++k) {
    Real* y = &ys[kArgs * (k - k0)];
    Real* x = &xs[kArgs * (k - k0)];
    if (net.pore_walls[k]) {  // wall_pore_geometry_3d
      std::fill(y, y + kArgs, 0.0);
      std::fill(x, x + kArgs, 1.0);
      continue;
    }
    const Index* v = &net.pore_v[4 * static_cast<std::size_t>(k)];
    V3 c[4];
    for (int i = 0; i < 4; ++i) c[i] = V3{p.x[v[i]], p.y[v[i]], p.z[v[i]]};
    Real len[4][4];  // edge lengths
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) len[i][j] = len[j][i] = norm(sub(c[j], c[i]));
    Real twice_area[4];  // of face i; |e1 x e2| at each of its corners
    for (int i = 0; i < 4; ++i) {
      // Face i (opposite corner i): corners c[i+1], c[i+2], c[i+3]; its outward normal points away from c[i].
      const V3 a = c[(i + 1) % 4];
      const V3 N = cross(sub(c[(i + 2) % 4], a), sub(c[(i + 3) % 4], a));
      twice_area[i] = norm(N);
      const Real sgn = dot(N, sub(c[i], a)) > 0 ? -1.0 : 1.0;
      const Real inv = twice_area[i] > 0 ? sgn / twice_area[i] : 0;
      normal[12 * (k - k0) + 3 * i] = N.x * inv;
      normal[12 * (k - k0) + 3 * i + 1] = N.y * inv;
      normal[12 * (k - k0) + 3 * i + 2] = N.z * inv;
    }
    // Edges from corner 0: the volume here, the power centre below.
    const V3 d1 = sub(c[1], c[0]), d2 = sub(c[2], c[0]), d3 = sub(c[3], c[0]);
    const V3 n23 = cross(d2, d3);
    const Real det = dot(d1, n23);
    const Real six_vol = std::abs(det);
    vol[k - k0] = six_vol / 6;
    for (int i = 0; i < 4; ++i) {
      const int o1 = (i + 1) % 4, o2 = (i + 2) % 4, o3 = (i + 3) % 4;
      const V3 u = sub(c[o1], c[i]), w = sub(c[o2], c[i]), s = sub(c[o3], c[i]);
      const Real lu = len[i][o1], lw = len[i][o2], ls = len[i][o3];
      const Real uw = dot(u, w), us = dot(u, s), ws = dot(w, s);
      y[i] = six_vol;
      x[i] = lu * lw * ls + uw * ls + us * lw + ws * lu;
      // The angle at corner i in each face through it (face f holds i as its corner (i - f + 3) % 4;
      // corners 0 and 1 only).
      auto face_angle_at_i = [&](int f, Real cosine_term) {  // atan2(|e1 x e2|, e1 . e2)
        const int m = (i - f + 3) % 4;
        if (m >= 2) return;
        y[4 + 2 * f + m] = twice_area[f];
        x[4 + 2 * f + m] = cosine_term;
      };
      face_angle_at_i(o1, ws);  // the face without o1: edges w, s
      face_angle_at_i(o2, us);  // edges u, s
      face_angle_at_i(o3, uw);  // edges u, w
    }
    net.pore_cx[k] = 0.25 * (p.x[v[0]] + p.x[v[1]] + p.x[v[2]] + p.x[v[3]]);
    net.pore_cy[k] = 0.25 * (p.y[v[0]] + p.y[v[1]] + p.y[v[2]] + p.y[v[3]]);
    net.pore_cz[k] = 0.25 * (p.z[v[0]] + p.z[v[1]] + p.z[v[2]] + p.z[v[3]]);
    // The power centre (the weighted Voronoi vertex dual to the tetrahedron, PFV's pore centre): equal
    // power |x - c_i|^2 - R_i^2 to the four spheres; relative to c_0, 2 d_i . x = |d_i|^2 - R_i^2 + R_0^2
    // (i = 1..3), solved by Cramer's rule. A flat tetrahedron (det ~ 0) keeps its centroid, and so does a
    // pore on the convex hull: its power centre lies outside the sample, where the network has no fluid
    // (with it, k/k_KC fell from 0.44 to 0.48 porosity; with the centroid 1.43 / 1.93 / 2.18 at 0.40 /
    // 0.44 / 0.48, and the 3D consolidation test's decay rate came 4 points closer to Terzaghi's).
    const Real r0 = p.radius[v[0]] * p.radius[v[0]];
    const Real b1 = 0.5 * (dot(d1, d1) - p.radius[v[1]] * p.radius[v[1]] + r0);
    const Real b2 = 0.5 * (dot(d2, d2) - p.radius[v[2]] * p.radius[v[2]] + r0);
    const Real b3 = 0.5 * (dot(d3, d3) - p.radius[v[3]] * p.radius[v[3]] + r0);
    const V3 n31 = cross(d3, d1), n12 = cross(d1, d2);
    const Real scale = (dot(d1, d1) + dot(d2, d2) + dot(d3, d3)) / 3;
    if (!net.pore_hull[k] && std::abs(det) > 1e-9 * scale * std::sqrt(scale)) {
      const Real inv = 1 / det;
      net.pore_px[k] = c[0].x + (b1 * n23.x + b2 * n31.x + b3 * n12.x) * inv;
      net.pore_py[k] = c[0].y + (b1 * n23.y + b2 * n31.y + b3 * n12.y) * inv;
      net.pore_pz[k] = c[0].z + (b1 * n23.z + b2 * n31.z + b3 * n12.z) * inv;
    } else {
      net.pore_px[k] = net.pore_cx[k];
      net.pore_py[k] = net.pore_cy[k];
      net.pore_pz[k] = net.pore_cz[k];
    }
  }
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"  // the loop above fills every argument
  atan2_nonneg(ys, xs, th, static_cast<int>(kArgs * (k1 - k0)));
#pragma GCC diagnostic pop
  for (Index k = k0; k < k1; ++k) {
    if (net.pore_walls[k]) continue;
    const Index* v = &net.pore_v[4 * static_cast<std::size_t>(k)];
    const Real* t = &th[kArgs * (k - k0)];
    const Real* n = &normal[12 * (k - k0)];
    Real* patch = &net.pore_patch[12 * static_cast<std::size_t>(k)];
    Real solid = 0;
    for (int i = 0; i < 4; ++i) {
      const Real R = p.radius[v[i]];
      solid += 2 * t[i] * R * R * R / 3;  // sphere sector inside the tetrahedron
      Real a[3] = {0, 0, 0};
      for (int face = 0; face < 4; ++face) {  // the faces through corner i
        if (face == i) continue;
        const int m = (i - face + 3) % 4;  // corner i is corner m of face `face`
        const Real theta = m < 2 ? t[4 + 2 * face + m] : kPi - t[4 + 2 * face] - t[4 + 2 * face + 1];
        const Real w = 0.5 * theta * R * R;
        for (int q = 0; q < 3; ++q) a[q] += w * n[3 * face + q];
      }
      for (int q = 0; q < 3; ++q) patch[3 * i + q] = a[q];
    }
    const Real V = vol[k - k0];
    net.pore_cell[k] = V;
    net.pore_void[k] = std::max(std::max(V - solid, net.params.min_void_fraction * V), net.void_floor);
  }
}

// A throat's length between its pores' power centres, floored at a quarter of its spheres' mean radius
// (throat_geometry_3d), and its conductance from the fluid area and hydraulic radius.
void throat_conductance_3d(Network2D& net, Index c, Real af, Real rh, Real mean_radius) {
  const Index pa = net.ch_pore[2 * c], pb = net.ch_pore[2 * c + 1];
  const V3 d{net.pore_px[pb] - net.pore_px[pa], net.pore_py[pb] - net.pore_py[pa], net.pore_pz[pb] - net.pore_pz[pa]};
  const Real L = std::max(norm(d), 0.25 * mean_radius);
  net.ch_length[c] = L;
  net.ch_aperture[c] = 2 * rh;
  net.ch_cond[c] = std::min(net.pfv_factor * af * rh * rh / (2 * L), net.ch_cond_cap);
}

// PFV's hydraulic radius of a throat (Chareyre et al. 2012, eq. 11; YADE's volumePoreVoronoiFraction
// and surfaceSolidThroat): R_h = (fluid volume) / (solid surface) in the region between the facet and
// the two pores' power centres p1, p2, the tetrahedra (u, v, p1, p2) over the facet's edges uv; a
// sphere at u or v takes the sector Omega R^3 / 3 and the surface Omega R^2 of its corner's solid angle.
// Against the facet's own A_f / (wetted perimeter) it is 1.6x larger at the median, and a random packing's
// permeability came to 0.67 / 0.79 / 0.93 x Kozeny-Carman at porosity 0.40 / 0.44 / 0.48 (walls in the
// triangulation), where the facet's gave 0.25 / 0.31 / 0.38.
// The solid angle at u of tetrahedron (u, v, p1, p2): 2 atan2(|a . (b x c)|, |a||b||c| + (a.b)|c| +
// (a.c)|b| + (b.c)|a|), a, b, c the edges from u (Van Oosterom & Strackee 1983).
void solid_angle_args(V3 u, V3 v, V3 p1, V3 p2, Real& y, Real& x) {
  const V3 a = sub(v, u), b = sub(p1, u), c = sub(p2, u);
  const Real la = norm(a), lb = norm(b), lc = norm(c);
  y = std::abs(dot(a, cross(b, c)));
  x = la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la;
}

// Throats [c0, c1) (after the pores' power centres): fluid area A_f = A - sum_k theta_k R_k^2 / 2, PFV's
// hydraulic radius R_h (above; ch_aperture = 2 R_h), length L and conductance g mu = pfv_factor A_f R_h^2
// / (2 L) (Chareyre et al. 2012), clamped; L the distance between the pores' power centres.
void throat_geometry_3d(Network2D& net, const Particles3D& p, Index c0, Index c1) {
  auto pos = [&](Index i) { return V3{p.x[i], p.y[i], p.z[i]}; };
  auto pc = [&](Index k) { return V3{net.pore_px[k], net.pore_py[k], net.pore_pz[k]}; };
  // Per throat: the facet's angles at corners 0 and 1, then the solid angles at both ends of its three
  // edges in the tetrahedra (v_j, v_j+1, p1, p2).
  // Without walls the facet's A_f / perimeter (PFV's regions reach far outside the hull there: power
  // centres of pores along the hull lie beyond it, and a packing's permeability came to ~100 x Kozeny-
  // Carman), and only the facet's angles.
  const bool pfv = net.n_walls > 0;
  const int nargs = pfv ? 8 : 2;
  Real ys[8 * kGeometryBlock], xs[8 * kGeometryBlock], th[8 * kGeometryBlock], area[kGeometryBlock],
      region[kGeometryBlock];
  for (Index c = c0; c < c1; ++c) {
    const Index* v = &net.ch_part[3 * static_cast<std::size_t>(c)];
    Real* y = &ys[nargs * (c - c0)];
    Real* x = &xs[nargs * (c - c0)];
    region[c - c0] = 0;
    if (v[2] >= net.n_particles) {  // a wall corner (the last: walls sort after the spheres); wall_throat_geometry_3d
      std::fill(y, y + nargs, 0.0);
      std::fill(x, x + nargs, 1.0);
      area[c - c0] = 0;
      continue;
    }
    const V3 P[3] = {pos(v[0]), pos(v[1]), pos(v[2])};
    const Real twice_area = norm(cross(sub(P[1], P[0]), sub(P[2], P[0])));  // |u x w| at every corner
    area[c - c0] = 0.5 * twice_area;
    for (int j = 0; j < 2; ++j) {  // the angle at corner j: atan2(|u x w|, u . w); at corner 2 pi minus both
      y[j] = twice_area;
      x[j] = dot(sub(P[(j + 1) % 3], P[j]), sub(P[(j + 2) % 3], P[j]));
    }
    if (!pfv) continue;
    // solid_angle_args at both ends of each edge, sharing what they share: the edge's length, each sphere's
    // distances to p1 and p2, and the tetrahedron's triple product (the same at both ends).
    const V3 p1 = pc(net.ch_pore[2 * c]), p2 = pc(net.ch_pore[2 * c + 1]);
    V3 b[3], d[3];
    Real lb[3], ld[3], bd[3];
    for (int j = 0; j < 3; ++j) {
      b[j] = sub(p1, P[j]);
      d[j] = sub(p2, P[j]);
      lb[j] = norm(b[j]);
      ld[j] = norm(d[j]);
      bd[j] = dot(b[j], d[j]);
    }
    Real vol = 0;
    for (int j = 0; j < 3; ++j) {
      const int k = (j + 1) % 3;
      const V3 e = sub(P[k], P[j]);
      const Real le = norm(e);
      const Real det = std::abs(dot(e, cross(b[j], d[j])));
      vol += det / 6;
      y[2 + 2 * j] = det;  // at P[j]: edges e, b_j, d_j
      x[2 + 2 * j] = le * lb[j] * ld[j] + dot(e, b[j]) * ld[j] + dot(e, d[j]) * lb[j] + bd[j] * le;
      y[3 + 2 * j] = det;  // at P[k]: edges -e, b_k, d_k
      x[3 + 2 * j] = le * lb[k] * ld[k] - dot(e, b[k]) * ld[k] - dot(e, d[k]) * lb[k] + bd[k] * le;
    }
    region[c - c0] = vol;
  }
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"  // the loop above fills every argument
  atan2_nonneg(ys, xs, th, static_cast<int>(nargs * (c1 - c0)));
#pragma GCC diagnostic pop
  for (Index c = c0; c < c1; ++c) {
    const Index* v = &net.ch_part[3 * static_cast<std::size_t>(c)];
    if (v[2] >= net.n_particles) continue;
    const Real* t = &th[nargs * (c - c0)];
    const Real angle[3] = {t[0], t[1], kPi - t[0] - t[1]};
    const Real R[3] = {p.radius[v[0]], p.radius[v[1]], p.radius[v[2]]};
    Real solid = 0, perim = 0;
    for (int j = 0; j < 3; ++j) {
      solid += 0.5 * angle[j] * R[j] * R[j];
      perim += angle[j] * R[j];
    }
    const Real af = std::max(area[c - c0] - solid, net.params.min_void_fraction * area[c - c0]);
    // Each sphere's solid angle in the region: its two tetrahedra (edges j-1 and j).
    Real surface[3] = {0, 0, 0}, sector = 0;
    for (int j = 0; j < 3 && pfv; ++j) {
      const Real omega = 2 * (t[2 + 2 * j] + t[3 + 2 * ((j + 2) % 3)]);
      surface[j] = omega * R[j] * R[j];
      sector += surface[j] * R[j] / 3;
    }
    const Real total_surface = surface[0] + surface[1] + surface[2];
    // A region without thickness (p1 = p2 in the facet's plane) has no ratio: the facet's own A_f / perimeter.
    const Real rh = pfv && total_surface > 1e-12 * perim * perim
                        ? std::max(region[c - c0] - sector, net.params.min_void_fraction * region[c - c0]) / total_surface
                        : af / perim;
    // L between the pores' power centres, as PFV (Chareyre et al. 2012): the centroids' distance gave
    // 5-9 x Kozeny-Carman's permeability on random packings (docs/porenet.md section 9).
    // Two tetrahedra with almost coincident power centres are halves of one pore body, not a throat of
    // length ~0: L at least a quarter of the facet's mean radius. The packings' permeability does not see
    // the floor (k/k_KC 1.50 / 2.11 / 1.37 with it, 1.51 / 2.11 / 1.38 at a tenth of the radius; hull pores
    // then on their power centres too), but the two-phase transport step does: a tenth made such throats
    // 2.5x more conductive and the implicit steps halved 2.7x more often
    // (SaturatedUcs3D.SmallestPoresFirstDrainedStepsWithoutHalving).
    throat_conductance_3d(net, c, af, rh, (R[0] + R[1] + R[2]) / 3);
    // Wall shear tau = R_h dp / L over the wetted surface: A_f dp in all, each sphere its surface's share
    // in the region (add_shear_forces_3d).
    for (int j = 0; j < 3; ++j)
      net.ch_shear[3 * static_cast<std::size_t>(c) + j] = total_surface > 0 ? af * surface[j] / total_surface
                                                                            : perim > 0 ? af * angle[j] * R[j] / perim : 0.0;
  }
}

// Pores and throats with walls as corners (BoxWalls; PFV's boundary spheres). A wall vertex is the
// limit of a sphere of radius -> infinity beyond the plane: a corner at infinity in the direction d_w
// (from the sample into the wall), so every edge from a sphere to it points along d_w, and a pore is
// the tetrahedron's part inside the box. Corner geometry: a sphere corner's cone, solid angle and
// face angles as pore_geometry_3d's, with the edge directions to the walls; a wall corner's patch is
// A d_w (A: the pore's area on the wall).
struct WallCorner {
  bool wall;
  V3 c;     // sphere centre
  Real R;   // sphere radius
  int axis;  // wall: its axis and plane; d = sign e_axis
  Real sign, plane;
};

V3 axis_dir(int axis, Real sign) {
  V3 d{0, 0, 0};
  (axis == 0 ? d.x : axis == 1 ? d.y : d.z) = sign;
  return d;
}
Real coord(V3 a, int axis) { return axis == 0 ? a.x : axis == 1 ? a.y : a.z; }
// The edge direction from sphere corner `from` to corner `to`.
V3 edge_dir(const WallCorner& from, const WallCorner& to) {
  return to.wall ? axis_dir(to.axis, to.sign) : sub(to.c, from.c);
}
// Distance from a sphere's centre to a wall plane (>= 0: a centre beyond the wall counts as on it).
Real height(const WallCorner& s, const WallCorner& w) { return std::max(Real(0), (w.plane - coord(s.c, w.axis)) * w.sign); }
Real angle_between(V3 u, V3 w) { return std::atan2(norm(cross(u, w)), dot(u, w)); }

WallCorner corner_of(const Network2D& net, const Particles3D& p, Index v) {
  WallCorner q{};
  if (v >= net.n_particles) {
    const int w = static_cast<int>(v - net.n_particles);
    q.wall = true;
    q.axis = w / 2;
    q.sign = w % 2 ? 1.0 : -1.0;
    q.plane = net.wall_plane[static_cast<std::size_t>(w)];
  } else {
    q.wall = false;
    q.c = V3{p.x[v], p.y[v], p.z[v]};
    q.R = p.radius[v];
  }
  return q;
}

// The point on the pore's walls with equal power |x - c_i|^2 - R_i^2 to its spheres (the limit of the
// power centre as the wall spheres grow): 2 (c_i - c_0) . x = |c_i|^2 - R_i^2 - |c_0|^2 + R_0^2 for the
// sphere corners i > 0, x's coordinates on the walls' axes fixed. Degenerate systems (projected spheres
// in a line) give the centroid.
V3 wall_power_centre(const WallCorner* s, int ns, const WallCorner* w, int nw, V3 centroid) {
  Real x[3] = {centroid.x, centroid.y, centroid.z};
  bool fixed[3] = {false, false, false};
  for (int j = 0; j < nw; ++j) {
    x[w[j].axis] = w[j].plane;
    fixed[w[j].axis] = true;
  }
  int free_axis[3], nf = 0;
  for (int a = 0; a < 3; ++a)
    if (!fixed[a]) free_axis[nf++] = a;
  if (nf == 0) return V3{x[0], x[1], x[2]};
  // nf = ns - 1 equations (one wall: 2 x 2; two walls: 1 x 1).
  Real A[2][2] = {{0, 0}, {0, 0}}, b[2] = {0, 0};
  for (int i = 1; i < ns; ++i) {
    const V3 d = sub(s[i].c, s[0].c);
    Real rhs = dot(s[i].c, s[i].c) - s[i].R * s[i].R - dot(s[0].c, s[0].c) + s[0].R * s[0].R;
    for (int a = 0; a < 3; ++a)
      if (fixed[a]) rhs -= 2 * coord(d, a) * x[a];
    for (int f = 0; f < nf; ++f) A[i - 1][f] = 2 * coord(d, free_axis[f]);
    b[i - 1] = rhs;
  }
  if (nf == 1) {
    if (std::abs(A[0][0]) > 1e-9 * norm(sub(s[1].c, s[0].c))) x[free_axis[0]] = b[0] / A[0][0];
  } else {
    const Real det = A[0][0] * A[1][1] - A[0][1] * A[1][0];
    const Real scale = std::abs(A[0][0] * A[1][1]) + std::abs(A[0][1] * A[1][0]);
    if (std::abs(det) > 1e-9 * scale) {
      x[free_axis[0]] = (b[0] * A[1][1] - b[1] * A[0][1]) / det;
      x[free_axis[1]] = (A[0][0] * b[1] - A[1][0] * b[0]) / det;
    }
  }
  return V3{x[0], x[1], x[2]};
}

struct WallPore {
  Real cell, solid;
  Real patch[12];
  V3 centroid, power_centre;
};
WallPore wall_pore(const WallCorner* q) {
  WallPore out{};
  // Outward unit normal of face f (opposite corner f), through one of its sphere corners.
  V3 normal[4];
  for (int f = 0; f < 4; ++f) {
    normal[f] = V3{0, 0, 0};
    int o[3], m = 0;
    for (int i = 0; i < 4; ++i)
      if (i != f) o[m++] = i;
    int r = -1;
    for (int j = 0; j < 3; ++j)
      if (!q[o[j]].wall) r = j;
    if (r < 0) continue;  // three walls: no sphere has this face
    const WallCorner& base = q[o[r]];
    V3 N = cross(edge_dir(base, q[o[(r + 1) % 3]]), edge_dir(base, q[o[(r + 2) % 3]]));
    const Real len = norm(N);
    if (!(len > 0)) continue;
    const Real sgn = dot(N, edge_dir(base, q[f])) > 0 ? -1.0 : 1.0;
    normal[f] = V3{N.x * sgn / len, N.y * sgn / len, N.z * sgn / len};
  }
  Real solid = 0;
  WallCorner spheres[4], walls[3];
  int ns = 0, nw = 0;
  for (int i = 0; i < 4; ++i) {
    Real* patch = &out.patch[3 * i];
    patch[0] = patch[1] = patch[2] = 0;
    if (q[i].wall) {
      walls[nw++] = q[i];
      continue;
    }
    spheres[ns++] = q[i];
    V3 e[3];
    int o[3], m = 0;
    for (int j = 0; j < 4; ++j)
      if (j != i) {
        o[m] = j;
        e[m++] = edge_dir(q[i], q[j]);
      }
    // Solid angle (Van Oosterom & Strackee 1983), then the face angles at i.
    const Real l0 = norm(e[0]), l1 = norm(e[1]), l2 = norm(e[2]);
    const Real omega = 2 * std::atan2(std::abs(dot(e[0], cross(e[1], e[2]))),
                                      l0 * l1 * l2 + dot(e[0], e[1]) * l2 + dot(e[0], e[2]) * l1 + dot(e[1], e[2]) * l0);
    const Real R = q[i].R;
    solid += omega * R * R * R / 3;
    for (int f = 0; f < 3; ++f) {  // the face without corner o[f]: edges e[(f+1)%3], e[(f+2)%3]
      const Real w = 0.5 * angle_between(e[(f + 1) % 3], e[(f + 2) % 3]) * R * R;
      patch[0] += w * normal[o[f]].x;
      patch[1] += w * normal[o[f]].y;
      patch[2] += w * normal[o[f]].z;
    }
  }
  // The pore inside the box, its area on each wall, and its centroid (the mean of its vertices: each
  // sphere centre and its projections onto the pore's walls and their intersections).
  Real V = 0, wall_area[3] = {0, 0, 0};
  V3 centroid{0, 0, 0};
  int nvert = 0;
  auto add_vertex = [&](V3 a) {
    centroid = V3{centroid.x + a.x, centroid.y + a.y, centroid.z + a.z};
    ++nvert;
  };
  auto project = [&](V3 a, int mask) {  // onto the walls in mask
    Real x[3] = {a.x, a.y, a.z};
    for (int j = 0; j < nw; ++j)
      if (mask >> j & 1) x[walls[j].axis] = walls[j].plane;
    return V3{x[0], x[1], x[2]};
  };
  for (int i = 0; i < ns; ++i)
    for (int mask = 0; mask < (1 << nw); ++mask) add_vertex(project(spheres[i].c, mask));
  centroid = V3{centroid.x / nvert, centroid.y / nvert, centroid.z / nvert};
  if (nw == 1) {  // prism: projected triangle x mean height
    const V3 d = axis_dir(walls[0].axis, walls[0].sign);
    const Real a_proj = 0.5 * std::abs(dot(cross(sub(spheres[1].c, spheres[0].c), sub(spheres[2].c, spheres[0].c)), d));
    V = a_proj * (height(spheres[0], walls[0]) + height(spheres[1], walls[0]) + height(spheres[2], walls[0])) / 3;
    wall_area[0] = a_proj;
  } else if (nw == 2) {  // cross-sections h1(s) x h2(s), linear along the edge
    const V3 e = cross(axis_dir(walls[0].axis, 1), axis_dir(walls[1].axis, 1));
    const Real len = std::abs(dot(sub(spheres[1].c, spheres[0].c), e));
    const Real h1a = height(spheres[0], walls[0]), h1b = height(spheres[1], walls[0]);
    const Real h2a = height(spheres[0], walls[1]), h2b = height(spheres[1], walls[1]);
    V = len * ((h1a * h2a + h1b * h2b) / 3 + (h1a * h2b + h1b * h2a) / 6);
    wall_area[0] = len * (h2a + h2b) / 2;
    wall_area[1] = len * (h1a + h1b) / 2;
  } else {  // the box corner
    const Real h[3] = {height(spheres[0], walls[0]), height(spheres[0], walls[1]), height(spheres[0], walls[2])};
    V = h[0] * h[1] * h[2];
    wall_area[0] = h[1] * h[2];
    wall_area[1] = h[0] * h[2];
    wall_area[2] = h[0] * h[1];
  }
  for (int i = 0, j = 0; i < 4; ++i)
    if (q[i].wall) {
      const V3 d = axis_dir(q[i].axis, q[i].sign);
      Real* patch = &out.patch[3 * i];
      patch[0] = wall_area[j] * d.x;
      patch[1] = wall_area[j] * d.y;
      patch[2] = wall_area[j] * d.z;
      ++j;
    }
  out.centroid = centroid;
  out.power_centre = wall_power_centre(spheres, ns, walls, nw, centroid);
  out.cell = V;
  out.solid = solid;
  return out;
}

void wall_pore_geometry_3d(Network2D& net, const Particles3D& p, Index k) {
  const Index* v = &net.pore_v[4 * static_cast<std::size_t>(k)];
  WallCorner q[4];
  for (int i = 0; i < 4; ++i) q[i] = corner_of(net, p, v[i]);
  const WallPore g = wall_pore(q);
  std::copy(g.patch, g.patch + 12, &net.pore_patch[12 * static_cast<std::size_t>(k)]);
  net.pore_cx[k] = g.centroid.x;
  net.pore_cy[k] = g.centroid.y;
  net.pore_cz[k] = g.centroid.z;
  net.pore_px[k] = g.power_centre.x;
  net.pore_py[k] = g.power_centre.y;
  net.pore_pz[k] = g.power_centre.z;
  net.pore_cell[k] = g.cell;
  net.pore_void[k] = std::max(std::max(g.cell - g.solid, net.params.min_void_fraction * g.cell), net.void_floor);
}

// A throat with walls: one wall (spheres a, b), the trapezoid from the edge ab to the wall, its sides
// along d_w (the angles at a and b add to pi); two walls (sphere a), the rectangle h1 x h2 from a to the
// box edge, a quarter of the sphere's disc in it. PFV's R_h as throat_geometry_3d's over the polygon's
// edges (PFV's volumeSingleFictiousPore and volumeDoubleFictiousPore); the pores' power centres lie on
// the walls, so a polygon edge on a wall spans a flat region whose wall area is wetted surface. The
// channel shear the walls take is not applied; the spheres keep their share.
void wall_throat_geometry_3d(Network2D& net, const Particles3D& p, Index c) {
  const Index* v = &net.ch_part[3 * static_cast<std::size_t>(c)];
  WallCorner q[3];
  for (int j = 0; j < 3; ++j) q[j] = corner_of(net, p, v[j]);  // spheres first (walls sort last)
  // The polygon: points with a sphere's radius (0: a point on the walls) and the wall an edge to the next
  // point lies on (-1: none).
  struct Vertex {
    V3 x;
    Real R;
    int sphere;  // index into q, -1 for a point
    int wall_edge;
  };
  Vertex poly[4];
  int m = 0;
  auto proj = [](V3 a, const WallCorner& w) {
    Real x[3] = {a.x, a.y, a.z};
    x[w.axis] = w.plane;
    return V3{x[0], x[1], x[2]};
  };
  auto wall_index = [&](const WallCorner& w) { return 2 * w.axis + (w.sign > 0 ? 1 : 0); };
  Real area = 0, angle[2] = {0, 0}, wall_perim = 0;
  int ns = 0;
  if (!q[1].wall) {  // one wall: a, b, b', a'
    ns = 2;
    const V3 d = axis_dir(q[2].axis, q[2].sign);
    const V3 ab = sub(q[1].c, q[0].c);
    const Real along = dot(ab, d);
    const Real across = std::sqrt(std::max(Real(0), dot(ab, ab) - along * along));
    area = across * (height(q[0], q[2]) + height(q[1], q[2])) / 2;
    angle[0] = angle_between(ab, d);
    angle[1] = kPi - angle[0];
    wall_perim = across;
    poly[m++] = {q[0].c, q[0].R, 0, -1};
    poly[m++] = {q[1].c, q[1].R, 1, -1};
    poly[m++] = {proj(q[1].c, q[2]), 0, -1, wall_index(q[2])};
    poly[m++] = {proj(q[0].c, q[2]), 0, -1, -1};
  } else if (!q[0].wall) {  // two walls: a, a1, e, a2
    ns = 1;
    const Real h1 = height(q[0], q[1]), h2 = height(q[0], q[2]);
    area = h1 * h2;
    angle[0] = kPi / 2;
    wall_perim = h1 + h2;
    poly[m++] = {q[0].c, q[0].R, 0, -1};
    poly[m++] = {proj(q[0].c, q[1]), 0, -1, wall_index(q[1])};
    poly[m++] = {proj(proj(q[0].c, q[1]), q[2]), 0, -1, wall_index(q[2])};
    poly[m++] = {proj(q[0].c, q[2]), 0, -1, -1};
  }
  Real solid = 0, perim = wall_perim, mean_radius = 0;
  for (int j = 0; j < ns; ++j) {
    solid += 0.5 * angle[j] * q[j].R * q[j].R;
    perim += angle[j] * q[j].R;
    mean_radius += q[j].R / ns;
  }
  const Real af = std::max(area - solid, net.params.min_void_fraction * area);
  const Index pa = net.ch_pore[2 * c], pb = net.ch_pore[2 * c + 1];
  const V3 p1{net.pore_px[pa], net.pore_py[pa], net.pore_pz[pa]}, p2{net.pore_px[pb], net.pore_py[pb], net.pore_pz[pb]};
  Real vol = 0, sector = 0, surface[2] = {0, 0}, wall_surface = 0;
  for (int i = 0; i < m; ++i) {
    const Vertex& u = poly[i];
    const Vertex& w = poly[(i + 1) % m];
    vol += std::abs(dot(sub(w.x, u.x), cross(sub(p1, u.x), sub(p2, u.x)))) / 6;
    if (u.wall_edge >= 0) {
      const V3 s = cross(sub(w.x, u.x), sub(p2, p1));
      wall_surface += 0.5 * std::abs(coord(s, u.wall_edge / 2));
    }
    for (const Vertex* end : {&u, &w}) {
      if (end->sphere < 0) continue;
      Real y, x;
      solid_angle_args(end->x, end == &u ? w.x : u.x, p1, p2, y, x);
      const Real omega = 2 * std::atan2(y, x);
      surface[end->sphere] += omega * end->R * end->R;
      sector += omega * end->R * end->R * end->R / 3;
    }
  }
  const Real total_surface = surface[0] + surface[1] + wall_surface;
  const Real rh = total_surface > 1e-12 * perim * perim
                      ? std::max(vol - sector, net.params.min_void_fraction * vol) / total_surface
                      : (perim > 0 ? af / perim : 0.0);
  throat_conductance_3d(net, c, af, rh, mean_radius);
  for (int j = 0; j < 3; ++j)
    net.ch_shear[3 * static_cast<std::size_t>(c) + j] =
        j < ns && total_surface > 0 ? af * surface[j] / total_surface : 0.0;
}

// A geometry update: the pores, then the throats (they need the pores' centroids), each parallel over
// blocks.
void update_geometry_3d(Network2D& net, const Particles3D& p) {
  const Index np = net.n_pores(), nc = net.n_channels();
#pragma omp parallel for schedule(static) if (np > kParallelMin)
  for (Index b = 0; b < (np + kGeometryBlock - 1) / kGeometryBlock; ++b)
    pore_geometry_3d(net, p, b * kGeometryBlock, std::min(np, (b + 1) * kGeometryBlock));
  const auto nwp = static_cast<Index>(net.wall_pores.size()), nwc = static_cast<Index>(net.wall_throats.size());
#pragma omp parallel for schedule(static) if (nwp > kParallelMin)
  for (Index i = 0; i < nwp; ++i) wall_pore_geometry_3d(net, p, net.wall_pores[static_cast<std::size_t>(i)]);
#pragma omp parallel for schedule(static) if (nc > kParallelMin)
  for (Index b = 0; b < (nc + kGeometryBlock - 1) / kGeometryBlock; ++b)
    throat_geometry_3d(net, p, b * kGeometryBlock, std::min(nc, (b + 1) * kGeometryBlock));
#pragma omp parallel for schedule(static) if (nwc > kParallelMin)
  for (Index i = 0; i < nwc; ++i) wall_throat_geometry_3d(net, p, net.wall_throats[static_cast<std::size_t>(i)]);
}

// Clamp local conductances relative to the median (YADE clamps to maxKdivKmean x the mean,
// METHODS §5.3a; here the median: the wide flat facets near the hull reach 1e5 x the typical
// conductance and would dominate a mean). The median is the one of the build (kept in ch_cond_cap).
void clamp_conductances(Network2D& net) {
  for (Index c = 0; c < net.n_channels(); ++c) net.ch_cond[c] = std::min(net.ch_cond[c], net.ch_cond_cap);
}

void min_void_floor(Network2D& net) {
  for (Index k = 0; k < net.n_pores(); ++k) net.pore_void[k] = std::max(net.pore_void[k], net.void_floor);
}

void set_wall_planes(Network2D& net, const BoxWalls& walls) {
  for (int a = 0; a < 3; ++a) {
    if (!(walls.lo[a] < walls.hi[a]))
      throw InputError(fmt::format("porenet: walls along axis {} at {} and {}; the lower one must be below the upper",
                                   a, walls.lo[a], walls.hi[a]));
    net.wall_plane[2 * a] = walls.lo[a];
    net.wall_plane[2 * a + 1] = walls.hi[a];
  }
}

}  // namespace

Network2D build_network_3d(const Particles3D& p, const NetworkParams& params, Real pfv_factor, const BoxWalls* walls) {
  const std::size_t n = p.x.size();
  if (p.y.size() != n || p.z.size() != n || p.radius.size() != n || (!p.gid.empty() && p.gid.size() != n))
    throw InputError("porenet: 3D particle arrays (x, y, z, radius, gid) differ in length");
  if (n < 4) throw InputError(fmt::format("porenet: {} particles; a 3D network needs at least 4", n));
  for (std::size_t k = 0; k < n; ++k)
    if (!(p.radius[k] > 0)) throw InputError(fmt::format("porenet: particle {} has radius {}; must be > 0", k, p.radius[k]));
  if (!(pfv_factor > 0)) throw InputError(fmt::format("porenet: pfv_factor = {}; must be > 0", pfv_factor));
  auto gid = [&](Index k) -> std::int64_t { return p.gid.empty() ? k : p.gid[k]; };
  Network2D net;
  net.dim = 3;
  net.params = params;
  net.n_particles = static_cast<Index>(n);
  std::vector<std::pair<Kernel::Weighted_point_3, Index>> pts(n);
  for (std::size_t k = 0; k < n; ++k)
    pts[k] = {Kernel::Weighted_point_3(Kernel::Point_3(p.x[k], p.y[k], p.z[k]), p.radius[k] * p.radius[k]),
              static_cast<Index>(k)};
  if (walls) {
    // PFV's boundary spheres: radius 1e5 x the box, centred beyond each wall so that their surface
    // meets the sample as a plane (off the plane by at most 1e-5 of the box across the wall).
    set_wall_planes(net, *walls);
    net.n_walls = 6;
    Real size = 0;
    for (int a = 0; a < 3; ++a) size = std::max(size, walls->hi[a] - walls->lo[a]);
    for (std::size_t k = 0; k < n; ++k) {
      const Real x[3] = {p.x[k], p.y[k], p.z[k]};
      for (int a = 0; a < 3; ++a)
        if (!(x[a] > walls->lo[a] && x[a] < walls->hi[a]))
          throw InputError(fmt::format("porenet: sphere {} has its centre at {} on axis {}, outside the walls [{}, {}]",
                                       gid(static_cast<Index>(k)), x[a], a, walls->lo[a], walls->hi[a]));
    }
    const Real big = 1e5 * size;
    for (int w = 0; w < 6; ++w) {
      Real c[3];
      for (int a = 0; a < 3; ++a) c[a] = 0.5 * (walls->lo[a] + walls->hi[a]);
      const int a = w / 2;
      c[a] = w % 2 ? walls->hi[a] + big : walls->lo[a] - big;
      pts.push_back({Kernel::Weighted_point_3(Kernel::Point_3(c[0], c[1], c[2]), big * big),
                     static_cast<Index>(n) + w});
    }
  }
  Regular rt;
  rt.insert(pts.begin(), pts.end());
  if (rt.dimension() < 3) throw InputError("porenet: the sphere centres are coplanar; no 3D pore can be formed");
  net.hidden_particles = static_cast<Index>(pts.size()) - static_cast<Index>(rt.number_of_vertices());
  // Wall vertices sort after every sphere (their ids above any sphere's), so a throat lists its walls last.
  auto vid = [&](Index k) -> std::int64_t {
    return k < static_cast<Index>(n) ? gid(k) : std::numeric_limits<std::int64_t>::max() - 6 + (k - static_cast<Index>(n));
  };

  struct Cell {
    std::array<std::int64_t, 4> key;
    std::array<Index, 4> v;
  };
  std::vector<Cell> cells;
  cells.reserve(rt.number_of_finite_cells());
  for (auto c = rt.finite_cells_begin(); c != rt.finite_cells_end(); ++c) {
    Cell cl;
    int wall_axes = 0, n_wall = 0;
    for (int i = 0; i < 4; ++i) cl.v[i] = c->vertex(i)->info();
    for (int i = 0; i < 4; ++i) {
      cl.key[i] = vid(cl.v[i]);
      if (cl.v[i] >= static_cast<Index>(n)) {
        const int axis = (cl.v[i] - static_cast<Index>(n)) / 2;
        // Two opposite walls in one cell: in the limit of infinite wall spheres it has no volume (a layer
        // one sphere thick between them); four walls: no sphere.
        if (wall_axes >> axis & 1)
          throw InputError("porenet: a tetrahedron joins two opposite walls; the sample is one sphere thick "
                           "between them (walls need a sample at least two spheres across)");
        wall_axes |= 1 << axis;
        ++n_wall;
      }
    }
    if (n_wall == 4) continue;
    std::sort(cl.key.begin(), cl.key.end());
    cells.push_back(cl);
  }
  std::sort(cells.begin(), cells.end(), [](const Cell& a, const Cell& b) { return a.key < b.key; });
  const Index np = static_cast<Index>(cells.size());
  net.pore_v.resize(4 * static_cast<std::size_t>(np));
  for (Index k = 0; k < np; ++k)
    for (int i = 0; i < 4; ++i) net.pore_v[4 * k + i] = cells[k].v[i];
  // Facets: sorted gid triple -> pores; shared = throat, single = hull.
  struct Facet {
    std::array<std::int64_t, 3> key;
    std::array<Index, 3> v;
    Index pore;
  };
  std::vector<Facet> facets;
  facets.reserve(4 * static_cast<std::size_t>(np));
  for (Index k = 0; k < np; ++k)
    for (int i = 0; i < 4; ++i) {
      Facet f;
      for (int j = 0; j < 3; ++j) f.v[j] = net.pore_v[4 * k + (i + 1 + j) % 4];
      std::sort(f.v.begin(), f.v.end(), [&](Index a, Index b) { return vid(a) < vid(b); });
      for (int j = 0; j < 3; ++j) f.key[j] = vid(f.v[j]);
      f.pore = k;
      facets.push_back(f);
    }
  std::sort(facets.begin(), facets.end(),
            [](const Facet& a, const Facet& b) { return std::tie(a.key, a.pore) < std::tie(b.key, b.pore); });
  net.pore_hull.assign(np, 0);
  for (std::size_t e = 0; e < facets.size();) {
    if (e + 1 < facets.size() && facets[e + 1].key == facets[e].key) {
      net.ch_pore.push_back(facets[e].pore);
      net.ch_pore.push_back(facets[e + 1].pore);
      for (int j = 0; j < 3; ++j) net.ch_part.push_back(facets[e].v[j]);
      net.ch_kind.push_back(ChannelKind::T2T);
      net.ch_pair.push_back(-1);
      e += 2;
    } else {
      net.pore_hull[facets[e].pore] = 1;
      e += 1;
    }
  }
  const Index nc = static_cast<Index>(net.ch_pore.size() / 2);
  // Pores and throats with walls; with walls the pores on them are the sample's boundary (pore_hull).
  net.pore_walls.assign(np, 0);
  for (Index k = 0; k < np; ++k) {
    for (int i = 0; i < 4; ++i)
      if (net.pore_v[4 * k + i] >= static_cast<Index>(n))
        net.pore_walls[k] |= static_cast<std::uint8_t>(1u << (net.pore_v[4 * k + i] - static_cast<Index>(n)));
    if (net.pore_walls[k]) net.wall_pores.push_back(k);
    if (net.n_walls) net.pore_hull[k] = net.pore_walls[k] ? 1 : 0;
  }
  for (Index c = 0; c < nc; ++c)
    if (net.ch_part[3 * c + 2] >= static_cast<Index>(n)) net.wall_throats.push_back(c);
  net.wp_start.assign(7, 0);
  if (net.n_walls) {
    for (Index k : net.wall_pores)
      for (int i = 0; i < 4; ++i)
        if (net.pore_v[4 * k + i] >= static_cast<Index>(n)) ++net.wp_start[net.pore_v[4 * k + i] - static_cast<Index>(n) + 1];
    for (int w = 0; w < 6; ++w) net.wp_start[w + 1] += net.wp_start[w];
    net.wp_pore.resize(net.wp_start[6]);
    net.wp_corner.resize(net.wp_start[6]);
    std::vector<Index> wfill(net.wp_start.begin(), net.wp_start.end() - 1);
    for (Index k : net.wall_pores)
      for (int i = 0; i < 4; ++i)
        if (net.pore_v[4 * k + i] >= static_cast<Index>(n)) {
          const Index e = wfill[net.pore_v[4 * k + i] - static_cast<Index>(n)]++;
          net.wp_pore[e] = k;
          net.wp_corner[e] = static_cast<std::uint8_t>(i);
        }
  }
  // Geometry as each update does (pores with their patch vectors, then throats), then the void floor
  // and the conductance cap, both from this first geometry.
  net.pore_area.assign(np, 0);
  net.pore_cell.resize(np);
  net.pore_void.resize(np);
  net.pore_cx.resize(np);
  net.pore_cy.resize(np);
  net.pore_cz.resize(np);
  net.pore_px.resize(np);
  net.pore_py.resize(np);
  net.pore_pz.resize(np);
  net.pore_patch.assign(12 * static_cast<std::size_t>(np), 0);
  net.ch_length.assign(nc, 0);
  net.ch_aperture.assign(nc, 0);
  net.ch_cond.assign(nc, 0);
  net.ch_shear.assign(3 * static_cast<std::size_t>(nc), 0);
  net.pfv_factor = pfv_factor;
  net.void_floor = 0;
  net.ch_cond_cap = std::numeric_limits<Real>::infinity();
  update_geometry_3d(net, p);
  Real mean_cell = 0;
  for (Index k = 0; k < np; ++k) mean_cell += net.pore_cell[k];
  mean_cell /= static_cast<Real>(np);
  net.void_floor = params.min_void_relative * mean_cell;
  min_void_floor(net);
  if (nc > 0) {
    std::vector<Real> sorted(net.ch_cond);
    std::nth_element(sorted.begin(), sorted.begin() + nc / 2, sorted.end());
    net.ch_cond_cap = params.max_cond_ratio * sorted[nc / 2];
    clamp_conductances(net);
  }
  net.pc_start.assign(np + 1, 0);
  for (Index c = 0; c < nc; ++c) {
    ++net.pc_start[net.ch_pore[2 * c] + 1];
    ++net.pc_start[net.ch_pore[2 * c + 1] + 1];
  }
  for (Index k = 0; k < np; ++k) net.pc_start[k + 1] += net.pc_start[k];
  net.pc_ch.resize(net.pc_start[np]);
  std::vector<Index> fill(net.pc_start.begin(), net.pc_start.end() - 1);
  for (Index c = 0; c < nc; ++c) {
    net.pc_ch[fill[net.ch_pore[2 * c]]++] = c;
    net.pc_ch[fill[net.ch_pore[2 * c + 1]]++] = c;
  }
  // Particle -> pore corners (pores in ascending order per particle).
  net.pp_start.assign(n + 1, 0);
  for (Index k = 0; k < np; ++k)
    for (int i = 0; i < 4; ++i)
      if (net.pore_v[4 * k + i] < static_cast<Index>(n)) ++net.pp_start[net.pore_v[4 * k + i] + 1];
  for (std::size_t q = 0; q < n; ++q) net.pp_start[q + 1] += net.pp_start[q];
  net.pp_pore.resize(net.pp_start[n]);
  net.pp_corner.resize(net.pp_start[n]);
  std::vector<Index> pfill(net.pp_start.begin(), net.pp_start.end() - 1);
  for (Index k = 0; k < np; ++k)
    for (int i = 0; i < 4; ++i) {
      if (net.pore_v[4 * k + i] >= static_cast<Index>(n)) continue;
      const Index q = pfill[net.pore_v[4 * k + i]]++;
      net.pp_pore[q] = k;
      net.pp_corner[q] = static_cast<std::uint8_t>(i);
    }
  return net;
}

void update_network_3d(Network2D& net, const Particles3D& p, const BoxWalls* walls) {
  if (net.dim != 3) throw InputError("porenet: update_network_3d needs a network from build_network_3d");
  if (p.x.size() != static_cast<std::size_t>(net.n_particles))
    throw InputError(fmt::format("porenet: {} particles for a network built on {}", p.x.size(), net.n_particles));
  if (walls && !net.n_walls) throw InputError("porenet: walls given to update a network built without them");
  if (walls) set_wall_planes(net, *walls);
  update_geometry_3d(net, p);
}

void wall_pore_void_gradient(const Network2D& net, const Particles3D& p, Index k, int corner, Real g[3]) {
  const Index* v = &net.pore_v[4 * static_cast<std::size_t>(k)];
  WallCorner q[4];
  for (int i = 0; i < 4; ++i) q[i] = corner_of(net, p, v[i]);
  g[0] = g[1] = g[2] = 0;
  if (q[corner].wall) return;
  // Central differences of max(V - solid, phi V) (the void without the relative floor); step 1e-6 R.
  const Real h = 1e-6 * q[corner].R;
  const V3 c0 = q[corner].c;
  for (int a = 0; a < 3; ++a) {
    Real val[2];
    for (int s = 0; s < 2; ++s) {
      q[corner].c = c0;
      (a == 0 ? q[corner].c.x : a == 1 ? q[corner].c.y : q[corner].c.z) += s ? h : -h;
      const WallPore w = wall_pore(q);
      val[s] = std::max(w.cell - w.solid, net.params.min_void_fraction * w.cell);
    }
    g[a] = (val[1] - val[0]) / (2 * h);
  }
}

}  // namespace ff::porenet
