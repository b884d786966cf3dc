#include "coupling/hydrofrac/borehole.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/error.hpp"

namespace ff::coupling::hydrofrac {

bool in_hole(const BoreholeGeometry& g, const Vec3& x, Real pad) {
  const Real dx = x.x() - g.centre.x(), dy = x.y() - g.centre.y();
  const Real r = g.radius + pad;
  if (dx * dx + dy * dy < r * r) return true;
  if (g.perforation_length <= 0) return false;
  for (int s = 0; s < g.perforation_sides; ++s) {
    const Real a = g.perforation_azimuth + s * kPi;
    const Real ex = std::cos(a), ey = std::sin(a);
    const Real along = dx * ex + dy * ey, across = -dx * ey + dy * ex;
    if (along >= 0 && along <= g.radius + g.perforation_length + pad && std::abs(across) <= 0.5 * g.perforation_width + pad)
      return true;
  }
  return false;
}

std::size_t remove_particles(dem::DemSystem& sys, const std::vector<char>& remove) {
  auto& P = sys.particles;
  const std::size_t n = P.size();
  std::vector<Index> new_index(n, -1);
  Index k = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (!remove[i]) new_index[i] = k++;
  const std::size_t removed = n - static_cast<std::size_t>(k);
  if (removed == 0) return 0;
  // Bonds touching a removed particle go (compact keeps the order of the rest), then the ends
  // are renumbered; the order of the kept particles is kept, so i < j still holds.
  auto& B = sys.bonds;
  for (std::size_t b = 0; b < B.size(); ++b)
    if (remove[B.i[b]] || remove[B.j[b]]) B.broken[b] = 1;
  B.compact(n);
  for (std::size_t b = 0; b < B.size(); ++b) {
    B.i[b] = new_index[B.i[b]];
    B.j[b] = new_index[B.j[b]];
  }
  // As the sample builder does: neighbour pairs and wall contacts are dropped before the
  // renumbering, which would attach their history to other particles.
  dem::ParticleStore kept = std::move(P);
  kept.keep(remove);
  P = dem::ParticleStore{};
  sys.wall_contacts().clear();
  sys.rebuild_neighbors();
  P = std::move(kept);
  sys.initialise();
  return removed;
}

namespace {

// A regular grid over a box; cells indexed x fastest.
struct Grid {
  Vec3 lo = Vec3::Zero();
  Real h = 0;
  long nx = 1, ny = 1, nz = 1;
  long size() const { return nx * ny * nz; }
  long index(long x, long y, long z) const { return (z * ny + y) * nx + x; }
  Vec3 centre(long c) const {
    const long x = c % nx, y = (c / nx) % ny, z = c / (nx * ny);
    return lo + h * Vec3(static_cast<Real>(x) + 0.5, static_cast<Real>(y) + 0.5, nz > 1 ? static_cast<Real>(z) + 0.5 : 0.0);
  }
  long cell_of(const Vec3& p) const {
    const long x = static_cast<long>(std::floor((p.x() - lo.x()) / h));
    const long y = static_cast<long>(std::floor((p.y() - lo.y()) / h));
    const long z = nz > 1 ? static_cast<long>(std::floor((p.z() - lo.z()) / h)) : 0;
    if (x < 0 || y < 0 || z < 0 || x >= nx || y >= ny || z >= nz) return -1;
    return index(x, y, z);
  }
};

// Unit directions with equal area weights: a circle (2D) or a Fibonacci sphere (3D).
std::vector<Vec3> directions(int dim, int n) {
  std::vector<Vec3> d(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) {
    if (dim == 2) {
      const Real a = 2 * kPi * (k + 0.5) / n;
      d[static_cast<std::size_t>(k)] = Vec3(std::cos(a), std::sin(a), 0);
    } else {
      const Real z = 1 - (2.0 * k + 1) / n, s = std::sqrt(std::max<Real>(0, 1 - z * z));
      const Real phi = k * kPi * (3 - std::sqrt(5.0));
      d[static_cast<std::size_t>(k)] = Vec3(s * std::cos(phi), s * std::sin(phi), z);
    }
  }
  return d;
}

}  // namespace

HoleSurface hole_surface(const dem::DemSystem& sys, const BoreholeGeometry& g, Real cell, Real inflate, Real reach) {
  const auto& P = sys.particles;
  const int dim = g.dim;
  const Real extent = g.radius + (g.perforation_length > 0 ? g.perforation_length + g.perforation_width : 0) + reach + cell;
  Grid grid;
  grid.h = cell;
  grid.lo = Vec3(g.centre.x() - extent, g.centre.y() - extent, dim == 3 ? g.z_lo : 0.0);
  grid.nx = grid.ny = static_cast<long>(std::ceil(2 * extent / cell));
  grid.nz = dim == 3 ? std::max(1L, static_cast<long>(std::ceil((g.z_hi - g.z_lo) / cell))) : 1;
  // 0 free, 1 covered by a particle or outside the region, 2 flooded
  std::vector<std::uint8_t> state(static_cast<std::size_t>(grid.size()), 0);
  for (long c = 0; c < grid.size(); ++c)
    if (!in_hole(g, grid.centre(c), reach)) state[static_cast<std::size_t>(c)] = 1;
  for (std::size_t i = 0; i < P.size(); ++i) {
    const Vec3& x = P.pos[i];
    const Real r = P.radius[i] + inflate;
    if (!in_hole(g, x, reach + r)) continue;
    const long x0 = std::max(0L, static_cast<long>(std::floor((x.x() - r - grid.lo.x()) / cell)));
    const long x1 = std::min(grid.nx - 1, static_cast<long>(std::floor((x.x() + r - grid.lo.x()) / cell)));
    const long y0 = std::max(0L, static_cast<long>(std::floor((x.y() - r - grid.lo.y()) / cell)));
    const long y1 = std::min(grid.ny - 1, static_cast<long>(std::floor((x.y() + r - grid.lo.y()) / cell)));
    long z0 = 0, z1 = 0;
    if (dim == 3) {
      z0 = std::max(0L, static_cast<long>(std::floor((x.z() - r - grid.lo.z()) / cell)));
      z1 = std::min(grid.nz - 1, static_cast<long>(std::floor((x.z() + r - grid.lo.z()) / cell)));
    }
    for (long z = z0; z <= z1; ++z)
      for (long y = y0; y <= y1; ++y)
        for (long xx = x0; xx <= x1; ++xx) {
          const long c = grid.index(xx, y, z);
          if ((grid.centre(c) - x).squaredNorm() < r * r) state[static_cast<std::size_t>(c)] = 1;
        }
  }
  // Seeds: free cells within half the radius of the axis.
  std::vector<long> queue;
  for (long c = 0; c < grid.size(); ++c) {
    const Vec3 q = grid.centre(c);
    const Real dx = q.x() - g.centre.x(), dy = q.y() - g.centre.y();
    if (state[static_cast<std::size_t>(c)] == 0 && dx * dx + dy * dy < 0.25 * g.radius * g.radius) {
      state[static_cast<std::size_t>(c)] = 2;
      queue.push_back(c);
    }
  }
  if (queue.empty())
    throw InputError("borehole.radius: the hole is filled by particles at its axis (no free cell within half its radius); "
                     "use a larger borehole.radius (at least 2 sample.radius_max)");
  for (std::size_t q = 0; q < queue.size(); ++q) {
    const long c = queue[q];
    const long x = c % grid.nx, y = (c / grid.nx) % grid.ny, z = c / (grid.nx * grid.ny);
    const long nb[6][3] = {{x - 1, y, z}, {x + 1, y, z}, {x, y - 1, z}, {x, y + 1, z}, {x, y, z - 1}, {x, y, z + 1}};
    for (int k = 0; k < (dim == 3 ? 6 : 4); ++k) {
      const long a = nb[k][0], b = nb[k][1], d = nb[k][2];
      if (a < 0 || b < 0 || d < 0 || a >= grid.nx || b >= grid.ny || d >= grid.nz) continue;
      const long n = grid.index(a, b, d);
      if (state[static_cast<std::size_t>(n)] != 0) continue;
      state[static_cast<std::size_t>(n)] = 2;
      queue.push_back(n);
    }
  }
  HoleSurface s;
  const Real cell_volume = dim == 3 ? cell * cell * cell : cell * cell;
  s.volume = static_cast<Real>(queue.size()) * cell_volume;
  s.effective_radius = dim == 3 ? std::sqrt(s.volume / (kPi * std::max<Real>(g.z_hi - g.z_lo, cell))) : std::sqrt(s.volume / kPi);
  const int nd = dim == 3 ? 192 : 72;
  const std::vector<Vec3> dirs = directions(dim, nd);
  for (std::size_t i = 0; i < P.size(); ++i) {
    const Vec3& x = P.pos[i];
    const Real r = P.radius[i];
    if (!in_hole(g, x, reach + r)) continue;
    const Real dA = dim == 3 ? 4 * kPi * r * r / nd : 2 * kPi * r / nd;
    Vec3 a = Vec3::Zero();
    bool wet = false;
    for (const Vec3& n : dirs) {
      const long c = grid.cell_of(x + (r + inflate + 0.75 * cell) * n);
      if (c < 0 || state[static_cast<std::size_t>(c)] != 2) continue;
      a += dA * n;
      wet = true;
    }
    if (!wet) continue;
    s.particle.push_back(static_cast<Index>(i));
    s.area.push_back(a);
  }
  return s;
}

std::vector<Index> index_of_ids(const dem::ParticleStore& p) {
  std::vector<Index> m(static_cast<std::size_t>(std::max<std::int64_t>(p.next_id, 0)), -1);
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.id[i] >= 0 && p.id[i] < p.next_id) m[static_cast<std::size_t>(p.id[i])] = static_cast<Index>(i);
  return m;
}

