// Moving particles as solid cells with moving-wall bounce-back (issue 15): the alternatives to the
// partially saturated cells of lbm/psm.hpp, chosen once per solver (SolverSettings::particle_scheme).
// Same interface as the PSM: the caller hands the solver a ParticleSet before each step and reads
// back the force and torque on every particle after it (docs/lbm.md, "Moving solid cells").
//
// Solid cells: every lattice cell whose centre lies strictly inside a particle (the first particle
// of the set that contains it owns it). A fluid cell x with a solid neighbour x - c_q has a link;
// its unknown population g_q(x, t+1) comes from
//   - StairwiseBounceBack: the wall half-way along the link, Ladd (1994), J. Fluid Mech. 271:285,
//     as in [S003] Sec. 2.3.2, Eq. 8:   g_q(x, t+1) = g*_o(x, t) + 6 w_q rho_0 (c_q . u_w)
//   - InterpolatedBounceBack: the wall where the link meets the sphere (exact ray-sphere
//     intersection, fraction delta from x), Bouzidi, Firdaouss & Lallemand (2001), Phys. Fluids
//     13:3452, with the moving-wall term of Lallemand & Luo (2003), as [S002] Sec. 3 uses
//     (boundary.hpp: reflect()).
// o = opp(q), u_w = v + omega x (x_w - X) the particle's velocity at the wall point, rho_0 = 1
// ([S003] Sec. 2.3.2: nearly incompressible).
//
// Force: momentum exchange, Ladd (1994), [S003] Eq. 11, on each link the momentum the fluid loses,
//   F = c_o (g*_o(x, t) + g_q(x, t+1)),  T = (x_w - X) x F,
// plus the momentum of the cells that change (Aidun, Lu & Ding 1998, J. Fluid Mech. 373:287): a
// cell a particle covers hands its fluid momentum sum_q c_q g_q to the particle; a cell it
// uncovers is refilled and the refill's momentum rho u_w is taken from the particle. The fluid
// momentum plus the particles' impulse is thus conserved to round-off (test_lbm_moving_conservation),
// which the Galilean-invariant link form of Wen et al. (2014) would not do exactly.
//
// Refill rule (both schemes): a cell that a particle uncovers gets the equilibrium at the average
// density of its neighbours that are fluid before and after the change (rho = 1 if none) and the
// wall velocity of the uncovering particle at the cell centre, f = f^eq(rho_avg, u_w) (the
// "equilibrium refill" compared by Peng et al. 2016, Comput. Fluids 129:37). Mass is not
// conserved by covering and refill: MovingBoundaryStats reports what each change of the set adds
// and removes.
//
// Cost and the bulk kernel: the bulk kernel is unchanged. Solid cells stay in their bulk span
// and are streamed and collided like fluid (garbage in, garbage out), which keeps the kernel
// branch-free; each link writes its reflected population into the slot its fluid cell reads in the
// next step and replaces the population the fluid cell sent into the wall, which the solid cell
// reads next, by g^eq_o(1, u_s) (cost proportional to links). Links that stood for two steps are
// applied by lattice row inside the bulk sweep, a few rows behind it, while those rows' populations
// are still in cache (apply_rows; after the sweep they are in memory: that pass cost 3 LBM steps on
// the 2D benchmark's 593,000 links, the sweep's 1.5); the others, and a changing set's, in apply();
// the cells just covered, and those next to a static solid or the lattice's edge, get f^eq(1, u_s)
// in every slot (with a body force, every solid cell: set_reset_all()). The other inputs of a
// solid cell come from solid cells, near f^eq(1, u_s)
// (exactly f^eq(1, 0) for particles at rest), so the solid cells hold finite values near the
// particle's velocity without a reset of every covered cell; no fluid cell ever reads a solid cell
// (the links overwrite those slots). This works because in the AA pattern every slot a fluid cell
// reads at t+1 is written by its link after every cell that touches that slot in step t has run.
//
// Incremental set (the particles move ~0.002 cells per step): each particle keeps its solid cells
// and its links in its own slice of two arrays (with room to grow). set_particles() rescans a
// particle only when it has moved more than `margin` since its last scan (margin: the smallest
// distance of a lattice point from its surface then, so no cell can have crossed it), its radius
// changed, it overlaps another particle, or a particle before it took one of its cells; a rescan
// visits the rows of its bounding box (cost proportional to its covered cells, never to the
// lattice). Links (and the exposed cells) are rebuilt only for the particles whose cells changed
// or lie within two lattice steps of a cell that changed; the wall velocity is computed at use from
// (v, omega), the Bouzidi fraction when the particle moved. Every cached value is the exact function
// of the current set, and each particle's cells and links are in scan order, so the result does not
// depend on which particles were rescanned (nor on a resume, which rebuilds everything).
//
// Resume: the solid cells of the last step are state (the refill of the next change depends on
// them). A resumed run calls Solver::restore() and then Solver::restore_particles() with the set
// of the last step before the checkpoint; the run then continues bit-for-bit.
#pragma once
#include <cstdint>
#include <vector>

