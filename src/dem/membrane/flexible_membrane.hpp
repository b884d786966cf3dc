// Flexible-wall (FW) membrane of a triaxial test: a cylindrical sleeve of triangular wall
// elements whose target load is the confining pressure times their current area, moved by the
// wall-servo law (METHODS.md 3; [S000] Zhao, Konietzky & Herbst 2021, sec. 5.1 and Figs. 8-9;
// servo law of the Itasca PFC "wall servo" command). The elements are formed on shared vertices,
// so the sleeve never opens while it bulges unevenly; how the vertices follow the servos is
// MembraneVertexRule.
//
// Geometry (METHODS.md 3). N_theta x N_z square units on radius R_m, z0 <= z <= z0 + H; vertex
// P(i,j) = (R cos(2 pi i/N_theta), R sin(2 pi i/N_theta), z0 + j H/N_z) + axis offset, i periodic.
// Unit (i,j) holds T1 = (P(i,j), P(i+1,j), P(i,j+1)) (element 2u) and T2 = (P(i+1,j), P(i+1,j+1),
// P(i,j+1)) (element 2u+1), u = j N_theta + i. The axis is parallel to z.
//
// One step, called by the engine through MembraneBoundary (membrane_boundary.hpp; order as for
// rigid walls, see dem_system.cpp):
//   1. if the neighbour list is rebuilt: find_candidates(pos, radius, skin). The engine's rebuild
//      test must include motion_since_build() (+ max_step_motion(dt)), as for walls;
//   2. compute_forces<Law>(...) with the particle positions of this step;
//   3. the particle gather adds, in candidate order, -load.f to the force and load.m to the moment
//      of particle candidate_particles()[c] (add_loads_to() does exactly this);
//   4. particles integrate; 5. move(dt, z_bottom, z_top) with the platen planes: servo
//      velocities, vertex update, new geometry.
//
// Loaded band. The confining fluid acts on the whole sleeve, but only the part between the
// platens presses on the sample; beyond them the real membrane rests on the platens. So the
// target load of element k is p times its area between z_bottom and z_top (clipped), lumped
// at its vertices like a finite-element pressure load (barycentric weights of the clipped
// centroid). Elements outside the band have no target; with no contact they move inward at
// v_max and stop at r_min.
//
// Contacts: each particle-element candidate gets the facet geometry of triangle_contact.hpp and
// the engine's contact law (the element is body B with rB = 0, like a rigid wall). A particle
// touching several elements keeps one contact per local minimum of its distance to the mesh:
// an edge or vertex contact is dropped when an element sharing that edge/vertex is strictly
// closer, and coincident closest points of adjacent elements count once (lowest element index).
// So a sphere on a shared edge of a flat pair, or on a convex (ridge) edge, has one contact with
// force kn * overlap, as on a face; in a concave crease (valley) it touches both faces, as a
// sphere in a V-groove (only within a band about r * crease angle wide).
//
// Units: SI. Ownership: the membrane stores its own geometry, candidates and contact history;
// particle data are read through spans valid for the call. 3D only (spheres).
#pragma once
#include <array>
#include <cmath>
#include <filesystem>
#include <span>
#include <vector>

#include "dem/boundary.hpp"
#include "dem/contact/boundary_friction.hpp"
#include "dem/contact/contact_geometry.hpp"
#include "dem/membrane/triangle_contact.hpp"

