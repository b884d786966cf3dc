// Partially saturated cells (PSM): moving particles in the LBM through a per-cell solid fraction,
// Noble & Torczynski (1998), Int. J. Mod. Phys. C 9:1189 (as in waLBerla and MechSys). No DEM
// dependency: the caller hands the solver a ParticleSet before each step and reads back the
// hydrodynamic force and torque on every particle after it (docs/lbm.md, "Partially saturated
// cells (issue 15)").
//
// Per covered cell, with eps its covered fraction and tau the shear relaxation time,
//   B(eps, tau) = eps (tau - 1/2) / ((1 - eps) + (tau - 1/2))                       (N&T 1998)
//   f_q(x + c_q, t + 1) = f_q + (1 - B) Omega^f_q + sum_s B_s Omega^s_q(u_s)          (N&T 1998)
// Omega^f is the solver's own collision (TRT or BGK, with its forcing, so the body force acts on
// the fluid fraction 1 - B). Omega^s is N&T's original solid operator, a bounce-back of the
// non-equilibrium part (N&T 1998; not the "superposition" variant of Holdych 2003):
//   Omega^s_q = f_{-q}(x) - f_q(x) + f^eq_q(rho, u_s) - f^eq_{-q}(rho, u),
// with rho and u the cell's fluid moments and u_s = v + omega x (x - X) the particle's velocity at
// the cell centre. It conserves mass; its momentum goes to the particle:
//   F_s = -B_s sum_q c_q Omega^s_q,  T_s = (x - X_s) x F_s                           (N&T 1998)
// Several particles in one cell (touching grains of bonded rock): eps = min(1, sum_s eps_s),
// B from eps, B_s = B eps_s / sum eps_s (Owen, Leonardi & Feng 2011, Int. J. Numer. Meth. Eng.
// 87:66).
//
// Covered fraction of a cell by a disk or sphere: the cell is cut by the plane tangent to the
// particle on the line from its centre through the cell centre, moved inwards by the mean gap
// between that plane and the curved surface over the cell, (D - 1)/(24 r); the volume of a unit
// square or cube below a plane is exact (inclusion-exclusion over the corners, Scardovelli &
// Zaleski 2000, J. Comput. Phys. 164:228). Measured against 64^2 / 32^3 sub-cell
// sampling: total covered volume within 0.1% for r >= 3 cells, each cell within 0.02 (test_psm).
//
// Wall links of a covered boundary cell: each covering particle s takes B_s times the part of the
// link's momentum exchange tangential to the wall, the wall the normal part and the rest
// (Solver::reduce_forces; docs/coupling.md, "Wall links of covered cells").
//
// Cost: a rebuild (set_particles) clears the cells of the previous particle set and visits, in each
// row of a particle's bounding box, only the cells within r + half a cell diagonal of its centre;
// nothing sweeps the lattice. The fractions are computed in parallel over fixed chunks of particles
// and gathered in particle order; the covered cells are then listed in lattice order (x fastest),
// so the cells and entries are the same on any thread count. With a refresh distance the fractions
// are kept over small moves and only the velocities are taken (set_particles). Bulk spans with
// covered cells run a fused kernel (psm_sweep.cpp): the collision and the PSM update in one pass,
// reading per cell B, V = sum_s B_s u_s and S = sum_s B_s u_s u_s^T (exact for any number of
// particles on the cell: f^eq is quadratic in the velocity) and writing the cell's rho and u; spans
// without covered cells keep the bulk kernel (its speed away from particles). Boundary cells apply
// the same update inside their own path; with every particle at rest (quasi-static walls) the
// kernel reads B alone. Every cell owns its slots (AA pattern), so cells are independent; the
// particles' forces are summed in one pass over the covered cells in lattice order (with every
// particle at rest, a particle's consecutive cells along a row as one run: a few contiguous sums of
// the cells' forces B (rho u - f_body), which the kernel writes instead of rho and u; in blocks of
// lattice planes at least as tall as any particle, the even blocks in parallel, then the odd ones;
// Psm::reduce): results are the same on any thread count.
#pragma once
#include <cstdint>
#include <vector>

#include "core/types.hpp"
#include "lbm/collision.hpp"
#include "lbm/grid.hpp"

