// Contact geometry and kinematics shared by particle-particle and particle-wall contacts, so
// the force laws never learn whether the other body is a wall (STYLE.md B).
// Conventions (METHODS.md 1.2): n points from A to B; gap = d - (RA + RB) (< 0: overlap);
// increments are B relative to A; d_delta_n > 0 means opening.
#pragma once
#include <cmath>

#include "core/types.hpp"

namespace ff::dem {

struct ContactGeom {
  Vec3 n;            // unit normal from A to B
  Real gap;          // [m]
  Vec3 xc;           // contact point [m]
  Real rA, rB;       // radii; a wall has rB = 0
  Real d_delta_n;    // normal displacement increment (opening > 0) [m]
  Vec3 d_delta_s;    // shear displacement increment of B relative to A [m]
  Vec3 d_theta;      // relative rotation increment (wB - wA) dt [rad]
  Real mean_spin_n;  // 0.5 (wA + wB) . n, used to rotate stored shear vectors
};

// History carried by a frictional contact between steps (shared by the contact laws so the
// engine stores one array whatever the law).
struct ContactState {
  Vec3 fs = Vec3::Zero();  // shear force on B [N]
};

// Relative motion at the contact point (METHODS.md 1.2).
// Energy bookkeeping of one contact over one step (DemSettings::track_energy): the elastic work
// stored in (or released from) the incremental shear spring, and the energy dissipated by slip.
struct ContactWork {
  Real shear = 0;  // dU_s [J]
  Real slip = 0;   // D_slip >= 0 [J]
};

// Incremental shear spring of stiffness k whose force went from f0 (rotated into the new plane)
// to f1 under the tangential displacement increment ds: the elastic part of the increment is
// -(f1 - f0)/k, so dU_s = (|f1|^2 - |f0|^2)/(2k), and the rest, ds + (f1 - f0)/k, is slip,
// dissipating -(f0 + f1)/2 . (ds + (f1 - f0)/k) (Itasca PFC 5/6 documentation, "Energy
// tracking", slip energy E_mu of the linear model). With a stiffness that varies along the path
// (Hertz-Mindlin) the stored energy is the sum of these increments, the "work of the shear force
// increments", rather than |Fs|^2/(2 k) with the current k.
[[gnu::always_inline]] inline void shear_work(const Vec3& f0, const Vec3& f1, Real k, const Vec3& ds, ContactWork& w) {
  w.shear = (f1.squaredNorm() - f0.squaredNorm()) / (2 * k);
  w.slip = -0.5 * (f0 + f1).dot(ds + (f1 - f0) / k);
}

[[gnu::always_inline]] inline void contact_kinematics(ContactGeom& g, const Vec3& xA, const Vec3& vA, const Vec3& wA, const Vec3& xB,
                               const Vec3& vB, const Vec3& wB, Real dt) {
  const Vec3 vc = (vB + wB.cross(g.xc - xB)) - (vA + wA.cross(g.xc - xA));
  const Real vn = vc.dot(g.n);
  g.d_delta_n = vn * dt;
  g.d_delta_s = (vc - vn * g.n) * dt;
  g.d_theta = (wB - wA) * dt;
  g.mean_spin_n = 0.5 * (wA + wB).dot(g.n);
}

// Brings a stored shear vector into the current contact plane: drop the out-of-plane part,
// keep the magnitude, rotate by the mean spin about n (standard incremental DEM practice,
// as YADE/LIGGGHTS; METHODS.md 1.2).
[[gnu::always_inline]] inline void rotate_into_plane(Vec3& v, const ContactGeom& g, Real dt) {
  const Real mag2 = v.squaredNorm();
  if (mag2 == 0) return;
  const Real vn = v.dot(g.n);
  v -= vn * g.n;
  // Magnitude restored by (1 - x)^(-1/2), x = vn^2/mag2 = sin^2 of the plane's tilt this step.
  // Tilts are tiny in a time step, so a two-term series (truncation 5/16 x^3 < 4e-16 for
  // x < 1e-5) replaces the sqrt, which sits on this kernel's critical latency path.
  const Real x = vn * vn / mag2;
  if (x < 1e-5) v *= 1 + x * (0.5 + 0.375 * x);
  else if (x < 1) v *= 1 / std::sqrt(1 - x);
  v -= v.cross(g.mean_spin_n * dt * g.n);
}

// Sphere-sphere geometry; returns false when the centres coincide (then n is arbitrary, x).
[[gnu::always_inline]] inline bool sphere_sphere(ContactGeom& g, const Vec3& xA, Real rA, const Vec3& xB, Real rB) {
  const Vec3 d = xB - xA;
  const Real d2 = d.squaredNorm(), dist = std::sqrt(d2);
  g.n = d2 > 0 ? Vec3(d * (1.0 / dist)) : Vec3::UnitX();
  g.gap = dist - (rA + rB);
  g.xc = xA + (rA + 0.5 * g.gap) * g.n;
  g.rA = rA;
  g.rB = rB;
  return d2 > 0;
}

}  // namespace ff::dem
