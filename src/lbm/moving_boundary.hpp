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
// Cost and the bulk kernel: nothing changes in the bulk sweep. Solid cells stay in their bulk span
// and are streamed and collided like fluid (garbage in, garbage out), which keeps the kernel
// branch-free; after the sweeps of a step a post-pass (cost proportional to links) writes each link's
// reflected population into the slot its fluid cell reads in the next step, and then resets every
// solid cell to f^eq(1, u_s) (cost proportional to covered cells), so solid cells hold finite values
// and their sampled moments are the particle's velocity. This works because in the AA pattern
// every slot a fluid cell reads at t+1 is written by the post-pass after every cell of step t has
// run. set_particles() visits the rows of each particle's bounding box that it can cover and the
// cells of the previous set: the cost is proportional to the covered cells, never to the lattice.
// Links are rebuilt only for the particles whose solid cells changed or lie within two lattice
// steps of a cell that changed; the others keep their nodes and slots and only move (new wall
// fraction and velocity), with the same arithmetic, so the result does not depend on which
// particles were rebuilt (benchmarks/coupled checks the populations against the full rebuild).
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

  // Static fluid cells (1) per padded cell, set by the solver once per geometry; forgets the set.
  void set_fluid_mask(std::vector<std::uint8_t> fluid);
  // New particle set before a step of parity `odd` on populations f. bookkeeping = false only
  // rebuilds the solid cells and links of a set (resume): no covering, no refill.
  void set_particles(const ParticleSet& p, T* f, bool odd, bool bookkeeping);
  // Post-pass after the sweeps of a step of parity `odd`: reflected populations of every link,
  // then the solid cells' reset. Then reduce() sums the per-particle loads in a fixed order.
  void apply(T* f, bool odd);
  void reduce();

  bool active() const { return !cells_.empty(); }
  bool solid(CellIndex cell) const { return !owner_.empty() && owner_[std::size_t(cell)] >= 0; }
  const std::vector<Vec3>& forces() const { return force_; }
  const std::vector<Vec3>& torques() const { return torque_; }
  const MovingBoundaryStats& stats() const { return stats_; }
  std::size_t num_cells() const { return cells_.size(); }
  std::size_t num_links() const { return links_.size(); }

 private:
  struct SolidCell {
    CellIndex cell;
    int x[3];
    std::int32_t particle;
    std::uint64_t id;  // the particle's id (its index if the set has no ids), for refill attribution
    Vec3 arm;          // cell centre minus particle centre (unwrapped)
    T us[3];           // particle velocity at the cell centre
    bool edge;         // on a periodic lattice edge: neighbours wrap (slow path)
  };
  // 96 bytes (double): apply(), the links' update and reduce() each stream the whole array, so
  // what can be recomputed from the solid cell is not stored (the fluid node, the wall point).
  struct MovingLink {
    std::uint8_t q;    // incoming direction: the fluid node x = solid cell + c_q
    bool has_second;   // x + c_q is fluid
    std::int32_t particle;
    std::int32_t solid;  // its solid cell (index into cells_)
    double delta;      // wall fraction along the link from x (x_w = x - delta c_q)
    T mw;              // moving-wall term 6 w_q c_q . u_w, u_w the wall velocity at x_w
    // Slots per step parity: g*_o(x), g*_q(x), g*_o(x + c_q) of this step, g_q(x) of the next.
    CellIndex slot[2][4];
  };
  CellIndex pre(const int* x, int q, bool odd) const;   // slot g_q is read from in a step of parity odd
  CellIndex post(const int* x, int q, bool odd) const;  // slot g*_q is written to
  bool fluid_now(CellIndex c) const { return fluid_[std::size_t(c)] && owner_[std::size_t(c)] < 0; }
  void build_links(const ParticleSet& p, bool incremental);
  void add_links(std::int32_t solid, const ParticleSet& p);  // the links of one solid cell
  void link_motion(MovingLink& k, const ParticleSet& p) const;  // delta, arm, u_w of a link
  void mark_dirty(CellIndex changed);  // particles whose links may see a changed cell

  Grid grid_;
  ParticleScheme scheme_;
  bool incompressible_;
  std::int64_t pre_off_[2][Q];        // pre() as an offset from the cell index where nothing wraps
  std::vector<std::uint8_t> fluid_;   // per padded cell: static fluid
  std::vector<std::int32_t> owner_;   // per padded cell: index into cells_ of the current set, -1 if fluid
  std::vector<std::int32_t> next_;    // per padded cell: scratch for the new set
  std::vector<SolidCell> cells_, new_cells_;
  std::vector<MovingLink> links_, new_links_;
  // Incremental links: per particle its range in cells_ (cfirst_/ccount_; nfirst_/ncount_ for
  // new_cells_) and in links_; a particle is dirty when its cells or a cell within two lattice
  // steps of them changed, and only dirty particles rebuild their links.
  std::vector<std::int32_t> cfirst_, ccount_, nfirst_, ncount_, lfirst_, lcount_, nlfirst_, nlcount_;
  std::vector<std::uint8_t> dirty_;
  // The cell indices of cells_ / new_cells_ alone (the passes over every solid cell read only
  // these), and the cells that turned solid (in new_cells_) and fluid (in cells_) in this set.
  std::vector<CellIndex> cell_, new_cell_;
  std::vector<std::int32_t> covered_, uncovered_;
  bool links_valid_ = false;          // links_ belong to cells_ (false after set_fluid_mask())
  std::vector<double> link_force_;    // 3 per link
  std::vector<Vec3> impulse_, impulse_torque_;  // per particle, from covering and refill
  std::vector<Vec3> force_, torque_;
  MovingBoundaryStats stats_;
};

extern template class MovingBoundary<D2Q9, double>;
extern template class MovingBoundary<D2Q9, float>;
extern template class MovingBoundary<D3Q19, double>;
extern template class MovingBoundary<D3Q19, float>;

}  // namespace ff::lbm