namespace ff::lbm {

// The particles of one step, structure of arrays, lattice units (cell (x, y, z) has its centre at
// (x, y, z)); disks on D2Q9 (z and the x, y components of omega are ignored), spheres on D3Q19.
struct ParticleSet {
  std::vector<std::uint64_t> id;    // the caller's ids, carried along (not used by the solver)
  std::vector<Vec3> position;
  std::vector<double> radius;
  std::vector<Vec3> velocity;
  std::vector<Vec3> omega;
  std::size_t size() const { return radius.size(); }
  void resize(std::size_t n) {
    id.resize(n);
    position.resize(n, Vec3::Zero());
    radius.resize(n, 0.0);
    velocity.resize(n, Vec3::Zero());
    omega.resize(n, Vec3::Zero());
  }
};

// Every particle of `p` lies within `cells` of `positions` with the radius in `radii` (the same
// count; z ignored on D2Q9): a set that a refresh distance lets stand (Psm::set_refresh; the
// coupler's CouplerSettings::set_refresh).
bool within_refresh(const ParticleSet& p, const std::vector<Vec3>& positions, const std::vector<double>& radii,
                    double cells, int dim);

// Noble & Torczynski's (1998) two weightings of a cell's solid operator: the tau-dependent
// B(eps, tau) = eps (tau - 1/2) / ((1 - eps) + (tau - 1/2)) (their preferred one, the default), and the
// linear B = eps. The tau-dependent one is below eps in partly covered cells: narrow throats resist too
// little and the body force pushes sum (1 - B) > V_f, so a dense packing's permeability comes out 2-3x
// Kozeny-Carman at 4 cells per radius; the linear one gives -3..+32 % there at tau 0.6 (both grow with
// tau: docs/coupling.md, "Permeability").
enum class PsmWeighting : std::uint8_t { TauDependent = 0, Linear = 1 };
inline double psm_weight(double eps, double tau) { return eps * (tau - 0.5) / ((1.0 - eps) + (tau - 0.5)); }
inline double psm_weight(double eps, double tau, PsmWeighting w) {
  return w == PsmWeighting::Linear ? eps : psm_weight(eps, tau);
}

// Covered fraction of the unit cell centred at `d` (cell centre minus particle centre) by a disk
// (dim 2, d[2] ignored) or sphere of radius r (plane approximation above).
double psm_cell_fraction(int dim, const Vec3& d, double r);

// Per padded cell, the bulk cells the particles cover (Psm::bulk_cells), for the fused kernel: B,
// and the sums over the covering particles s of B_s u_s (V) and of B_s u_s u_s^T (S: xx, xy, yy in 2D;
// xx, xy, xz, yy, yz, zz in 3D), which give sum_s B_s Omega^s_q exactly, for any number of particles
// (f^eq is quadratic in the velocity); written by the kernel, the cell's rho (1 if incompressible)
// and u, the collision's moments, from which each particle's force follows (Psm::reduce); with every
// particle at rest (Psm::moving() false) rho is not written and u holds the cell's force
// B (rho u - f_body) instead (lattice units; f_body the fluid's body force, Relax::force).
// B = 0: not a covered bulk cell. Components beyond D (V, u) or beyond the 2D three (S) are null.
template <class T>
struct PsmCells {
  const T* B = nullptr;
  const T* V[3] = {nullptr, nullptr, nullptr};
  const T* S[6] = {nullptr, nullptr, nullptr, nullptr, nullptr, nullptr};
  T* rho = nullptr;
  T* u[3] = {nullptr, nullptr, nullptr};
};
// The fused stream-collide + PSM kernel of one bulk span (psm_sweep.cpp), the bulk kernel's
// signature plus the cells: g = (1 - B) g* + B g + sum_s B_s Omega^s where B > 0, g* elsewhere.
template <class T>
using PsmSpanFn = void (*)(const Grid&, T*, CellIndex, int, int, int, int, bool, const Relax<T>&, T*, T* const*,
                           const PsmCells<T>&);
template <class L, class T>
PsmSpanFn<T> psm_span_kernel(CollisionModel model, bool force, bool moments, bool incomp, bool moving);

template <class L, class T>
class Psm {
 public:
  static constexpr int Q = L::Q;
  Psm(const Grid& grid, double tau, PsmWeighting weighting = PsmWeighting::TauDependent);

