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

// The geometry runs over blocks of facets or pores: a first loop gathers the atan2 arguments of the
// block, atan2_nonneg evaluates them in one vectorised call, a second loop uses the angles.
constexpr Index kGeometryBlock = 128;

// Facets [f0, f1): each one's angle at its corners, its unit normal and, for a throat, the fluid area
// and hydraulic radius (ch_aperture = 2 R_h; ch_cond = pfv_factor A_f R_h^2 until
// throat_conductance_3d divides by 2 L). The pressure forces read the angles and normals (forces.cpp),
// so each is computed once a step.
void facet_geometry_3d(Network2D& net, const Particles3D& p, Index f0, Index f1) {
  auto pos = [&](Index i) { return V3{p.x[i], p.y[i], p.z[i]}; };
  Real ys[3 * kGeometryBlock] = {}, xs[3 * kGeometryBlock] = {}, area[kGeometryBlock];
  for (Index f = f0; f < f1; ++f) {
    const Index* v = net.facet_corners(f);
    const V3 A = pos(v[0]), B = pos(v[1]), C = pos(v[2]);
    const V3 N = cross(sub(B, A), sub(C, A));
    const Real len = norm(N);
    area[f - f0] = 0.5 * len;
    const Real inv = len > 0 ? 1 / len : 0;
    Real* n = &net.face_normal[3 * static_cast<std::size_t>(f)];
    n[0] = N.x * inv;
    n[1] = N.y * inv;
    n[2] = N.z * inv;
    for (int j = 0; j < 3; ++j) {  // the angle at corner j: atan2(|u x w|, u . w)
      const V3 o = pos(v[j]);
      const V3 u = sub(pos(v[(j + 1) % 3]), o), w = sub(pos(v[(j + 2) % 3]), o);
      ys[3 * (f - f0) + j] = norm(cross(u, w));
      xs[3 * (f - f0) + j] = dot(u, w);
    }
  }
  Real* th = &net.face_angle[3 * static_cast<std::size_t>(f0)];
  atan2_nonneg(ys, xs, th, static_cast<int>(3 * (f1 - f0)));
  for (Index f = f0; f < std::min(f1, net.n_channels()); ++f) {
    const Index* v = net.facet_corners(f);
    Real solid = 0, perim = 0;
    for (int j = 0; j < 3; ++j) {
      const Real R = p.radius[v[j]];
      solid += 0.5 * th[3 * (f - f0) + j] * R * R;
      perim += th[3 * (f - f0) + j] * R;
    }
    const Real af = std::max(area[f - f0] - solid, net.params.min_void_fraction * area[f - f0]);
    const Real rh = af / perim;
    net.ch_aperture[f] = 2 * rh;
    net.ch_cond[f] = net.pfv_factor * af * rh * rh;
  }
}

// Pores [k0, k1): volume, void (METHODS §5.2; the floors), centroid, and which of the pore's facets'
// normals point into it (after facet_geometry_3d). The solid angle at corner i is Omega_i =
// 2 atan2(|u . (v x w)|, |u||v||w| + (u.v)|w| + (u.w)|v| + (v.w)|u|) with u, v, w the edges from it
// (Van Oosterom & Strackee 1983, IEEE Trans. Biomed. Eng. 30:125).
void pore_geometry_3d(Network2D& net, const Particles3D& p, Index k0, Index k1) {
  auto pos = [&](Index i) { return V3{p.x[i], p.y[i], p.z[i]}; };
  Real ys[4 * kGeometryBlock] = {}, xs[4 * kGeometryBlock] = {}, half[4 * kGeometryBlock], vol[kGeometryBlock];
  for (Index k = k0; k < k1; ++k) {
    const Index* v = &net.pore_v[4 * static_cast<std::size_t>(k)];
    std::uint8_t in = 0;
    for (int i = 0; i < 4; ++i) {
      const V3 o = pos(v[i]);
      const V3 u = sub(pos(v[(i + 1) % 4]), o), w = sub(pos(v[(i + 2) % 4]), o), s = sub(pos(v[(i + 3) % 4]), o);
      const Real lu = norm(u), lw = norm(w), ls = norm(s);
      ys[4 * (k - k0) + i] = std::abs(dot(u, cross(w, s)));
      xs[4 * (k - k0) + i] = lu * lw * ls + dot(u, w) * ls + dot(u, s) * lw + dot(w, s) * lu;
      const Index f = net.pore_face[4 * static_cast<std::size_t>(k) + i];
      const Real* n = &net.face_normal[3 * static_cast<std::size_t>(f)];
      const V3 d = sub(o, pos(net.facet_corners(f)[0]));  // towards the corner opposite the facet
      if (n[0] * d.x + n[1] * d.y + n[2] * d.z > 0) in |= static_cast<std::uint8_t>(1u << i);
    }
    const V3 a = pos(v[0]);
    vol[k - k0] = std::abs(dot(sub(pos(v[1]), a), cross(sub(pos(v[2]), a), sub(pos(v[3]), a)))) / 6;
    net.pore_cx[k] = 0.25 * (p.x[v[0]] + p.x[v[1]] + p.x[v[2]] + p.x[v[3]]);
    net.pore_cy[k] = 0.25 * (p.y[v[0]] + p.y[v[1]] + p.y[v[2]] + p.y[v[3]]);
    net.pore_cz[k] = 0.25 * (p.z[v[0]] + p.z[v[1]] + p.z[v[2]] + p.z[v[3]]);
    net.pore_face_in[k] = in;
  }
  atan2_nonneg(ys, xs, half, static_cast<int>(4 * (k1 - k0)));
  for (Index k = k0; k < k1; ++k) {
    const Index* v = &net.pore_v[4 * static_cast<std::size_t>(k)];
    Real solid = 0;
    for (int i = 0; i < 4; ++i) {
      const Real R = p.radius[v[i]];
      solid += 2 * half[4 * (k - k0) + i] * R * R * R / 3;  // sphere sector inside the tetrahedron
    }
    const Real V = vol[k - k0];
    net.pore_cell[k] = V;
    net.pore_void[k] = std::max(std::max(V - solid, net.params.min_void_fraction * V), net.void_floor);
  }
}

