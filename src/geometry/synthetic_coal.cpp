#include "geometry/synthetic_coal.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "core/error.hpp"
#include "geometry/mesh_primitives.hpp"

namespace ff::geom {

namespace {

// Uniform in [a, b) from the top 53 bits (the same on every platform, unlike std:: distributions).
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : g_(seed) {}
  Real uniform(Real a, Real b) { return a + (b - a) * static_cast<Real>(g_() >> 11) * 0x1.0p-53; }

 private:
  std::mt19937_64 g_;
};

Real deg(Real d) { return d * kPi / 180.0; }

Quat rotation_zx(Real about_z, Real about_x) {
  return Quat(Eigen::AngleAxis<Real>(about_z, Vec3::UnitZ()) * Eigen::AngleAxis<Real>(about_x, Vec3::UnitX()));
}

Real ellipsoid_volume(const Ellipsoid& e) { return 4.0 / 3.0 * kPi * e.semi_axes.prod(); }

// Factor by which an icosphere refined `subdivisions` times must be scaled to enclose the volume
// of its sphere (the inscribed polyhedron is smaller).
Real icosphere_volume_scale(int subdivisions) {
  const TriangleMesh m = make_ellipsoid_mesh(Vec3::Zero(), Vec3::Ones(), Quat::Identity(), subdivisions);
  return std::cbrt(4.0 / 3.0 * kPi / mesh_volume(m));
}

// Placement works on "check bodies": each ellipsoid enlarged to enclose its surface mesh (the
// coarsest one written, 2 subdivisions) plus a gap, so that disjoint check bodies give disjoint
// closed shells and valid ray parity in point-in-mesh. Checks sample the check body's surface
// (642 points): enough for bodies whose gap is a few percent of their size.
class Placer {
 public:
  Placer(Real radius, Real height, Real gap)
      : radius_(radius), height_(height), gap_(gap), scale_(icosphere_volume_scale(2)),
        unit_(make_ellipsoid_mesh(Vec3::Zero(), Vec3::Ones(), Quat::Identity(), 3).vertices) {}

  Ellipsoid check_body(const Ellipsoid& e) const {
    return Ellipsoid{e.c, e.semi_axes * scale_ + Vec3::Constant(gap_), e.orientation};
  }
  std::vector<Vec3> surface(const Ellipsoid& body) const {
    std::vector<Vec3> p;
    p.reserve(unit_.size());
    for (const Vec3& u : unit_) p.push_back(body.c + body.orientation * body.semi_axes.cwiseProduct(u));
    return p;
  }
  // Every sampled point satisfies `inside(p)`.
  template <class Pred>
  bool all_points(const Ellipsoid& e, Pred inside) const {
    for (const Vec3& p : surface(check_body(e)))
      if (!inside(p)) return false;
    return true;
  }
  bool in_cylinder(const Ellipsoid& e) const {
    return all_points(e, [&](const Vec3& p) {
      return p.head<2>().norm() <= radius_ && p.z() >= 0 && p.z() <= height_;
    });
  }
  bool overlaps(const Ellipsoid& a, const Ellipsoid& b) const {
    const Ellipsoid ca = check_body(a), cb = check_body(b);
    const Aabb ba = ca.bounds(), bb = cb.bounds();
    if ((ba.hi.array() < bb.lo.array()).any() || (bb.hi.array() < ba.lo.array()).any()) return false;
    if (ca.contains(cb.c) || cb.contains(ca.c)) return true;
    for (const Vec3& p : surface(ca))
      if (cb.contains(p)) return true;
    for (const Vec3& p : surface(cb))
      if (ca.contains(p)) return true;
    return false;
  }
  bool overlaps_any(const Ellipsoid& e, const std::vector<Ellipsoid>& placed) const {
    return std::any_of(placed.begin(), placed.end(), [&](const Ellipsoid& o) { return overlaps(e, o); });
  }

