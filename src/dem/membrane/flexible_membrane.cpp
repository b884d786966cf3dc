#include "dem/membrane/flexible_membrane.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

#include "core/error.hpp"
#include "dem/laws.hpp"
#include "dem/neighbor_list.hpp"
#include "io/vtk.hpp"

namespace ff::dem {

namespace {
// Horizontal offset of x from the axis.
Vec3 radial(const Vec3& x, Real ax, Real ay) { return Vec3(x.x() - ax, x.y() - ay, 0); }

// Clips triangle (a, b, c) to z_lo <= z <= z_hi (Sutherland-Hodgman); returns the corner count.
int clip_to_slab(const Vec3& a, const Vec3& b, const Vec3& c, Real z_lo, Real z_hi, std::array<Vec3, 8>& poly) {
  std::array<Vec3, 8> tmp;
  poly[0] = a;
  poly[1] = b;
  poly[2] = c;
  int np = 3;
  for (int side = 0; side < 2 && np > 0; ++side) {
    const Real zc = side == 0 ? z_lo : z_hi;
    auto inside = [&](const Vec3& q) { return side == 0 ? q.z() >= z_lo : q.z() <= z_hi; };
    int nt = 0;
    for (int e = 0; e < np; ++e) {
      const Vec3 &P = poly[e], &Q = poly[(e + 1) % np];
      const bool ip = inside(P), iq = inside(Q);
      if (ip) tmp[nt++] = P;
      if (ip != iq) tmp[nt++] = P + (zc - P.z()) / (Q.z() - P.z()) * (Q - P);
    }
    np = nt;
    for (int e = 0; e < np; ++e) poly[e] = tmp[e];
  }
  return np;
}

// Grows the capacity to 1.25 n when it is below n (amortised: later rebuilds reuse it).
template <class T>
void reserve_headroom(std::vector<T>& v, std::size_t n) {
  if (v.capacity() < n) v.reserve(n + n / 4 + 16);
}

// Barycentric weights of q (in the plane of the triangle) on (a, b, c).
std::array<Real, 3> barycentric(const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 v0 = b - a, v1 = c - a, v2 = q - a;
  const Real d00 = v0.dot(v0), d01 = v0.dot(v1), d11 = v1.dot(v1), d20 = v2.dot(v0), d21 = v2.dot(v1);
  const Real den = d00 * d11 - d01 * d01;
  const Real v = (d11 * d20 - d01 * d21) / den, w = (d00 * d21 - d01 * d20) / den;
  return {1 - v - w, v, w};
}
}  // namespace

MembraneSettings membrane_around_cylinder(Real sample_radius, Real z_bottom, Real z_top, int n_theta, int n_z,
                                          Real clearance, Real length_factor) {
  MembraneSettings m;
  m.n_theta = n_theta;
  m.radius = membrane_circumradius(sample_radius * (1 + clearance), n_theta);
  m.height = length_factor * (z_top - z_bottom);
  m.z0 = 0.5 * (z_bottom + z_top) - 0.5 * m.height;
  m.n_z = n_z > 0 ? n_z : membrane_square_rows(m.radius, n_theta, m.height);
  return m;
}

int membrane_square_rows(Real radius, int n_theta, Real height) {
  const Real chord = 2 * radius * std::sin(kPi / n_theta);
  return std::max(1, static_cast<int>(std::lround(height / chord)));
}

FlexibleMembrane::FlexibleMembrane(const MembraneSettings& s) : s_(s) {
  auto bad = [](const char* what) { throw InputError(fmt::format("flexible membrane: {}", what)); };
  if (s.n_theta < 3) bad("n_theta must be >= 3 units around the circumference");
  if (s.n_z < 1) bad("n_z must be >= 1 row of units");
  if (!(s.radius > 0)) bad("radius must be > 0 (sample radius + clearance)");
  if (!(s.height > 0)) bad("height must be > 0 (longer than the sample)");
  if (!(s.pressure >= 0)) bad("pressure must be >= 0");
  if (!(s.v_max > 0)) bad("v_max must be > 0 (S000 used 0.01 m/s, above the platen speed)");
  if (!(s.relaxation > 0 && s.relaxation <= 1)) bad("relaxation (alpha_s) must be in (0, 1] (PFC default 0.8)");
  if (!(s.r_min > 0 && s.r_min < s.radius))
    bad("r_min must be in (0, radius): set it a little below the platen radius (free rows stop there)");
  if (!valid_boundary_friction(s.friction))
    bad("friction must be >= 0, or kGroupFriction (each particle's own group contact friction)");
  tol_ = 1e-9 * s.radius;
  const int nt = s.n_theta, nz = s.n_z;
  x_.resize(static_cast<std::size_t>(nt) * (nz + 1));
  for (int j = 0; j <= nz; ++j)
    for (int i = 0; i < nt; ++i) {
      const Real a = 2 * kPi * i / nt;
      x_[vertex_index(i, j)] =
          Vec3(s.axis_x + s.radius * std::cos(a), s.axis_y + s.radius * std::sin(a), s.z0 + s.height * j / nz);
    }
  xv_.assign(x_.size(), Vec3::Zero());
  x_build_ = x_;
  rdir_.resize(x_.size());
  for (std::size_t v = 0; v < x_.size(); ++v) rdir_[v] = radial(x_[v], s.axis_x, s.axis_y).normalized();
  ftv_.assign(x_.size(), 0);
  fcv_.assign(x_.size(), 0);
  kcv_.assign(x_.size(), 0);
  auto vi = [&](int i, int j) { return static_cast<Index>(vertex_index(i, j)); };
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nt; ++i) {
      tri_.push_back({vi(i, j), vi(i + 1, j), vi(i, j + 1)});          // T1, lower-left
      tri_.push_back({vi(i + 1, j), vi(i + 1, j + 1), vi(i, j + 1)});  // T2, upper-right
    }
  // Owner rule (METHODS.md 3): P(i,j) follows T1 of unit (i,j); the top row follows T2 of the
  // unit below.
  owner_.resize(x_.size());
  for (int j = 0; j <= nz; ++j)
    for (int i = 0; i < nt; ++i)
      owner_[vertex_index(i, j)] = static_cast<Index>(j < nz ? 2 * (j * nt + i) : 2 * ((nz - 1) * nt + i) + 1);
  const std::size_t ne = tri_.size();
  area_.assign(ne, 0);
  area_band_.assign(ne, 0);
  load_w_.assign(ne, {1.0 / 3, 1.0 / 3, 1.0 / 3});
  normal_.assign(ne, Vec3::Zero());
  centroid_.assign(ne, Vec3::Zero());
  fc_.assign(ne, 0);
  kc_.assign(ne, 0);
  vservo_.assign(ne, 0);
  ncontact_.assign(ne, 0);
  box_lo_.assign(ne, Vec3::Zero());
  box_hi_.assign(ne, Vec3::Zero());
  group_off_.assign(1, 0);
  update_geometry();
}

