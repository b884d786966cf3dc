// The lattice Boltzmann solver: populations, geometry (faces, solid objects), one time step,
// macroscopic fields and forces on solids. Lattice units only (lbm/units.hpp converts).
//
// Templated on the lattice (D2Q9, D3Q19) and on the storage precision (float, double); the
// four combinations are compiled once in solver.cpp, and drivers pick one at run time.
//
// Memory layout: populations f[q * N + cell] (one array per direction), N = padded cells.
// Streaming uses the in-place AA pattern (Bailey et al. 2009): even steps read and write a
// cell's own populations (stored in swapped slots), odd steps read from and write to the
// neighbours. One array, no write-allocate traffic. docs/lbm.md explains the choice.
//
// Cells are split once, in finalize(): plain fluid cells whose neighbours are all fluid
// form row spans updated by the branch-free kernel (stream_collide.hpp); every other fluid
// cell is a BoundaryCell updated by a general path that applies the wall and open-face
// conditions link by link. Solid cells are never updated; their memory holds the bounced
// populations. Outflow nodes copy populations of the layer inside them, so they are updated
// last, after the bulk and every other boundary cell (docs/lbm.md, "Outflow boundaries").
//
// Ownership: the Solver owns all its arrays; references returned stay valid until the
// next finalize(). Not copyable (large), movable.
#pragma once
#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/types.hpp"
#include "lbm/aligned_vector.hpp"
#include "lbm/boundary.hpp"
#include "lbm/collision.hpp"
#include "lbm/descriptor.hpp"
#include "lbm/grid.hpp"
#include "lbm/moving_boundary.hpp"
#include "lbm/psm.hpp"
#include "lbm/shapes.hpp"

namespace ff::lbm {

enum class CellType : std::uint8_t { Fluid = 0, Solid = 1, Open = 2 };

// Condition on one face of the box (faces numbered as in grid.hpp). Periodic is set by
// the Grid; the other kinds need a non-periodic axis.
struct FaceCondition {
  // Outflow: an open face whose unknown populations are extrapolated from the interior
  // (zero-gradient) or convected out with the velocity `convective_velocity` (Yang 2013).
  // The pressure there is free. An outflow face needs at least 3 cells along its axis and may
  // meet walls and periodic faces, not other open faces.
  enum class Kind { Periodic, Wall, Velocity, Pressure, Outflow };
  enum class Outflow { ZeroGradient, Convective };
  Kind kind = Kind::Wall;
  Outflow outflow = Outflow::ZeroGradient;
  double convective_velocity = 0;  // Convective: lattice speed; 0: the face's mean normal velocity
  // Outflow: the copied populations carry the node's own density rather than the donor's (true),
  // which keeps a pressure gradient at the outlet from acting as a mass source. false: the
  // plain copy g_q(x) = g_q(x + n), for comparison only (the density then drifts).
  bool outflow_density_free = true;
  Vec3 velocity = Vec3::Zero();  // Wall: wall velocity (moving wall); Velocity: inflow velocity
  double density = 1;            // Pressure: prescribed density (p = c_s^2 rho)
  // Velocity: per-cell velocity, overrides `velocity`. On a Wall it makes the face a moving-wall
  // (bounce-back) inflow, [S003] Eq. 8, with the velocity of the adjacent fluid cell's profile.
  std::function<Vec3(int x, int y, int z)> profile;
};

struct SolverSettings {
  CollisionModel collision = CollisionModel::Trt;
  double tau = 0.8;                  // relaxation time of the shear modes (viscosity)
  double magic = 3.0 / 16.0;         // TRT magic parameter Lambda
  Vec3 body_force = Vec3::Zero();    // force density, lattice units (Guo forcing)
  // He & Luo (1997) incompressible equilibrium (collision.hpp): rho_0 = 1 in the momentum terms.
  bool incompressible = false;
  // How set_particles() puts moving particles into the fluid (lbm/moving_boundary.hpp), fixed per solver.
  ParticleScheme particle_scheme = ParticleScheme::Psm;
  PsmWeighting psm_weighting = PsmWeighting::TauDependent;  // the PSM's B (lbm/psm.hpp)
  // PSM: keep the solid fractions while every particle stays within this many cells of where they
  // were computed (0: recompute at every set_particles; Psm::set_particles).
  double psm_refresh = 0;
  // Bounce-back schemes: links that stood for two steps are applied inside the bulk sweep
  // (MovingBoundary, "Links inside the bulk sweep"); false: always after it (the same results,
  // slower: for tests).
  bool links_in_sweep = true;
};

// A solid body (or a wall of the box) and the hydrodynamic load on it.
struct SolidObject {
  std::string name;
  WallScheme scheme = WallScheme::HalfwayBounceBack;
  std::optional<Shape> shape;          // gives the link fractions; none: half-way (delta = 1/2)
  Vec3 center = Vec3::Zero();          // torque reference point, lattice units
  Vec3 velocity = Vec3::Zero();        // rigid motion: u_w = velocity + omega x (x_w - center)
  Vec3 omega = Vec3::Zero();
  Vec3 force = Vec3::Zero();           // of the last step (time t + 1/2), lattice units,
  Vec3 torque = Vec3::Zero();          //   relative to the reference pressure c_s^2 rho_0
  long links = 0;                      // fluid->solid links (0: the object touches no fluid)
};

template <class L, class T>
class Solver {
 public:
  static constexpr int Q = L::Q;
  // Objects 0..5 are the six faces of the box ("wall x-" ... "wall z+").
  static constexpr int kFirstUserObject = kNumFaces;

