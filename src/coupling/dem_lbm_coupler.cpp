#include "coupling/dem_lbm_coupler.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/error.hpp"
#include "coupling/particle_set.hpp"
#include "dem/diagnostics.hpp"

namespace ff::coupling {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Gauss-Legendre nodes and weights on [-1, 1] (Newton on P_m; Press et al., Numerical Recipes,
// 3rd ed., Sec. 4.6).
void gauss_legendre(int m, std::vector<double>& x, std::vector<double>& w) {
  x.assign(std::size_t(m), 0.0);
  w.assign(std::size_t(m), 0.0);
  for (int i = 0; i < (m + 1) / 2; ++i) {
    double z = std::cos(M_PI * (i + 0.75) / (m + 0.5)), pp = 0;
    for (int it = 0; it < 100; ++it) {
      double p1 = 1, p2 = 0;
      for (int j = 0; j < m; ++j) {
        const double p3 = p2;
        p2 = p1;
        p1 = ((2.0 * j + 1.0) * z * p2 - j * p3) / (j + 1.0);
      }
      pp = m * (z * p1 - p2) / (z * z - 1.0);
      const double dz = p1 / pp;
      z -= dz;
      if (std::abs(dz) < 1e-15) break;
    }
    x[std::size_t(i)] = -z;
    x[std::size_t(m - 1 - i)] = z;
    w[std::size_t(i)] = w[std::size_t(m - 1 - i)] = 2.0 / ((1.0 - z * z) * pp * pp);
  }
}

}  // namespace

double coupled_dem_time_step(const dem::DemSystem& s, double safety) {
  double dt = dem::critical_time_step(s);
  const auto& p = s.particles;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const int pt = s.materials.pair(p.group[i], p.group[i]);
    const double k = dem::pair_stiffness(s, pt, p.radius[i], p.radius[i], 0.01 * p.radius[i]);
    if (k > 0 && p.inv_mass[i] > 0) dt = std::min(dt, std::sqrt(1.0 / (p.inv_mass[i] * k)));
  }
  // 0 also when a stiffness overflows (critical_time_step: inf, or NaN from 0 x inf) or k / m does:
  // a contact modulus of 1e308 was blamed on a missing stiffness.
  if (!std::isfinite(dt) || !(dt > 0))
    throw InputError("coupling: no DEM time step follows from the particles: their contact stiffness is 0 (set the DEM "
                     "step), or so large against their mass that it overflows (lower dem.contact_modulus in "
                     "sedimentation, dem.contact.*.emod elsewhere)");
  return safety * dt;
}

template <class L, class T>
DemLbmCoupler<L, T>::DemLbmCoupler(dem::DemSystem& dem, lbm::Solver<L, T>& fluid, const FluidScales& scales,
                                   const CouplerSettings& s)
    : dem_(dem), fluid_(fluid), scales_(scales), cs_(s), dx_(scales.units.dx()) {
  if (!(s.wall_motion >= 0 && s.wall_motion <= 1) || !(s.set_refresh >= 0 && s.set_refresh < 1))
    throw InputError(fmt::format("coupling: wall_motion {} must lie in [0, 1] and set_refresh {} in [0, 1) cells",
                                 s.wall_motion, s.set_refresh));
  if (s.set_refresh > 0 && s.wall_motion != 0)
    throw InputError("coupling: set_refresh > 0 keeps the particles' velocities of the last hand-over for many steps; "
                     "it needs quasi-static walls (wall_motion = 0)");
  if (dem.settings.dim != L::D)
    throw InputError(fmt::format("coupling: the DEM is {}D but the lattice {} is {}D", dem.settings.dim, L::name, L::D));
  if (std::abs(fluid.settings().tau - scales.units.tau()) > 1e-12 * scales.units.tau())
    throw InputError(fmt::format("coupling: the solver's tau {} differs from the fluid scales' {}", fluid.settings().tau,
                                 scales.units.tau()));
  n_sub_ = ff::coupling::sub_steps(scales.dt(), dem.settings.dt);
  dem_.settings.dt = scales.dt() / double(n_sub_);
  // Surface quadrature: symmetric under n -> -n, so the weights of a closed surface sum n dA to 0.
  if (L::D == 2) {
    const int n = std::max(8, cs_.quadrature);
    for (int k = 0; k < n; ++k) {
      const double a = 2.0 * M_PI * (k + 0.5) / n;
      qn_.emplace_back(std::cos(a), std::sin(a), 0.0);
      qw_.push_back(2.0 * M_PI / n);
    }
  } else {
    const int m = std::max(4, cs_.quadrature / 8), nphi = 2 * m;
    std::vector<double> x, w;
    gauss_legendre(m, x, w);
    for (int i = 0; i < m; ++i)
      for (int k = 0; k < nphi; ++k) {
        const double phi = 2.0 * M_PI * (k + 0.5) / nphi, st = std::sqrt(1.0 - x[std::size_t(i)] * x[std::size_t(i)]);
        qn_.emplace_back(st * std::cos(phi), st * std::sin(phi), x[std::size_t(i)]);
        qw_.push_back(w[std::size_t(i)] * 2.0 * M_PI / nphi);
      }
  }
  resize(dem.particles.size());
}