void connected_cracks(const dem::DemSystem& sys, const std::vector<Index>& id_index, const std::vector<Index>& wall,
                      const std::vector<JointPair>& joints, std::vector<std::size_t>& event, std::vector<std::size_t>& joint,
                      std::vector<char>& visited) {
  // One scratch array: the particles reached, then the edges walked (no allocation once it has
  // grown to its size: the crack log is reserved for every bond).
  const auto& ev = sys.cracks.events;
  const std::size_t np = sys.particles.size();
  visited.assign(np + ev.size() + joints.size(), 0);
  char* edge_done = visited.data() + np;
  for (Index i : wall) visited[static_cast<std::size_t>(i)] = 1;
  auto idx = [&](std::int64_t id) -> Index {
    return id >= 0 && static_cast<std::size_t>(id) < id_index.size() ? id_index[static_cast<std::size_t>(id)] : -1;
  };
  event.clear();
  joint.clear();
  // Sweeps until nothing new is reached (a chain of n cracks needs at most n sweeps; the
  // cracks reached are then listed in log order, whatever the sweep that found them).
  for (bool grew = true; grew;) {
    grew = false;
    for (std::size_t k = 0; k < ev.size() + joints.size(); ++k) {
      if (edge_done[k]) continue;
      const bool is_event = k < ev.size();
      const Index a = is_event ? idx(ev[k].i) : idx(joints[k - ev.size()].a);
      const Index b = is_event ? idx(ev[k].j) : idx(joints[k - ev.size()].b);
      if (a < 0 || b < 0) continue;
      char& va = visited[static_cast<std::size_t>(a)];
      char& vb = visited[static_cast<std::size_t>(b)];
      if (!va && !vb) continue;
      va = vb = 1;
      edge_done[k] = 1;
      grew = true;
    }
  }
  for (std::size_t k = 0; k < ev.size(); ++k)
    if (edge_done[k]) event.push_back(k);
  for (std::size_t k = 0; k < joints.size(); ++k)
    if (edge_done[ev.size() + k]) joint.push_back(k);
}