std::size_t FlexibleMembrane::vertex_index(int i, int j) const {
  const int nt = s_.n_theta;
  return static_cast<std::size_t>(j) * nt + static_cast<std::size_t>(((i % nt) + nt) % nt);
}

void FlexibleMembrane::set_pressure(Real p) {
  if (!(p >= 0)) throw InputError(fmt::format("flexible membrane: pressure must be >= 0 (got {})", p));
  s_.pressure = p;
}

void FlexibleMembrane::update_geometry() {
  for (std::size_t k = 0; k < tri_.size(); ++k) {
    const Vec3 &a = x_[tri_[k][0]], &b = x_[tri_[k][1]], &c = x_[tri_[k][2]];
    const Vec3 cr = (b - a).cross(c - a);
    const Real len = cr.norm();
    if (!(len > 0))
      throw NumericalError(fmt::format(
          "flexible membrane: element {} collapsed to zero area; lower its servo speed cap (triaxial.servo_velocity) or "
          "the time step (dem.time_step_safety)",
          k));
    area_[k] = 0.5 * len;
    centroid_[k] = (a + b + c) / 3.0;
    Vec3 n = cr / len;
    // Orient towards the axis (METHODS.md 3: flip if n . (c - axis point) > 0).
    if (n.dot(radial(centroid_[k], s_.axis_x, s_.axis_y)) > 0) n = -n;
    normal_[k] = n;
  }
}

