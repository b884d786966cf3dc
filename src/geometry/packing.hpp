// Dense random packings of spheres (3D) or disks (2D) for bonded-particle samples.
//
// Algorithm: collective rearrangement with radius expansion, as in PFC's bonded-particle genesis
// (Potyondy & Cundall 2004, Int. J. Rock Mech. Min. Sci. 41:1329, Sec. 3.1) and the force-biased
// family (Jodrey & Tory 1985, Phys. Rev. A 32:2347; Moscinski et al. 1989, Mol. Simul. 3:201):
//  1. Draw radii uniformly in [radius_min, radius_max] until the solid volume (2D: disk area) is
//     closest to (1 - porosity) * container volume (2D: circle or rectangle area); N follows from that.
//  2. Place the centres uniformly at random inside the container shrunk by each radius, with the
//     radii at start_radius_scale of full size.
//  3. Geometric relaxation: every overlapping pair pushes both partners apart along its normal by
//     the overlap (f_i = sum_j overlap_ij n_ji = -grad E, E = 1/2 sum overlap^2) and particles are
//     projected back inside the walls after every move; contacts from a Verlet list on a uniform
//     cell grid. The pushes drive two stages:
//     a. thermal compression: soft-sphere dynamics at constant kinetic energy while the radii grow
//        slowly to 98.5% (a soft-sphere Lubachevsky & Stillinger 1990, J. Stat. Phys. 60:561). The
//        thermal rearrangement raises the solid fraction reachable without overlaps (measured in the
//        25 x 50 mm cylinder: from about 0.622 to about 0.628), so porosity 0.38 is off the jamming
//        limit;
//     b. FIRE minimisation (Bitzek et al. 2006, Phys. Rev. Lett. 97:170201; FIRE 2.0, Guenole et al.
//        2020) of E, growing the radii by 0.1% whenever the largest overlap is below 1% of the mean
//        radius, up to full size. FIRE adds inertia and an adaptive step to the push; a fixed-step
//        push is steepest descent, which slows down sharply near jamming.
//  4. Stop when the largest overlap is below overlap_tolerance * mean radius; or after
//     max_iterations, or 5000 steps without progress (jammed), reporting what was reached
//     (converged = false and a warning).
// Deterministic for a seed: single thread, fixed loop orders, ff::Rng; independent of OpenMP
// settings. Output particles are ordered along the cell grid (z slowest), not in drawing order.
// Cost: ~750 thermal steps + a few hundred to a few thousand FIRE steps, each O(N); the 28k-sphere
// cylinder at porosity 0.38 takes ~3 s of CPU (tests/unit/geometry/test_packing_30k.cpp; ~7 s with
// the thermal step 0.2 and skin 0.3 r used before issue 13). Sample genesis asks for overlaps
// below 2e-4 mean radii and leaves the rest to the DEM stage with real contact forces.
// Achievable porosity: random close packing leaves about 0.36 (spheres) / 0.16 (disks), and walls
// loosen the packing within about one diameter, so small containers need more. Requests below
// kMinPorosity3D / kMinPorosity2D throw ff::InputError; requests between that and what the actual
// container allows stop early with converged = false.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "core/types.hpp"
#include "geometry/shapes.hpp"

namespace ff::geom {

inline constexpr Real kMinPorosity3D = 0.35;
inline constexpr Real kMinPorosity2D = 0.16;

struct PackingSpec {
  int dim = 3;  // 3: spheres in a cylinder or box; 2: disks (z = 0) in a circle or rectangle
  // Cylinder in 2D: the circle of radius cyl_radius about the origin in the x-y plane (cyl_height ignored).
  enum class Container { Cylinder, Box } container = Container::Cylinder;
  Real cyl_radius = 12.5e-3, cyl_height = 50e-3;  // cylinder along z, base at z = 0, axis at x = y = 0 [m]
  Vec3 box_lo{0, 0, 0}, box_hi{25e-3, 25e-3, 50e-3};  // box (2D: x-y rectangle, z ignored) [m]
  Real radius_min = 0.4e-3, radius_max = 0.6e-3;  // uniform radius distribution in [min, max] [m]
  Real porosity = 0.38;                           // target porosity (void fraction of the container)
  std::uint64_t seed = 1;
  // Relaxation controls.
  Real overlap_tolerance = 0.005;  // stop when max overlap < overlap_tolerance * mean radius
  int max_iterations = 100000;     // cap on FIRE relaxation steps
  Real start_radius_scale = 0.9;   // radii start at this fraction of their final size
};

// Throws ff::InputError for a spec dense_random_packing() refuses (radii, porosity below the
// achievable minimum, a container smaller than two diameters, more than 5e7 particles),
// without making the packing.
void check_packing_spec(const PackingSpec& spec);

struct Packing {
  std::vector<Vec3> position;  // [m]; z = 0 in 2D
  std::vector<Real> radius;    // [m]
  Real achieved_porosity = 0;  // 1 - (sum of particle volumes or areas) / container volume or area
  Real max_overlap_ratio = 0;  // max over contacts of overlap / min(r_i, r_j)
  int iterations = 0;          // relaxation steps taken (thermal + FIRE)
  int thermal_steps = 0;       // of which in the thermal compression stage
  bool converged = false;      // max overlap reached overlap_tolerance * mean radius
};

// Throws ff::InputError for an invalid spec (naming the field and the valid range).
Packing dense_random_packing(const PackingSpec& spec);

// Material group of each centre: region_group[k] for the last region k containing it, else
// default_group. Throws ff::InputError if the two spans differ in length. With `assigned`, its
// k-th entry is the number of centres region k gave its group to.
std::vector<int> assign_groups(std::span<const Vec3> centres, std::span<const Region> regions,
                               std::span<const int> region_group, int default_group,
                               std::vector<std::size_t>* assigned = nullptr);

}  // namespace ff::geom

namespace ff {
using geom::assign_groups;
using geom::dense_random_packing;
using geom::Packing;
using geom::PackingSpec;
}  // namespace ff