  // Which cells may be covered, set by the solver once per geometry: per padded cell the bulk span
  // that updates it (>= 0), kBoundaryCell, or kNotFluid (solid or ghost, never covered).
  static constexpr std::int32_t kBoundaryCell = -2, kNotFluid = -1;
  void set_cell_spans(std::vector<std::int32_t> span_of_cell, std::size_t num_spans);
  // Clears the previous set's cells and covers those of `p`; throws InputError on bad input.
  // With a refresh distance d > 0 (set_refresh) the fractions are kept while every particle lies
  // within d cells of where they were computed (same count and radii): then only the particles'
  // velocities are taken (V and S of every covered bulk cell), at a cost of one pass over the cells
  // instead of a rebuild. The fractions then lag the particles by at most d cells (psm_cell_fraction
  // itself is within 0.02 of the sub-cell integral), and the forces' arms by as much.
  void set_particles(const ParticleSet& p);
  void set_refresh(double cells) { refresh_ = cells; }
  double refresh() const { return refresh_; }
  // The positions and radii the current fractions were computed from (a checkpoint keeps them:
  // with a refresh distance they are state), and a rebuild from them (resume; velocities zero
  // until the next set_particles).
  const std::vector<Vec3>& geometry_positions() const { return ref_pos_; }
  const std::vector<double>& geometry_radii() const { return ref_radius_; }
  void restore_geometry(const std::vector<Vec3>& positions, const std::vector<double>& radii);
  long rebuilds() const { return rebuilds_; }  // full rebuilds so far (set_particles that moved the cells)

  // ---- hooks of Solver::step()
  bool active() const { return !cells_.empty(); }
  std::int32_t slot(CellIndex cell) const { return slot_[std::size_t(cell)]; }
  // A span with covered bulk cells runs the fused kernel (psm_span_kernel) on bulk_cells() instead
  // of the bulk kernel.
  bool span_covered(std::int64_t span) const { return span_fused_[std::size_t(span)] != 0; }
  PsmCells<T> bulk_cells();
  // Some particle moves (nonzero velocity or spin): the fused kernel reads the cells' V and S;
  // otherwise they are zero, neither kept nor read.
  bool moving() const { return moving_; }
  // One boundary cell: g holds its post-collision populations, gpre the pre-collision ones.
  void apply(std::int32_t slot, const T* gpre, T* g, const Relax<T>& r, bool force, bool incomp);
  // Per-particle force and torque of the step (one pass over the covered cells in lattice order);
  // body_force the fluid's (lattice units, as the collision had it).
  void reduce(const Vec3& body_force);
  // The tangential part Ft of a wall link's momentum exchange in `cell` (Solver::reduce_forces,
  // after reduce(), in link order): B_s Ft goes to each particle s covering the cell (torque with
  // the cell's arm); returns the sum handed out, B Ft (zero if the cell is uncovered).
  Vec3 book_wall_link(CellIndex cell, const Vec3& Ft);
  // Per particle, the part of forces() booked from wall links in the last step.
  const std::vector<Vec3>& wall_link_forces() const { return wall_force_; }

  // ---- results of the last step, lattice units, indexed like the ParticleSet
  const std::vector<Vec3>& forces() const { return force_; }
  const std::vector<Vec3>& torques() const { return torque_; }
  // Covered cells and the solid fraction of the current set (for output and tests).
  std::size_t num_cells() const { return cells_.size(); }
  double solid_fraction(CellIndex cell) const;  // eps, 0 where uncovered
  double weight(CellIndex cell) const;          // B, 0 where uncovered