#include "core/types.hpp"
#include "lbm/collision.hpp"
#include "lbm/grid.hpp"
#include "lbm/psm.hpp"

namespace ff::lbm {

// How moving particles enter the fluid (issue 15).
enum class ParticleScheme : std::uint8_t {
  Psm,                     // partially saturated cells (lbm/psm.hpp), the default
  StairwiseBounceBack,     // solid cells, half-way moving bounce-back ([S003] Sec. 2.3-2.4)
  InterpolatedBounceBack,  // solid cells, Bouzidi interpolation with the exact link fractions ([S002] Sec. 3)
};
const char* particle_scheme_name(ParticleScheme s);

// What the last set_particles() changed (covering and refill), lattice units.
struct MovingBoundaryStats {
  long solid_cells = 0, links = 0;
  long covered = 0, uncovered = 0;  // cells that became solid / fluid
  long unattributed = 0;            // uncovered cells whose particle is no longer in the set
  double mass_removed = 0;          // sum of rho over the covered cells
  double mass_added = 0;            // sum of the refill densities
  Vec3 impulse = Vec3::Zero();      // momentum moved from the fluid to the particles by the change
};

template <class L, class T>
class MovingBoundary {
 public:
  static constexpr int Q = L::Q;
  MovingBoundary(const Grid& grid, ParticleScheme scheme, bool incompressible);

  // Static fluid cells per padded cell (1: updated by the solver's boundary sweep, 2: by the bulk
  // sweep; 0: not fluid), set by the solver once per geometry; forgets the set.
  void set_fluid_mask(std::vector<std::uint8_t> fluid);
  // New particle set before a step of parity `odd` on populations f. bookkeeping = false only
  // rebuilds the solid cells and links of a set (resume): no covering, no refill.
  void set_particles(const ParticleSet& p, T* f, bool odd, bool bookkeeping);
  // After the sweeps of a step of parity `odd`: reflected populations of every link the sweep did
  // not apply, then the solid cells' reset. Then reduce() sums the per-particle loads in a fixed
  // order. `inline_rows`: the lattice rows whose links the bulk sweep applied (apply_rows), one
  // range per thread; empty when it applied none (then every link is applied here).
  void apply(T* f, bool odd, const std::vector<std::pair<std::int64_t, std::int64_t>>& inline_rows = {});
  void reduce();

  // ---- Links inside the bulk sweep (Solver::bulk_sweep). A link reads and writes only slots that
  // its fluid node x and the cells x -+ c_q own in this step (AA pattern), so once rows
  // row(x) - lag .. row(x) + lag are swept nothing else touches them (lattice row = y + ny z; lag 1
  // in 2D, ny + 1 in 3D). Links are grouped per row and particle (a group: one particle's links in
  // one row); groups with a cell that is not a bulk cell (boundary cells are updated after the
  // sweep) or a link round a periodic edge wait for apply(), as do the rows at the ends of each
  // thread's block. Each particle's load is the sum of its groups' in row order, each group's from
  // zero in link order, and apply() without the index sums a particle's links the same way (its
  // slice is in node-row order): the same on any thread count, whichever rows the sweep applied,
  // and after a resume. A link of a particle at rest reads constants kept while the particle keeps
  // its place (reflect()'s coefficients and the torque lever; apply() computes them the same way).
  // The row index is built (apply(), once the links stood for two steps): the sweep may apply them.
  bool rows_ready() const { return active() && rows_epoch_ == links_epoch_; }
  // false: no row index, every link after the sweep (the same results, slower: for tests).
  void set_row_index(bool on) {
    row_index_ = on;
    if (!on) rows_epoch_ = 0;
  }
  std::int64_t row_lag() const { return L::D == 3 ? std::int64_t(grid_.ny) + 1 : 1; }
  void prepare_rows();  // before the sweep: fractions and constants of the particles that moved
  void apply_rows(T* f, bool odd, std::int64_t r0, std::int64_t r1) const;  // links of rows [r0, r1)
  // With a body force the solid cells' own collision drives them: every solid cell is then reset
  // each step (as the links alone keep them near f^eq(1, u_s) only without one). Set by the solver.
  void set_reset_all(bool all) { reset_all_ = all; }

