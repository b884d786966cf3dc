// Symmetric pore-pressure system on a network's pattern (one row per pore, one off-diagonal entry per
// channel) and its preconditioned conjugate-gradient solver, shared by the single- and two-phase
// implicit steps.
// Preconditioners: Jacobi, or DIC (diagonal incomplete Cholesky, the D-ILU of Meijerink & van der
// Vorst 1977, Math. Comp. 31:148, as OpenFOAM's DIC): M = (D + L) D^-1 (D + L^T), L the strictly
// lower part of A, D_i = a_ii - sum_{j<i} a_ij^2 / D_j. The pressure matrices are symmetric
// M-matrices (negative off-diagonals, diagonally dominant), so every D_i > 0. Applied per fixed
// block of kDicBlock consecutive pores (couplings between blocks dropped: block-Jacobi DIC), the
// blocks in parallel and each one's triangular solves in order, so the result does not depend on
// the thread count. Small systems (one block) run without a parallel region.
// AMG: one V-cycle of porenet/amg.hpp (plain aggregation, hybrid Gauss-Seidel); the aggregates are
// built at the first solve and kept for later matrices on the same pattern (each solve refreshes the
// coarse values only); they are rebuilt when a solve needs more than twice the iterations of the
// first solve after the last build (plus 10), or after reset_preconditioner(). An AMG-CG that has not
// converged in kAmgMaxIterations (or meets a non-positive curvature) is redone with DIC from the same
// start (amg_fallbacks()).
// Stopping: ||r|| <= tol ||b|| (r, b in the system's units: mass or volume per pore), and no further
// than the round-off floor: once ||r|| <= 16 eps ||A||_inf ||x|| the residual is below what the
// floating-point product A x resolves (nearly singular closed samples: the
// compressibility diagonal V/K is 1e-3..1e-6 of the conductances' dt G); counted in floor_stops().
// State check (optional `storage` C_i, the row's compressibility in its units per Pa): the implicit
// steps update each pore's mass with the solved fluxes and take its pressure from the equation of
// state, so a row residual r_i becomes a pressure mismatch r_i / C_i, not r_i / a_ii. Where the
// conductances dwarf the storage (closed saturated samples: C_i / a_ii down to 1e-9) the global test
// leaves mismatches of tol (a_ii / C_i) ||b||, and since the next step's b carries them, they grew
// ~6x per step at tol 1e-8 until pores were torn past the spinodal (benchmarks/porenet's closed S 1
// sample). With storage, CG also iterates until |r_i| <= max(state_tol C_i, 16 eps sum_k |a_ik| max|x|)
// in every row with C_i > 0 (the second term: the round-off floor of that row's product).
// Warm start: the caller passes its initial guess in x (e.g. the last step's pressure change).
// Storage: Eigen column-major; the matrix is symmetric so column i is also row i.
#pragma once
#include <Eigen/SparseCore>
#include <span>
#include <vector>

#include "porenet/amg.hpp"
#include "porenet/network.hpp"

namespace ff::porenet {

inline constexpr Index kDicBlock = 8192;
// AMG-CG iterations before the DIC fallback (AMG needs < 100 on the 3D networks measured).
inline constexpr int kAmgMaxIterations = 400;

// The implicit steps' state-check bound: a pore's pressure mismatch at most this fraction of the
// largest |p| (1 mPa at atmospheric pressure).
inline constexpr Real kStateTolerance = 1e-8;

enum class Preconditioner : std::uint8_t { Jacobi = 0, DIC = 1, AMG = 2 };

class PressureSystem {
 public:
  explicit PressureSystem(const Network2D& net);

  Eigen::SparseMatrix<Real>& matrix() { return A_; }
  const Eigen::SparseMatrix<Real>& matrix() const { return A_; }
  // Channel of each stored entry, -1 on the diagonal.
  const std::vector<Index>& entry_channel() const { return entry_channel_; }

  // Solves A x = b to ||r|| <= tol ||b|| (and the state check above with storage), x holding the
  // initial guess; returns the iterations. Throws NumericalError after max_iterations.
  int solve(std::span<const Real> b, std::span<Real> x, Preconditioner pc, Real tol, int max_iterations,
            std::span<const Real> storage = {}, Real state_tol = 0);

  // AMG: rebuild the aggregates at the next solve (e.g. after the conductances changed by orders).
  void reset_preconditioner() { amg_rebuild_ = true; }
  // AMG's state for a checkpoint: the matrix values its aggregates were built from and the rebuild
  // rule's counters (empty before the first AMG setup). Restored on the same pattern, the aggregates
  // are built again from those values, so that the next solves are the uninterrupted run's.
  std::vector<Real> amg_state() const;
  void restore_amg_state(std::span<const Real> state);
  const Amg& amg() const { return amg_; }
  long amg_setups() const { return amg_setups_; }
  long floor_stops() const { return floor_stops_; }
  long state_iterations() const { return state_iterations_; }  // iterations past the global test
  long amg_fallbacks() const { return amg_fallbacks_; }  // AMG solves redone with DIC

 private:
  void setup_preconditioner(Preconditioner pc);
  void apply_preconditioner(Preconditioner pc, const std::vector<Real>& r, std::vector<Real>& z);

  Index n_;
  Eigen::SparseMatrix<Real> A_;
  std::vector<Index> entry_channel_, diag_pos_, lo_begin_, hi_end_;
  std::vector<Real> pivot_;  // inverse pivots (DIC) or inverse diagonal (Jacobi)
  std::vector<Real> r_, z_, d_, ad_, x0_, scratch_, row_abs_;
  Amg amg_;
  bool amg_rebuild_ = true, amg_check_ = false;
  int amg_setup_iters_ = 0;
  long amg_setups_ = 0, floor_stops_ = 0, amg_fallbacks_ = 0, state_iterations_ = 0;
};

}  // namespace ff::porenet