 private:
  struct Cell {
    CellIndex cell;
    std::int32_t first = 0, count = 0;  // entries [first, first + count)
    double eps = 0;                     // sum of the particles' fractions (before the cap at 1)
    T B = 0;
    bool boundary = false;
    bool edge = false;  // on a periodic lattice edge
  };
  struct Entry {
    std::int32_t particle;
    T Bs;                   // B_s
    double eps;
    Vec3 arm;               // cell centre minus particle centre (unwrapped)
  };
  void build(const ParticleSet& p);          // the fractions, entries and spans of `p`
  void take_kinematics(const ParticleSet& p);  // kin_ and the bulk cells' V and S, cells kept
  void cell_velocity_sums(const Cell& c);      // V and S of one bulk cell from kin_
  Grid grid_;
  double tau_;
  double refresh_ = 0;
  long rebuilds_ = 0;
  bool moving_ = false;
  std::vector<Vec3> ref_pos_;
  std::vector<double> ref_radius_;
  PsmWeighting weighting_ = PsmWeighting::TauDependent;
  std::vector<std::int32_t> span_of_;    // per padded cell (set_cell_spans)
  std::vector<std::uint8_t> span_fused_;  // per span: has covered bulk cells
  std::vector<std::int32_t> fused_spans_;  // those spans (cleared by the next set)
  // Per padded cell (bulk_cells): B, V, S of covered bulk cells; rho, u written by the kernel.
  static constexpr int kS = L::D == 3 ? 6 : 3;
  std::vector<T> cell_B_, cell_V_[3], cell_S_[6], cell_rho_, cell_u_[3];
  // Per padded cell: index into cells_, -1 if uncovered.
  std::vector<std::int32_t> slot_;
  // Rebuild scratch (build): per lattice row (y, z), the particles crossing it (row_item_
  // [row_first_[row] ..)) and where its cells and entries are (row_out_).
  struct RowItem {
    std::int32_t particle, y, z;  // y, z unwrapped
  };
  std::vector<std::int64_t> row_first_, row_fill_;
  std::vector<RowItem> row_item_;
  std::vector<Cell> cells_;          // in lattice order (x fastest), so that the sweep reads them in order
  std::vector<Entry> entries_;       // grouped by cell, particle order within a cell
  struct RowOut {  // where build() left a row (thread, first cell and entry there, counts) and where it goes
    int thread = 0;
    std::int64_t cell_begin = 0, cells = 0, entry_begin = 0, entries = 0;
    std::int64_t cell_dest = 0, entry_dest = 0;  // its first cell in cells_, entry in entries_
  };
  std::vector<RowOut> row_out_;
  struct RowCandidate {  // an entry of a row before its cell is known: x, particle, eps, arm
    std::int32_t x, particle;
    double eps;
    Vec3 arm;
  };
  struct RowScratch {  // per thread
    std::vector<RowCandidate> cand;
    std::vector<std::int32_t> count;  // per x + 1
    std::vector<Cell> cells;          // its rows' cells and entries, in row order
    std::vector<Entry> entries;
  };
  std::vector<RowScratch> scratch_;
  struct Kinematics {
    Vec3 v, w;
    bool moves() const { return v != Vec3::Zero() || w != Vec3::Zero(); }
  };
  std::vector<Kinematics> kin_;
  // Particle s's velocity and angular velocity; disks: (vx, vy, 0) and (0, 0, wz), the rest ignored.
  static Kinematics kinematics(const ParticleSet& p, std::size_t s) {
    if constexpr (L::D == 3) return {p.velocity[s], p.omega[s]};
    return {Vec3(p.velocity[s][0], p.velocity[s][1], 0), Vec3(0, 0, p.omega[s][2])};
  }
  std::vector<double> entry_force_;  // 3 per entry of a boundary cell
  // The covered cells in lattice order as reduce() visits them, each item self-contained (read in
  // order, no look-up of cells_ and entries_): a run of `count` consecutive bulk cells of one
  // particle alone (the same row, x ascending; their forces as the kernel wrote them), one particle's
  // entry of a shared bulk cell (count 1, its share B_s / B of the cell's force), or a boundary cell
  // (particle -1: its entries' forces from apply()). Read once per step each (48 bytes with double);
  // the lattice row is the one whose items these are (row_runs_).
  struct Run {
    std::int32_t x;             // the first cell's x in the row
    std::int32_t count;         // cells in the run (1: a shared cell's entry or a boundary cell)
    std::int32_t particle;      // -1: a boundary cell
    T share;                    // B_s / B (1 but for a shared cell's entry)
    Vec3 arm;                   // the first cell's arm
  };
  std::vector<Run> runs_;
  bool runs_built_ = false;  // runs_ belong to the current cells (built once a static set is reduced)
  std::vector<std::int64_t> row_runs_;  // per lattice row, its first item in runs_ (build_runs)
  // reduce()'s blocks of rows (first rows, then the end; a single block: a serial pass).
  std::vector<std::int64_t> reduce_blocks_;
  void build_runs();
  std::vector<Vec3> force_, torque_, wall_force_;
};

extern template class Psm<D2Q9, double>;
extern template class Psm<D2Q9, float>;
extern template class Psm<D3Q19, double>;
extern template class Psm<D3Q19, float>;

}  // namespace ff::lbm
