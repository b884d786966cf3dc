#include "dem/sample_builder.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <numeric>

#include "core/error.hpp"
#include "core/log.hpp"
#include "dem/dem_params.hpp"
#include "geometry/packing.hpp"
#include "geometry/point_in_mesh.hpp"
#include "geometry/shapes.hpp"
#include "dem/diagnostics.hpp"

namespace ff::dem {

void declare_sample_params(ParamTable& t) {
  t.string("sample.shape", "cylinder",
           "sample shape: cylinder (3D, axis z, base at z = 0), box (3D box, or 2D rectangle in x-y loaded along y) "
           "or disc (2D: disks in a circle of sample.diameter centred at the origin of the x-y plane)")
      .one_of({"cylinder", "box", "disc"});
  t.real("sample.diameter", 25e-3, "m", "cylinder or disc diameter").positive();
  t.real("sample.height", 50e-3, "m", "sample height along the loading axis (z in 3D, y in 2D)").positive();
  t.real("sample.width", 25e-3, "m", "box width along x").positive();
  t.real("sample.depth", 25e-3, "m", "box depth along y (3D box only)").positive();
  t.real("sample.radius_min", 0.4e-3, "m", "smallest particle radius (uniform distribution)").positive();
  t.real("sample.radius_max", 0.6e-3, "m", "largest particle radius").positive();
  t.real("sample.porosity", 0.38, "-", "target porosity of the packing (3D >= 0.35, 2D >= 0.16)").open_range(0, 1);
  t.integer("sample.seed", 1, "-", "random seed of the packing (same seed, same sample)").non_negative();
  t.real("sample.locked_in_stress", 0.1e6, "Pa", "isotropic stress left in the packing when bonds are installed is reduced below this").positive();
  t.real("sample.bond_gap", 0.05e-3, "m", "bonds are installed between particles whose gap is at most this (seed 000: 0.05 mm)").non_negative();
  t.string("sample.default_group", "", "group of particles outside every region and image window (required when more than one group is declared)");
  t.real("sample.genesis_tolerance", 1e-2, "-",
         "equilibrium criterion of the genesis: mean |unbalanced force| / max(mean contact force, force of one contact "
         "at sample.locked_in_stress) (docs/dem.md); a warning when not met")
      .positive();
  t.integer("sample.genesis_max_steps", 1000, "-", "step cap of each genesis equilibration (after each radius shrink)").positive();
  // Regions assigning groups (later regions win).
  t.string("sample.region.*.group", "", "group of the particles whose centres lie in this region");
  t.string("sample.region.*.shape", "sphere", "region shape").one_of({"box", "sphere", "cylinder", "ellipsoid", "stl"});
  t.real_list("sample.region.*.center", {0, 0, 0}, "m", "sphere/ellipsoid centre, cylinder base centre").size(3);
  t.real("sample.region.*.radius", 1e-3, "m", "sphere or cylinder radius").positive();
  t.real_list("sample.region.*.lo", {0, 0, 0}, "m", "box lower corner").size(3);
  t.real_list("sample.region.*.hi", {0, 0, 0}, "m", "box upper corner").size(3);
  t.real_list("sample.region.*.axis", {0, 0, 1}, "m", "cylinder axis direction (normalised)").size(3);
  t.real("sample.region.*.length", 1e-3, "m", "cylinder length along its axis").positive();
  t.real_list("sample.region.*.semi_axes", {1e-3, 1e-3, 1e-3}, "m", "ellipsoid semi-axes").size(3).positive();
  t.real_list("sample.region.*.rotation", {0, 0, 0}, "deg", "ellipsoid rotation: angles about x, then y, then z")
      .size(3)
      .range(-360, 360);
  t.string("sample.region.*.file", "", "closed STL surface (relative paths from the scenario file's folder)");
  // Voxel image (applied after the regions: a voxel window wins over every region).
  t.string("sample.voxels.folder", "",
           "folder of 8- or 16-bit binary PGM slices, one per z level in file-name order (relative paths from the "
           "scenario file's folder; empty: no image). Groups from the image override sample.region.*; particles "
           "outside the image or in voxels of no window keep their group");
  t.real_list("sample.voxels.origin", {0, 0, 0}, "m", "centre of voxel (0, 0, 0): column 0, row 0 of the first slice").size(3);
  t.real_list("sample.voxels.spacing", {1e-4, 1e-4, 1e-4}, "m", "voxel size along x (columns), y (rows), z (slices)")
      .size(3)
      .positive();
  t.integer("sample.voxels.threshold.*.min", 0, "-",
            "lowest grey value of window *, which maps to the declared group of that name or, for * = pore, removes the "
            "particles before bonding")
      .range(0, 65535);
  t.integer("sample.voxels.threshold.*.max", 65535, "-", "highest grey value of the window (windows must not overlap)")
      .range(0, 65535);
}

namespace {

// The regions' names in [[sample.region]] order (0, 1, ..., 10: by length, then text).
std::vector<std::string> sorted_region_names(const Config& cfg) {
  auto names = cfg.names("sample.region");
  std::sort(names.begin(), names.end(), [](const std::string& a, const std::string& b) {
    return a.size() != b.size() ? a.size() < b.size() : a < b;
  });
  return names;
}

std::vector<Region> read_regions(const Config& cfg, const Materials& mat, std::vector<int>& region_group) {
  std::vector<Region> regions;
  auto names = sorted_region_names(cfg);
  if (names.size() > kMaxRegions)
    throw InputError(fmt::format("{}: the scenario has {} [[sample.region]] entries; the limit is {} (every particle is "
                                 "tested against every region; merge inclusions into one STL surface)",
                                 cfg.scenario_name(), names.size(), kMaxRegions));
  const std::filesystem::path base = std::filesystem::path(cfg.scenario_name()).parent_path();
  for (auto& n : names) {
    const std::string k = "sample.region." + n + ".";
    const std::string group = cfg.string(k + "group");
    const int g = mat.group_index(group);
    if (g < 0) cfg.fail(k + "group", fmt::format("'{}' is not a declared group ([dem.group.NAME])", group));
    const std::string shape = cfg.string(k + "shape");
    auto v3 = [&](const std::string& key) {
      const auto& l = cfg.real_list(k + key);
      return Vec3(l[0], l[1], l[2]);
    };
    if (shape == "sphere") {
      regions.emplace_back(Sphere{v3("center"), cfg.real(k + "radius")});
    } else if (shape == "box") {
      const Vec3 lo = v3("lo"), hi = v3("hi");
      if ((hi - lo).minCoeff() <= 0) cfg.fail(k + "hi", "every coordinate of hi must exceed lo");
      regions.emplace_back(Box{lo, hi});
    } else if (shape == "cylinder") {
      const Vec3 ax = v3("axis");
      if (ax.norm() == 0) cfg.fail(k + "axis", "the axis must not be the zero vector");
      regions.emplace_back(Cylinder{v3("center"), ax.normalized(), cfg.real(k + "radius"), cfg.real(k + "length")});
    } else if (shape == "ellipsoid") {
      const Vec3 rot = v3("rotation") * (kPi / 180.0);
      const Quat q = Eigen::AngleAxis<Real>(rot.z(), Vec3::UnitZ()) * Eigen::AngleAxis<Real>(rot.y(), Vec3::UnitY()) *
                     Eigen::AngleAxis<Real>(rot.x(), Vec3::UnitX());
      regions.emplace_back(Ellipsoid{v3("center"), v3("semi_axes"), q});
    } else {
      std::filesystem::path f = cfg.string(k + "file");
      if (f.empty()) cfg.fail(k + "file", "an stl region needs file = \"path/to/surface.stl\"");
      if (f.is_relative()) f = base / f;
      try {
        regions.emplace_back(geom::load_mesh_region(f));
      } catch (const InputError& e) {
        cfg.fail(k + "file", e.what());
      }
    }
    region_group.push_back(g);
  }
  return regions;
}

std::string group_list(const Materials& mat) {
  std::string s;
  for (const auto& g : mat.group_names) s += (s.empty() ? "" : ", ") + g;
  return s;
}

// Keeps the particles with !remove[i] (every declared field; ids stay with their particles).
// Called before bonds exist: every neighbour pair and wall contact is dropped first, because the
// renumbering would attach their history to other particles.
void remove_particles(DemSystem& sys, const std::vector<char>& remove) {
  ParticleStore& P = sys.particles;
  ParticleStore kept = std::move(P);
  kept.keep(remove);
  P = ParticleStore{};
  sys.wall_contacts().clear();
  sys.rebuild_neighbors();
  P = std::move(kept);
  sys.initialise();
}

}  // namespace

VoxelGroups read_voxel_groups(const Config& cfg, const Materials& mat) {
  VoxelGroups vg;
  const std::string folder_key = "sample.voxels.folder";
  auto names = cfg.names("sample.voxels.threshold");
  std::sort(names.begin(), names.end());
  auto key_of = [&](const std::string& name) {  // the key the file set, for error messages
    const std::string k = "sample.voxels.threshold." + name;
    return cfg.has(k + ".min") ? k + ".min" : k + ".max";
  };
  std::filesystem::path folder = cfg.string(folder_key);
  if (folder.empty()) {
    if (!names.empty())
      cfg.fail(key_of(names[0]), "grey-value windows need an image: set sample.voxels.folder = \"path/to/slices\"");
    return vg;
  }
  if (names.empty())
    cfg.fail(folder_key, fmt::format("the image needs at least one grey-value window: sample.voxels.threshold.NAME.min/max "
                                     "with NAME a declared group ({}) or pore", group_list(mat)));
  struct Window {
    std::string name;
    geom::GreyRange range;
  };
  std::vector<Window> windows;
  for (const auto& name : names) {
    const std::string k = "sample.voxels.threshold." + name;
    const int label = name == "pore" ? kPoreLabel : mat.group_index(name);
    if (name != "pore" && label < 0)
      cfg.fail(key_of(name), fmt::format("'{}' is neither a declared group ({}) nor pore", name, group_list(mat)));
    const long lo = cfg.integer(k + ".min"), hi = cfg.integer(k + ".max");
    if (lo > hi) cfg.fail(k + ".max", fmt::format("max = {} is below min = {}; a window holds min <= grey value <= max", hi, lo));
    windows.push_back({name, geom::GreyRange{static_cast<std::uint16_t>(lo), static_cast<std::uint16_t>(hi), label}});
  }
  std::sort(windows.begin(), windows.end(), [](const Window& a, const Window& b) { return a.range.min < b.range.min; });
  for (std::size_t n = 1; n < windows.size(); ++n) {
    const Window &a = windows[n - 1], &b = windows[n];
    if (b.range.min <= a.range.max)
      cfg.fail(key_of(b.name), fmt::format("window [{}, {}] of '{}' overlaps window [{}, {}] of '{}'; windows must be "
                                           "disjoint so that every grey value maps to one group",
                                           b.range.min, b.range.max, b.name, a.range.min, a.range.max, a.name));
  }
  if (folder.is_relative()) folder = std::filesystem::path(cfg.scenario_name()).parent_path() / folder;
  auto v3 = [&](const std::string& key) {
    const auto& l = cfg.real_list(key);
    return Vec3(l[0], l[1], l[2]);
  };
  try {
    vg.image = geom::read_pgm_stack(folder, v3("sample.voxels.origin"), v3("sample.voxels.spacing"));
  } catch (const InputError& e) {
    cfg.fail(folder_key, fmt::format("{} (allowed: a folder of equally sized 8- or 16-bit binary PGM slices, "
                                     "relative to the scenario file's folder)", e.what()));
  }
  for (const Window& w : windows) vg.windows.push_back(w.range);
  return vg;
}

std::vector<std::size_t> spatial_order(const std::vector<Vec3>& pos, const std::vector<Real>& rad) {
  const Real h = 2 * *std::max_element(rad.begin(), rad.end());
  Vec3 lo = pos[0];
  for (auto& p : pos) lo = lo.cwiseMin(p);
  std::vector<std::int64_t> key(pos.size());
  for (std::size_t i = 0; i < pos.size(); ++i) {
    const Vec3 c = (pos[i] - lo) / h;
    key[i] = (static_cast<std::int64_t>(c.z()) << 40) + (static_cast<std::int64_t>(c.y()) << 20) + static_cast<std::int64_t>(c.x());
  }
  std::vector<std::size_t> order(pos.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return key[a] < key[b]; });
  return order;
}

