#include "drivers/hydrofrac/dfn.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>

#include "core/error.hpp"
#include "io/csv.hpp"

namespace ff::drivers::hydrofrac {

void declare_dfn_params(ParamTable& t) {
  t.string("dfn.file", "",
           "CSV of natural fractures (relative to the scenario's folder), columns x_m,y_m,angle_deg,length_m (2D "
           "segments; 3D: vertical discs, z_m added, length = diameter); empty: the generator below");
  t.integer("dfn.count", 0, "-",
            "number of generated natural fractures (0: none); at most 10,000 (each is tested against every bond)")
      .non_negative()
      .at_most(10000);
  t.integer("dfn.seed", 1, "-", "random seed of the generator").non_negative();
  t.string("dfn.positions", "random", "random (uniform in the block) or grid (dfn.spacing apart, rows along x)")
      .one_of({"random", "grid"});
  t.real("dfn.spacing", 5e-3, "m", "grid positions: centre-to-centre distance").positive();
  t.string("dfn.angles", "fixed", "fixed (dfn.angle), staggered (+-dfn.angle alternating by grid row) or random")
      .one_of({"fixed", "staggered", "random"});
  t.real("dfn.angle", 60, "deg", "trace direction from x (the sigma_H direction)").range(-360, 360);
  t.real("dfn.length_min", 2e-3, "m", "shortest fracture (segment length, disc diameter)").positive();
  t.real("dfn.length_max", 4e-3, "m", "longest fracture (uniform between min and max)").positive();
  t.real("dfn.buffer", 2e-3, "m", "no fracture comes closer than this to the borehole wall").non_negative();
}

namespace {
Real segment_distance(const Vec3& p, const Joint& j) {  // x-y distance of p to the segment
  const Real ex = std::cos(j.angle), ey = std::sin(j.angle);
  const Real dx = p.x() - j.centre.x(), dy = p.y() - j.centre.y();
  const Real s = std::clamp(dx * ex + dy * ey, -0.5 * j.length, 0.5 * j.length);
  return std::hypot(dx - s * ex, dy - s * ey);
}
}  // namespace

std::vector<Joint> make_joints(const Config& cfg, const Vec3& lo, const Vec3& hi, const Vec3& centre, Real hole_radius, int dim,
                               long* outside, std::string* shortfall) {
  std::vector<Joint> out;
  const Real buffer = cfg.real("dfn.buffer");
  const std::string file = cfg.string("dfn.file");
  if (!file.empty()) {
    std::filesystem::path f = file;
    if (f.is_relative()) f = std::filesystem::path(cfg.scenario_name()).parent_path() / f;
    CsvTable t;
    try {
      t = read_csv(f);
    } catch (const Error& e) {
      cfg.fail("dfn.file", fmt::format("{} (allowed: a CSV with columns x_m,y_m,{}angle_deg,length_m)", e.what(),
                                       dim == 3 ? "z_m," : ""));
    }
    long n_outside = 0;
    std::vector<std::string> need = {"x_m", "y_m", "angle_deg", "length_m"};
    if (dim == 3) need.push_back("z_m");
    for (const auto& c : need)
      if (!t.has(c))
        cfg.fail("dfn.file", fmt::format("'{}' has no column '{}' (needed: {})", f.string(), c, fmt::join(need, ",")));
    for (std::size_t r = 0; r < t.rows(); ++r) {
      Joint j;
      j.centre = Vec3(t.column("x_m")[r], t.column("y_m")[r], dim == 3 ? t.column("z_m")[r] : 0.0);
      j.angle = t.column("angle_deg")[r] * kPi / 180;
      j.length = t.column("length_m")[r];
      if (!(j.length > 0) || !j.centre.allFinite() || !std::isfinite(j.angle))
        cfg.fail("dfn.file", fmt::format("'{}' row {}: lengths must be > 0 and every value a number", f.string(), r + 1));
      bool inside = true;
      for (int a = 0; a < dim; ++a) inside = inside && j.centre[a] >= lo[a] && j.centre[a] <= hi[a];
      n_outside += !inside;
      out.push_back(j);
    }
    if (out.empty())
      cfg.fail("dfn.file", fmt::format("'{}' lists no fracture (a header alone); remove dfn.file for none", f.string()));
    // Every centre outside the block: most likely another unit (mm) or origin, and nothing would be cut.
    if (n_outside == static_cast<long>(out.size())) {
      std::string box;
      for (int a = 0; a < dim; ++a) box += fmt::format("{}[{}, {}]", a ? " x " : "", lo[a], hi[a]);
      cfg.fail("dfn.file", fmt::format("'{}': every fracture's centre lies outside the block, {} m; coordinates are in "
                                       "metres from the block's corner",
                                       f.string(), box));
    }
    if (outside) *outside = n_outside;
    return out;
  }
  const long n = cfg.integer("dfn.count");
  if (n == 0) return out;
  const Real lmin = cfg.real("dfn.length_min"), lmax = cfg.real("dfn.length_max");
  if (lmax < lmin) cfg.fail("dfn.length_max", fmt::format("{} m is below dfn.length_min = {} m", lmax, lmin));
  std::mt19937_64 rng(static_cast<std::uint64_t>(cfg.integer("dfn.seed")));
  auto uniform = [&](Real a, Real b) { return a + (b - a) * (static_cast<Real>(rng() >> 11) * 0x1.0p-53); };
  const std::string angles = cfg.string("dfn.angles"), positions = cfg.string("dfn.positions");
  const Real angle = cfg.real("dfn.angle") * kPi / 180, spacing = cfg.real("dfn.spacing");
  // Grid: rows along x, `spacing` apart, alternate rows shifted by half a spacing.
  std::vector<Vec3> grid;
  std::vector<int> grid_row;
  if (positions == "grid") {
    const double points = std::ceil((hi.x() - lo.x()) / spacing) * std::ceil((hi.y() - lo.y()) / spacing);
    if (!(points <= 1e6))
      cfg.fail("dfn.spacing", fmt::format("{} m puts {:.3g} grid positions in the {} x {} m block (at most 1e6): use a "
                                          "larger spacing",
                                          spacing, points, hi.x() - lo.x(), hi.y() - lo.y()));
    int row = 0;
    for (Real y = lo.y() + 0.5 * spacing; y < hi.y(); y += spacing, ++row)
      for (Real x = lo.x() + (row % 2 ? spacing : 0.5 * spacing); x < hi.x(); x += spacing) {
        grid.emplace_back(x, y, dim == 3 ? 0.5 * (lo.z() + hi.z()) : 0.0);
        grid_row.push_back(row);
      }
  }
  const long tries_max = 100 * n + 1000;
  long tries = 0, near_hole = 0;  // candidates, and those within the buffer
  for (std::size_t g = 0; static_cast<long>(out.size()) < n && tries < tries_max; ++tries) {
    Joint j;
    int row = 0;
    if (positions == "grid") {
      if (g >= grid.size()) break;
      j.centre = grid[g];
      row = grid_row[g++];
    } else {
      j.centre = Vec3(uniform(lo.x(), hi.x()), uniform(lo.y(), hi.y()), dim == 3 ? uniform(lo.z(), hi.z()) : 0.0);
      row = static_cast<int>(std::floor((j.centre.y() - lo.y()) / spacing));
    }
    j.length = uniform(lmin, lmax);
    j.angle = angles == "fixed" ? angle : angles == "staggered" ? (row % 2 ? -angle : angle) : uniform(0, kPi);
    if (segment_distance(centre, j) < hole_radius + buffer) {
      ++near_hole;
      continue;
    }
    out.push_back(j);
  }
  // Fewer than asked: say so and why (a buffer wider than the block, or a grid coarser than it, used
  // to leave no fracture without a word). None at all: refused, naming the key to change.
  if (static_cast<long>(out.size()) < n) {
    const std::string why =
        positions == "grid"
            ? fmt::format("the grid (dfn.spacing = {:g} m) has {} positions in the block, {} of them within dfn.buffer "
                          "= {:g} m of the borehole wall",
                          spacing, grid.size(), near_hole, buffer)
            : fmt::format("{} of {} random candidates came within dfn.buffer = {:g} m of the borehole wall", near_hole,
                          tries, buffer);
    const char* key = positions == "grid" && near_hole == 0 ? "dfn.spacing" : "dfn.buffer";
    if (out.empty())
      cfg.fail(key, fmt::format("no natural fracture could be placed (dfn.count = {}): {}; use a smaller {}", n, why, key));
    if (shortfall) *shortfall = fmt::format("dfn: {} of dfn.count = {} natural fractures placed: {}", out.size(), n, why);
  }
  return out;
}

std::vector<JointPair> cut_bonds(dem::DemSystem& sys, const std::vector<Joint>& joints) {
  std::vector<JointPair> pairs;
  if (joints.empty()) return pairs;
  auto& B = sys.bonds;
  const auto& P = sys.particles;
  const int dim = sys.settings.dim;
  for (std::size_t b = 0; b < B.size(); ++b) {
    if (B.broken[b]) continue;
    const Vec3 &xa = P.pos[B.i[b]], &xb = P.pos[B.j[b]];
    bool cut = false;
    for (const Joint& j : joints) {
      // The joint's plane (2D: its line): normal in x-y, perpendicular to the trace.
      const Vec3 n(-std::sin(j.angle), std::cos(j.angle), 0);
      const Real da = (xa - j.centre).dot(n), db = (xb - j.centre).dot(n);
      if ((da > 0) == (db > 0) || da == db) continue;
      const Vec3 x = xa + (da / (da - db)) * (xb - xa);  // where the bond crosses the plane
      const Vec3 d = x - j.centre;
      const Real along = d.x() * std::cos(j.angle) + d.y() * std::sin(j.angle);
      cut = dim == 2 ? std::abs(along) <= 0.5 * j.length : along * along + d.z() * d.z() <= 0.25 * j.length * j.length;
      if (cut) break;
    }
    if (!cut) continue;
    const Index a = B.i[b], c = B.j[b];
    Real size = 0;
    sys.materials.with_bond_law([&]<class Law>(std::type_identity<Law>) {
      size = Law::crack_size(sys.materials.bond_params<Law>()[B.pair[b]], P.radius[a], P.radius[c], dim);
    });
    pairs.push_back(JointPair{P.id[a], P.id[c], dim == 3 ? kPi * size * size : 2 * size});
    B.broken[b] = 1;
  }
  B.compact(P.size());
  return pairs;
}

}  // namespace ff::drivers::hydrofrac