template <class L, class T>
void DemLbmCoupler<L, T>::resize(std::size_t n) {
  set_.resize(n);
  force_.assign(n, Vec3::Zero());
  torque_.assign(n, Vec3::Zero());
  dry_force_.assign(n, Vec3::Zero());
  p_particle_.assign(n, scales_.background_pressure);
  has_dry_.assign(n, 0);
  dry_clear_.assign(n, 0);
  dry_x_.assign(n, Vec3::Zero());
  dry_r_.assign(n, 0.0);
}

// The nearest cell of a point within r of a centre within kDryMove (per axis) of x lies in
// floor(x - r - kDryMove + 0.5) .. floor(x + r + kDryMove + 0.5) along each axis (a 1e-6 margin for
// rounding): none of those is dry, so no surface point is dry while the particle stays there.
template <class L, class T>
bool DemLbmCoupler<L, T>::clear_box(const Vec3& x, double r) const {
  const double reach = r + kDryMove + 1e-6;
  int lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  for (int a = 0; a < L::D; ++a) {
    lo[a] = int(std::floor(x[a] - reach + 0.5));
    hi[a] = int(std::floor(x[a] + reach + 0.5));
  }
  for (int z = lo[2]; z <= hi[2]; ++z)
    for (int y = lo[1]; y <= hi[1]; ++y)
      for (int v = lo[0]; v <= hi[0]; ++v)
        if (dry(Vec3(v, y, z))) return false;
  return true;
}

template <class L, class T>
bool DemLbmCoupler<L, T>::dry(const Vec3& xl) const {
  const auto& g = fluid_.grid();
  int c[3] = {0, 0, 0};
  for (int a = 0; a < L::D; ++a) {
    int v = int(std::floor(xl[a] + 0.5));
    const int n = g.n(a);
    if (g.periodic[std::size_t(a)]) {
      v %= n;
      if (v < 0) v += n;
    } else if (v < 0 || v >= n) {
      return fluid_.face(2 * a + (v < 0 ? 0 : 1)).kind == lbm::FaceCondition::Kind::Wall;
    }
    c[a] = v;
  }
  return fluid_.is_solid(c[0], c[1], c[2]);
}

template <class L, class T>
void DemLbmCoupler<L, T>::build_set() {
  fill_particle_set(dem_.particles, cs_.origin, scales_.units, L::D, set_, cs_.wall_motion);
}

template <class L, class T>
bool DemLbmCoupler<L, T>::set_stale() const {
  return !(cs_.set_refresh > 0) || !lbm::within_refresh(set_, handed_, handed_r_, cs_.set_refresh, L::D);
}

template <class L, class T>
void DemLbmCoupler<L, T>::pressure_loads() {
  const auto& g = fluid_.grid();
  const auto& p = dem_.particles;
  // Each particle writes its own load: in parallel, the same result on any thread count.
#pragma omp parallel for schedule(dynamic, 64) if (p.size() > 1024)
  for (std::size_t i = 0; i < p.size(); ++i) {
    dry_force_[i] = Vec3::Zero();
    if (!has_dry_[i]) continue;
    // p_s: mean physical pressure of the fluid cells within r + 1.5 cells of the centre.
    const Vec3 c = set_.position[i];
    const double reach = set_.radius[i] + 1.5;
    double sum = 0;
    long cnt = 0;
    const int z0 = L::D == 3 ? int(std::floor(c.z() - reach)) : 0, z1 = L::D == 3 ? int(std::ceil(c.z() + reach)) : 0;
    for (int z = z0; z <= z1; ++z)
      for (int y = int(std::floor(c.y() - reach)); y <= int(std::ceil(c.y() + reach)); ++y)
        for (int x = int(std::floor(c.x() - reach)); x <= int(std::ceil(c.x() + reach)); ++x) {
          const Vec3 d(x - c.x(), y - c.y(), L::D == 3 ? z - c.z() : 0.0);
          if (d.squaredNorm() > reach * reach) continue;
          const int xs = g.periodic[0] ? g.step(x, 0, 0) : x, ys = g.periodic[1] ? g.step(y, 0, 1) : y;
          const int zs = L::D == 3 && g.periodic[2] ? g.step(z, 0, 2) : z;
          // step() wraps one period at most; particles lie within one period of the box.
          if (!g.is_interior(xs, ys, zs) || fluid_.is_solid(xs, ys, zs)) continue;
          sum += fluid_.density(xs, ys, zs);
          ++cnt;
        }
    if (cnt == 0) continue;  // entirely dry: no fluid presses on it
    const double ps = scales_.pressure(sum / double(cnt));
    p_particle_[i] = ps;
    const double r = p.radius[i], area = L::D == 3 ? r * r : r;  // 2D: per metre of depth (unit-thickness disk)
    const double rl = set_.radius[i];  // points on the surface
    Vec3 f = Vec3::Zero();
    for (std::size_t k = 0; k < qn_.size(); ++k)
      if (dry(c + rl * qn_[k])) f += qn_[k] * qw_[k];
    dry_force_[i] = f * (ps * area);
  }
}