namespace {

void sort_spatially(std::vector<Vec3>& pos, std::vector<Real>& rad) {
  const std::vector<std::size_t> order = spatial_order(pos, rad);
  std::vector<Vec3> p2(pos.size());
  std::vector<Real> r2(pos.size());
  for (std::size_t i = 0; i < order.size(); ++i) {
    p2[i] = pos[order[i]];
    r2[i] = rad[order[i]];
  }
  pos.swap(p2);
  rad.swap(r2);
}

// Genesis equilibrium measure: mean |unbalanced force| over all particles / F_ref, with F_ref the
// mean force of the loaded interactions (PFC's "average ratio") but at least `floor`, the force a
// contact carries at the locked-in stress target. Without the floor the ratio of a loose packing
// (few, nearly unloaded contacts: a packing below jamming has no force network at zero stress)
// compares noise with noise and never settles.
Real genesis_force_ratio(const DemSystem& sys, Real floor) {
  const auto& P = sys.particles;
  if (P.size() == 0) return 0;
  Real unbalanced = 0, contact = 0;
  std::size_t loaded = 0;
  for (std::size_t i = 0; i < P.size(); ++i) unbalanced += P.force[i].norm();
  auto add = [&](const PairLoad& L) {
    const Real f = L.f.norm();
    if (f > 0) contact += f, ++loaded;
  };
  for (const auto& L : sys.pair_loads()) add(L);
  for (const auto& wc : sys.wall_contacts())
    for (const auto& L : wc.load) add(L);
  const Real ref = std::max(floor, loaded > 0 ? contact / static_cast<Real>(loaded) : Real(0));
  return unbalanced / static_cast<Real>(P.size()) / ref;
}

// Cycles in blocks of 50 steps until genesis_force_ratio < tol (or the step cap). Velocities are
// zeroed after each block (PFC's "calm"): the packing is static and its masses are arbitrary, so
// the kinetic energy is only a nuisance; without it free particles of a loose packing would keep
// flying between collisions. Returns the steps; `ratio` is the last measure.
long equilibrate(DemSystem& sys, Real tol, long max_steps, Real floor, Real& ratio, bool progress) {
  long s = 0;
  auto last = std::chrono::steady_clock::now();
  ratio = INFINITY;
  while (s < max_steps) {
    const long block = std::min<long>(50, max_steps - s);
    sys.run(block);
    s += block;
    ratio = genesis_force_ratio(sys, floor);
    for (auto& v : sys.particles.vel) v.setZero();
    for (auto& w : sys.particles.omega) w.setZero();
    if (ratio < tol) break;
    if (progress && std::chrono::steady_clock::now() - last > std::chrono::seconds(3)) {
      last = std::chrono::steady_clock::now();
      log::info("genesis: cycling, step {}, unbalanced-force ratio {:.3g} (tolerance {:g})", s, ratio, tol);
    }
  }
  return s;
}

// Mean stress (compression > 0) of all particles, over the container volume.
Real mean_stress(const DemSystem& sys, Real volume, int dim) {
  const Mat3 s = average_stress(sys, [](const Vec3&) { return true; }, volume);
  return dim == 3 ? -s.trace() / 3.0 : -(s(0, 0) + s(1, 1)) / 2.0;
}

// Scale factor of all radii that brings the mean stress of the particle contacts, estimated
// from their normal forces, p = sum F d / (dim V) (Love-Weber trace), down to `goal`.
Real shrink_factor_for_stress(const DemSystem& sys, Real goal, Real volume) {
  const auto& P = sys.particles;
  const auto pi = sys.neighbors().first(), pj = sys.neighbors().second();
  const int dim = sys.settings.dim;
  auto stress_at = [&](Real s) {
    Real sum = 0;
    for (std::size_t k = 0; k < pi.size(); ++k) {
      const Index a = pi[k], b = pj[k];
      const Real d = (P.pos[b] - P.pos[a]).norm();
      const Real overlap = s * (P.radius[a] + P.radius[b]) - d;
      if (overlap <= 0) continue;
      const int pt = sys.materials.pair(P.group[a], P.group[b]);
      Real f = 0;
      sys.materials.with_contact_law([&]<class Law>(std::type_identity<Law>) {
        f = Law::normal_force(sys.materials.contact_params<Law>()[pt], s * P.radius[a], s * P.radius[b], overlap, dim);
      });
      sum += f * d;
    }
    return sum / (dim * volume);
  };
  if (stress_at(1.0) <= goal) return 1.0;
  Real lo = 0.9, hi = 1.0;  // a 10% shrink opens every contact of a converged packing
  for (int k = 0; k < 50; ++k) {
    const Real mid = 0.5 * (lo + hi);
    (stress_at(mid) > goal ? hi : lo) = mid;
  }
  return lo;
}

// The container and packing the sample keys ask for, checked without making the packing.
struct SampleGeometry {
  geom::PackingSpec spec;
  bool cylinder = true;
  Real width = 0, height = 0, volume = 0;
};

SampleGeometry sample_geometry(const Config& cfg, int dim) {
  SampleGeometry g;
  const std::string shape = cfg.string("sample.shape");
  if (dim == 2 && shape == "cylinder")
    cfg.fail("sample.shape", "a 2D sample is a rectangle or a circle: use shape = \"box\" or \"disc\"");
  if (dim == 3 && shape == "disc")
    cfg.fail("sample.shape", "\"disc\" is a 2D shape (dem.dim = 2); a 3D sample is shape = \"cylinder\" or \"box\"");
  g.cylinder = shape != "box";  // cylinder (3D) or disc (2D): round about the z axis through the origin
  const Real rmin = cfg.real("sample.radius_min"), rmax = cfg.real("sample.radius_max");
  if (rmax < rmin)
    cfg.fail("sample.radius_max", fmt::format("{} m is below sample.radius_min = {} m; radius_max must be >= radius_min",
                                              rmax, rmin));
  geom::PackingSpec& spec = g.spec;
  spec.dim = dim;
  spec.radius_min = rmin;
  spec.radius_max = rmax;
  spec.porosity = cfg.real("sample.porosity");
  spec.seed = static_cast<std::uint64_t>(cfg.integer("sample.seed"));
  // Overlaps of 2e-4 mean radii carry forces of the order of a contact at the locked-in stress
  // (0.1 MPa x d^2 ~ 0.1 N for coal, kn ~ 2e6 N/m, r = 0.5 mm): the DEM cycling then only has to
  // settle them. The packer's default, 5e-3, left forces 25 times larger that 1000 steps of
  // damped cycling did not settle (an unjammed packing relaxes slowly near jamming).
  spec.overlap_tolerance = 2e-4;
  const Real width = g.cylinder ? cfg.real("sample.diameter") : cfg.real("sample.width");
  const Real H = g.cylinder && dim == 2 ? width : cfg.real("sample.height");  // a disc's height is its diameter
  if (width < 4 * rmax || H < 4 * rmax)
    cfg.fail(width < 4 * rmax ? (g.cylinder ? "sample.diameter" : "sample.width") : "sample.height",
             fmt::format("the sample must be at least 4 particle radii wide and high (radius_max = {} m)", rmax));
  if (g.cylinder) {
    spec.container = geom::PackingSpec::Container::Cylinder;
    spec.cyl_radius = 0.5 * width;
    spec.cyl_height = H;
    g.volume = kPi * 0.25 * width * width * (dim == 3 ? H : 1.0);  // 2D: per metre of thickness
  } else {
    if (dim == 3 && cfg.real("sample.depth") < 4 * rmax)
      cfg.fail("sample.depth", fmt::format("the sample must be at least 4 particle radii deep (radius_max = {} m)", rmax));
    spec.container = geom::PackingSpec::Container::Box;
    spec.box_lo = Vec3::Zero();
    spec.box_hi = dim == 3 ? Vec3(width, cfg.real("sample.depth"), H) : Vec3(width, H, 0);
    g.volume = dim == 3 ? width * cfg.real("sample.depth") * H : width * H;
  }
  g.width = width;
  g.height = H;
  const Real min_por = dim == 3 ? geom::kMinPorosity3D : geom::kMinPorosity2D;
  if (spec.porosity < min_por)
    cfg.fail("sample.porosity", fmt::format("{} is denser than a random packing can be made here; use >= {}", spec.porosity, min_por));
  try {
    geom::check_packing_spec(spec);
  } catch (const InputError& e) {
    cfg.fail("sample.radius_min", e.what());
  }
  return g;
}

// Group of the particles outside every region and window. Group tables come back from TOML in
// name order, not file order, so "the first group" would be a surprise (inclusion before
// matrix): with several groups the user must name it.
int default_group(const Config& cfg, const Materials& mat) {
  const std::string& name = cfg.string("sample.default_group");
  if (name.empty() && mat.groups() > 1)
    cfg.fail("sample.default_group", fmt::format("{} groups are declared; name the one that fills the sample (e.g. \"{}\")",
                                                 mat.groups(), mat.group_names[0]));
  if (name.empty()) return 0;
  const int g = mat.group_index(name);
  if (g < 0) cfg.fail("sample.default_group", fmt::format("'{}' is not a declared group ({}); declare it with [dem.group.{}]",
                                                          name, group_list(mat), name));
  return g;
}

}  // namespace