  bool active() const { return ncells_ > 0; }
  bool solid(CellIndex cell) const { return !owner_.empty() && owner_[std::size_t(cell)] >= 0; }
  const std::vector<Vec3>& forces() const { return force_; }
  const std::vector<Vec3>& torques() const { return torque_; }
  const MovingBoundaryStats& stats() const { return stats_; }
  std::size_t num_cells() const { return ncells_; }
  std::size_t num_links() const { return nlinks_; }

 private:
  // A solid cell: lattice index and unwrapped coordinates (arm = xu - X exactly as scanned).
  struct SolidCell {
    CellIndex cell;
    std::int32_t xu[3];
    bool edge;  // on a periodic lattice edge: neighbours wrap (slow path)
  };
  // A link: fluid node x (solid cell + c_q) and direction q; slots from fixed offsets unless x lies on
  // a periodic lattice edge (edge: wrapped neighbours, slow path). 32 bytes (double).
  struct MovingLink {
    CellIndex node;
    std::int32_t xu[3];  // the solid cell's unwrapped coordinates
    std::uint8_t q;
    bool has_second;     // x + c_q is fluid
    bool edge;
    double delta;        // wall fraction along the link from x (x_w = x - delta c_q)
  };
  struct Slice {  // a particle's range in cells_ / links_: [first, first + count), room for cap
    std::int32_t first = 0, count = 0, cap = 0;
  };
  struct Motion {
    Vec3 x, v, w;  // centre, velocity, angular velocity (2D: z only)
    bool moves() const { return v != Vec3::Zero() || w != Vec3::Zero(); }  // (as Psm's Kinematics)
  };
  CellIndex pre(const int* x, int q, bool odd) const;   // slot g_q is read from in a step of parity odd
  CellIndex post(const int* x, int q, bool odd) const;  // slot g*_q is written to
  bool fluid_now(CellIndex c) const { return fluid_[std::size_t(c)] && owner_[std::size_t(c)] < 0; }
  bool on_edge(CellIndex c) const;  // on a periodic lattice edge
  Vec3 arm_of(CellIndex c, std::size_t s, const std::vector<Motion>& m) const;  // minimum image
  void release_all();
  // Scans particle s into scan_ (cells inside it, static fluid), sets its margin; false if unchanged.
  void scan(std::size_t s, const ParticleSet& p);
  void claim(std::size_t s);  // ownership of scan_ for particle s; updates its slice when it changed
  void build_links(std::size_t s, const ParticleSet& p);  // links and exposed cells of particle s
  void update_delta(std::size_t s);  // per particle, in parallel
  double link_delta(const MovingLink& k, const Motion& m, double r) const;
  void mark_dirty(CellIndex changed);  // particles whose links may see a changed cell
  template <class V>
  void place(V& arr, Slice& sl, std::int32_t need, std::vector<Slice>& all, V& spare, std::vector<std::int32_t>* par);
  void reset_cell(T* f, CellIndex c, bool edge, const Vec3& arm, const Motion& m, bool next) const;
  // Links by lattice row (Solver::bulk_sweep applies them row by row): per row a copy of what each
  // link reads (links_ in row order would be a cache miss per link), in two parts: what a link of a
  // particle at rest needs (RowLink: its constants, set_constants), and the geometry for the rest.
  struct RowLink {
    CellIndex node;
    T a, b;                                // at rest: g_q(x, t + 1) = a A + b X
    double lever[L::D == 3 ? 3 : 1];       // (x_w - X) x c_o (2D: its z)
    std::uint8_t q, second;                // X: 0 = A, 1 = B = g*_q(x, t), 2 = C = g*_o(x + c_q, t)
    bool edge, late;
  };
  struct RowGeometry {
    double delta;
    std::int32_t xu[3];  // the solid cell's unwrapped coordinates
    std::int32_t particle;
    bool has_second;
  };
  // Consecutive links of one particle in one row: the unit the sweep applies and whose force and
  // torque it sums (items [first, first + count) of row_item_). Late: left to apply().
  struct Group {
    std::int64_t first;
    std::int32_t count, particle;
    bool late;
  };
  // K: a RowGeometry or a MovingLink (delta, xu, has_second); H: a RowLink or a MovingLink (node, q, edge).
  template <class K>
  Vec3 link_arm(const K& k, int q, const Motion& m) const;  // wall point minus particle centre
  template <class K>
  void set_constants(RowLink& h, const K& k, const Motion& m) const;
  template <bool kMoving, class H, class K>
  double exchange(T* f, bool odd, const H& h, const K& k, const Motion& m, const Vec3& arm) const;
  template <bool kMoving, class H, class K>
  void add_link(T* f, bool odd, const H& h, const K& k, const Motion& m, Vec3& F, Vec3& M) const;
  template <bool kMoving>
  void particle_links(T* f, bool odd, std::size_t s, Vec3& F, Vec3& M) const;
  void apply_groups(T* f, bool odd, const std::vector<std::pair<std::int64_t, std::int64_t>>& inline_rows);
  std::int64_t node_row(const MovingLink& k) const;  // the lattice row of its fluid node
  template <bool kMoving>
  void apply_group_as(T* f, bool odd, std::int64_t g) const;
  void apply_group(T* f, bool odd, std::int64_t g) const;
  void build_rows();  // row_item_, groups_ and their indices from the current links
  std::vector<std::int64_t> row_count_;   // per row, its first item (nrows + 1)
  std::vector<RowLink> row_item_;
  std::vector<RowGeometry> row_geo_;      // parallel to row_item_
  std::vector<Vec3> const_x_;             // per particle, the position and radius its links'
  std::vector<double> const_r_;           // constants were set at
  std::vector<std::int32_t> row_pos_;     // per link index, its item
  std::vector<std::int64_t> link_row_, row_fill_;  // build_rows() scratch
  std::vector<Group> groups_;
  std::vector<std::int64_t> row_group_;   // per row, its first group (nrows + 1)
  std::vector<std::int64_t> part_group_first_;  // per particle its groups in part_group_ (row order)
  std::vector<std::int32_t> part_group_;
  std::vector<Vec3> group_force_, group_torque_;
  std::vector<std::int64_t> deferred_groups_;  // apply(): the groups the sweep left to it
  std::vector<std::pair<std::int64_t, std::int64_t>> done_rows_;  // apply(): the sweep's rows, sorted
  std::uint64_t links_epoch_ = 1, rows_epoch_ = 0, applied_epoch_ = 0;
  int stood_ = 0;  // apply() calls in a row with the same links
  bool row_index_ = true;

