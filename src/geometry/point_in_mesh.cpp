#include "geometry/point_in_mesh.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "core/error.hpp"
#include "geometry/stl.hpp"

namespace ff::geom {

// One ray direction: projected vertex coordinates and the 2D bins of the triangle shadows.
struct RayGrid {
  Vec3 e1, e2, d;                   // (e1, e2) span the projection plane, d is the ray direction
  std::vector<Real> u, v, w;        // per vertex: plane coordinates and depth along d
  Real u0 = 0, v0 = 0, inv_cell = 1;  // grid origin and 1 / cell size
  int nu = 1, nv = 1;
  std::vector<int> start;           // CSR: triangles of cell c are tri[start[c] .. start[c+1])
  std::vector<int> tri;

  int cell_u(Real x) const { return std::clamp(static_cast<int>(std::floor((x - u0) * inv_cell)), 0, nu - 1); }
  int cell_v(Real y) const { return std::clamp(static_cast<int>(std::floor((y - v0) * inv_cell)), 0, nv - 1); }
};

struct MeshRegion::Data {
  TriangleMesh mesh;
  std::string name;
  Aabb box;
  std::array<RayGrid, 3> rays;
};

namespace {

RayGrid build_ray_grid(const TriangleMesh& mesh, const Vec3& dir) {
  RayGrid g;
  g.d = dir.normalized();
  g.e1 = g.d.unitOrthogonal();
  g.e2 = g.d.cross(g.e1);
  const std::size_t nvert = mesh.vertices.size();
  g.u.resize(nvert);
  g.v.resize(nvert);
  g.w.resize(nvert);
  Real umin = INFINITY, umax = -INFINITY, vmin = INFINITY, vmax = -INFINITY;
  for (std::size_t i = 0; i < nvert; ++i) {
    const Vec3& x = mesh.vertices[i];
    g.u[i] = x.dot(g.e1);
    g.v[i] = x.dot(g.e2);
    g.w[i] = x.dot(g.d);
    umin = std::min(umin, g.u[i]);
    umax = std::max(umax, g.u[i]);
    vmin = std::min(vmin, g.v[i]);
    vmax = std::max(vmax, g.v[i]);
  }
  // About one cell per triangle: a ray then meets a handful of candidate shadows.
  const Real du = std::max(umax - umin, Real(1e-300)), dv = std::max(vmax - vmin, Real(1e-300));
  const Real ntri = static_cast<Real>(mesh.triangles.size());
  const Real cell = std::max(std::sqrt(du * dv / ntri), std::max(du, dv) / 2048.0);
  g.u0 = umin;
  g.v0 = vmin;
  g.inv_cell = 1.0 / cell;
  g.nu = std::max(1, static_cast<int>(std::ceil(du / cell)));
  g.nv = std::max(1, static_cast<int>(std::ceil(dv / cell)));
  const std::size_t ncell = static_cast<std::size_t>(g.nu) * g.nv;
  g.start.assign(ncell + 1, 0);
  auto for_cells = [&](const std::array<int, 3>& t, auto&& fn) {
    const Real tu0 = std::min({g.u[t[0]], g.u[t[1]], g.u[t[2]]}), tu1 = std::max({g.u[t[0]], g.u[t[1]], g.u[t[2]]});
    const Real tv0 = std::min({g.v[t[0]], g.v[t[1]], g.v[t[2]]}), tv1 = std::max({g.v[t[0]], g.v[t[1]], g.v[t[2]]});
    for (int j = g.cell_v(tv0); j <= g.cell_v(tv1); ++j) {
      for (int i = g.cell_u(tu0); i <= g.cell_u(tu1); ++i) fn(static_cast<std::size_t>(j) * g.nu + i);
    }
  };
  for (const auto& t : mesh.triangles) for_cells(t, [&](std::size_t c) { ++g.start[c + 1]; });
  for (std::size_t c = 0; c < ncell; ++c) g.start[c + 1] += g.start[c];
  g.tri.resize(g.start[ncell]);
  std::vector<int> fill(g.start.begin(), g.start.end() - 1);
  for (std::size_t k = 0; k < mesh.triangles.size(); ++k) {
    for_cells(mesh.triangles[k], [&](std::size_t c) { g.tri[fill[c]++] = static_cast<int>(k); });
  }
  return g;
}

// Top-left rule for an edge direction (du, dv) that has the triangle's interior on its left: it
// assigns a point exactly on an edge (or vertex) to the triangles on one side only, as if the point
// were shifted by (+e, +e^2) (simulation of simplicity).
inline bool top_left(Real du, Real dv) { return dv < 0 || (dv == 0 && du > 0); }

// Parity of the crossings of the ray p + t d (t > 0) with the surface.
bool odd_crossings(const TriangleMesh& mesh, const RayGrid& g, const Vec3& p) {
  const Real pu = p.dot(g.e1), pv = p.dot(g.e2), pw = p.dot(g.d);
  if (pu < g.u0 || pv < g.v0 || pu > g.u0 + g.nu / g.inv_cell || pv > g.v0 + g.nv / g.inv_cell) return false;
  const std::size_t c = static_cast<std::size_t>(g.cell_v(pv)) * g.nu + g.cell_u(pu);
  bool odd = false;
  for (int k = g.start[c]; k < g.start[c + 1]; ++k) {
    const auto& t = mesh.triangles[g.tri[k]];
    // Corners relative to the query (Woop et al. 2013): every triangle sees the same rounded
    // offsets of a shared vertex, and e[m] = a x b is exactly antisymmetric in (a, b), so the two
    // triangles of an edge, and the fan of a vertex, agree on which side the query lies.
    Real a_u[3], a_v[3];
    for (int m = 0; m < 3; ++m) {
      a_u[m] = g.u[t[m]] - pu;
      a_v[m] = g.v[t[m]] - pv;
    }
    Real e[3];  // e[m]: twice the signed area of (query, corner m, corner m+1)
    for (int m = 0; m < 3; ++m) {
      const int n = (m + 1) % 3;
      e[m] = a_u[m] * a_v[n] - a_v[m] * a_u[n];
    }
    const Real area2 = e[0] + e[1] + e[2];  // projected area (sign = orientation)
    if (area2 == 0) continue;               // seen edge-on: its neighbours carry the crossing
    const Real s = area2 > 0 ? 1.0 : -1.0;
    bool inside = true;
    for (int m = 0; m < 3 && inside; ++m) {
      const Real em = s * e[m];
      if (em < 0) {
        inside = false;
      } else if (em == 0) {
        const int n = (m + 1) % 3;
        inside = top_left(s * (a_u[n] - a_u[m]), s * (a_v[n] - a_v[m]));
      }
    }
    if (!inside) continue;
    // Depth of the crossing by barycentric interpolation; the weight of corner m is the area
    // opposite to it.
    const Real w_hit = (e[1] * g.w[t[0]] + e[2] * g.w[t[1]] + e[0] * g.w[t[2]]) / area2;
    if (w_hit > pw) odd = !odd;
  }
  return odd;
}

}  // namespace

MeshRegion::MeshRegion(TriangleMesh mesh, std::string name) {
  if (mesh.triangles.empty()) throw InputError(fmt::format("surface '{}' has no triangles", name));
  const int open = open_edge_count(mesh);
  if (open > 0) {
    throw InputError(fmt::format("surface '{}' is not closed: {} open edges (every edge must be shared by exactly "
                                 "two triangles; repair the mesh, e.g. close holes and remove duplicate faces)",
                                 name, open));
  }
  auto data = std::make_shared<Data>();
  data->box = mesh_bounds(mesh);
  const std::array<Vec3, 3> dirs = ray_directions();
  for (int r = 0; r < 3; ++r) data->rays[r] = build_ray_grid(mesh, dirs[r]);
  data->mesh = std::move(mesh);
  data->name = std::move(name);
  data_ = std::move(data);
}

bool MeshRegion::contains(const Vec3& p) const {
  if (!data_->box.contains(p)) return false;
  const bool a = odd_crossings(data_->mesh, data_->rays[0], p);
  const bool b = odd_crossings(data_->mesh, data_->rays[1], p);
  if (a == b) return a;
  return odd_crossings(data_->mesh, data_->rays[2], p);
}

int MeshRegion::inside_votes(const Vec3& p) const {
  if (!data_->box.contains(p)) return 0;
  int votes = 0;
  for (const RayGrid& g : data_->rays) votes += odd_crossings(data_->mesh, g, p);
  return votes;
}

// Three directions with irrational components, far apart, none along a coordinate axis or diagonal.
std::array<Vec3, 3> MeshRegion::ray_directions() {
  return {Vec3(std::sqrt(2.0) - 1, 1, std::sqrt(3.0) - 1).normalized(),
          Vec3(1, 2 - std::sqrt(5.0), std::sqrt(7.0) - 2).normalized(),
          Vec3(3 - std::sqrt(11.0), std::sqrt(13.0) - 3.5, 1).normalized()};
}

Aabb MeshRegion::bounds() const { return data_->box; }
const TriangleMesh& MeshRegion::mesh() const { return data_->mesh; }
const std::string& MeshRegion::name() const { return data_->name; }

MeshRegion load_mesh_region(const std::filesystem::path& stl_path) {
  return MeshRegion(read_stl(stl_path), stl_path.string());
}

}  // namespace ff::geom