std::size_t install_sample_bonds(const Config& cfg, DemSystem& sys) {
  const Real gap = cfg.real("sample.bond_gap");
  Real rmax = 0;
  for (Real r : sys.particles.radius) rmax = std::max(rmax, r);
  if (gap > rmax)
    cfg.fail("sample.bond_gap", fmt::format("{:.6g} m is above the sample's largest particle radius ({:.6g} m): bonds "
                                            "join neighbours across small gaps; give at most that",
                                            gap, rmax));
  return sys.install_bonds(gap);
}

Real crushing_stress(const Config& cfg) {
  const int dim = static_cast<int>(cfg.integer("dem.dim"));
  const Materials mat = build_materials(cfg);
  const Real r = 0.5 * (cfg.real("sample.radius_min") + cfg.real("sample.radius_max"));
  Real force = 0;
  mat.with_contact_law([&]<class Law>(std::type_identity<Law>) {
    for (const auto& p : mat.contact_params<Law>()) force = std::max(force, Law::normal_force(p, r, r, 0.5 * r, dim));
  });
  return force / (dim == 3 ? 4 * r * r : 2 * r);
}

void refuse_crushing_stress(const Config& cfg, const std::string& key) {
  const Real limit = crushing_stress(cfg);
  if (cfg.real(key) >= limit)
    cfg.fail(key, fmt::format("{:.4g} Pa would crush the sample: at {:.4g} Pa the contacts between particles of the mean "
                              "radius already overlap by half a radius (dem.contact_law = \"{}\", its stiffest pair in "
                              "[dem.contact.*]); give a stress below that (rock: up to a few hundred MPa)",
                              cfg.real(key), limit, cfg.string("dem.contact_law")));
}