  Grid grid_;
  ParticleScheme scheme_;
  bool incompressible_;
  std::int64_t pre_off_[2][Q], post_off_[2][Q], cq_off_[Q];
  std::vector<std::uint8_t> fluid_;   // per padded cell: static fluid (1: a boundary cell, 2: a bulk cell)
  // Per padded cell: the particle that owns it (-1: fluid; -2 - s: released by s in this set).
  std::vector<std::int32_t> owner_;
  std::size_t np_ = 0;
  std::vector<Motion> mot_, prev_mot_;
  std::vector<std::uint64_t> pid_, prev_pid_;
  std::vector<double> radius_;
  // Per particle: last scan (position, radius, margin), flags, slices.
  std::vector<Vec3> scan_x_;
  std::vector<double> scan_r_, margin_;
  std::vector<std::uint8_t> rescan_, contested_, dirty_;
  std::vector<Vec3> delta_x_;  // position and radius of the links' Bouzidi fractions
  std::vector<double> delta_r_;
  std::vector<Slice> cs_, ls_;
  std::vector<std::int32_t> ecount_;          // exposed cells of the particle (offsets in eoff_)
  std::vector<SolidCell> cells_, cells_spare_;
  std::vector<std::int32_t> eoff_, eoff_spare_;  // parallel to cells_: offsets of exposed cells in the slice
  std::vector<MovingLink> links_, links_spare_;
  std::vector<SolidCell> scan_;               // scratch: one particle's scan
  std::vector<MovingLink> new_links_;         // scratch: one particle's links
  std::vector<MovingLink> sorted_links_;      // scratch: them in node-row order
  std::vector<std::int32_t> sort_count_;      // scratch: per row of the particle's span
  std::vector<std::int32_t> new_eoff_;
  std::vector<CellIndex> covered_, released_, pending_;  // pending_: covered cells to reset once
  std::size_t ncells_ = 0, nlinks_ = 0;
  bool links_valid_ = false;          // the slices belong to owner_ (false after set_fluid_mask())
  bool applied_ = false;
  bool reset_all_ = false;
  std::vector<Vec3> impulse_, impulse_torque_;  // per particle, from covering and refill
  std::vector<Vec3> lforce_, ltorque_;          // per particle, from the links of the last apply()
  std::vector<Vec3> force_, torque_;
  MovingBoundaryStats stats_;
};

extern template class MovingBoundary<D2Q9, double>;
extern template class MovingBoundary<D2Q9, float>;
extern template class MovingBoundary<D3Q19, double>;
extern template class MovingBoundary<D3Q19, float>;

}  // namespace ff::lbm
