// Internal to packing.cpp: container walls, Verlet list and the two relaxation stages of
// dense_random_packing (see packing.hpp for the algorithm and its sources).
#pragma once
#include <vector>

#include "core/rng.hpp"
#include "core/types.hpp"
#include "geometry/aabb.hpp"

namespace ff::geom::packing_detail {

// Admissible centre positions for a particle of radius r: a z-axis cylinder (base z = 0) or a box;
// in 2D the x-y circle of radius R about the origin (cylinder = true) or the x-y rectangle, z = 0.
struct Walls {
  int dim = 3;
  bool cylinder = true;
  Real R = 0, H = 0;
  Vec3 lo{Vec3::Zero()}, hi{Vec3::Zero()};

  Real measure() const;  // volume (3D) or area (2D)
  Aabb bounds() const;
  Vec3 random_point(Rng& rng, Real r) const;
  // Moves x back inside and removes the outward velocity component.
  void project(Vec3& x, Vec3& v, Real r) const;
};

// Particles during relaxation; the current radius is scale * r_full.
struct State {
  std::vector<Vec3> x, v, f;
  std::vector<Vec3> x_ref;  // positions at the last neighbour-list build
  std::vector<Real> r_full;
  Real scale = 1;
  Real scale_ref = 1;  // scale at the last build
  std::size_t size() const { return x.size(); }
};

// Half Verlet list (pairs i < j within r_i + r_j + skin) over a uniform cell grid. A rebuild also
// reorders the particles along the grid (stable counting sort by cell), keeping neighbours close in
// memory; every array of State is permuted together.
class VerletList {
 public:
  VerletList(const Aabb& box, int dim, Real cell_min);
  void rebuild(State& s, Real skin);
  int begin(std::size_t i) const { return pair_start_[i]; }
  int end(std::size_t i) const { return pair_start_[i + 1]; }
  int partner(int k) const { return partner_[k]; }

 private:
  int cell_of(const Vec3& p) const;
  template <class T>
  void permute(std::vector<T>& a, std::vector<T>& scratch) const;

  int dim_;
  Vec3 lo_;
  int n_[3];
  Real inv_[3];
  std::vector<int> cell_, start_, fill_, order_, pair_start_, partner_, scratch_int_;
  std::vector<Vec3> scratch_vec_;
  std::vector<Real> scratch_real_;
};

struct RelaxSettings {
  Real skin = 0;              // Verlet skin [m]
  Real tolerance = 0;         // target max overlap [m]
  Real growth_tolerance = 0;  // the FIRE stage grows the radii only while max overlap < this [m]
  Real growth_step = 0;       // relative radius increment of one FIRE-stage growth
  int max_iterations = 0;     // cap on FIRE iterations
  int stall_window = 0;       // stop when neither growth nor a 5% lower max overlap in this many steps
  // Thermal compression stage.
  Real anneal_speed = 0;        // rms particle speed [m per unit time]
  Real anneal_growth_rate = 0;  // radius growth per step, relative
  Real anneal_end_scale = 0;    // the stage ends when the radii reach this fraction of full size
  bool progress = false;        // a log line every few seconds (large packings)
};

struct RelaxResult {
  int iterations = 0;
  Real max_overlap = 0;
  bool converged = false;
};

// Time step of the thermal stage (unit masses and stiffness: a contact lasts pi / sqrt(2) / 0.6,
// about 4 steps; symplectic Euler is stable below dt = sqrt(2)). 0.2 (11 steps a contact) gave the
// same packings at three times the steps.
inline constexpr Real kThermalDt = 0.6;

// Stage 1: soft-sphere molecular dynamics at constant kinetic energy while the radii grow slowly
// (a soft-sphere analogue of Lubachevsky & Stillinger 1990, J. Stat. Phys. 60:561): the thermal
// motion lets the packing rearrange before it jams, which raises the density it can reach
// without overlaps. Returns the number of steps.
int thermal_compression(State& s, const Walls& walls, VerletList& nl, const RelaxSettings& set, Rng& rng);

// Stage 2: FIRE minimisation of E = 1/2 sum overlap^2 with radius growth up to full size.
RelaxResult fire_relaxation(State& s, const Walls& walls, VerletList& nl, const RelaxSettings& set);

}  // namespace ff::geom::packing_detail