// Throat c (after facet_geometry_3d and the pores' centroids): length and unclamped conductance
// g mu = pfv_factor A_f R_h^2 / (2 L) (Chareyre et al. 2012).
void throat_conductance_3d(Network2D& net, const Particles3D& p, Index c) {
  const Index* v = &net.ch_part[3 * static_cast<std::size_t>(c)];
  const Index pa = net.ch_pore[2 * c], pb = net.ch_pore[2 * c + 1];
  const V3 d{net.pore_cx[pb] - net.pore_cx[pa], net.pore_cy[pb] - net.pore_cy[pa], net.pore_cz[pb] - net.pore_cz[pa]};
  // Adjacent slivers have almost coincident centroids: L at least a tenth of the mean radius.
  const Real L = std::max(norm(d), 0.1 * (p.radius[v[0]] + p.radius[v[1]] + p.radius[v[2]]) / 3);
  net.ch_length[c] = L;
  net.ch_cond[c] = std::min(net.ch_cond[c] / (2 * L), net.ch_cond_cap);
}

// The three passes of a geometry update, each parallel over its items.
void update_geometry_3d(Network2D& net, const Particles3D& p) {
  const Index nf = net.n_facets(), np = net.n_pores();
#pragma omp parallel for schedule(static) if (nf > kParallelMin)
  for (Index b = 0; b < (nf + kGeometryBlock - 1) / kGeometryBlock; ++b)
    facet_geometry_3d(net, p, b * kGeometryBlock, std::min(nf, (b + 1) * kGeometryBlock));
#pragma omp parallel for schedule(static) if (np > kParallelMin)
  for (Index b = 0; b < (np + kGeometryBlock - 1) / kGeometryBlock; ++b)
    pore_geometry_3d(net, p, b * kGeometryBlock, std::min(np, (b + 1) * kGeometryBlock));
#pragma omp parallel for schedule(static) if (net.n_channels() > kParallelMin)
  for (Index c = 0; c < net.n_channels(); ++c) throat_conductance_3d(net, p, c);
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
    int face;  // the pore's corner opposite the facet
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
      f.face = i;
      facets.push_back(f);
    }
  std::sort(facets.begin(), facets.end(),
            [](const Facet& a, const Facet& b) { return std::tie(a.key, a.pore) < std::tie(b.key, b.pore); });
  net.pore_hull.assign(np, 0);
  net.pore_face.assign(4 * static_cast<std::size_t>(np), -1);
  std::vector<std::size_t> hull_facets;
  for (std::size_t e = 0; e < facets.size();) {
    if (e + 1 < facets.size() && facets[e + 1].key == facets[e].key) {
      const Index c = static_cast<Index>(net.ch_pore.size() / 2);
      net.ch_pore.push_back(facets[e].pore);
      net.ch_pore.push_back(facets[e + 1].pore);
      for (int j = 0; j < 3; ++j) net.ch_part.push_back(facets[e].v[j]);
      net.ch_kind.push_back(ChannelKind::T2T);
      net.ch_pair.push_back(-1);
      net.pore_face[4 * static_cast<std::size_t>(facets[e].pore) + facets[e].face] = c;
      net.pore_face[4 * static_cast<std::size_t>(facets[e + 1].pore) + facets[e + 1].face] = c;
      e += 2;
    } else {
      net.pore_hull[facets[e].pore] = 1;
      hull_facets.push_back(e);
      e += 1;
    }
  }
  const Index nc = static_cast<Index>(net.ch_pore.size() / 2);
  for (std::size_t h = 0; h < hull_facets.size(); ++h) {
    const Facet& f = facets[hull_facets[h]];
    for (int j = 0; j < 3; ++j) net.hull_part.push_back(f.v[j]);
    net.hull_pore.push_back(f.pore);
    net.pore_face[4 * static_cast<std::size_t>(f.pore) + f.face] = nc + static_cast<Index>(h);
  }
  net.pore_face_slot.assign(np, 0);
  for (Index k = 0; k < np; ++k)
    for (int i = 0; i < 4; ++i) {
      const Index f = net.pore_face[4 * static_cast<std::size_t>(k) + i];
      const Index* fv = f < nc ? &net.ch_part[3 * static_cast<std::size_t>(f)] : &net.hull_part[3 * static_cast<std::size_t>(f - nc)];
      for (int c = 0; c < 4; ++c) {
        if (c == i) continue;
        const Index j = net.pore_v[4 * static_cast<std::size_t>(k) + c];
        const std::uint32_t slot = fv[0] == j ? 0u : fv[1] == j ? 1u : 2u;
        net.pore_face_slot[k] |= slot << (2 * (4 * i + c));
      }
    }
  // Geometry: pores, throats, facet angles and normals (as each update), then the floors.
  net.pore_area.assign(np, 0);
  net.pore_cell.resize(np);
  net.pore_void.resize(np);
  net.pore_cx.resize(np);
  net.pore_cy.resize(np);
  net.pore_cz.resize(np);
  net.pore_face_in.assign(np, 0);
  net.ch_length.assign(nc, 0);
  net.ch_aperture.assign(nc, 0);
  net.ch_cond.assign(nc, 0);
  net.face_angle.assign(3 * static_cast<std::size_t>(net.n_facets()), 0);
  net.face_normal.assign(3 * static_cast<std::size_t>(net.n_facets()), 0);
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
