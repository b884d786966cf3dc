#include "geometry/packing_relax.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/log.hpp"

namespace ff::geom::packing_detail {

// ---------------------------------------------------------------------------------------------
// Walls

Real Walls::measure() const {
  if (cylinder) return dim == 3 ? kPi * R * R * H : kPi * R * R;
  const Vec3 e = hi - lo;
  return dim == 3 ? e.x() * e.y() * e.z() : e.x() * e.y();
}

Aabb Walls::bounds() const {
  if (cylinder) return Aabb{Vec3(-R, -R, 0), Vec3(R, R, dim == 3 ? H : 0)};
  return dim == 3 ? Aabb{lo, hi} : Aabb{Vec3(lo.x(), lo.y(), 0), Vec3(hi.x(), hi.y(), 0)};
}

Vec3 Walls::random_point(Rng& rng, Real r) const {
  if (cylinder) {
    const Real rho = R - r;
    Real x, y;
    do {  // rejection from the square keeps the disk sampling uniform
      x = rng.uniform(-rho, rho);
      y = rng.uniform(-rho, rho);
    } while (x * x + y * y > rho * rho);
    return Vec3(x, y, dim == 3 ? rng.uniform(r, H - r) : 0.0);
  }
  Vec3 p = Vec3::Zero();
  for (int a = 0; a < dim; ++a) p[a] = rng.uniform(lo[a] + r, hi[a] - r);
  return p;
}

void Walls::project(Vec3& x, Vec3& v, Real r) const {
  if (cylinder) {
    const Real rho_max = R - r;
    const Real rho2 = x.x() * x.x() + x.y() * x.y();
    if (rho2 > rho_max * rho_max) {
      const Real rho = std::sqrt(rho2);
      const Real ex = x.x() / rho, ey = x.y() / rho;
      x.x() = ex * rho_max;
      x.y() = ey * rho_max;
      const Real vr = v.x() * ex + v.y() * ey;
      if (vr > 0) {
        v.x() -= vr * ex;
        v.y() -= vr * ey;
      }
    }
    if (dim == 2) return;  // circle: no end planes
    if (x.z() < r) {
      x.z() = r;
      v.z() = std::max(v.z(), Real(0));
    } else if (x.z() > H - r) {
      x.z() = H - r;
      v.z() = std::min(v.z(), Real(0));
    }
    return;
  }
  for (int a = 0; a < dim; ++a) {
    if (x[a] < lo[a] + r) {
      x[a] = lo[a] + r;
      v[a] = std::max(v[a], Real(0));
    } else if (x[a] > hi[a] - r) {
      x[a] = hi[a] - r;
      v[a] = std::min(v[a], Real(0));
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Verlet list

VerletList::VerletList(const Aabb& box, int dim, Real cell_min) : dim_(dim), lo_(box.lo) {
  for (int a = 0; a < 3; ++a) {
    const Real len = box.hi[a] - box.lo[a];
    n_[a] = a < dim ? std::max(1, static_cast<int>(std::floor(len / cell_min))) : 1;
    inv_[a] = a < dim ? n_[a] / len : 0;
  }
}

int VerletList::cell_of(const Vec3& p) const {
  int c[3];
  for (int a = 0; a < 3; ++a) c[a] = std::clamp(static_cast<int>((p[a] - lo_[a]) * inv_[a]), 0, n_[a] - 1);
  return (c[2] * n_[1] + c[1]) * n_[0] + c[0];
}

template <class T>
void VerletList::permute(std::vector<T>& a, std::vector<T>& scratch) const {
  scratch.resize(a.size());
  for (std::size_t k = 0; k < a.size(); ++k) scratch[k] = a[order_[k]];
  a.swap(scratch);
}

void VerletList::rebuild(State& s, Real skin) {
  const std::size_t n = s.size();
  const std::size_t ncell = static_cast<std::size_t>(n_[0]) * n_[1] * n_[2];
  cell_.resize(n);
  start_.assign(ncell + 1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    cell_[i] = cell_of(s.x[i]);
    ++start_[cell_[i] + 1];
  }
  for (std::size_t c = 0; c < ncell; ++c) start_[c + 1] += start_[c];
  order_.resize(n);
  fill_.assign(start_.begin(), start_.end() - 1);
  for (std::size_t i = 0; i < n; ++i) order_[fill_[cell_[i]]++] = static_cast<int>(i);
  permute(s.x, scratch_vec_);
  permute(s.v, scratch_vec_);
  permute(s.r_full, scratch_real_);
  permute(cell_, scratch_int_);
  s.x_ref = s.x;
  s.scale_ref = s.scale;

  pair_start_.assign(n + 1, 0);
  partner_.clear();
  const int z_reach = dim_ == 3 ? 1 : 0;
  for (std::size_t i = 0; i < n; ++i) {
    const int c = cell_[i];
    const int cx = c % n_[0], cy = (c / n_[0]) % n_[1], cz = c / (n_[0] * n_[1]);
    const Real ri = s.scale * s.r_full[i];
    for (int z = std::max(0, cz - z_reach); z <= std::min(n_[2] - 1, cz + z_reach); ++z) {
      for (int y = std::max(0, cy - 1); y <= std::min(n_[1] - 1, cy + 1); ++y) {
        for (int x = std::max(0, cx - 1); x <= std::min(n_[0] - 1, cx + 1); ++x) {
          const int nc = (z * n_[1] + y) * n_[0] + x;
          // Particles are stored in cell order, so the partners j > i of a cell are its tail.
          for (int j = std::max(start_[nc], static_cast<int>(i) + 1); j < start_[nc + 1]; ++j) {
            const Real reach = ri + s.scale * s.r_full[j] + skin;
            if ((s.x[j] - s.x[i]).squaredNorm() < reach * reach) partner_.push_back(j);
          }
        }
      }
    }
    pair_start_[i + 1] = static_cast<int>(partner_.size());
  }
}

// ---------------------------------------------------------------------------------------------
// Overlap "forces" f_i = sum_j overlap_ij * n_ji (pushing i away from j): each overlapping pair
// pushes both partners apart along its normal; f = -grad E with E = 1/2 sum overlap^2. One pass over
// the half list; since pairs (i, j > i) come in order of i, f_i is final once row i is done and the
// FIRE sums are taken on the fly. Single thread, fixed order: bitwise reproducible.
namespace {

struct ForceSums {
  Real max_overlap = 0, power = 0, f2 = 0, v2 = 0;
};

ForceSums overlap_forces(State& s, const VerletList& nl) {
  const std::size_t n = s.size();
  std::fill(s.f.begin(), s.f.end(), Vec3::Zero());
  ForceSums sums;
  for (std::size_t i = 0; i < n; ++i) {
    const Real ri = s.scale * s.r_full[i];
    const Vec3 xi = s.x[i];
    Vec3 fi = s.f[i];
    for (int k = nl.begin(i); k < nl.end(i); ++k) {
      const int j = nl.partner(k);
      const Vec3 d = s.x[j] - xi;
      const Real sum = ri + s.scale * s.r_full[j];
      const Real d2 = d.squaredNorm();
      if (d2 >= sum * sum) continue;
      const Real dist = std::sqrt(d2);
      const Real overlap = sum - dist;
      sums.max_overlap = std::max(sums.max_overlap, overlap);
      // Coincident centres (probability zero, but keep it finite): push along x.
      const Vec3 push = dist > 0 ? Vec3(d * (overlap / dist)) : Vec3(overlap, 0, 0);
      fi -= push;
      s.f[j] += push;
    }
    s.f[i] = fi;
    sums.power += fi.dot(s.v[i]);
    sums.f2 += fi.squaredNorm();
    sums.v2 += s.v[i].squaredNorm();
  }
  return sums;
}

// A log line every 3 s when asked (checked every 64 steps).
class Progress {
 public:
  explicit Progress(bool on) : on_(on), last_(std::chrono::steady_clock::now()) {}
  bool due(int step) {
    if (!on_ || step % 64 != 0 || std::chrono::steady_clock::now() - last_ < std::chrono::seconds(3)) return false;
    last_ = std::chrono::steady_clock::now();
    return true;
  }

 private:
  bool on_;
  std::chrono::steady_clock::time_point last_;
};

// Rebuilds the list when it may have missed a pair: 2 * (max displacement + radius growth) > skin.
class ListGuard {
 public:
  ListGuard(State& s, VerletList& nl, Real skin)
      : nl_(nl), skin_(skin), r_max_(*std::max_element(s.r_full.begin(), s.r_full.end())) {
    nl_.rebuild(s, skin_);
  }
  void update(State& s) {
    if (2 * (std::sqrt(max_disp2_) + (s.scale - s.scale_ref) * r_max_) > skin_) {
      nl_.rebuild(s, skin_);
      max_disp2_ = 0;
    }
  }
  void moved(const Vec3& x, const Vec3& x_ref) { max_disp2_ = std::max(max_disp2_, (x - x_ref).squaredNorm()); }

 private:
  VerletList& nl_;
  Real skin_, r_max_;
  Real max_disp2_ = 0;
};

}  // namespace

int thermal_compression(State& s, const Walls& walls, VerletList& nl, const RelaxSettings& set, Rng& rng) {
  constexpr Real dt = kThermalDt;
  const std::size_t n = s.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Real vz = walls.dim == 3 ? rng.normal() : 0.0;
    s.v[i] = set.anneal_speed * Vec3(rng.normal(), rng.normal(), vz);
  }
  const Real target_v2 = set.anneal_speed * set.anneal_speed * walls.dim * static_cast<Real>(n);
  ListGuard guard(s, nl, set.skin);
  int steps = 0;
  Progress progress(set.progress);
  while (s.scale < set.anneal_end_scale) {
    if (progress.due(steps))
      log::info("packing: {} particles, thermal compression step {}, radii at {:.4f} of full size (stage ends at {:.4f})", n,
                steps, s.scale, set.anneal_end_scale);
    guard.update(s);
    overlap_forces(s, nl);
    Real v2 = 0;
    for (std::size_t i = 0; i < n; ++i) {
      s.v[i] += dt * s.f[i];
      v2 += s.v[i].squaredNorm();
    }
    // Isokinetic thermostat: rescale to the target kinetic energy every step.
    const Real factor = v2 > 0 ? std::sqrt(target_v2 / v2) : 1;
    for (std::size_t i = 0; i < n; ++i) {
      s.v[i] *= factor;
      Vec3 x = s.x[i] + dt * s.v[i];
      walls.project(x, s.v[i], s.scale * s.r_full[i]);
      s.x[i] = x;
      guard.moved(x, s.x_ref[i]);
    }
    s.scale = std::min(set.anneal_end_scale, s.scale * (1 + set.anneal_growth_rate));
    ++steps;
  }
  for (Vec3& v : s.v) v.setZero();
  return steps;
}

// FIRE 2.0 (Guenole et al. 2020, Comput. Mater. Sci. 175:109584, Algorithm 2, semi-implicit Euler)
// with unit masses and unit stiffness and the standard parameters; dt_max = 0.5 was chosen by
// trial (1.0 oscillates), and FIRE halves the step whenever the power F.v turns negative.
RelaxResult fire_relaxation(State& s, const Walls& walls, VerletList& nl, const RelaxSettings& set) {
  constexpr Real dt_start = 0.1, dt_max = 0.5, dt_min = 0.002;
  constexpr Real f_inc = 1.1, f_dec = 0.5, alpha_start = 0.1, f_alpha = 0.99;
  constexpr int n_delay = 5;
  const std::size_t n = s.size();
  Real dt = dt_start, alpha = alpha_start;
  int n_positive = 0;
  ListGuard guard(s, nl, set.skin);
  RelaxResult res;
  Real best = INFINITY;  // lowest max overlap since the last growth
  int last_progress = 0;
  Progress progress(set.progress);
  for (int it = 0; it < set.max_iterations; ++it) {
    guard.update(s);
    ForceSums fs = overlap_forces(s, nl);
    if (progress.due(it))
      log::info("packing: {} particles, relaxation step {}, radii at {:.4f} of full size, max overlap {:.2g} (target {:.2g})",
                n, it, s.scale, fs.max_overlap, set.tolerance);
    res.max_overlap = fs.max_overlap;
    res.iterations = it;
    if (s.scale >= 1 && fs.max_overlap < set.tolerance) {
      res.converged = true;
      return res;
    }
    if (fs.max_overlap < 0.95 * best) {
      best = fs.max_overlap;
      last_progress = it;
    } else if (it - last_progress > set.stall_window) {
      return res;  // jammed: more iterations will not remove the overlaps
    }
    if (s.scale < 1 && fs.max_overlap < set.growth_tolerance) {
      s.scale = std::min(Real(1), s.scale * (1 + set.growth_step));
      best = INFINITY;
      continue;  // forces change with the radii: recompute before moving
    }
    if (fs.power > 0) {
      if (++n_positive > n_delay) {
        dt = std::min(dt * f_inc, dt_max);
        alpha *= f_alpha;
      }
    } else {
      n_positive = 0;
      if (dt * f_dec >= dt_min) dt *= f_dec;
      alpha = alpha_start;
      for (std::size_t i = 0; i < n; ++i) {
        s.x[i] -= 0.5 * dt * s.v[i];
        s.v[i].setZero();
        walls.project(s.x[i], s.v[i], s.scale * s.r_full[i]);
        guard.moved(s.x[i], s.x_ref[i]);
      }
      fs.power = fs.v2 = 0;
    }
    // v' = v + dt f has |v'|^2 = |v|^2 + 2 dt F.v + dt^2 |F|^2; FIRE mixes v' towards F.
    const Real v2_new = std::max(Real(0), fs.v2 + 2 * dt * fs.power + dt * dt * fs.f2);
    const Real mix = fs.f2 > 0 ? alpha * std::sqrt(v2_new / fs.f2) : 0;
    for (std::size_t i = 0; i < n; ++i) {
      Vec3 v = (1 - alpha) * (s.v[i] + dt * s.f[i]) + mix * s.f[i];
      Vec3 x = s.x[i] + dt * v;
      walls.project(x, v, s.scale * s.r_full[i]);
      s.v[i] = v;
      s.x[i] = x;
      guard.moved(x, s.x_ref[i]);
    }
  }
  res.iterations = set.max_iterations;
  return res;
}

}  // namespace ff::geom::packing_detail