namespace ff::dem {

// How the vertices follow the servos (the sleeve stays closed with either: elements are formed
// on shared vertices).
enum class MembraneVertexRule : std::uint8_t {
  // Default. The servo law of METHODS.md 3 applied at each vertex to the loads lumped there:
  // the target loads of its elements (loaded band, above) and the contact normal forces and
  // stiffnesses split by the barycentric weights of their contact points. The vertex moves
  // along its fixed horizontal radial line (mesh angles and heights never change, so elements
  // cannot fold). At equilibrium every vertex balances, hence -sum F^c = p sum A_band (mean
  // confinement = p), though single elements are balanced only on average. The update matrix
  // D^-1 J (J = sum_c kn w w^T, D its row sums) has eigenvalues in [0, 1]: stable for alpha_s <= 1.
  Nodal,
  // METHODS.md 3 reading of [S000] Fig. 9, kept for comparison: vertex P(i,j) moves with the
  // translation (servo velocity x normal) of T1 of unit (i,j); top-row vertices with T2 of the
  // unit below. It does not converge: a T1 whose contacts sit far from its own vertex keeps
  // driving that vertex into the particles (its force hardly changes), T2 elements get no
  // feedback, and the checkerboard mode of the T1 errors grows by 1 + alpha_s/3 per step in the
  // uncapped regime. Around a rigid cylinder of spheres it over-presses 16-100x (test
  // MembraneCylinder.OwnerRuleOverPresses), also with a 40x smaller v_max.
  Owner,
};

struct MembraneSettings {
  int n_theta = 16;              // square units around the circumference ([S000] demo: 16)
  int n_z = 8;                   // rows of units along z
  // Initial radius R_m of the vertex circle [m]. The flat facets lie R_m cos(pi/N_theta) from the
  // axis at their middle: take R_m = membrane_circumradius(sample radius + clearance, N_theta).
  Real radius = 0;
  Real z0 = 0, height = 0;       // sleeve from z0 to z0 + height (longer than the sample) [m]
  Real axis_x = 0, axis_y = 0;   // the axis: the vertical line through (axis_x, axis_y) [m]
  Real pressure = 0;             // confining pressure p [Pa]
  Real v_max = 0.01;             // servo speed cap [m/s] ([S000]: 0.01, above the platen speed)
  Real relaxation = 0.8;         // alpha_s, servo relaxation factor (PFC default 0.8) [-]
  // Vertices never come closer to the axis than r_min (required, 0 < r_min < radius) [m]. Rows
  // beyond the sample ends touch no particle and move inward at v_max; the clamp stops them. Set
  // it a little below the platen radius (the smallest expected sample radius), so the membrane
  // still follows a sample that contracts but free rows do not fold through the platens.
  Real r_min = 0;
  Real friction = 0;             // particle-membrane Coulomb friction (0: pure pressure; kGroupFriction:
                                 // each particle's own group contact friction) [-]
  MembraneVertexRule rule = MembraneVertexRule::Nodal;
  std::size_t parallel_min = 2048;  // contact loops with fewer candidates run on one thread
};

// Rows of nearly square units for a sleeve (chord 2 R sin(pi/N_theta) ~ H/N_z), at least 1.
int membrane_square_rows(Real radius, int n_theta, Real height);
// Vertex radius whose facets (N_theta-gon) clear a cylinder of radius inner_radius.
inline Real membrane_circumradius(Real inner_radius, int n_theta) { return inner_radius / std::cos(kPi / n_theta); }
// Sleeve geometry around a cylinder sample on the z axis between the platen planes z_bottom and
// z_top: facets `clearance` x R outside it, `length_factor` x the sample height, centred on it;
// n_z = 0 picks nearly square units. Other settings keep their defaults.
MembraneSettings membrane_around_cylinder(Real sample_radius, Real z_bottom, Real z_top, int n_theta, int n_z,
                                          Real clearance, Real length_factor);

// Particle arrays read by the contact loop (spans over the engine's ParticleStore).
struct MembraneParticles {
  std::span<const Vec3> pos, vel, omega;
  std::span<const Real> radius;
  std::span<const std::int32_t> group;
};

// Result of one (particle, element) candidate: f = force ON THE ELEMENT [N] (the particle
// receives -f), m = moment on the particle [N m], xc = contact point [m].
using MembraneLoad = BoundaryLoad;

class FlexibleMembrane {
 public:
  explicit FlexibleMembrane(const MembraneSettings& s);  // throws InputError on bad settings

  const MembraneSettings& settings() const { return s_; }
  void set_pressure(Real p);  // staged confinement; target forces follow on the next move()

  // Topology. Vertex (i,j), j = 0..N_z, has index j N_theta + (i mod N_theta).
  std::size_t element_count() const { return tri_.size(); }
  std::size_t vertex_count() const { return x_.size(); }
  std::size_t vertex_index(int i, int j) const;
  std::span<const Vec3> vertices() const { return x_; }
  std::span<const Vec3> vertex_velocities() const { return xv_; }
  const std::array<Index, 3>& element_vertices(std::size_t k) const { return tri_[k]; }

  // Element geometry (recomputed whenever vertices move).
  Real area(std::size_t k) const { return area_[k]; }
  const Vec3& normal(std::size_t k) const { return normal_[k]; }  // unit, towards the axis
  const Vec3& centroid(std::size_t k) const { return centroid_[k]; }

  // Servo quantities of the last compute_forces()/move() (METHODS.md 3).
  Real loaded_area(std::size_t k) const { return area_band_[k]; }  // area between the platens [m^2]
  Real contact_force(std::size_t k) const { return fc_[k]; }  // F^c: signed, < 0 when pushed [N]
  Real contact_stiffness(std::size_t k) const { return kc_[k]; }  // K^c [N/m]
  int contacts(std::size_t k) const { return ncontact_[k]; }
  Real servo_velocity(std::size_t k) const { return vservo_[k]; }  // v_n along normal(k) [m/s]
  // Servo law: v_n = G (F^t + F^c), G = alpha_s / (K^c dt), |v_n| <= v_max; v_max inward when
  // K^c = 0 (PFC wall servo; METHODS.md 3). Positive = along the inward normal.
  static Real servo_law(Real f_target, Real f_contact, Real k_contact, Real dt, Real alpha, Real v_max);

