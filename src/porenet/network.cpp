#include "porenet/network.hpp"

#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fmt/format.h>
#include <utility>

#include "core/error.hpp"
#include "porenet/atan2_batch.hpp"
#include "porenet/reduce.hpp"

namespace ff::porenet {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Triangulation_vertex_base_with_info_2<Index, Kernel>;
using Tds = CGAL::Triangulation_data_structure_2<Vb>;
using Delaunay = CGAL::Delaunay_triangulation_2<Kernel, Tds>;

std::int64_t gid_of(const Particles2D& p, Index n) { return p.gid.empty() ? n : p.gid[n]; }

void check_particles(const Particles2D& p) {
  const std::size_t n = p.x.size();
  if (p.y.size() != n || p.radius.size() != n || (!p.gid.empty() && p.gid.size() != n))
    throw InputError(fmt::format("porenet: particle arrays differ in length (x {}, y {}, radius {}, gid {}); "
                                 "give one entry per particle (gid may be empty)",
                                 n, p.y.size(), p.radius.size(), p.gid.size()));
  if (n < 3) throw InputError(fmt::format("porenet: {} particles; a network needs at least 3", n));
  for (std::size_t k = 0; k < n; ++k)
    if (!(p.radius[k] > 0) || !std::isfinite(p.x[k]) || !std::isfinite(p.y[k]))
      throw InputError(fmt::format("porenet: particle {} has radius {} at ({}, {}); radii must be > 0 and "
                                   "positions finite", k, p.radius[k], p.x[k], p.y[k]));
}

void check_pairs(const PairList& pr, Index n) {
  const std::size_t m = pr.i.size();
  if (pr.j.size() != m || pr.state.size() != m || pr.sigma_n.size() != m || pr.opening.size() != m)
    throw InputError("porenet: pair list arrays (i, j, state, sigma_n, opening) differ in length");
  for (std::size_t k = 0; k < m; ++k)
    if (pr.i[k] < 0 || pr.j[k] < 0 || pr.i[k] >= n || pr.j[k] >= n || pr.i[k] == pr.j[k])
      throw InputError(fmt::format("porenet: pair {} joins particles {} and {}; both must be distinct "
                                   "indices in [0, {})", k, pr.i[k], pr.j[k], n));
}

// Pore geometry from its three corners (counter-clockwise): area, void, centroid (METHODS §5.2),
// for pores [k0, k1) (at most kAngleBlock): the interior angles of the disc sectors in one vectorised
// atan2 call (libm's scalar atan2, three per pore, was the larger part of the 2D geometry update).
constexpr Index kAngleBlock = 256;
void pore_geometry(Network2D& net, const Particles2D& p, Index k0, Index k1) {
  Real ys[3 * kAngleBlock], xs[3 * kAngleBlock], theta[3 * kAngleBlock];
  for (Index k = k0; k < k1; ++k) {
    const Index* v = &net.pore_v[3 * k];
    for (int c = 0; c < 3; ++c) {
      const Index a = v[c], b = v[(c + 1) % 3], d = v[(c + 2) % 3];
      const Real ux = p.x[b] - p.x[a], uy = p.y[b] - p.y[a];
      const Real wx = p.x[d] - p.x[a], wy = p.y[d] - p.y[a];
      ys[3 * (k - k0) + c] = std::abs(ux * wy - uy * wx);  // the interior angle at corner c
      xs[3 * (k - k0) + c] = ux * wx + uy * wy;
    }
  }
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"  // the loop above fills every argument
  atan2_nonneg(ys, xs, theta, static_cast<int>(3 * (k1 - k0)));
#pragma GCC diagnostic pop
  const Real t = net.params.thickness;
  for (Index k = k0; k < k1; ++k) {
    const Index* v = &net.pore_v[3 * k];
    Real solid = 0;
    for (int c = 0; c < 3; ++c) solid += 0.5 * theta[3 * (k - k0) + c] * p.radius[v[c]] * p.radius[v[c]];  // sectors
    const Real area = 0.5 * ((p.x[v[1]] - p.x[v[0]]) * (p.y[v[2]] - p.y[v[0]]) -
                             (p.y[v[1]] - p.y[v[0]]) * (p.x[v[2]] - p.x[v[0]]));
    net.pore_area[k] = area;
    net.pore_cell[k] = area * t;
    // Overlapping discs count their lens twice: floor the void at a fraction of the cell.
    net.pore_void[k] = std::max(area - solid, net.params.min_void_fraction * area) * t;
    net.pore_cx[k] = (p.x[v[0]] + p.x[v[1]] + p.x[v[2]]) / 3;
    net.pore_cy[k] = (p.y[v[0]] + p.y[v[1]] + p.y[v[2]]) / 3;
  }
}

void channel_geometry(Network2D& net, const Particles2D& p, const PairList& pairs, Index c) {
  const Index pa = net.ch_pore[2 * c], pb = net.ch_pore[2 * c + 1];
  const Index a = net.ch_part[2 * c], b = net.ch_part[2 * c + 1];
  const Real lx = net.pore_cx[pb] - net.pore_cx[pa], ly = net.pore_cy[pb] - net.pore_cy[pa];
  const Real ex = p.x[b] - p.x[a], ey = p.y[b] - p.y[a];
  const Real e = length_2d(ex, ey);
  const Real l = length_2d(lx, ly);
  // A vanishing centre line (degenerate pair of triangles) would give infinite conductance.
  const Real L = std::max(l, 1e-3 * e);
  const Real sin_omega = l > 0 ? std::abs(ex * ly - ey * lx) / (e * l) : 1.0;
  net.ch_length[c] = L;
  net.ch_edge[c] = e;
  net.ch_sin_omega[c] = sin_omega;
  const NetworkParams& q = net.params;
  Real h;
  const Index k = net.ch_pair[c];
  if (k >= 0) {
    h = aperture_b1(q, pairs.state[k], pairs.sigma_n[k], pairs.opening[k]);
  } else {
    const Real len = q.b2_edge == B2Edge::Centre ? e : std::max(e - p.radius[a] - p.radius[b], Real(0));
    h = q.b2_gamma * len * sin_omega;  // Eq. B2, cos(90° - omega) = sin(omega)
  }
  h = std::max(h, q.min_aperture);
  net.ch_aperture[c] = h;
  net.ch_cond[c] = h * h * h * q.thickness / (12 * L);  // cubic law, METHODS §5.3b
}

}  // namespace