 private:
  Real radius_, height_, gap_, scale_;
  std::vector<Vec3> unit_;
};

// Adds ellipsoids drawn by `draw(rng, size)` until their volume reaches `fraction` of the
// cylinder, then shrinks the last one about its centre (it stays inside and disjoint) to hit the
// target exactly. Random sequential addition jams below the target with large bodies, so the size
// factor drops by 5% after every 500 failed draws in a row (smaller bodies fill the gaps).
template <class Draw, class Accept>
std::vector<Ellipsoid> fill(const SyntheticCoalSpec& spec, Real fraction, const Placer& placer, Rng& rng, Draw draw,
                            Accept accept) {
  const Real R = 0.5 * spec.diameter, H = spec.height;
  const Real target = fraction * kPi * R * R * H;
  std::vector<Ellipsoid> placed;
  Real volume = 0, size = 1;
  constexpr int kMaxAttempts = 100000;
  for (int attempt = 0, failures = 0; attempt < kMaxAttempts; ++attempt) {
    Ellipsoid e = draw(rng, size);
    if (!placer.in_cylinder(e) || !accept(e) || placer.overlaps_any(e, placed)) {
      if (++failures == 500) {
        failures = 0;
        size = std::max(0.3, 0.95 * size);
      }
      continue;
    }
    failures = 0;
    const Real v = ellipsoid_volume(e);
    if (volume + v >= target) {
      e.semi_axes *= std::cbrt((target - volume) / v);
      placed.push_back(e);
      return placed;
    }
    placed.push_back(e);
    volume += v;
  }
  throw Error(fmt::format("synthetic {} sample: only {:.1f}% of {:.1f}% inclusion volume placed after {} attempts",
                          to_string(spec.kind), 100 * volume / (kPi * R * R * H), 100 * fraction, kMaxAttempts));
}

// C1: thin vertical lenses, semi-axes (width, thickness, height) in the body frame, striking
// within +-15 deg of one random direction and dipping at most 5 deg from vertical.
std::vector<Ellipsoid> c1_veins(const SyntheticCoalSpec& spec, const Placer& placer, Rng& rng) {
  const Real R = 0.5 * spec.diameter, H = spec.height;
  const Real strike = rng.uniform(0, kPi);
  auto draw = [&](Rng& r, Real size) {
    const Vec3 semi = size * Vec3(r.uniform(0.35, 0.60) * R, r.uniform(0.10, 0.16) * R, r.uniform(0.30, 0.45) * H);
    const Quat q = rotation_zx(strike + deg(r.uniform(-15, 15)), deg(r.uniform(-5, 5)));
    const Real rho = R * std::sqrt(r.uniform(0, 1)), phi = r.uniform(0, 2 * kPi);
    const Vec3 c(rho * std::cos(phi), rho * std::sin(phi), r.uniform(semi.z(), H - semi.z()));
    return Ellipsoid{c, semi, q};
  };
  return fill(spec, kC1InclusionFraction, placer, rng, draw, [](const Ellipsoid&) { return true; });
}

// C4: blobs (radial, tangential, axial semi-axes) hugging the lateral surface in the central part.
std::vector<Ellipsoid> c4_blobs(const SyntheticCoalSpec& spec, const Placer& placer, Rng& rng) {
  const Real R = 0.5 * spec.diameter, H = spec.height;
  const Real r_in = (1 - kC4SurfaceBand) * R, z_lo = kC4EndMargin * H, z_hi = (1 - kC4EndMargin) * H;
  auto draw = [&](Rng& r, Real size) {
    const Vec3 semi = size * Vec3(r.uniform(0.16, 0.20) * R, r.uniform(0.35, 0.50) * R, r.uniform(0.45, 0.65) * R);
    const Real phi = r.uniform(0, 2 * kPi);
    const Quat q = Quat(Eigen::AngleAxis<Real>(phi, Vec3::UnitZ())) *
                   Quat(Eigen::AngleAxis<Real>(deg(r.uniform(-20, 20)), Vec3::UnitX()));
    const Real rho = r.uniform(r_in + semi.x(), R - semi.x());
    const Vec3 c(rho * std::cos(phi), rho * std::sin(phi), r.uniform(z_lo + semi.z(), z_hi - semi.z()));
    return Ellipsoid{c, semi, q};
  };
  auto in_band = [&](const Ellipsoid& e) {
    return placer.all_points(e, [&](const Vec3& p) { return p.head<2>().norm() >= r_in && p.z() >= z_lo && p.z() <= z_hi; });
  };
  return fill(spec, kC4InclusionFraction, placer, rng, draw, in_band);
}

// Small spherical pores in the matrix (radius 8% of the diameter, about two particle radii in
// the examples), clear of every inclusion.
std::vector<Sphere> pores(const SyntheticCoalSpec& spec, const std::vector<Ellipsoid>& inclusions, int count,
                          const Placer& placer, Rng& rng) {
  const Real R = 0.5 * spec.diameter, H = spec.height, rp = 0.08 * spec.diameter;
  std::vector<Sphere> out;
  for (int attempt = 0; attempt < 10000 && static_cast<int>(out.size()) < count; ++attempt) {
    const Real rho = (R - 2 * rp) * std::sqrt(rng.uniform(0, 1)), phi = rng.uniform(0, 2 * kPi);
    const Ellipsoid as_body{Vec3(rho * std::cos(phi), rho * std::sin(phi), rng.uniform(2 * rp, H - 2 * rp)),
                            Vec3::Constant(rp), Quat::Identity()};
    if (!placer.overlaps_any(as_body, inclusions)) out.push_back(Sphere{as_body.c, rp});
  }
  return out;
}

}  // namespace

