// Closest point of a triangle to a sphere centre, with the Voronoi feature (face, edge or
// vertex) it lies in, and the ball-facet contact geometry it gives (METHODS.md 1.2: n from the
// closest point of the facet, gap = d - R). Closest point after Ericson (2005), Real-Time
// Collision Detection, sec. 5.1.5 (region tests on the dot products d1..d6).
// The facet is body B with rB = 0, exactly like a rigid wall (walls.hpp), so the same contact
// laws apply. Triangles must not be degenerate (zero area).
#pragma once
#include <array>
#include <cstdint>

#include "dem/contact/contact_geometry.hpp"

namespace ff::dem {

// Feature of triangle (a, b, c) that holds the closest point. Edge01 is edge a-b, Edge12 b-c,
// Edge20 c-a; VertexK is corner K.
enum class TriFeature : std::uint8_t { Face, Edge01, Edge12, Edge20, Vertex0, Vertex1, Vertex2 };

// Corners of the feature as a bit mask (bit K = corner K): Face 0b111, Edge12 0b110, Vertex0 0b001...
inline unsigned feature_corners(TriFeature f) {
  switch (f) {
    case TriFeature::Face: return 0b111;
    case TriFeature::Edge01: return 0b011;
    case TriFeature::Edge12: return 0b110;
    case TriFeature::Edge20: return 0b101;
    case TriFeature::Vertex0: return 0b001;
    case TriFeature::Vertex1: return 0b010;
    case TriFeature::Vertex2: return 0b100;
  }
  return 0b111;
}

struct TriClosest {
  Vec3 point;                 // closest point of the triangle [m]
  std::array<Real, 3> bary;   // its barycentric weights on (a, b, c) (velocity interpolation)
  TriFeature feature;
};

// Ericson (2005) sec. 5.1.5, ClosestPtPointTriangle, with the region recorded.
inline TriClosest closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const Real d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return {a, {1, 0, 0}, TriFeature::Vertex0};
  const Vec3 bp = p - b;
  const Real d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return {b, {0, 1, 0}, TriFeature::Vertex1};
  const Real vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const Real v = d1 / (d1 - d3);
    return {a + v * ab, {1 - v, v, 0}, TriFeature::Edge01};
  }
  const Vec3 cp = p - c;
  const Real d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return {c, {0, 0, 1}, TriFeature::Vertex2};
  const Real vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const Real w = d2 / (d2 - d6);
    return {a + w * ac, {1 - w, 0, w}, TriFeature::Edge20};
  }
  const Real va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const Real w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {b + w * (c - b), {0, 1 - w, w}, TriFeature::Edge12};
  }
  const Real denom = 1 / (va + vb + vc);
  const Real v = vb * denom, w = vc * denom;
  return {a + v * ab + w * ac, {1 - v - w, v, w}, TriFeature::Face};
}

// Ball (centre x, radius r; body A) against a facet (body B) whose closest point is `cp`:
// n = (q - x)/|q - x| from the ball to the facet, gap = |q - x| - r, xc = x + (r + gap/2) n
// (METHODS.md 1.2). `inward` is the facet normal pointing to the side the balls live on.
// Returns false when the centre is not strictly on that side (a ball that went through the
// facet gets no force from it, as rigid walls do).
inline bool ball_triangle(ContactGeom& g, const TriClosest& cp, const Vec3& x, Real r, const Vec3& inward) {
  const Vec3 d = cp.point - x;
  const Real side = -d.dot(inward);
  if (side <= 0) return false;
  const Real dist = d.norm();
  g.n = d * (1.0 / dist);
  g.gap = dist - r;
  g.xc = x + (r + 0.5 * g.gap) * g.n;
  g.rA = r;
  g.rB = 0;
  return true;
}

}  // namespace ff::dem