Real aperture_b1(const NetworkParams& p, PairState state, Real sigma_n, Real opening) {
  // Eq. B1; an open crack carries its opening on top of the stress-free aperture of its faces.
  const Real s = std::max(sigma_n, Real(0));
  Real h = p.b1_beta * (p.b1_h_inf + (p.b1_h0 - p.b1_h_inf) * std::exp(-p.b1_stress_coeff * s));
  if (state == PairState::BrokenBond) h += std::max(opening, Real(0));
  return h;
}

Network2D build_network_2d(const Particles2D& p, const PairList& pairs, const NetworkParams& params) {
  check_particles(p);
  const Index n = static_cast<Index>(p.x.size());
  check_pairs(pairs, n);
  if (!(params.thickness > 0) || params.min_void_fraction < 0 || params.min_void_fraction >= 1 ||
      params.b1_h0 < 0 || params.b1_h_inf < 0 || params.b2_gamma < 0 || params.min_aperture < 0)
    throw InputError("porenet: network parameters out of range (thickness > 0, 0 <= min_void_fraction < 1, "
                     "apertures and gamma >= 0)");
  Network2D net;
  net.params = params;
  net.n_particles = n;

  std::vector<std::pair<Kernel::Point_2, Index>> pts(static_cast<std::size_t>(n));
  for (Index k = 0; k < n; ++k) pts[static_cast<std::size_t>(k)] = {Kernel::Point_2(p.x[k], p.y[k]), k};
  Delaunay dt;
  dt.insert(pts.begin(), pts.end());
  if (static_cast<Index>(dt.number_of_vertices()) != n)
    throw InputError(fmt::format("porenet: {} particles but {} distinct centres; particles must not share a centre",
                                 n, dt.number_of_vertices()));
  if (dt.dimension() < 2) throw InputError("porenet: all particle centres are collinear; no pore can be formed");

  // Faces as corner triples, rotated so the smallest global id comes first (orientation kept).
  struct Face {
    std::array<std::int64_t, 3> key;
    std::array<Index, 3> v;
  };
  std::vector<Face> faces;
  faces.reserve(dt.number_of_faces());
  for (auto f = dt.finite_faces_begin(); f != dt.finite_faces_end(); ++f) {
    std::array<Index, 3> v{f->vertex(0)->info(), f->vertex(1)->info(), f->vertex(2)->info()};
    int first = 0;
    for (int c = 1; c < 3; ++c)
      if (gid_of(p, v[c]) < gid_of(p, v[first])) first = c;
    std::rotate(v.begin(), v.begin() + first, v.end());
    std::array<std::int64_t, 3> key{gid_of(p, v[0]), gid_of(p, v[1]), gid_of(p, v[2])};
    std::sort(key.begin(), key.end());
    faces.push_back({key, v});
  }
  std::sort(faces.begin(), faces.end(), [](const Face& a, const Face& b) { return a.key < b.key; });
  for (std::size_t k = 1; k < faces.size(); ++k)
    if (faces[k].key == faces[k - 1].key)
      throw InputError("porenet: repeated global particle ids (gid); give each particle a unique id");
  const Index np = static_cast<Index>(faces.size());
  net.pore_v.resize(3 * static_cast<std::size_t>(np));
  for (Index k = 0; k < np; ++k)
    for (int c = 0; c < 3; ++c) net.pore_v[3 * k + c] = faces[k].v[c];
  net.pore_area.resize(np);
  net.pore_cell.resize(np);
  net.pore_void.resize(np);
  net.pore_cx.resize(np);
  net.pore_cy.resize(np);
  net.pore_hull.assign(np, 0);

  // Edges: (gid pair, particle pair, pore). Two entries with one key = one channel.
  struct EdgeRef {
    std::int64_t g0, g1;
    Index a, b, pore;
  };
  std::vector<EdgeRef> edges;
  edges.reserve(3 * static_cast<std::size_t>(np));
  for (Index k = 0; k < np; ++k)
    for (int c = 0; c < 3; ++c) {
      Index a = net.pore_v[3 * k + (c + 1) % 3], b = net.pore_v[3 * k + (c + 2) % 3];
      if (gid_of(p, b) < gid_of(p, a)) std::swap(a, b);
      edges.push_back({gid_of(p, a), gid_of(p, b), a, b, k});
    }
  std::sort(edges.begin(), edges.end(), [](const EdgeRef& x, const EdgeRef& y) {
    return std::tie(x.g0, x.g1, x.pore) < std::tie(y.g0, y.g1, y.pore);
  });

  // Pairs by sorted global-id key, for matching contact/bond channels.
  struct PairKey {
    std::int64_t g0, g1;
    Index k;
  };
  std::vector<PairKey> pkeys(pairs.size());
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    std::int64_t g0 = gid_of(p, pairs.i[k]), g1 = gid_of(p, pairs.j[k]);
    if (g1 < g0) std::swap(g0, g1);
    pkeys[k] = {g0, g1, static_cast<Index>(k)};
  }
  std::sort(pkeys.begin(), pkeys.end(),
            [](const PairKey& x, const PairKey& y) { return std::tie(x.g0, x.g1) < std::tie(y.g0, y.g1); });
  for (std::size_t k = 1; k < pkeys.size(); ++k)
    if (pkeys[k].g0 == pkeys[k - 1].g0 && pkeys[k].g1 == pkeys[k - 1].g1)
      throw InputError(fmt::format("porenet: pairs {} and {} join the same two particles; list each contact or "
                                   "bond once", pkeys[k - 1].k, pkeys[k].k));
  Index matched = 0;
  for (std::size_t e = 0; e < edges.size();) {
    const bool shared = e + 1 < edges.size() && edges[e + 1].g0 == edges[e].g0 && edges[e + 1].g1 == edges[e].g1;
    if (!shared) {
      net.pore_hull[edges[e].pore] = 1;
      e += 1;
      continue;
    }
    net.ch_pore.push_back(edges[e].pore);
    net.ch_pore.push_back(edges[e + 1].pore);
    net.ch_part.push_back(edges[e].a);
    net.ch_part.push_back(edges[e].b);
    auto it = std::lower_bound(pkeys.begin(), pkeys.end(), edges[e], [](const PairKey& x, const EdgeRef& y) {
      return std::tie(x.g0, x.g1) < std::tie(y.g0, y.g1);
    });
    const bool is_pair = it != pkeys.end() && it->g0 == edges[e].g0 && it->g1 == edges[e].g1;
    net.ch_pair.push_back(is_pair ? it->k : -1);
    net.ch_kind.push_back(is_pair ? ChannelKind::S2S : ChannelKind::T2T);
    matched += is_pair ? 1 : 0;
    e += 2;
  }
  // Hull edges can carry a contact too; count only the pairs without any Delaunay channel.
  net.n_pairs = static_cast<Index>(pairs.size());
  net.unmatched_pairs = net.n_pairs - matched;
  const Index nc = static_cast<Index>(net.ch_pair.size());
  net.ch_length.resize(nc);
  net.ch_edge.resize(nc);
  net.ch_sin_omega.resize(nc);
  net.ch_aperture.resize(nc);
  net.ch_cond.resize(nc);

  // CSR pore -> channels (channel ids ascending within a pore).
  net.pc_start.assign(np + 1, 0);
  for (Index c = 0; c < nc; ++c) {
    ++net.pc_start[net.ch_pore[2 * c] + 1];
    ++net.pc_start[net.ch_pore[2 * c + 1] + 1];
  }
  for (Index k = 0; k < np; ++k) net.pc_start[k + 1] += net.pc_start[k];
  net.pc_ch.resize(net.pc_start[np]);
  {
    std::vector<Index> fill(net.pc_start.begin(), net.pc_start.end() - 1);
    for (Index c = 0; c < nc; ++c) {
      net.pc_ch[fill[net.ch_pore[2 * c]]++] = c;
      net.pc_ch[fill[net.ch_pore[2 * c + 1]]++] = c;
    }
  }
  // CSR particle -> (pore, corner), pores ascending.
  net.pp_start.assign(n + 1, 0);
  for (Index k = 0; k < 3 * np; ++k) ++net.pp_start[net.pore_v[k] + 1];
  for (Index k = 0; k < n; ++k) net.pp_start[k + 1] += net.pp_start[k];
  net.pp_pore.resize(3 * np);
  net.pp_corner.resize(3 * np);
  {
    std::vector<Index> fill(net.pp_start.begin(), net.pp_start.end() - 1);
    for (Index k = 0; k < np; ++k)
      for (int c = 0; c < 3; ++c) {
        const Index slot = fill[net.pore_v[3 * k + c]]++;
        net.pp_pore[slot] = k;
        net.pp_corner[slot] = static_cast<std::uint8_t>(c);
      }
  }
  // CSR particle -> channels walled by it.
  net.pw_start.assign(n + 1, 0);
  for (Index c = 0; c < 2 * nc; ++c) ++net.pw_start[net.ch_part[c] + 1];
  for (Index k = 0; k < n; ++k) net.pw_start[k + 1] += net.pw_start[k];
  net.pw_ch.resize(2 * nc);
  {
    std::vector<Index> fill(net.pw_start.begin(), net.pw_start.end() - 1);
    for (Index c = 0; c < nc; ++c) {
      net.pw_ch[fill[net.ch_part[2 * c]]++] = c;
      net.pw_ch[fill[net.ch_part[2 * c + 1]]++] = c;
    }
  }
  update_network_2d(net, p, pairs);
  return net;
}

