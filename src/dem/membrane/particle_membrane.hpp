// Particle membrane of a triaxial test: the traditional lateral boundary that [S000] (Zhao,
// Konietzky & Herbst 2021, sec. 1 and 6, Fig. 15) compares its flexible wall against, after de
// Bono et al. (2012) and Cheung & O'Sullivan (2008) (METHODS.md 3, "alternatives"). A layer of
// bonded spheres around the sample, each pushed towards the axis by a force of CONSTANT
// magnitude: the confining pressure times its share of the membrane's area when it is built
// (InwardLoads, added to ParticleStore::ext_force every step). As the sample bulges the forces neither grow with the stretched
// area nor tilt with the bulging surface, so the confinement actually applied drops; [S000] finds
// a clearly lower peak strength than with its flexible wall.
//
// Direction. Each force points horizontally at the axis from the sphere's current position.
// Forces frozen in their initial directions would be dead loads on a body free to turn about the
// axis: turned by phi, each gets a tangential part f sin(phi) in the sense of the turn, a torque
// N f R_c sin(phi) that turns it further (U = sum f R_c cos(phi) is largest at phi = 0). With a
// frictionless sample contact nothing resists: in a 7 x 14 mm test the whole membrane spun and
// flew off at ~70 m/s near 0.5% axial strain. Central forces exert no moment about the axis.
//
// Geometry. n_z rows of n_theta equal spheres of radius r_m, row j at z_bottom + (2j + 1) r_m,
// so the rows touch each other and the end rows touch the platens (2 n_z r_m is exactly the
// platen gap). Ring neighbours touch too: the centres lie on radius R_c = r_m / sin(pi/n_theta),
// with n_theta the smallest count for which the membrane's inner surface R_c - r_m clears the
// sample by the requested clearance. r_m is the requested radius adjusted by at most
// kRadiusTolerance, choosing the row count whose inner surface comes closest to sample radius +
// clearance. Sphere (i, j) has index first + j n_theta + i, i periodic.
//
// Loads. The pressure acts on the membrane's inner surface (radius R_in = R_c - r_m), where it
// meets the sample: each sphere gets f = p 2 pi R_in H / (n_theta n_z), so that the sample feels p
// when the membrane is built (taking the centre radius would over-confine by r_m / R, ~10% for
// r_m = 0.5 mm around a 10 mm core). The applied confinement reported later is the total force
// over the current inner surface 2 pi (mean centre radius - r_m) x platen gap.
//
// Material. The spheres form their own group (kGroupName), appended to the Materials after the
// sample's groups: ring and row neighbours are joined by bonds of the active bond law with a soft,
// latex-like modulus and strengths so high that they never break; membrane-membrane contacts use
// the same modulus, no friction; membrane-sample contacts use the sample group's own contact
// properties with the membrane friction. No bond joins the membrane to the sample. Unbonded
// (ParticleMembraneMaterial::bonded = false) the spheres are loose and hold together only where
// they touch.
//
// Units: SI. 3D only.
#pragma once
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "dem/dem_system.hpp"

namespace ff::dem {

struct ParticleMembraneSpec {
  Real sample_radius = 0;     // R: sample on the z axis [m]
  Real z_bottom = 0, z_top = 0;  // platen planes [m]
  Real particle_radius = 0;   // requested r_m (adjusted to fit the height) [m]
  Real clearance = 0;         // gap between the sample radius and the inner surface [m]
  Real pressure = 0;          // confining pressure p [Pa]
};

// The membrane's layout and loads, fixed when it is built (raw bytes in checkpoints).
struct ParticleMembraneLayout {
  std::int64_t first = 0;        // index of sphere (0, 0)
  std::int64_t n_theta = 0, n_z = 0;
  std::int32_t group = -1;       // material group of the spheres
  std::int32_t pad = 0;
  Real particle_radius = 0;      // r_m [m]
  Real centre_radius = 0;        // R_c [m]
  Real z_bottom = 0, z_top = 0;  // platen planes when built [m]
  Real pressure = 0;             // p [Pa]
  Real force = 0;                // constant inward force on each sphere [N]
  Real mass_factor = 1;          // inertial mass scaling of the spheres (stabilise_particle_membrane)

