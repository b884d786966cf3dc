#include "drivers/flow/probes.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "drivers/flow/flow_case.hpp"

namespace ff::drivers {

void declare_probe_params(ParamTable& t) {
  t.string_list("probes.names", {}, "names of point probes of pressure and velocity, written per sample to series.csv "
                                    "(p_<name>_Pa, ux_<name>_m_per_s, ...) and at the end to summary.json; letters, "
                                    "digits and _");
  t.real_list("probes.x", {}, "m", "x of each probe (as many as probes.names; the domain starts at 0)");
  t.real_list("probes.y", {}, "m", "y of each probe (as many as probes.names)");
  t.real_list("probes.z", {}, "m", "D3Q19 only: z of each probe; empty: mid-depth");
  t.string_list("probes.delta_p", {}, "two probe names a, b: adds dp_<a>_<b>_Pa = p_a - p_b to series.csv and "
                                      "delta_p_Pa (final) to summary.json")
      .size_between(0, 2);
}

ProbeSet read_probes(const Config& cfg, bool d3q19, double depth) {
  ProbeSet p;
  p.three_d = d3q19;
  const auto& names = cfg.string_list("probes.names");
  const auto& xs = cfg.real_list("probes.x");
  const auto& ys = cfg.real_list("probes.y");
  const auto& zs = cfg.real_list("probes.z");
  const auto n = names.size();
  auto need = [&](const char* key, std::size_t have) {
    if (have != n)
      cfg.fail(key, fmt::format("{} values for {} probe name(s) in probes.names: give one per probe", have, n));
  };
  need("probes.x", xs.size());
  need("probes.y", ys.size());
  if (!d3q19 && !zs.empty()) cfg.fail("probes.z", "only a D3Q19 lattice has a z coordinate: remove probes.z");
  if (d3q19 && !zs.empty()) need("probes.z", zs.size());
  for (std::size_t i = 0; i < n; ++i) {
    const std::string& nm = names[i];
    const bool ok = !nm.empty() && std::all_of(nm.begin(), nm.end(), [](char c) {
      return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
    });
    if (!ok)
      cfg.fail("probes.names", fmt::format("probe {} is named '{}': use letters, digits and _ only (it becomes part "
                                           "of column names)", i, nm));
    for (std::size_t j = 0; j < i; ++j)
      if (names[j] == nm) cfg.fail("probes.names", fmt::format("probes {} and {} are both named '{}'", j, i, nm));
    const double z = d3q19 ? (zs.empty() ? 0.5 * depth : zs[i]) : 0.0;
    p.points.push_back({nm, Vec3(xs[i], ys[i], z)});
  }
  const auto& dp = cfg.string_list("probes.delta_p");
  if (!dp.empty()) {
    if (dp.size() != 2) cfg.fail("probes.delta_p", "give two probe names, a and b (Delta p = p_a - p_b)");
    std::array<int, 2> idx{-1, -1};
    for (int k = 0; k < 2; ++k) {
      for (std::size_t i = 0; i < n; ++i)
        if (names[i] == dp[k]) idx[k] = int(i);
      if (idx[k] < 0)
        cfg.fail("probes.delta_p", fmt::format("'{}' is not one of the probes.names", dp[k]));
    }
    if (idx[0] == idx[1]) cfg.fail("probes.delta_p", "give two different probes");
    p.delta_p = idx;
  }
  return p;
}

void check_probe_positions(const Config& cfg, const ProbeSet& p, double dx, int nx, int ny, int nz,
                           const std::function<bool(int, int, int)>& solid) {
  const std::array<int, 3> n{nx, ny, nz};
  const char* keys[3] = {"probes.x", "probes.y", "probes.z"};
  for (std::size_t i = 0; i < p.points.size(); ++i) {
    const Vec3& x = p.points[i].position;
    for (int a = 0; a < (p.three_d ? 3 : 2); ++a)
      if (!(x[a] >= 0 && x[a] <= n[a] * dx))
        cfg.fail(keys[a], fmt::format("probe {} ('{}') at {} = {} m lies outside the domain, [0, {:.6g}] m", i,
                                      p.points[i].name, "xyz"[a], x[a], n[a] * dx));
    // Lattice coordinates; the nearest fluid node must lie within ~1 cell.
    const Vec3 q = x / dx - Vec3(0.5, 0.5, p.three_d ? 0.5 : 0.0);
    const double reach = 1.5;
    double nearest = 1e300;
    const int z0 = p.three_d ? int(std::floor(q.z() - reach)) : 0, z1 = p.three_d ? int(std::ceil(q.z() + reach)) : 0;
    for (int z = std::max(0, z0); z <= std::min(nz - 1, z1); ++z)
      for (int y = std::max(0, int(std::floor(q.y() - reach))); y <= std::min(ny - 1, int(std::ceil(q.y() + reach))); ++y)
        for (int xx = std::max(0, int(std::floor(q.x() - reach))); xx <= std::min(nx - 1, int(std::ceil(q.x() + reach)));
             ++xx)
          if (!solid(xx, y, z))
            nearest = std::min(nearest, (Vec3(xx, y, p.three_d ? z : 0.0) - q).norm());
    if (!(nearest <= reach))
      cfg.fail("probes.names", fmt::format("probe {} ('{}') at ({}, {}{}) m lies inside a solid, more than {} cells "
                                           "from the nearest fluid node: move it into the fluid or onto a surface",
                                           i, p.points[i].name, x.x(), x.y(), p.three_d ? fmt::format(", {}", x.z()) : "",
                                           reach));
  }
}

ProbeStencil probe_stencil(const Vec3& p, int nx, int ny, int nz, std::span<const std::uint8_t> solid) {
  const std::array<int, 3> n{nx, ny, nz};
  const int dims = nz > 1 ? 3 : 2;
  auto index = [&](int x, int y, int z) { return std::size_t(x) + std::size_t(nx) * (std::size_t(y) + std::size_t(ny) * z); };
  auto fluid = [&](int x, int y, int z) {
    return x >= 0 && y >= 0 && z >= 0 && x < nx && y < ny && z < nz && solid[index(x, y, z)] == 0;
  };
  ProbeStencil s;
  // 1. Multilinear when every surrounding node is fluid (an axis where the point lies on a
  // node plane needs that plane only).
  {
    std::array<int, 3> lo{0, 0, 0};
    std::array<double, 3> f{0, 0, 0};
    std::array<int, 3> span{1, 1, 1};
    for (int a = 0; a < dims; ++a) {
      lo[a] = int(std::floor(p[a]));
      f[a] = p[a] - lo[a];
      span[a] = f[a] > 0 ? 2 : 1;
    }
    bool ok = true;
    for (int k = 0; k < span[2] && ok; ++k)
      for (int j = 0; j < span[1] && ok; ++j)
        for (int i = 0; i < span[0] && ok; ++i) ok = fluid(lo[0] + i, lo[1] + j, lo[2] + k);
    if (ok) {
      for (int k = 0; k < span[2]; ++k)
        for (int j = 0; j < span[1]; ++j)
          for (int i = 0; i < span[0]; ++i) {
            const double w = (i ? f[0] : 1 - f[0]) * (j ? f[1] : 1 - f[1]) * (k ? f[2] : 1 - f[2]);
            s.node.push_back(index(lo[0] + i, lo[1] + j, lo[2] + k));
            s.weight.push_back(w);
          }
      s.method = dims == 3 ? "trilinear" : "bilinear";
      return s;
    }
  }
  // 2. Weighted least squares over the fluid nodes within kFitRadius (widened by up to one
  // cell where these do not determine a quadratic, e.g. half a cell from a wall): a quadratic
  // in the offsets from the point, so the fitted value at the point is the constant coefficient.
  for (const double radius : {kFitRadius, kFitRadius + 0.5, kFitRadius + 1.0}) {
    const bool widest = radius == kFitRadius + 1.0;
    std::vector<std::array<int, 3>> nodes;
    std::vector<double> wts;
    const double r2max = radius * radius, h = radius + 0.5;
    std::array<int, 3> from{0, 0, 0}, to{0, 0, 0};
    for (int a = 0; a < dims; ++a) {
      from[a] = std::max(0, int(std::floor(p[a] - radius)));
      to[a] = std::min(n[a] - 1, int(std::ceil(p[a] + radius)));
    }
    for (int z = from[2]; z <= to[2]; ++z)
      for (int y = from[1]; y <= to[1]; ++y)
        for (int x = from[0]; x <= to[0]; ++x) {
          if (!fluid(x, y, z)) continue;
          const Vec3 d(x - p.x(), y - p.y(), dims == 3 ? z - p.z() : 0.0);
          const double r2 = d.squaredNorm();
          if (r2 > r2max) continue;
          nodes.push_back({x, y, z});
          const double t = 1 - r2 / (h * h);  // Wendland-like taper: near nodes count most
          wts.push_back(t * t);
        }
    if (nodes.empty()) {
      if (widest)
        throw InputError(fmt::format("no fluid node within {} cells of the probe at lattice point ({:.3g}, {:.3g}, "
                                     "{:.3g})",
                                     radius, p.x(), p.y(), p.z()));
      continue;
    }
    // Terms per axis by the number of distinct node coordinates along it (a single plane on a
    // 2D or thin lattice carries no z terms).
    std::array<int, 3> distinct{0, 0, 0};
    for (int a = 0; a < 3; ++a) {
      std::vector<int> c;
      for (auto& nd : nodes) c.push_back(nd[a]);
      std::sort(c.begin(), c.end());
      distinct[a] = int(std::unique(c.begin(), c.end()) - c.begin());
    }
    bool full = true;  // every axis of the lattice can carry its quadratic term
    for (int a = 0; a < dims; ++a) full = full && distinct[a] >= 3;
    if (!full && !widest) continue;
    for (int order = 2; order >= 0; --order) {
      // Basis: 1; x_a (distinct >= 2); x_a^2 (>= 3); x_a x_b (both >= 2) -- up to `order`.
      std::vector<std::function<double(const Vec3&)>> basis{[](const Vec3&) { return 1.0; }};
      for (int a = 0; a < 3 && order >= 1; ++a)
        if (distinct[a] >= 2) basis.push_back([a](const Vec3& d) { return d[a]; });
      for (int a = 0; a < 3 && order >= 2; ++a) {
        if (distinct[a] >= 3) basis.push_back([a](const Vec3& d) { return d[a] * d[a]; });
        for (int b = a + 1; b < 3; ++b)
          if (distinct[a] >= 2 && distinct[b] >= 2) basis.push_back([a, b](const Vec3& d) { return d[a] * d[b]; });
      }
      const int m = int(nodes.size()), q = int(basis.size());
      if (m < q) continue;
      Eigen::MatrixXd B(m, q);
      for (int k = 0; k < m; ++k) {
        const Vec3 d(nodes[k][0] - p.x(), nodes[k][1] - p.y(), dims == 3 ? nodes[k][2] - p.z() : 0.0);
        const double sw = std::sqrt(wts[k]);
        for (int c = 0; c < q; ++c) B(k, c) = sw * basis[c](d);
      }
      Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(B);
      cod.setThreshold(1e-10);
      if (cod.rank() < q) {
        if (order == 2 && !widest) break;  // try a wider radius first
        continue;
      }
      const Eigen::MatrixXd pinv = cod.pseudoInverse();
      for (int k = 0; k < m; ++k) {
        s.node.push_back(index(nodes[k][0], nodes[k][1], nodes[k][2]));
        s.weight.push_back(pinv(0, k) * std::sqrt(wts[k]));
      }
      s.method = fmt::format("{} least squares over {} fluid nodes within {} cells",
                             order == 2 ? "quadratic" : order == 1 ? "linear" : "constant", m, radius);
      return s;
    }
  }
  throw InputError("probe fit failed");  // unreachable: the constant fit needs one node
}

void Probes::columns(std::vector<std::string>& out) const {
  for (auto& p : set_.points) {
    out.push_back(fmt::format("p_{}_Pa", p.name));
    out.push_back(fmt::format("ux_{}_m_per_s", p.name));
    out.push_back(fmt::format("uy_{}_m_per_s", p.name));
    if (set_.three_d) out.push_back(fmt::format("uz_{}_m_per_s", p.name));
  }
  if (set_.delta_p)
    out.push_back(fmt::format("dp_{}_{}_Pa", set_.points[(*set_.delta_p)[0]].name, set_.points[(*set_.delta_p)[1]].name));
}

void Probes::measure(const FlowSample& s, std::vector<double>& row) {
  if (set_.empty()) return;
  const std::size_t plane = std::size_t(s.nx) * std::size_t(s.ny);
  const int nz = int(s.pressure.size() / plane);  // 1 until FlowSample holds every plane
  if (stencils_.empty()) {
    for (auto& p : set_.points) {
      Vec3 q = p.position / dx_ - Vec3(0.5, 0.5, 0.5);
      if (nz == 1) q.z() = 0;
      stencils_.push_back(probe_stencil(q, s.nx, s.ny, nz, s.solid));
    }
  }
  const std::size_t first = row.size();
  for (auto& st : stencils_) {
    double pr = 0;
    Vec3 u = Vec3::Zero();
    for (std::size_t k = 0; k < st.node.size(); ++k) {
      pr += st.weight[k] * s.pressure[st.node[k]];
      u += st.weight[k] * s.velocity[st.node[k]];
    }
    row.push_back(pr);
    row.push_back(u.x());
    row.push_back(u.y());
    if (set_.three_d) row.push_back(u.z());
  }
  if (set_.delta_p) {
    const std::size_t per = set_.three_d ? 4 : 3;
    row.push_back(row[first + per * std::size_t((*set_.delta_p)[0])] - row[first + per * std::size_t((*set_.delta_p)[1])]);
  }
}

std::vector<std::string> series_columns(const Config& cfg, const FlowCase& fc, const Probes& probes) {
  // Names end in their SI unit (time_s, ..._Pa, ..._m_per_s); dimensionless ones have none.
  std::vector<std::string> cols = {"step", "time_s"};
  for (auto& c : fc.columns()) cols.push_back(c);
  const std::size_t own = cols.size();
  probes.columns(cols);
  for (std::size_t i = own; i < cols.size(); ++i)
    if (std::find(cols.begin(), cols.begin() + std::ptrdiff_t(own), cols[i]) != cols.begin() + std::ptrdiff_t(own))
      cfg.fail("probes.names", fmt::format("the probe column '{}' repeats a column the driver already writes to "
                                           "series.csv: rename the probe(s) in probes.names",
                                           cols[i]));
  return cols;
}

}  // namespace ff::drivers