Real FlexibleMembrane::servo_law(Real f_target, Real f_contact, Real k_contact, Real dt, Real alpha, Real v_max) {
  // PFC wall servo (Itasca PFC manual, "wall servo"), as written in METHODS.md 3.
  if (!(k_contact > 0)) return v_max;
  const Real v = alpha * (f_target + f_contact) / (k_contact * dt);
  return std::clamp(v, -v_max, v_max);
}

void FlexibleMembrane::find_candidates(std::span<const Vec3> pos, std::span<const Real> radius, Real skin) {
  // Keep the old candidates so contact history survives (same merge as the neighbour list).
  old_p_.swap(cand_p_);
  old_e_.swap(cand_e_);
  old_state_.swap(state_);
  cand_p_.clear();
  cand_e_.clear();
  group_off_.assign(1, 0);
  const std::size_t ne = tri_.size();
  Real r_max = 0;
  for (Real r : radius) r_max = std::max(r_max, r);
  const Real margin = r_max + skin;
  // Uniform grid over the element boxes inflated by the largest search distance.
  Vec3 lo = Vec3::Constant(std::numeric_limits<Real>::infinity()), hi = -lo;
  Real extent = 0;
  for (std::size_t k = 0; k < ne; ++k) {
    Vec3 bl = x_[tri_[k][0]], bh = bl;
    for (int c = 1; c < 3; ++c) {
      bl = bl.cwiseMin(x_[tri_[k][c]]);
      bh = bh.cwiseMax(x_[tri_[k][c]]);
    }
    box_lo_[k] = bl;
    box_hi_[k] = bh;
    extent = std::max(extent, (bh - bl).maxCoeff());
    lo = lo.cwiseMin(bl);
    hi = hi.cwiseMax(bh);
  }
  lo.array() -= margin;
  hi.array() += margin;
  Real h = std::max(extent, margin);
  std::array<long, 3> n{};
  auto dims = [&] {
    for (int d = 0; d < 3; ++d) n[d] = std::max(1L, static_cast<long>(std::ceil((hi[d] - lo[d]) / h)));
    return n[0] * n[1] * n[2];
  };
  while (dims() > static_cast<long>(64 * ne + 64)) h *= 1.5;  // bound the grid memory
  const long ncell = n[0] * n[1] * n[2];
  auto cell_of = [&](const Vec3& p, int d) {
    return std::clamp(static_cast<long>(std::floor((p[d] - lo[d]) / h)), 0L, n[d] - 1);
  };
  reserve_headroom(cell_off_, ncell + 1);
  cell_off_.assign(ncell + 1, 0);
  for (int pass = 0; pass < 2; ++pass) {
    for (std::size_t k = 0; k < ne; ++k) {
      const Vec3 bl = box_lo_[k].array() - margin, bh = box_hi_[k].array() + margin;
      for (long cz = cell_of(bl, 2); cz <= cell_of(bh, 2); ++cz)
        for (long cy = cell_of(bl, 1); cy <= cell_of(bh, 1); ++cy)
          for (long cx = cell_of(bl, 0); cx <= cell_of(bh, 0); ++cx) {
            const long cell = (cz * n[1] + cy) * n[0] + cx;
            if (pass == 0) ++cell_off_[cell + 1];
            else cell_elem_[cell_off_[cell]++] = static_cast<Index>(k);
          }
    }
    if (pass == 0) {
      for (long c = 0; c < ncell; ++c) cell_off_[c + 1] += cell_off_[c];
      reserve_headroom(cell_elem_, cell_off_[ncell]);
      cell_elem_.resize(cell_off_[ncell]);
    } else {  // the fill advanced each start to the next cell's start: shift back
      for (long c = ncell; c > 0; --c) cell_off_[c] = cell_off_[c - 1];
      cell_off_[0] = 0;
    }
  }
  // Each particle looks only at its own cell, whose elements are listed in increasing order:
  // candidates come out sorted by (particle, element).
  for (std::size_t i = 0; i < pos.size(); ++i) {
    const Vec3& x = pos[i];
    if ((x.array() < lo.array()).any() || (x.array() > hi.array()).any()) continue;
    const long cell = (cell_of(x, 2) * n[1] + cell_of(x, 1)) * n[0] + cell_of(x, 0);
    const Real reach = radius[i] + skin;
    const std::size_t before = cand_p_.size();
    for (std::int64_t e = cell_off_[cell]; e < cell_off_[cell + 1]; ++e) {
      const Index k = cell_elem_[e];
      if ((x.array() < box_lo_[k].array() - reach).any() || (x.array() > box_hi_[k].array() + reach).any()) continue;
      const TriClosest cp = closest_point_on_triangle(x, x_[tri_[k][0]], x_[tri_[k][1]], x_[tri_[k][2]]);
      if ((cp.point - x).squaredNorm() >= reach * reach) continue;
      cand_p_.push_back(static_cast<Index>(i));
      cand_e_.push_back(k);
    }
    if (cand_p_.size() > before) group_off_.push_back(static_cast<std::int64_t>(cand_p_.size()));
  }
  const std::size_t nc = cand_p_.size();
  // Headroom so that slowly growing lists do not allocate at every rebuild (no allocation in
  // the time loop once the contact set has settled).
  reserve_headroom(cand_p_, nc);
  reserve_headroom(cand_e_, nc);
  reserve_headroom(group_off_, group_off_.size());
  reserve_headroom(state_, nc);
  reserve_headroom(load_, nc);
  reserve_headroom(cp_, nc);
  reserve_headroom(dist_, nc);
  reserve_headroom(kn_, nc);
  reserve_headroom(touch_, nc);
  NeighborList::carry_over<ContactState>(old_p_, old_e_, old_state_, cand_p_, cand_e_, state_, ContactState{});
  load_.assign(nc, MembraneLoad{});
  cp_.resize(nc);
  dist_.assign(nc, 0);
  kn_.assign(nc, 0);
  touch_.assign(nc, 0);
  x_build_ = x_;
  motion_ = 0;
}