  std::int64_t count() const { return n_theta * n_z; }
  Real inner_radius() const { return centre_radius - particle_radius; }
  Real total_force() const { return force * static_cast<Real>(count()); }
};

// Material of the membrane spheres.
struct ParticleMembraneMaterial {
  Real emod = 1e7;       // bond and membrane-membrane contact modulus [Pa]
  Real density = 1000;   // [kg/m^3]
  Real friction = 0;     // membrane-sample contact friction [-] (kGroupFriction: the sample group's own)
  bool bonded = true;    // ring and row neighbours bonded (false: loose spheres, only their contacts)
};

inline constexpr const char* kParticleMembraneGroup = "membrane";
// Largest relative change of the requested sphere radius when fitting the rows and the ring.
inline constexpr Real kRadiusTolerance = 0.15;
// Strength of the membrane bonds [Pa]: far above any load the membrane sees (never break).
inline constexpr Real kUnbreakable = 1e100;

// Layout for the spec (pure geometry, nothing added). Throws InputError for a bad spec.
ParticleMembraneLayout particle_membrane_layout(const ParticleMembraneSpec& s);
// Centre of sphere (i, j) as built.
Vec3 particle_membrane_position(const ParticleMembraneLayout& l, int i, int j);

// Appends the membrane group to `m` (pair tables re-indexed for one more group; see the file
// comment for the pair properties) and returns its index. Throws InputError when a group of that
// name exists. Bond pair indices of existing bonds must be moved with remap_pair_indices().
int add_particle_membrane_group(Materials& m, const ParticleMembraneMaterial& pm);
// Re-indexes pair indices a*n_old + b to a*n_new + b.
void remap_pair_indices(std::span<std::int32_t> pair, int n_old, int n_new);

// Loads of constant magnitude `force` [N] towards the z axis on a set of particles: each step
// (add_external_loads stage) every one gets f = -force (x, y, 0) / |(x, y)| from its current
// position, ADDED to ParticleStore::ext_force (none on the axis itself). Holds particle indices,
// renumbered by reorder_particles(); no state of its own to checkpoint (whoever attached it
// attaches it again at a resume).
class InwardLoads final : public Boundary {
 public:
  InwardLoads(std::vector<Index> particles, Real force) : particle_(std::move(particles)), force_(force) {}
  std::span<const Index> particles() const { return particle_; }
  Real force() const { return force_; }

  std::unique_ptr<Boundary> clone() const override { return std::make_unique<InwardLoads>(*this); }
  void update_neighbors(const DemSystem&, bool, Real) override {}
  void compute_forces(const DemSystem&) override {}
  void add_external_loads(ParticleStore& p) const override;
  void add_loads(std::span<Vec3>, std::span<Vec3>) const override {}
  void after_integrate(const DemSystem&) override {}
  void reorder(std::span<const Index> new_of_old) override;
  std::span<const Index> contact_particles() const override { return {}; }
  std::span<const BoundaryLoad> contact_loads() const override { return {}; }
  std::span<const Real> contact_stiffness() const override { return {}; }
  void save(CheckpointWriter&, const DemSystem&) const override {}
  void load(CheckpointReader&, const DemSystem&) override {}

 private:
  std::vector<Index> particle_;
  Real force_;
};

// Attaches the inward loads of a particle membrane (layout.force on each of its spheres) to
// `sys`: add_particle_membrane() does it; a driver that resumes from a checkpoint does it again.
InwardLoads& attach_particle_membrane_loads(DemSystem& sys, const ParticleMembraneLayout& l);

// Builds the membrane in `sys` (3D, materials and skin set): group, spheres (at rest), their
// constant inward loads (attach_particle_membrane_loads), ring and row bonds (unless !pm.bonded);
// initialises the system. Returns the layout.
ParticleMembraneLayout add_particle_membrane(DemSystem& sys, const ParticleMembraneSpec& spec,
                                             const ParticleMembraneMaterial& pm);

// Density scaling of the membrane spheres only (METHODS.md 1.6; their mass plays no role in a
// quasi-static test): scales their inertial masses so that each is stable at `dt` with `safety`
// when it presses on `assumed_contacts` sample spheres of the stiffest group and largest radius,
// besides its own bonds. Returns the factor (1: no scaling needed), also kept in l.mass_factor.
Real stabilise_particle_membrane(DemSystem& sys, ParticleMembraneLayout& l, Real dt, Real safety,
                                 int assumed_contacts = 4);

// Caps the speed of the membrane spheres at v_max [m/s] (their velocities only). The triaxial
// driver calls it after every step of the isotropic stage: under their full loads the light
// spheres would cross the clearance and hit the sample at tens of m/s and break bonds at its
// surface, while every servo of the test moves at most at its v_max.
void limit_particle_membrane_speed(ParticleStore& p, const ParticleMembraneLayout& l, Real v_max);

// Measurements.
// Mean distance of the sphere centres from the axis [m].
Real particle_membrane_mean_radius(const ParticleStore& p, const ParticleMembraneLayout& l);
// Confinement actually applied: total constant force / (2 pi (mean radius - r_m) (z_hi - z_lo)) [Pa].
Real particle_membrane_confinement(const ParticleStore& p, const ParticleMembraneLayout& l, Real z_lo, Real z_hi);
// Volume inside the inner surface between the planes: pi (mean radius - r_m)^2 (z_hi - z_lo) [m^3].
Real particle_membrane_volume(const ParticleStore& p, const ParticleMembraneLayout& l, Real z_lo, Real z_hi);
// Mean centre radius and mean z of each row j = 0..n_z-1.
void particle_membrane_profile(const ParticleStore& p, const ParticleMembraneLayout& l, std::span<Real> radius,
                               std::span<Real> z);
// Intact bonds between two membrane spheres.
std::size_t particle_membrane_bonds(const DemSystem& sys, const ParticleMembraneLayout& l);

}  // namespace ff::dem