  // Step API (see the file comment for the order).
  void find_candidates(std::span<const Vec3> pos, std::span<const Real> radius, Real skin);
  template <class Law>
  void compute_forces(const MembraneParticles& p, std::span<const typename Law::Params> pair_params, int n_groups,
                      Real dt);
  std::span<const Index> candidate_particles() const { return cand_p_; }
  std::span<const Index> candidate_elements() const { return cand_e_; }
  std::span<const MembraneLoad> candidate_loads() const { return load_; }
  // Normal stiffness of each candidate's contact, 0 when it carries no force (time step) [N/m].
  std::span<const Real> candidate_stiffness() const { return kn_; }
  std::span<ContactState> contact_states() { return state_; }  // shear history per candidate
  std::span<const ContactState> contact_states() const { return state_; }
  void add_loads_to(std::span<Vec3> force, std::span<Vec3> moment) const;
  // The particles were reordered (old index i is now new_of_old[i]): candidates renumbered and
  // sorted again by (particle, element) with their contact history and last loads.
  void remap_particles(std::span<const Index> new_of_old);
  // Servo + vertex update from the last compute_forces(); z of the platen planes [m].
  void move(Real dt, Real z_bottom, Real z_top);
  Real motion_since_build() const { return motion_; }  // max vertex travel since find_candidates [m]
  Real max_step_motion(Real dt) const { return s_.v_max * dt; }  // bound on the next move()

  // Measurements.
  // Mean applied confinement -sum F^c / sum A_band [Pa], loaded areas of the last move()
  // (METHODS.md 3 acceptance: equals p within ~1 % at equilibrium); 0 before the first move().
  Real mean_confinement() const;
  // Volume inside the sleeve between the planes z_lo < z_hi (the platens), by the divergence
  // theorem with the field (x - axis)/2 in the horizontal plane, which has no flux through the
  // planes [m^3]. The sleeve must span [z_lo, z_hi].
  Real enclosed_volume(Real z_lo, Real z_hi) const;
  // Mean distance to the axis (out_radius) and mean z (out_z) of each vertex ring j = 0..N_z.
  void radial_profile(std::span<Real> out_radius, std::span<Real> out_z) const;
  // PolyData of the triangles with cell arrays area, pressure (-F^c/A), servo_velocity, velocity,
  // normal, contacts and point array velocity (ParaView).
  void write_vtk(const std::filesystem::path& path) const;

  // Checkpoint restore: vertex positions and velocities (candidates are rebuilt afterwards).
  void restore_vertices(std::span<const Vec3> x, std::span<const Vec3> v);

 private:
  void update_geometry();
  void vertex_velocities_owner();
  void vertex_velocities_nodal(Real dt);
  bool keep_contact(std::size_t c, std::size_t begin, std::size_t end) const;

  MembraneSettings s_;
  Real tol_;  // coincidence tolerance of closest points (1e-9 R_m) [m]
  std::vector<Vec3> x_, xv_, x_build_;      // vertices, their velocities, positions at the last build
  std::vector<std::array<Index, 3>> tri_;   // element corners (vertex indices)
  std::vector<Vec3> rdir_;                  // unit horizontal direction from the axis at construction
  std::vector<Index> owner_;                // Owner rule: element each vertex follows
  std::vector<Real> ftv_, fcv_, kcv_;        // Nodal rule: lumped target, contact force, stiffness
  std::vector<Real> area_, area_band_;
  std::vector<std::array<Real, 3>> load_w_;  // barycentric weights of the loaded part's centroid
  std::vector<Vec3> normal_, centroid_;
  std::vector<Real> fc_, kc_, vservo_;
  std::vector<int> ncontact_;
  Real motion_ = 0;

  // Candidates sorted by (particle, element); group_off_ delimits each particle's run.
  std::vector<Index> cand_p_, cand_e_;
  std::vector<std::int64_t> group_off_;
  std::vector<ContactState> state_;
  std::vector<MembraneLoad> load_;
  std::vector<TriClosest> cp_;       // per-candidate scratch of compute_forces
  std::vector<Real> dist_, kn_;
  std::vector<std::uint8_t> touch_;
  // Work arrays of find_candidates (reused: no allocation in steady state).
  std::vector<Index> old_p_, old_e_;
  std::vector<ContactState> old_state_;
  std::vector<std::int64_t> cell_off_;
  std::vector<Index> cell_elem_;
  std::vector<Vec3> box_lo_, box_hi_;
};

}  // namespace ff::dem