void FlexibleMembrane::remap_particles(std::span<const Index> new_of_old) {
  // Candidates ordered by (new particle, element): each particle's run keeps its element order,
  // so the per-particle gather (add_loads_to) and keep_contact() see the same runs as before.
  const std::size_t nc = cand_p_.size();
  std::vector<std::size_t> order(nc);
  for (std::size_t c = 0; c < nc; ++c) order[c] = c;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return new_of_old[cand_p_[a]] < new_of_old[cand_p_[b]];
  });
  auto permute = [&](auto& v) {
    if (v.size() != nc) return;  // scratch not sized yet
    auto copy = v;
    for (std::size_t c = 0; c < nc; ++c) v[c] = copy[order[c]];
  };
  for (auto& p : cand_p_) p = new_of_old[p];
  permute(cand_p_);
  permute(cand_e_);
  permute(state_);
  permute(load_);
  permute(cp_);
  permute(dist_);
  permute(kn_);
  permute(touch_);
  group_off_.assign(1, 0);
  for (std::size_t c = 0; c < nc; ++c)
    if (c + 1 == nc || cand_p_[c + 1] != cand_p_[c]) group_off_.push_back(static_cast<std::int64_t>(c + 1));
}

bool FlexibleMembrane::keep_contact(std::size_t c, std::size_t begin, std::size_t end) const {
  // One contact per local minimum of the particle's distance to the mesh (file comment).
  if (!touch_[c]) return false;
  const auto& tc = tri_[cand_e_[c]];
  const unsigned corners = feature_corners(cp_[c].feature);
  for (std::size_t o = begin; o < end; ++o) {
    if (o == c || !touch_[o]) continue;
    const auto& to = tri_[cand_e_[o]];
    auto has = [&](Index v) { return v == to[0] || v == to[1] || v == to[2]; };
    int shared = 0;
    bool holds_feature = true;
    for (int q = 0; q < 3; ++q) {
      const bool h = has(tc[q]);
      shared += h;
      if ((corners >> q & 1u) && !h) holds_feature = false;
    }
    if (shared == 0) continue;
    // An edge/vertex point that another element containing it beats is not a local minimum.
    if (cp_[c].feature != TriFeature::Face && holds_feature && dist_[o] < dist_[c] - tol_) return false;
    // The same point found through two adjacent elements counts once (the first one).
    if (o < c && (cp_[o].point - cp_[c].point).squaredNorm() <= tol_ * tol_) return false;
  }
  return true;
}