template <class L, class T>
void DemLbmCoupler<L, T>::step(bool sample_fluid) {
  auto t0 = Clock::now();
  auto& p = dem_.particles;
  if (set_.size() != p.size()) resize(p.size());  // particles added or removed (not in a plain run)
  build_set();
  bool any_dry = false;
  // Each particle writes its own flag: in parallel, the same result on any thread count.
  const std::int64_t np = std::int64_t(p.size());
  if (cs_.pressure_load)
#pragma omp parallel for schedule(static) reduction(|| : any_dry) if (np > 1024)
    for (std::int64_t ii = 0; ii < np; ++ii) {
      const std::size_t i = std::size_t(ii);
      char d = 0;
      const double rl = set_.radius[i];
      const Vec3& x = set_.position[i];
      // Far from every dry cell since the last look (the particles move ~0.002 cells per step):
      // no surface point can be dry, the same answer as the points give.
      bool clear = dry_clear_[i] && rl == dry_r_[i];
      for (int a = 0; a < L::D && clear; ++a) clear = std::abs(x[a] - dry_x_[i][a]) < kDryMove;
      if (!clear) {
        for (std::size_t k = 0; k < qn_.size() && !d; ++k) d = dry(x + rl * qn_[k]) ? 1 : 0;
        dry_clear_[i] = !d && clear_box(x, rl);
        dry_x_[i] = x;
        dry_r_[i] = rl;
      }
      has_dry_[i] = d;
      any_dry = any_dry || d;
    }
  if (set_stale()) {
    fluid_.set_particles(set_);
    ++handovers_;
    if (cs_.set_refresh > 0) {
      handed_ = set_.position;
      handed_r_ = set_.radius;
    }
  }
  times.coupling += seconds_since(t0);
  t0 = Clock::now();
  fluid_.step(sample_fluid || any_dry);
  times.lbm += seconds_since(t0);
  t0 = Clock::now();
  if (any_dry) pressure_loads();
  const auto& F = fluid_.particle_forces();
  const auto& M = fluid_.particle_torques();
  const auto& u = scales_.units;
  const Vec3 g = dem_.settings.gravity;
  const double rho_f = u.rho();
  for (std::size_t i = 0; i < p.size(); ++i) {
    const SiLoad si = to_si_load(u, L::D, F[i], M[i]);
    Vec3 f = si.force;
    const Vec3 m = si.torque;
    if (cs_.pressure_load) f += dry_force_[i];
    if (cs_.buoyancy) {
      const double r = p.radius[i];
      const double vol = L::D == 3 ? 4.0 / 3.0 * M_PI * r * r * r : M_PI * r * r;
      f -= rho_f * vol * g;
    }
    force_[i] = f;
    torque_[i] = m;
  }
  times.coupling += seconds_since(t0);
  t0 = Clock::now();
  for (long s = 0; s < n_sub_; ++s) {
    dem_.update_neighbors();
    dem_.compute_forces();
    dem_.add_external_loads();
    for (std::size_t i = 0; i < p.size(); ++i) {
      p.ext_force[i] += force_[i];
      p.ext_moment[i] += torque_[i];
    }
    dem_.integrate();
  }
  times.dem += seconds_since(t0);
}

template <class L, class T>
Vec3 DemLbmCoupler<L, T>::fluid_momentum() const {
  // From the populations of the state before the next step, over the fluid cells (not the static
  // solids nor the particles' solid cells of the bounce-back schemes, whose populations are the
  // particles' own): AA pattern, even t: g_q(x) in f[q][x]; odd t: in f[opp q][x - c_q].
  const auto& g = fluid_.grid();
  const auto& f = fluid_.populations();
  const auto* mb = fluid_.moving_boundary();
  const lbm::CellIndex N = g.padded_size();
  const bool odd = fluid_.time_step() % 2 != 0;
  long double P[3] = {0, 0, 0};
  for (int z = 0; z < g.nz; ++z)
    for (int y = 0; y < g.ny; ++y)
      for (int x = 0; x < g.nx; ++x) {
        const lbm::CellIndex i = g.index(x, y, z);
        if (fluid_.is_solid(x, y, z) || (mb && mb->solid(i))) continue;
        for (int q = 1; q < L::Q; ++q) {
          const T v = odd ? f[std::size_t(L::opp[q] * N + g.neighbour(x, y, z, -L::c[q][0], -L::c[q][1], -L::c[q][2]))]
                          : f[std::size_t(q * N + i)];
          for (int a = 0; a < L::D; ++a) P[a] += (long double)(L::c[q][a]) * v;
        }
      }
  const auto& u = scales_.units;
  const double scale = u.rho() * std::pow(dx_, L::D) * u.velocity_factor();
  return scale * Vec3(double(P[0]), double(P[1]), double(P[2]));
}

template class DemLbmCoupler<lbm::D2Q9, double>;
template class DemLbmCoupler<lbm::D2Q9, float>;
template class DemLbmCoupler<lbm::D3Q19, double>;
template class DemLbmCoupler<lbm::D3Q19, float>;

}  // namespace ff::coupling
