#include "lbm/shapes.hpp"

#include <algorithm>
#include <cmath>

namespace ff::lbm {

namespace {
// Smallest root in [0, 1] of |a + s d - c|^2 = r^2 restricted to the axes in `mask`.
double sphere_entry(const Vec3& a, const Vec3& b, const Vec3& c, double r, const Vec3& mask) {
  const Vec3 d = (b - a).cwiseProduct(mask);
  const Vec3 m = (a - c).cwiseProduct(mask);
  const double A = d.squaredNorm();
  const double B = 2 * m.dot(d);
  const double C = m.squaredNorm() - r * r;
  if (A <= 0) return 0.5;
  const double disc = std::max(0.0, B * B - 4 * A * C);
  const double s = (-B - std::sqrt(disc)) / (2 * A);
  return std::clamp(s, 0.0, 1.0);
}
}  // namespace

bool inside(const Shape& s, const Vec3& p) {
  struct V {
    const Vec3& p;
    bool operator()(const Circle& c) const { return (p - c.center).head<2>().squaredNorm() <= c.radius * c.radius; }
    bool operator()(const Sphere& c) const { return (p - c.center).squaredNorm() <= c.radius * c.radius; }
    bool operator()(const Box& b) const {
      return (p.array() >= b.lo.array()).all() && (p.array() <= b.hi.array()).all();
    }
  };
  return std::visit(V{p}, s);
}

double entry_fraction(const Shape& s, const Vec3& a, const Vec3& b) {
  struct V {
    const Vec3& a;
    const Vec3& b;
    double operator()(const Circle& c) const { return sphere_entry(a, b, c.center, c.radius, Vec3(1, 1, 0)); }
    double operator()(const Sphere& c) const { return sphere_entry(a, b, c.center, c.radius, Vec3(1, 1, 1)); }
    double operator()(const Box& bx) const {
      // Slab method: the segment enters the box at the largest per-axis entry parameter.
      const Vec3 d = b - a;
      double enter = 0;
      for (int k = 0; k < 3; ++k) {
        if (d[k] == 0) continue;
        const double t0 = (bx.lo[k] - a[k]) / d[k], t1 = (bx.hi[k] - a[k]) / d[k];
        enter = std::max(enter, std::min(t0, t1));
      }
      return std::clamp(enter, 0.0, 1.0);
    }
  };
  return std::visit(V{a, b}, s);
}

Vec3 reference_point(const Shape& s) {
  struct V {
    Vec3 operator()(const Circle& c) const { return c.center; }
    Vec3 operator()(const Sphere& c) const { return c.center; }
    Vec3 operator()(const Box& b) const { return 0.5 * (b.lo + b.hi); }
  };
  return std::visit(V{}, s);
}

}  // namespace ff::lbm