FractureShape fracture_shape(const dem::DemSystem& sys, const std::vector<std::size_t>& events, const Vec3& centre) {
  FractureShape f;
  f.cracks = static_cast<long>(events.size());
  if (events.empty()) return f;
  Real sxx = 0, syy = 0, sxy = 0;
  for (std::size_t k : events) {
    const Vec3& p = sys.cracks.events[k].position;
    const Real dx = p.x() - centre.x(), dy = p.y() - centre.y();
    sxx += dx * dx;
    syy += dy * dy;
    sxy += dx * dy;
    f.max_distance = std::max(f.max_distance, std::hypot(dx, dy));
  }
  // Principal axis of the 2x2 second moment about the axis (not the centroid: two wings).
  const Real theta = 0.5 * std::atan2(2 * sxy, sxx - syy);
  const Real ex = std::cos(theta), ey = std::sin(theta);
  const Real m = 0.5 * (sxx + syy), d = std::sqrt(0.25 * (sxx - syy) * (sxx - syy) + sxy * sxy);
  f.anisotropy = m + d > 0 ? 1 - (m - d) / (m + d) : 0;
  Real lo = 0, hi = 0;
  for (std::size_t k : events) {
    const Vec3& p = sys.cracks.events[k].position;
    const Real s = (p.x() - centre.x()) * ex + (p.y() - centre.y()) * ey;
    lo = std::min(lo, s);
    hi = std::max(hi, s);
  }
  f.length = hi - lo;
  auto fold = [](Real rad) {
    Real deg = rad * 180 / kPi;
    while (deg <= -90) deg += 180;
    while (deg > 90) deg -= 180;
    return deg;
  };
  f.azimuth_deg = fold(theta);
  Real nxx = 0, nyy = 0, nxy = 0;
  for (std::size_t k : events) {
    const Vec3& n = sys.cracks.events[k].normal;
    nxx += n.x() * n.x();
    nyy += n.y() * n.y();
    nxy += n.x() * n.y();
  }
  f.normal_azimuth_deg = fold(0.5 * std::atan2(2 * nxy, nxx - nyy) + 0.5 * kPi);
  return f;
}

}  // namespace ff::coupling::hydrofrac