std::string to_string(CoalSampleKind kind) { return kind == CoalSampleKind::C1 ? "c1" : "c4"; }

Real SyntheticCoal::inclusion_fraction() const {
  Real v = 0;
  for (const Ellipsoid& e : inclusions) v += ellipsoid_volume(e);
  const Real R = 0.5 * spec.diameter;
  return v / (kPi * R * R * spec.height);
}

SyntheticCoal make_synthetic_coal(const SyntheticCoalSpec& spec) {
  if (!(spec.diameter > 0) || !(spec.height > 0) || !std::isfinite(spec.diameter) || !std::isfinite(spec.height)) {
    throw InputError(fmt::format("synthetic coal sample: diameter {} m and height {} m must be positive",
                                 spec.diameter, spec.height));
  }
  SyntheticCoal coal;
  coal.spec = spec;
  Rng rng(spec.seed);
  const Placer placer(0.5 * spec.diameter, spec.height, 0.02 * 0.5 * spec.diameter);
  if (spec.kind == CoalSampleKind::C1) {
    coal.inclusions = c1_veins(spec, placer, rng);
    coal.pores = pores(spec, coal.inclusions, 3, placer, rng);
  } else {
    coal.inclusions = c4_blobs(spec, placer, rng);
    coal.pores = pores(spec, coal.inclusions, 2, placer, rng);
  }
  return coal;
}

TriangleMesh inclusion_surface(const SyntheticCoal& coal, int subdivisions) {
  if (subdivisions < 2) throw InputError("inclusion_surface: subdivisions must be >= 2 (the placement gap assumes it)");
  const Real scale = icosphere_volume_scale(subdivisions);
  TriangleMesh all;
  for (const Ellipsoid& e : coal.inclusions) {
    const TriangleMesh m = make_ellipsoid_mesh(e.c, e.semi_axes * scale, e.orientation, subdivisions);
    const int offset = static_cast<int>(all.vertices.size());
    all.vertices.insert(all.vertices.end(), m.vertices.begin(), m.vertices.end());
    for (const auto& t : m.triangles) all.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  }
  return all;
}

VoxelImage voxelize(const SyntheticCoal& coal, Real voxel_size) {
  if (!(voxel_size > 0) || !std::isfinite(voxel_size)) {
    throw InputError(fmt::format("voxel size {} m must be positive", voxel_size));
  }
  const Real D = coal.spec.diameter, H = coal.spec.height, R = 0.5 * D;
  VoxelImage img;
  img.nx = img.ny = std::max(1, static_cast<int>(std::lround(D / voxel_size)));
  img.nz = std::max(1, static_cast<int>(std::lround(H / voxel_size)));
  img.spacing = Vec3(D / img.nx, D / img.ny, H / img.nz);
  img.origin = Vec3(-R, -R, 0) + 0.5 * img.spacing;
  img.value.assign(static_cast<std::size_t>(img.nx) * img.ny * img.nz, CoalGreyValues::outside);
  std::vector<Aabb> boxes;
  for (const Ellipsoid& e : coal.inclusions) boxes.push_back(e.bounds());
  for (int k = 0; k < img.nz; ++k)
    for (int j = 0; j < img.ny; ++j)
      for (int i = 0; i < img.nx; ++i) {
        const Vec3 p = img.origin + Vec3(i, j, k).cwiseProduct(img.spacing);
        if (p.head<2>().squaredNorm() > R * R) continue;
        std::uint16_t v = CoalGreyValues::matrix;
        for (std::size_t n = 0; n < coal.inclusions.size(); ++n)
          if (boxes[n].contains(p) && coal.inclusions[n].contains(p)) v = CoalGreyValues::inclusion;
        for (const Sphere& s : coal.pores)
          if (s.contains(p)) v = CoalGreyValues::pore;
        img.value[img.index(i, j, k)] = v;
      }
  return img;
}

Real voxel_inclusion_fraction(const VoxelImage& image) {
  std::size_t inside = 0, inclusion = 0;
  for (std::uint16_t v : image.value) {
    inside += v != CoalGreyValues::outside;
    inclusion += v == CoalGreyValues::inclusion;
  }
  return inside == 0 ? 0.0 : static_cast<Real>(inclusion) / static_cast<Real>(inside);
}

}  // namespace ff::geom