template <class Law>
void FlexibleMembrane::compute_forces(const MembraneParticles& p, std::span<const typename Law::Params> pair_params,
                                      int n_groups, Real dt) {
  const std::size_t ngrp = group_off_.size() - 1;
  const std::size_t nc = cand_p_.size();
  const long long ngrp_ll = static_cast<long long>(ngrp);
#pragma omp parallel for schedule(static) if (nc > s_.parallel_min)
  for (long long gi = 0; gi < ngrp_ll; ++gi) {
    const std::size_t b = group_off_[gi], e = group_off_[gi + 1];
    const Index i = cand_p_[b];
    const Vec3& x = p.pos[i];
    const Real r = p.radius[i];
    for (std::size_t c = b; c < e; ++c) {
      const auto& t = tri_[cand_e_[c]];
      cp_[c] = closest_point_on_triangle(x, x_[t[0]], x_[t[1]], x_[t[2]]);
      const Vec3 d = cp_[c].point - x;
      dist_[c] = d.norm();
      touch_[c] = dist_[c] < r && -d.dot(normal_[cand_e_[c]]) > 0;
    }
    for (std::size_t c = b; c < e; ++c) {
      MembraneLoad& out = load_[c];
      ContactGeom g;
      const std::size_t k = cand_e_[c];
      if (!keep_contact(c, b, e) || !ball_triangle(g, cp_[c], x, r, normal_[k])) {
        state_[c].fs.setZero();
        out = MembraneLoad{};
        kn_[c] = 0;
        continue;
      }
      const auto& t = tri_[k];
      const auto& w = cp_[c].bary;
      const Vec3 v_surface = w[0] * xv_[t[0]] + w[1] * xv_[t[1]] + w[2] * xv_[t[2]];
      contact_kinematics(g, x, p.vel[i], p.omega[i], g.xc, v_surface, Vec3::Zero(), dt);
      const int grp = p.group[i];
      auto prm = pair_params[static_cast<std::size_t>(grp) * n_groups + grp];
      prm.fric = boundary_friction(s_.friction, prm.fric);
      Real fn;
      const Vec3 f = Law::force(prm, g, state_[c], dt, 3, fn);  // force on the element
      out.f = f;
      out.m = -(g.rA + 0.5 * g.gap) * g.n.cross(f);  // moment on the particle
      out.xc = g.xc;
      kn_[c] = Law::normal_stiffness_at(prm, r, 0, -g.gap, 3);
    }
  }
  // Element totals in candidate order (deterministic, serial: a few hundred elements).
  std::fill(fc_.begin(), fc_.end(), 0.0);
  std::fill(kc_.begin(), kc_.end(), 0.0);
  std::fill(ncontact_.begin(), ncontact_.end(), 0);
  for (std::size_t c = 0; c < nc; ++c) {
    if (kn_[c] == 0) continue;
    const std::size_t k = cand_e_[c];
    fc_[k] += load_[c].f.dot(normal_[k]);
    kc_[k] += kn_[c];
    ++ncontact_[k];
  }
}

// One instance per registered contact law (taking the addresses instantiates them).
namespace {
template <class... L> auto instantiate_compute_forces(LawList<L...>) { return std::tuple{&FlexibleMembrane::compute_forces<L>...}; }
[[maybe_unused]] const auto kComputeForcesOfEveryLaw = instantiate_compute_forces(ContactLaws{});
}  // namespace