  Solver(const Grid& grid, const SolverSettings& settings);
  Solver(const Solver&) = delete;
  Solver& operator=(const Solver&) = delete;
  Solver(Solver&&) = default;

  const Grid& grid() const { return grid_; }
  const SolverSettings& settings() const { return settings_; }

  // ---- geometry; call finalize() after any change
  void set_face(int face, const FaceCondition& c);
  const FaceCondition& face(int f) const { return faces_[f]; }
  int add_object(std::string name, WallScheme scheme, const Vec3& center);
  // Marks every cell whose centre lies inside `shape` as solid and belonging to `object`;
  // the shape then also gives the link fractions of the object's interpolated scheme.
  void add_shape(int object, const Shape& shape);
  void set_solid(int x, int y, int z, int object);  // from a mask or an image
  bool is_solid(int x, int y, int z) const { return type_[grid_.index(x, y, z)] != CellType::Fluid; }
  void finalize();

  // ---- motion of solids (enters the moving-wall term of bounce-back)
  void set_object_motion(int object, const Vec3& velocity, const Vec3& omega);
  void set_body_force(const Vec3& f);
  // Multiplies every prescribed inflow velocity (Velocity faces, Wall faces with a profile), e.g. to ramp a flow up
  // smoothly instead of starting it impulsively (which rings the domain acoustically).
  void set_inflow_scale(double s) { inflow_scale_ = T(s); }

  // ---- state
  // f = f^eq(rho, u) from init(x, y, z, rho, u) on every fluid cell; time step 0.
  // Call after finalize().
  void initialize(const std::function<void(int, int, int, double&, Vec3&)>& init);
  // One fused stream-collide step. With `sample`, the macroscopic fields of time t (the
  // moments the collision used) are stored for density()/velocity()/max_speed().
  void step(bool sample = false);
  long time_step() const { return time_; }

  // ---- results of the last sampling step (or of initialize())
  double density(int x, int y, int z) const { return 1.0 + double(drho_[grid_.index(x, y, z)]); }
  Vec3 velocity(int x, int y, int z) const;
  double max_speed() const;   // over fluid cells; NaN if any cell is NaN
  double total_mass() const;  // sum of rho over fluid cells (deterministic order)
  const std::vector<SolidObject>& objects() const { return objects_; }
  std::size_t num_boundary_cells() const { return bcells_.size(); }
  std::size_t num_bulk_cells() const;
  std::size_t num_fluid_cells() const { return num_bulk_cells() + bcells_.size(); }

  // ---- moving particles as partially saturated cells (lbm/psm.hpp), set before each step(); the
  // covered cells' update then uses this set until the next call. Forces and torques of the
  // last step on each particle (lattice units, indexed like the set; Units::to_si_force and to_si_torque).
  // With SolverSettings::particle_scheme a bounce-back scheme, the particles are solid cells instead
  // (lbm/moving_boundary.hpp); the same calls apply.
  void set_particles(const ParticleSet& p);
  const std::vector<Vec3>& particle_forces() const;
  const std::vector<Vec3>& particle_torques() const;
  const Psm<L, T>* psm() const { return psm_.get(); }
  // Resume with psm_refresh > 0: the fractions from the positions and radii they were computed from
  // before the checkpoint (psm()->geometry_positions(), geometry_radii()), then set_particles as usual.
  void restore_psm_geometry(const std::vector<Vec3>& positions, const std::vector<double>& radii);
  const MovingBoundary<L, T>* moving_boundary() const { return mb_.get(); }
  // Resume: after restore(), the set of the last step before the checkpoint. Bounce-back schemes:
  // its solid cells are state (the next set_particles() refills the cells it uncovers). PSM: its
  // fractions (a function of the set alone), for a caller that steps on before handing a new set.
  void restore_particles(const ParticleSet& last);

  // ---- fluid state between steps (the populations the next step reads; the AA parity is handled here),
  // for sources that a coupled driver imposes after a step (e.g. a pressurised borehole).
  // Static solid or covered by a moving particle (bounce-back schemes) now.
  bool covered(int x, int y, int z) const;
  double cell_density(int x, int y, int z) const;  // rho = 1 + sum_q g_q of an interior cell
  // f = f^eq(rho, u) on each listed interior cell that is not covered(); returns the mass added,
  // sum (rho - rho_before) over those cells (lattice units).
  double impose_equilibrium(const std::vector<std::array<int, 3>>& cells, double rho, const Vec3& u);
  // The same with a velocity per cell, u_scale * u_dir[k] on cells[k] (a velocity source such as the
  // hydrofrac's injection box).
  double impose_equilibrium(const std::vector<std::array<int, 3>>& cells, double rho, const std::vector<Vec3>& u_dir,
                            double u_scale);

