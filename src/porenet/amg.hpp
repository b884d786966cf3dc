// Algebraic multigrid preconditioner for the pore-pressure systems (porenet/pcg.hpp), one V-cycle
// per application.
//
// Choice (issue 16, item 8): plain (unsmoothed) aggregation (Vanek, Mandel & Brezina 1996,
// Computing 56:179, without the prolongation smoothing; Notay 2010, ETNA 37:123) with
// over-interpolation (the Galerkin matrix divided by 1.5, Stueben 2001; AMGCL's default for
// plain aggregation), symmetric hybrid Gauss-Seidel smoothing and a dense Cholesky solve on the
// coarsest level. Why plain aggregation: the pressure matrices are symmetric M-matrices whose
// near-null space is the constant vector (closed samples: a graph Laplacian plus a small
// compressibility diagonal), which piecewise-constant prolongation reproduces exactly; and the
// coarse matrices are sums of fine entries (A_c(I,J) = sum over i in I, j in J of a_ij / 1.5), so a
// new matrix on the same pattern (every step: new conductances, densities, dt) refreshes the
// hierarchy with one gather per level: no sparse products, no allocation, and the same sums in the
// same order on any thread count. Smoothed aggregation converges in fewer cycles but needs the
// products A P and P^T A P anew at each refresh. The aggregates (strength of connection
// |a_ij| > eps sqrt(a_ii a_jj), eps = 0.08 halved per level) are built from the first matrix and
// kept while the pattern (the network's topology) is unchanged; PressureSystem rebuilds them when
// the iteration count has doubled since (conductances moved far from the ones they were built on).
// Rows without strong couplings (Dirichlet rows, pores with closed throats) stay out of the coarse
// levels: the smoother solves them.
// Smoother: Gauss-Seidel in fixed blocks of kAmgBlock rows (forward before, backward after the
// coarse correction: a symmetric cycle, as CG needs), couplings across blocks from the values
// before the sweep (hybrid GS), blocks in parallel: the result does not depend on the thread count.
#pragma once
#include <span>
#include <vector>

#include "core/types.hpp"

namespace ff::porenet {

inline constexpr Index kAmgBlock = 4096;

// A symmetric matrix in compressed rows (for Eigen's symmetric column-major storage the columns).
struct CsrView {
  Index n = 0;
  const Index* ptr = nullptr;
  const Index* col = nullptr;
  const Real* val = nullptr;
};

struct AmgParams {
  Real strength = 0.08;      // eps of the strength of connection on the finest level
  Index coarse_size = 128;   // coarsest level solved by dense Cholesky at or below this size
  int max_levels = 16;
  Real over_interp = 1.5;    // coarse matrices divided by this factor
  int sweeps = 1;            // Gauss-Seidel sweeps before and after the coarse correction
};

class Amg {
 public:
  explicit Amg(const AmgParams& prm = {}) : prm_(prm) {}

  // Aggregates and coarse patterns for A's pattern and values (allocates), then refresh(A). Keeps a
  // copy of the values: the aggregates depend on them, and a checkpoint saves them (setup_values).
  void setup(const CsrView& A);
  // The aggregates that setup() built from `values` (one per entry of A's pattern, as setup_values()
  // gave them), on A's pattern (A.val unused): a resumed run preconditions as the uninterrupted one.
  // The caller checks the count; refresh(A) then brings in the current values.
  void restore(const CsrView& A, std::span<const Real> values);
  const std::vector<Real>& setup_values() const { return setup_val_; }
  // New values on the pattern given to setup(): coarse matrices, pivots, Cholesky (no allocation).
  void refresh(const CsrView& A);
  // z = B r, B one symmetric V-cycle (an approximation of A^-1, symmetric positive definite).
  void apply(const Real* r, Real* z);

  bool ready() const { return !levels_.empty(); }
  int n_levels() const { return static_cast<int>(levels_.size()); }
  Index level_size(int l) const { return levels_[static_cast<std::size_t>(l)].n; }
  // Stored entries of all levels / of the finest.
  double operator_complexity() const;

 private:
  struct Level {
    Index n = 0;
    const Index* ptr = nullptr;  // the finest level's arrays are the caller's
    const Index* col = nullptr;
    const Real* val = nullptr;
    std::vector<Index> own_ptr, own_col, diag;
    std::vector<Real> own_val, inv_diag;
    // transfer to the next level: aggregate of each row (-1: none), rows of each aggregate (CSR),
    // the coarse entry of each stored entry (-1: not carried)
    std::vector<Index> agg, agg_ptr, agg_rows, entry_map;
    // x holds 2n values: the iterate, then (smooth()) the values of the rows outside a row's block
    // as the sweep began. The smoother's rows without their diagonal, in the stored order: each
    // entry's slot in x (j inside the row's block, n + j outside) and value (from the entry off_src).
    std::vector<Index> off_ptr, off_slot, off_src;
    std::vector<Real> off_val;
    std::vector<Real> x, b, r;
  };
  void build(const CsrView& A);  // setup() on given values
  void build_level_transfer(Level& f, Level& c, Real eps);
  void smooth(Level& L, bool forward, bool zero_start);
  void cycle(std::size_t l);
  void factor_coarsest();
  void solve_coarsest(Level& L);

  AmgParams prm_;
  std::vector<Level> levels_;
  std::vector<Real> setup_val_;  // the finest values the aggregates were built from
  std::vector<Real> chol_;  // dense lower Cholesky factor of the coarsest level, row-major
};

}  // namespace ff::porenet