void FlexibleMembrane::add_loads_to(std::span<Vec3> force, std::span<Vec3> moment) const {
  for (std::size_t c = 0; c < cand_p_.size(); ++c) {
    force[cand_p_[c]] -= load_[c].f;
    moment[cand_p_[c]] += load_[c].m;
  }
}

void FlexibleMembrane::vertex_velocities_owner() {
  for (std::size_t v = 0; v < x_.size(); ++v) {
    const Index k = owner_[v];
    xv_[v] = vservo_[k] * normal_[k];
  }
}

void FlexibleMembrane::vertex_velocities_nodal(Real dt) {
  // Loads lumped at the vertices (MembraneVertexRule::Nodal), summed in a fixed order.
  std::fill(ftv_.begin(), ftv_.end(), 0.0);
  std::fill(fcv_.begin(), fcv_.end(), 0.0);
  std::fill(kcv_.begin(), kcv_.end(), 0.0);
  for (std::size_t k = 0; k < tri_.size(); ++k)
    for (int q = 0; q < 3; ++q) ftv_[tri_[k][q]] += s_.pressure * area_band_[k] * load_w_[k][q];
  for (std::size_t c = 0; c < cand_p_.size(); ++c) {
    if (kn_[c] == 0) continue;
    const auto& t = tri_[cand_e_[c]];
    const Real fn = load_[c].f.dot(normal_[cand_e_[c]]);
    for (int q = 0; q < 3; ++q) {
      fcv_[t[q]] += cp_[c].bary[q] * fn;
      kcv_[t[q]] += cp_[c].bary[q] * kn_[c];
    }
  }
  for (std::size_t v = 0; v < x_.size(); ++v)
    xv_[v] = -servo_law(ftv_[v], fcv_[v], kcv_[v], dt, s_.relaxation, s_.v_max) * rdir_[v];
}

void FlexibleMembrane::move(Real dt, Real z_bottom, Real z_top) {
  if (!(z_bottom < z_top && dt > 0))
    throw Error(fmt::format("internal: membrane move needs dt > 0 and z_bottom < z_top (got {}, {}, {})", dt,
                            z_bottom, z_top));
  // Loaded part of each element (file comment of the header): clipped area and the barycentric
  // weights of its centroid, the consistent nodal split of a uniform pressure on it.
  std::array<Vec3, 8> poly;
  for (std::size_t k = 0; k < tri_.size(); ++k) {
    const Vec3 &a = x_[tri_[k][0]], &b = x_[tri_[k][1]], &c = x_[tri_[k][2]];
    const int np = clip_to_slab(a, b, c, z_bottom, z_top, poly);
    Real ab = 0;
    Vec3 cen = Vec3::Zero();
    for (int e = 1; e + 1 < np; ++e) {
      const Real ae = 0.5 * (poly[e] - poly[0]).cross(poly[e + 1] - poly[0]).norm();
      ab += ae;
      cen += ae * (poly[0] + poly[e] + poly[e + 1]) / 3.0;
    }
    area_band_[k] = ab;
    load_w_[k] = ab > 0 ? barycentric(cen / ab, a, b, c) : std::array<Real, 3>{1.0 / 3, 1.0 / 3, 1.0 / 3};
    vservo_[k] = servo_law(s_.pressure * ab, fc_[k], kc_[k], dt, s_.relaxation, s_.v_max);
  }
  if (s_.rule == MembraneVertexRule::Owner) vertex_velocities_owner();
  else vertex_velocities_nodal(dt);
  Real m2 = 0;
  for (std::size_t v = 0; v < x_.size(); ++v) {
    Vec3 xn = x_[v] + xv_[v] * dt;
    const Vec3 rho = radial(xn, s_.axis_x, s_.axis_y);
    const Real rn = rho.norm();
    if (rn < s_.r_min) {  // clamp: never closer to the axis than r_min
      const Vec3 dir = rn > 0 ? Vec3(rho / rn) : rdir_[v];
      xn.x() = s_.axis_x + s_.r_min * dir.x();
      xn.y() = s_.axis_y + s_.r_min * dir.y();
    }
    xv_[v] = (xn - x_[v]) / dt;
    x_[v] = xn;
    m2 = std::max(m2, (xn - x_build_[v]).squaredNorm());
  }
  motion_ = std::sqrt(m2);
  update_geometry();
}

