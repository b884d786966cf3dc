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
    const Index* v = &net.pore_v[4 * static_cast<std::size_t>(k)];
    V3 c[4];
    for (int i = 0; i < 4; ++i) c[i] = V3{p.x[v[i]], p.y[v[i]], p.z[v[i]]};
    Real* y = &ys[kArgs * (k - k0)];
    Real* x = &xs[kArgs * (k - k0)];
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

// Throats [c0, c1) (after the pores' centroids): fluid area A_f = A - sum_k theta_k R_k^2 / 2,
// hydraulic radius R_h = A_f / sum_k theta_k R_k (ch_aperture = 2 R_h), length L
// and conductance g mu = pfv_factor A_f R_h^2 / (2 L) (Chareyre et al. 2012), clamped; L the distance
// between the pores' power centres.
void throat_geometry_3d(Network2D& net, const Particles3D& p, Index c0, Index c1) {
  auto pos = [&](Index i) { return V3{p.x[i], p.y[i], p.z[i]}; };
  Real ys[2 * kGeometryBlock], xs[2 * kGeometryBlock], th[2 * kGeometryBlock], area[kGeometryBlock];
  for (Index c = c0; c < c1; ++c) {
    const Index* v = &net.ch_part[3 * static_cast<std::size_t>(c)];
    const V3 A = pos(v[0]), B = pos(v[1]), C = pos(v[2]);
    const Real twice_area = norm(cross(sub(B, A), sub(C, A)));  // |u x w| at every corner
    area[c - c0] = 0.5 * twice_area;
    for (int j = 0; j < 2; ++j) {  // the angle at corner j: atan2(|u x w|, u . w); at corner 2 pi minus both
      const V3 o = pos(v[j]);
      ys[2 * (c - c0) + j] = twice_area;
      xs[2 * (c - c0) + j] = dot(sub(pos(v[(j + 1) % 3]), o), sub(pos(v[(j + 2) % 3]), o));
    }
  }
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"  // the loop above fills every argument
  atan2_nonneg(ys, xs, th, static_cast<int>(2 * (c1 - c0)));
#pragma GCC diagnostic pop
  for (Index c = c0; c < c1; ++c) {
    const Index* v = &net.ch_part[3 * static_cast<std::size_t>(c)];
    const Real angle[3] = {th[2 * (c - c0)], th[2 * (c - c0) + 1], kPi - th[2 * (c - c0)] - th[2 * (c - c0) + 1]};
    Real solid = 0, perim = 0;
    for (int j = 0; j < 3; ++j) {
      const Real R = p.radius[v[j]];
      solid += 0.5 * angle[j] * R * R;
      perim += angle[j] * R;
    }
    const Real af = std::max(area[c - c0] - solid, net.params.min_void_fraction * area[c - c0]);
    const Real rh = af / perim;
    const Index pa = net.ch_pore[2 * c], pb = net.ch_pore[2 * c + 1];
    // L between the pores' power centres, as PFV (Chareyre et al. 2012): the centroids' distance gave
    // 5-9 x Kozeny-Carman's permeability on random packings (docs/porenet.md section 9).
    const V3 d{net.pore_px[pb] - net.pore_px[pa], net.pore_py[pb] - net.pore_py[pa], net.pore_pz[pb] - net.pore_pz[pa]};
    // Two tetrahedra with almost coincident power centres are halves of one pore body, not a throat of
    // length ~0: L at least a quarter of the facet's mean radius. The packings' permeability does not see
    // the floor (k/k_KC 1.50 / 2.11 / 1.37 with it, 1.51 / 2.11 / 1.38 at a tenth of the radius; hull pores
    // then on their power centres too), but the two-phase transport step does: a tenth made such throats
    // 2.5x more conductive and the implicit steps halved 2.7x more often
    // (SaturatedUcs3D.SmallestPoresFirstDrainedStepsWithoutHalving).
    const Real L = std::max(norm(d), 0.25 * (p.radius[v[0]] + p.radius[v[1]] + p.radius[v[2]]) / 3);
    net.ch_length[c] = L;
    net.ch_aperture[c] = 2 * rh;
    net.ch_cond[c] = std::min(net.pfv_factor * af * rh * rh / (2 * L), net.ch_cond_cap);
    // Wall shear tau = R_h dp / L over the wetted wall (perimeter x L): A_f dp in all, each sphere its
    // wetted arc's share (add_shear_forces_3d).
    for (int j = 0; j < 3; ++j)
      net.ch_shear[3 * static_cast<std::size_t>(c) + j] = perim > 0 ? af * angle[j] * p.radius[v[j]] / perim : 0.0;
  }
}