  // Convective outflow: the speed U of the face's last step (set or the mean outflow speed).
  double outflow_velocity(int face) const { return double(convective_u_[face]); }

  // ---- checkpoint: the populations and the step counter are the whole state (the particle set of
  // the PSM is an input of every step, so a resumed run that sets it again continues bit-for-bit). The convective
  // outflow's state (the previous step's incoming populations and outflow speed of each face
  // node) lives in otherwise unused slots of the open ghost cells, so it is part of populations().
  const AlignedVector<T>& populations() const { return f_; }
  void restore(const std::vector<T>& f, long time_step);

 private:
  // geq into the slots of interior cell x that the next step reads (AA pattern); returns rho minus the
  // cell's density before (impose_equilibrium's mass).
  double put_equilibrium(const std::array<int, 3>& x, const T* geq, double rho);
  struct Span {
    int x0, y, z, n;
  };
  // Below this many bulk cells a step runs on one thread (the fork/join would dominate).
  static constexpr std::int64_t kParallelMinCells = 16384;
  void bulk_sweep(bool odd, bool sample);
  void boundary_sweep(bool odd, bool sample);
  void update_boundary_cell(std::size_t i, bool odd, bool sample);
  void save_interpolation_inputs(bool odd);
  void save_outflow_inputs(bool odd);
  void apply_outflow(T* g, const BoundaryCell& b, const OpenNode<T>& nd, const CellIndex* src, bool odd);
  void reduce_forces();
  void compute_link_velocities();
  Vec3 wall_velocity(int object, const Vec3& x) const;
  CellIndex n_() const { return grid_.padded_size(); }

  Grid grid_;
  SolverSettings settings_;
  Relax<T> relax_;
  std::array<FaceCondition, kNumFaces> faces_;
  std::array<bool, kNumFaces> inflow_wall_{};  // Wall faces with a velocity profile
  std::vector<SolidObject> objects_;
  long time_ = 0;
  T inflow_scale_ = 1;

  AlignedVector<T> f_;                 // Q * N populations
  std::vector<CellType> type_;         // N
  std::vector<std::int16_t> object_;   // N: owning object of solid cells, -1 for fluid
  AlignedVector<T> drho_;              // N: sampled rho - 1
  std::array<AlignedVector<T>, 3> u_;  // N: sampled velocity

  std::vector<Span> spans_;
  std::int64_t num_bulk_cells_ = 0;
  std::vector<BoundaryCell> bcells_;
  std::vector<Link> links_;
  std::vector<OpenNode<T>> open_;
  std::vector<T> link_uw_;             // 3 per link: wall velocity at the link
  std::vector<T> link_saved_;          // 1 per link: g*_q(x, t) saved before the step
  std::vector<double> link_force_;     // 3 per link: momentum exchange of the last step
  // Outflow faces: the outflow nodes (boundary-cell indices, updated in a second pass), the donor
  // buffer (Q pre-collision populations per donor row), the bulk donors copied into it before
  // the step, and each face's convective speed U of the current step.
  struct BulkDonor {
    CellIndex cell;
    int x, y, z;
    std::int32_t row;
  };
  std::vector<std::int32_t> outflow_cells_;
  std::vector<T> donor_g_;
  std::vector<BulkDonor> bulk_donors_;
  std::array<T, kNumFaces> convective_u_{};
  std::unique_ptr<Psm<L, T>> psm_;     // created by the first set_particles()
  std::unique_ptr<MovingBoundary<L, T>> mb_;  // the same for the bounce-back schemes
  // The rows whose particle links the last bulk sweep applied (MovingBoundary::apply_rows), per thread.
  std::vector<std::pair<std::int64_t, std::int64_t>> mb_inline_rows_;
  std::vector<std::int64_t> row_span_;  // per lattice row (y + ny z), its first span; nrows + 1 entries
  // f(cell, span) for every bulk cell, span by span in lattice order.
  template <class F>
  void for_each_bulk_cell(F&& f) const {
    for (std::size_t s = 0; s < spans_.size(); ++s)
      for (int k = 0; k < spans_[s].n; ++k) f(grid_.index(spans_[s].x0 + k, spans_[s].y, spans_[s].z), s);
  }
  void moving_particles(const ParticleSet& p, bool bookkeeping);
  void prepare_psm();  // creates the PSM and (re)classifies its cells
  bool psm_kinds_stale_ = true;        // finalize() changed the cell classification
};

extern template class Solver<D2Q9, double>;
extern template class Solver<D2Q9, float>;
extern template class Solver<D3Q19, double>;
extern template class Solver<D3Q19, float>;

}  // namespace ff::lbm