Real FlexibleMembrane::mean_confinement() const {
  Real f = 0, a = 0;
  for (std::size_t k = 0; k < tri_.size(); ++k) {
    f -= fc_[k];
    a += area_band_[k];
  }
  return a > 0 ? f / a : 0.0;
}

Real FlexibleMembrane::enclosed_volume(Real z_lo, Real z_hi) const {
  // V = sum over the sleeve inside the slab of F . n_out dA with F = (x - axis)/2 horizontal
  // (div F = 1, no flux through the horizontal planes). F is linear, so each flat piece gives
  // F(centroid) . (vector area) exactly.
  Real vol = 0;
  std::array<Vec3, 8> poly;
  for (std::size_t k = 0; k < tri_.size(); ++k) {
    const int np = clip_to_slab(x_[tri_[k][0]], x_[tri_[k][1]], x_[tri_[k][2]], z_lo, z_hi, poly);
    for (int a = 1; a + 1 < np; ++a) {
      Vec3 varea = 0.5 * (poly[a] - poly[0]).cross(poly[a + 1] - poly[0]);
      if (varea.dot(normal_[k]) > 0) varea = -varea;  // outward
      const Vec3 cen = (poly[0] + poly[a] + poly[a + 1]) / 3.0;
      vol += 0.5 * radial(cen, s_.axis_x, s_.axis_y).dot(varea);
    }
  }
  return vol;
}

void FlexibleMembrane::radial_profile(std::span<Real> out_radius, std::span<Real> out_z) const {
  const int nt = s_.n_theta;
  for (int j = 0; j <= s_.n_z; ++j) {
    Real r = 0, z = 0;
    for (int i = 0; i < nt; ++i) {
      const Vec3& x = x_[vertex_index(i, j)];
      r += radial(x, s_.axis_x, s_.axis_y).norm();
      z += x.z();
    }
    if (j < static_cast<int>(out_radius.size())) out_radius[j] = r / nt;
    if (j < static_cast<int>(out_z.size())) out_z[j] = z / nt;
  }
}

void FlexibleMembrane::write_vtk(const std::filesystem::path& path) const {
  const std::size_t ne = tri_.size();
  std::vector<std::int64_t> conn(3 * ne);
  std::vector<double> pressure(ne);
  std::vector<Vec3> vel(ne);
  std::vector<std::int32_t> nc(ne);
  for (std::size_t k = 0; k < ne; ++k) {
    for (int c = 0; c < 3; ++c) conn[3 * k + c] = tri_[k][c];
    pressure[k] = -fc_[k] / area_[k];
    vel[k] = (xv_[tri_[k][0]] + xv_[tri_[k][1]] + xv_[tri_[k][2]]) / 3.0;
    nc[k] = ncontact_[k];
  }
  const VtkArray cell[] = {vtk_array("area", std::span<const double>(area_)),
                           vtk_array("pressure", std::span<const double>(pressure)),
                           vtk_array("servo_velocity", std::span<const double>(vservo_)),
                           vtk_array("velocity", std::span<const Vec3>(vel)),
                           vtk_array("normal", std::span<const Vec3>(normal_)),
                           vtk_array("contacts", std::span<const std::int32_t>(nc))};
  const VtkArray point[] = {vtk_array("velocity", std::span<const Vec3>(xv_))};
  write_vtp(path, x_, VtpCells{VtpCells::Triangles, conn}, point, cell);
}

void FlexibleMembrane::restore_vertices(std::span<const Vec3> x, std::span<const Vec3> v) {
  if (x.size() != x_.size() || v.size() != x_.size())
    throw InputError(fmt::format("flexible membrane: restore with {} vertices, the membrane has {}", x.size(),
                                 x_.size()));
  std::copy(x.begin(), x.end(), x_.begin());
  std::copy(v.begin(), v.end(), xv_.begin());
  update_geometry();
  x_build_ = x_;
  motion_ = 0;
}

}  // namespace ff::dem
