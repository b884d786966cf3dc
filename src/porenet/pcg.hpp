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
// Warm start: the caller passes its initial guess in x (e.g. the last step's pressure change).
// Storage: Eigen column-major; the matrix is symmetric so column i is also row i.
#pragma once
#include <Eigen/SparseCore>
#include <span>
#include <vector>

#include "porenet/network.hpp"

namespace ff::porenet {

inline constexpr Index kDicBlock = 8192;

enum class Preconditioner : std::uint8_t { Jacobi = 0, DIC = 1 };

class PressureSystem {
 public:
  explicit PressureSystem(const Network2D& net);

  Eigen::SparseMatrix<Real>& matrix() { return A_; }
  // Channel of each stored entry, -1 on the diagonal.
  const std::vector<Index>& entry_channel() const { return entry_channel_; }

  // Solves A x = b to ||r|| <= tol ||b||, x holding the initial guess; returns the iterations.
  // Throws NumericalError after max_iterations.
  int solve(std::span<const Real> b, std::span<Real> x, Preconditioner pc, Real tol, int max_iterations);

 private:
  void setup_preconditioner(Preconditioner pc);
  void apply_preconditioner(Preconditioner pc, const std::vector<Real>& r, std::vector<Real>& z);

  Index n_;
  Eigen::SparseMatrix<Real> A_;
  std::vector<Index> entry_channel_, diag_pos_, lo_begin_, hi_end_;
  std::vector<Real> pivot_;  // inverse pivots (DIC) or inverse diagonal (Jacobi)
  std::vector<Real> r_, z_, d_, ad_, scratch_;
};

}  // namespace ff::porenet