void validate_dem_sample(const Config& cfg) {
  const DemSettings settings = build_settings(cfg);
  const Materials mat = build_materials(cfg);
  sample_geometry(cfg, settings.dim);
  read_voxel_groups(cfg, mat);
  std::vector<int> region_group;
  read_regions(cfg, mat, region_group);
  default_group(cfg, mat);
  refuse_crushing_stress(cfg, "sample.locked_in_stress");
}

SampleInfo build_sample(const Config& cfg, DemSystem& sys) {
  const auto t0 = std::chrono::steady_clock::now();
  SampleInfo info;
  const int dim = sys.settings.dim;
  info.dim = dim;
  info.axis = dim == 3 ? 2 : 1;
  const SampleGeometry geo = sample_geometry(cfg, dim);
  const geom::PackingSpec& spec = geo.spec;
  info.cylinder = geo.cylinder;
  info.volume = geo.volume;
  const Real H = geo.height, width = geo.width;
  const VoxelGroups voxels = read_voxel_groups(cfg, sys.materials);  // before the packing: bad input fails fast
  geom::Packing pk;
  try {
    pk = geom::dense_random_packing(spec);
  } catch (const InputError& e) {
    cfg.fail("sample.porosity", e.what());
  }
  info.packing_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  sort_spatially(pk.position, pk.radius);

  // Groups: default, then regions (the last containing region wins), then voxel windows.
  std::vector<int> region_group;
  const auto regions = read_regions(cfg, sys.materials, region_group);
  std::vector<std::size_t> assigned;
  auto groups = geom::assign_groups(pk.position, regions, region_group, default_group(cfg, sys.materials), &assigned);
  // A region in the wrong place or units (mm for m) would leave its inclusion out without a word.
  const auto region_names = sorted_region_names(cfg);
  for (std::size_t k = 0; k < assigned.size(); ++k)
    if (assigned[k] == 0)
      log::warn("sample.region.{} (group '{}', {}): no particle centre took its group: it lies outside the sample, "
                "holds no centre (smaller than a particle) or later regions cover it; check its position and size "
                "(in m)",
                region_names[k], sys.materials.group_names[static_cast<std::size_t>(region_group[k])],
                cfg.string("sample.region." + region_names[k] + ".shape"));
  constexpr int kUnlabelled = -2;
  if (!voxels.empty()) {
    const auto label = geom::label_points(voxels.image, pk.position, voxels.windows, kUnlabelled);
    // The voxel layers (rounded index per axis) that the centres inside the image span: a spacing far
    // too large (km for mm) puts the whole sample in one layer, so every grain took the groups of one
    // row of the image, without a word (fuzzed, session 49).
    const auto& img = voxels.image;
    Vec3 layer_lo = Vec3::Constant(std::numeric_limits<Real>::infinity()), layer_hi = -layer_lo;
    std::size_t inside = 0, regrouped = 0;
    for (std::size_t i = 0; i < groups.size(); ++i) {
      if (img.contains(pk.position[i])) {
        ++inside;
        for (int a = 0; a < 3; ++a) {
          const Real layer = std::floor((pk.position[i][a] - img.origin[a]) / img.spacing[a] + 0.5);
          layer_lo[a] = std::min(layer_lo[a], layer);
          layer_hi[a] = std::max(layer_hi[a], layer);
        }
      }
      if (label[i] >= 0) {
        groups[i] = label[i];
        ++regrouped;
      }
    }
    if (inside == 0)
      log::warn("sample.voxels: no particle centre lies in the image (check sample.voxels.origin and spacing, in m)");
    const int n_axis[3] = {img.nx, img.ny, img.nz};
    for (int a = 0; a < dim && inside > 0; ++a)
      if (n_axis[a] >= 2 && layer_lo[a] == layer_hi[a])
        log::warn("sample.voxels: every particle centre in the image lies in one voxel layer along {} (spacing {:.4g} "
                  "m, {} layers): the image does not resolve the sample along {}; check sample.voxels.spacing (in m)",
                  "xyz"[a], img.spacing[a], n_axis[a], "xyz"[a]);
    log::info("sample.voxels: {} of {} particle centres in the image, {} assigned a group from it", inside,
              groups.size(), regrouped);
  }

  auto& P = sys.particles;
  P.resize(pk.position.size());
  for (std::size_t i = 0; i < P.size(); ++i) {
    P.pos[i] = pk.position[i];
    P.radius[i] = pk.radius[i];
    P.group[i] = groups[i];
    P.set_mass_from_density(i, sys.materials.density[groups[i]], dim);
  }

  // Rigid vessel.
  sys.walls.clear();
  auto plane = [&](const char* name, Vec3 point, Vec3 normal) {
    Wall w;
    w.name = name;
    w.point = point;
    w.normal = normal;
    w.friction = 0;
    sys.walls.push_back(w);
  };
  if (info.cylinder) {
    Wall c;
    c.kind = Wall::Kind::CylinderInside;
    c.name = "vessel";
    c.point = Vec3::Zero();
    c.normal = Vec3::UnitZ();
    c.radius = 0.5 * width;
    c.friction = 0;
    sys.walls.push_back(c);
    if (dim == 3) {  // in 2D the disks lie at z = 0: a plane there would touch every one
      plane("bottom", Vec3::Zero(), Vec3::UnitZ());
      plane("top", Vec3(0, 0, H), -Vec3::UnitZ());
    }
  } else {
    const Vec3 hi = spec.box_hi;
    plane("x-", Vec3::Zero(), Vec3::UnitX());
    plane("x+", hi, -Vec3::UnitX());
    plane("y-", Vec3::Zero(), Vec3::UnitY());
    plane("y+", hi, -Vec3::UnitY());
    if (dim == 3) {
      plane("z-", Vec3::Zero(), Vec3::UnitZ());
      plane("z+", hi, -Vec3::UnitZ());
    }
  }

  // Frictionless genesis: the contact friction is restored before bonding.
  const Materials saved = sys.materials;
  for_each_law(ContactLaws{}, [&]<class Law>(std::type_identity<Law>) {
    for (auto& p : sys.materials.contact_params<Law>()) p.fric = 0;
  });
  const int bond_law = sys.materials.bond_law;
  sys.materials.set_bond_law<NoBond>();
  Real rmean = 0;
  for (Real r : P.radius) rmean += r;
  rmean /= static_cast<Real>(P.size());
  sys.settings.skin = cfg.real("sample.genesis_tolerance") > 0 ? cfg.real("dem.skin_ratio") * rmean : 0;
  sys.initialise();
  // A density so small that the masses underflow (1e-300 kg/m^3), or a contact modulus that
  // overflows, gives no step: the packing went NaN at step 0, advised to lower the time step.
  auto genesis_step = [&] { return 0.8 * checked_critical_time_step(cfg, sys, "genesis's time step"); };
  sys.settings.dt = genesis_step();
  refuse_gravity_jump(cfg, sys);
  const Real tol = cfg.real("sample.genesis_tolerance");
  const long max_steps = cfg.integer("sample.genesis_max_steps");
  const Real target = cfg.real("sample.locked_in_stress");
  // Force of one contact at the target stress: p d^2 (2D: p d x 1 m), d the mean diameter.
  const Real floor = target * (dim == 3 ? 4 * rmean * rmean : 2 * rmean);
  const bool progress = P.size() > 20000;
  // Locked-in stress (PFC genesis step 3), straight from the packer's overlaps: shrink all radii
  // by the factor that brings the contact-force estimate of the mean stress to half the target
  // (bisection, no cycling), cycle to equilibrium, measure; repeat if still above the target.
  // The packer leaves overlaps below 0.5% of a radius, so equilibrating before the shrink (as
  // PFC does after its own expansion) would only relax stress that the shrink removes anyway.
  long steps = 0;
  Real shrink = 1, p = 0, ratio = 0;
  for (int it = 0; it < 4; ++it) {
    const Real s = shrink_factor_for_stress(sys, 0.5 * target, info.volume);
    if (s < 1) {
      shrink *= s;
      for (std::size_t i = 0; i < P.size(); ++i) {
        P.radius[i] *= s;
        P.set_mass_from_density(i, sys.materials.density[P.group[i]], dim);
      }
      sys.rebuild_neighbors();
      sys.settings.dt = genesis_step();
      refuse_gravity_jump(cfg, sys);
    }
    steps += equilibrate(sys, tol, max_steps, floor, ratio, progress);
    p = mean_stress(sys, info.volume, dim);
    if (p <= target) break;
  }
  info.locked_in_stress = p;
  info.unbalanced_force_ratio = ratio;
  info.equilibrium_reached = ratio < tol;
  info.coordination_contacts = 2.0 * static_cast<Real>(contacts_touching(sys)) / static_cast<Real>(P.size());
  info.genesis_steps = steps;
  if (p > target)
    log::warn("genesis: locked-in stress {:.3g} Pa is still above sample.locked_in_stress = {:.3g} Pa after 4 reductions", p, target);
  if (!info.equilibrium_reached)
    log::warn("genesis: no equilibrium after {} steps: unbalanced-force ratio {:.3g} > sample.genesis_tolerance = {:g} "
              "(raise sample.genesis_max_steps)",
              steps, ratio, tol);

  {  // Does the packing match the request? Say why not.
    Real solid = 0;
    for (Real r : P.radius) solid += dim == 3 ? 4.0 / 3.0 * kPi * r * r * r : kPi * r * r;
    const Real porosity = 1.0 - solid / info.volume;
    if (porosity > spec.porosity + 0.005)
      log::warn("genesis: porosity {:.3f} instead of sample.porosity = {:g}: {}; radii shrunk by {:.2g}% in all to bring "
                "the locked-in stress below {:.3g} Pa. Walls loosen a packing within about one particle diameter, so a "
                "sample {:.0f} mean diameters wide needs a higher porosity (or smaller particles)",
                porosity, spec.porosity,
                pk.converged ? "the packer reached it" : "the packer jammed before it (overlaps left)",
                100 * (1 - shrink), target, width / (2 * rmean));
  }

  // Bonds, with the real contact properties back.
  sys.materials = saved;
  sys.materials.bond_law = bond_law;
  if (!voxels.empty()) {  // pores, from the settled positions
    const auto label = geom::label_points(voxels.image, P.pos, voxels.windows, kUnlabelled);
    std::vector<char> remove(P.size());
    std::size_t removed = 0;
    for (std::size_t i = 0; i < P.size(); ++i) {
      remove[i] = label[i] == kPoreLabel;
      removed += remove[i];
    }
    if (removed > 0) {
      remove_particles(sys, remove);
      log::info("sample.voxels: {} particles removed in pore voxels", removed);
    }
    info.pore_particles = removed;
  }
  if (sys.materials.has_bonds()) info.bonds = install_sample_bonds(cfg, sys);
  {  // Floaters: particles held by fewer than 3 (2D: 2) bonds (PFC counts contacts; we report them).
    std::vector<int> degree(P.size(), 0);
    for (std::size_t b = 0; b < sys.bonds.i.size(); ++b) {
      ++degree[sys.bonds.i[b]];
      ++degree[sys.bonds.j[b]];
    }
    for (int d : degree) info.floaters += d < (dim == 3 ? 3 : 2);
  }
  Real solid = 0;
  for (Real r : P.radius) solid += dim == 3 ? 4.0 / 3.0 * kPi * r * r * r : kPi * r * r;
  info.porosity = 1.0 - solid / info.volume;
  // A packing looser than a random dense one leaves grains apart: the bonds do not make a rock (a
  // porosity of 0.9 gave 115 floaters of 116 disks and ran on silently).
  if (sys.materials.has_bonds() && P.size() > 0 && 4 * info.floaters > P.size())
    log::warn("sample: {} of {} particles ({:.0f}%) are held by fewer than {} bonds: at porosity {:.3f} (sample.porosity "
              "= {:g}) the grains barely touch and the bonds make a loose, partly disconnected rock. Dense random "
              "packings reach about {}: use a lower sample.porosity or a wider sample.bond_gap",
              info.floaters, P.size(), 100.0 * static_cast<Real>(info.floaters) / static_cast<Real>(P.size()),
              dim == 3 ? 3 : 2, info.porosity, spec.porosity, dim == 3 ? "0.36-0.42 in 3D" : "0.16-0.20 in 2D");

  // Remove the vessel; the sample starts at rest with zero displacement.
  sys.walls.clear();
  for (std::size_t i = 0; i < P.size(); ++i) {
    P.vel[i].setZero();
    P.omega[i].setZero();
    P.disp[i].setZero();
  }
  sys.time = 0;
  sys.step_count = 0;
  sys.cracks = CrackLog{};
  sys.initialise();
  info.height = H;
  info.width = width;
  info.area = dim == 2 ? width : (info.cylinder ? kPi * 0.25 * width * width : width * cfg.real("sample.depth"));
  info.genesis_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  info.coordination_bonds = P.size() > 0 ? 2.0 * static_cast<Real>(info.bonds) / static_cast<Real>(P.size()) : 0;
  log::info("sample: {} particles, {} bonds, porosity {:.3f}, locked-in stress {:.3g} Pa, {} floaters, genesis {} steps in {:.1f} s",
            P.size(), info.bonds, info.porosity, info.locked_in_stress, info.floaters, steps, info.genesis_seconds);
  log::info("sample: packing {:.1f} s; equilibrium {} (unbalanced-force ratio {:.2g}, tolerance {:g}); coordination {:.2f} "
            "bonds and {:.2f} touching contacts per particle",
            info.packing_seconds, info.equilibrium_reached ? "reached" : "NOT reached", info.unbalanced_force_ratio, tol,
            info.coordination_bonds, info.coordination_contacts);
  return info;
}

void add_platens(DemSystem& sys, const SampleInfo& info, Real friction) {
  const auto& P = sys.particles;
  Real lo = std::numeric_limits<Real>::infinity(), hi = -lo;
  for (std::size_t i = 0; i < P.size(); ++i) {
    lo = std::min(lo, P.pos[i][info.axis] - P.radius[i]);
    hi = std::max(hi, P.pos[i][info.axis] + P.radius[i]);
  }
  Vec3 n = Vec3::Zero();
  n[info.axis] = 1;
  Wall bottom, top;
  bottom.name = "platen_bottom";
  bottom.point = lo * n;
  bottom.normal = n;
  bottom.friction = friction;
  top.name = "platen_top";
  top.point = hi * n;
  top.normal = -n;
  top.friction = friction;
  sys.walls.push_back(bottom);
  sys.walls.push_back(top);
  sys.initialise();
}

}  // namespace ff::dem