// A geometry update: the pores, then the throats (they need the pores' centroids), each parallel over
// blocks.
void update_geometry_3d(Network2D& net, const Particles3D& p) {
  const Index np = net.n_pores(), nc = net.n_channels();
#pragma omp parallel for schedule(static) if (np > kParallelMin)
  for (Index b = 0; b < (np + kGeometryBlock - 1) / kGeometryBlock; ++b)
    pore_geometry_3d(net, p, b * kGeometryBlock, std::min(np, (b + 1) * kGeometryBlock));
#pragma omp parallel for schedule(static) if (nc > kParallelMin)
  for (Index b = 0; b < (nc + kGeometryBlock - 1) / kGeometryBlock; ++b)
    throat_geometry_3d(net, p, b * kGeometryBlock, std::min(nc, (b + 1) * kGeometryBlock));
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

}  // namespace

Network2D build_network_3d(const Particles3D& p, const NetworkParams& params, Real pfv_factor) {
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
  Regular rt;
  rt.insert(pts.begin(), pts.end());
  if (rt.dimension() < 3) throw InputError("porenet: the sphere centres are coplanar; no 3D pore can be formed");
  net.hidden_particles = static_cast<Index>(n) - static_cast<Index>(rt.number_of_vertices());

  struct Cell {
    std::array<std::int64_t, 4> key;
    std::array<Index, 4> v;
  };
  std::vector<Cell> cells;
  cells.reserve(rt.number_of_finite_cells());
  for (auto c = rt.finite_cells_begin(); c != rt.finite_cells_end(); ++c) {
    Cell cl;
    for (int i = 0; i < 4; ++i) cl.v[i] = c->vertex(i)->info();
    for (int i = 0; i < 4; ++i) cl.key[i] = gid(cl.v[i]);
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
      std::sort(f.v.begin(), f.v.end(), [&](Index a, Index b) { return gid(a) < gid(b); });
      for (int j = 0; j < 3; ++j) f.key[j] = gid(f.v[j]);
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
    for (int i = 0; i < 4; ++i) ++net.pp_start[net.pore_v[4 * k + i] + 1];
  for (std::size_t q = 0; q < n; ++q) net.pp_start[q + 1] += net.pp_start[q];
  net.pp_pore.resize(net.pp_start[n]);
  net.pp_corner.resize(net.pp_start[n]);
  std::vector<Index> pfill(net.pp_start.begin(), net.pp_start.end() - 1);
  for (Index k = 0; k < np; ++k)
    for (int i = 0; i < 4; ++i) {
      const Index q = pfill[net.pore_v[4 * k + i]]++;
      net.pp_pore[q] = k;
      net.pp_corner[q] = static_cast<std::uint8_t>(i);
    }
  return net;
}

void update_network_3d(Network2D& net, const Particles3D& p) {
  if (net.dim != 3) throw InputError("porenet: update_network_3d needs a network from build_network_3d");
  if (p.x.size() != static_cast<std::size_t>(net.n_particles))
    throw InputError(fmt::format("porenet: {} particles for a network built on {}", p.x.size(), net.n_particles));
  update_geometry_3d(net, p);
}

}  // namespace ff::porenet