void update_network_2d(Network2D& net, const Particles2D& p, const PairList& pairs) {
  if (net.dim != 2) throw InputError("porenet: update_network_2d called on a 3D network");
  if (static_cast<Index>(p.x.size()) != net.n_particles)
    throw InputError(fmt::format("porenet: update with {} particles, network built with {}", p.x.size(),
                                 net.n_particles));
  if (static_cast<Index>(pairs.size()) != net.n_pairs || pairs.sigma_n.size() != pairs.size() ||
      pairs.opening.size() != pairs.size() || pairs.state.size() != pairs.size())
    throw InputError(fmt::format("porenet: update with {} pairs, network built with {}; pass the same pair list "
                                 "(same order) with updated states", pairs.size(), net.n_pairs));
  const Index np = net.n_pores(), nc = net.n_channels();
  const Index nb = (np + kAngleBlock - 1) / kAngleBlock;
#pragma omp parallel for schedule(static) if (np > kParallelMin)
  for (Index b = 0; b < nb; ++b) pore_geometry(net, p, b * kAngleBlock, std::min(np, (b + 1) * kAngleBlock));
  Real mean_cell = 0;  // serial: a fixed-order sum
  for (Index k = 0; k < np; ++k) mean_cell += net.pore_cell[k];
  mean_cell /= static_cast<Real>(np);
  const Real floor_v = net.params.min_void_relative * mean_cell;
  net.void_floor = floor_v;
  for (Index k = 0; k < np; ++k) net.pore_void[k] = std::max(net.pore_void[k], floor_v);
#pragma omp parallel for schedule(static) if (nc > kParallelMin)
  for (Index c = 0; c < nc; ++c) channel_geometry(net, p, pairs, c);
}

}  // namespace ff::porenet
