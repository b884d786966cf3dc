#include "porenet/pcg.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>

#include "core/error.hpp"
#include "porenet/reduce.hpp"

namespace ff::porenet {

PressureSystem::PressureSystem(const Network2D& net) : n_(net.n_pores()) {
  const auto n = static_cast<std::size_t>(n_);
  std::vector<Eigen::Triplet<Real>> trip;
  trip.reserve(n + 2 * static_cast<std::size_t>(net.n_channels()));
  for (Index i = 0; i < n_; ++i) trip.emplace_back(i, i, 1.0);
  for (Index c = 0; c < net.n_channels(); ++c) {
    trip.emplace_back(net.ch_pore[2 * c], net.ch_pore[2 * c + 1], 0.0);
    trip.emplace_back(net.ch_pore[2 * c + 1], net.ch_pore[2 * c], 0.0);
  }
  A_.resize(n_, n_);
  A_.setFromTriplets(trip.begin(), trip.end());
  A_.makeCompressed();
  entry_channel_.assign(static_cast<std::size_t>(A_.nonZeros()), -1);
  diag_pos_.assign(n, -1);
  for (Index col = 0; col < n_; ++col)
    for (Index k = A_.outerIndexPtr()[col]; k < A_.outerIndexPtr()[col + 1]; ++k) {
      const Index row = A_.innerIndexPtr()[k];
      if (row == col) {
        diag_pos_[col] = k;
        continue;
      }
      for (Index e = net.pc_start[col]; e < net.pc_start[col + 1]; ++e) {
        const Index c = net.pc_ch[e];
        if (net.ch_pore[2 * c] == row || net.ch_pore[2 * c + 1] == row) entry_channel_[k] = c;
      }
    }
  // Per row, the stored entries inside its DIC block: [lo_begin_, diag) and (diag, hi_end_).
  lo_begin_.assign(n, 0);
  hi_end_.assign(n, 0);
  for (Index i = 0; i < n_; ++i) {
    const Index lo = i / kDicBlock * kDicBlock, hi = std::min(n_, lo + kDicBlock);
    Index k = A_.outerIndexPtr()[i];
    while (k < diag_pos_[i] && A_.innerIndexPtr()[k] < lo) ++k;
    lo_begin_[i] = k;
    k = A_.outerIndexPtr()[i + 1];
    while (k > diag_pos_[i] + 1 && A_.innerIndexPtr()[k - 1] >= hi) --k;
    hi_end_[i] = k;
  }
  pivot_.assign(n, 1);
  r_ = z_ = d_ = ad_ = x0_ = pivot_;
  scratch_.assign(static_cast<std::size_t>(std::max<Index>(reduce_blocks(n_), 1)), 0);
}

void PressureSystem::setup_preconditioner(Preconditioner pc) {
  const Real* val = A_.valuePtr();
  const auto* inner = A_.innerIndexPtr();
  if (pc == Preconditioner::AMG) {
    const CsrView v{n_, A_.outerIndexPtr(), inner, val};
    if (amg_rebuild_ || !amg_.ready()) {
      amg_.setup(v);
      amg_rebuild_ = false;
      amg_check_ = true;  // the next iteration count is the reference
      ++amg_setups_;
    } else {
      amg_.refresh(v);
    }
    return;
  }
  if (pc == Preconditioner::Jacobi) {
    for (Index i = 0; i < n_; ++i) pivot_[i] = 1 / val[diag_pos_[i]];
    return;
  }
  const Index nb = (n_ + kDicBlock - 1) / kDicBlock;
#pragma omp parallel for schedule(static) if (nb > 1)
  for (Index b = 0; b < nb; ++b) {
    const Index lo = b * kDicBlock, hi = std::min(n_, lo + kDicBlock);
    for (Index i = lo; i < hi; ++i) {  // entries of row i left of the diagonal (inner sorted)
      Real d = val[diag_pos_[i]];
      for (Index k = lo_begin_[i]; k < diag_pos_[i]; ++k) d -= val[k] * val[k] * pivot_[inner[k]];
      pivot_[i] = 1 / d;  // stored inverted
    }
  }
}

std::vector<Real> PressureSystem::amg_state() const {
  if (!amg_.ready()) return {};
  std::vector<Real> s{amg_rebuild_ ? 1.0 : 0.0, amg_check_ ? 1.0 : 0.0, static_cast<Real>(amg_setup_iters_)};
  s.insert(s.end(), amg_.setup_values().begin(), amg_.setup_values().end());
  return s;
}

void PressureSystem::restore_amg_state(std::span<const Real> state) {
  if (state.empty()) return;
  const auto nnz = static_cast<std::size_t>(A_.nonZeros());
  if (state.size() != 3 + nnz)
    throw InputError(fmt::format("porenet: an AMG state of {} values for a pressure system of {} entries", state.size(), nnz));
  // The aggregates from the values they were built from (A's pattern); the next solve refreshes the
  // hierarchy with A's values, as it would have without the checkpoint.
  amg_.restore(CsrView{n_, A_.outerIndexPtr(), A_.innerIndexPtr(), nullptr}, state.subspan(3));
  amg_rebuild_ = state[0] != 0;
  amg_check_ = state[1] != 0;
  amg_setup_iters_ = static_cast<int>(state[2]);
}

void PressureSystem::apply_preconditioner(Preconditioner pc, const std::vector<Real>& r, std::vector<Real>& z) {
  if (pc == Preconditioner::AMG) {
    amg_.apply(r.data(), z.data());
    return;
  }
  if (pc == Preconditioner::Jacobi) {
#pragma omp parallel for schedule(static) if (n_ > kDicBlock)
    for (Index i = 0; i < n_; ++i) z[i] = r[i] * pivot_[i];
    return;
  }
  const Real* val = A_.valuePtr();
  const auto* inner = A_.innerIndexPtr();
  const Index nb = (n_ + kDicBlock - 1) / kDicBlock;
#pragma omp parallel for schedule(static) if (nb > 1)
  for (Index b = 0; b < nb; ++b) {
    const Index lo = b * kDicBlock, hi = std::min(n_, lo + kDicBlock);
    for (Index i = lo; i < hi; ++i) {  // (D + L) y = r
      Real s = r[i];
      for (Index k = lo_begin_[i]; k < diag_pos_[i]; ++k) s -= val[k] * z[inner[k]];
      z[i] = s * pivot_[i];
    }
    for (Index i = hi - 1; i >= lo; --i) {  // (D + L^T) z = D y
      Real s = 0;
      for (Index k = diag_pos_[i] + 1; k < hi_end_[i]; ++k) s += val[k] * z[inner[k]];
      z[i] -= s * pivot_[i];
    }
  }
}

int PressureSystem::solve(std::span<const Real> b, std::span<Real> x, Preconditioner pc, Real tol, int max_it,
                          std::span<const Real> storage, Real state_tol) {
  const Real* val = A_.valuePtr();
  const auto* outer = A_.outerIndexPtr();
  const auto* inner = A_.innerIndexPtr();
  auto matvec = [&](const Real* in, std::vector<Real>& out) {
#pragma omp parallel for schedule(static) if (n_ > kDicBlock)
    for (Index i = 0; i < n_; ++i) {
      Real s = 0;
      for (Index k = outer[i]; k < outer[i + 1]; ++k) s += val[k] * in[inner[k]];
      out[i] = s;
    }
  };
  const Real bnorm2 = fixed_order_sum(n_, [&](Index i) { return b[i] * b[i]; }, scratch_);
  if (bnorm2 == 0) {
    std::fill(x.begin(), x.end(), 0.0);
    return 0;
  }
  const Real tol2 = tol * tol * bnorm2;
  auto finished = [&](int its) {
    if (pc == Preconditioner::AMG) {
      if (amg_check_) {
        amg_setup_iters_ = its;
        amg_check_ = false;
      } else if (its > 2 * amg_setup_iters_ + 10) {
        amg_rebuild_ = true;  // the aggregates no longer fit the matrix: rebuild at the next solve
      }
    }
    return its;
  };
  constexpr Real kFloor = 16 * std::numeric_limits<Real>::epsilon();
  const bool state = !storage.empty();
  // Row sums |A| (the round-off floors); max: order-independent.
  row_abs_.resize(n_);
  Real anorm = 0;
#pragma omp parallel for schedule(static) reduction(max : anorm) if (n_ > kDicBlock)
  for (Index i = 0; i < n_; ++i) {
    Real s = 0;
    for (Index k = outer[i]; k < outer[i + 1]; ++k) s += std::abs(val[k]);
    row_abs_[i] = s;
    anorm = std::max(anorm, s);
  }
  // True when a row's residual is above its pressure-mismatch bound (the state check).
  auto state_unmet = [&]() {
    if (!state) return false;
    Real xmax = 0;
#pragma omp parallel for schedule(static) reduction(max : xmax) if (n_ > kDicBlock)
    for (Index i = 0; i < n_; ++i) xmax = std::max(xmax, std::abs(x[i]));
    Real excess = 0;
#pragma omp parallel for schedule(static) reduction(max : excess) if (n_ > kDicBlock)
    for (Index i = 0; i < n_; ++i)
      if (storage[i] > 0)
        excess = std::max(excess, std::abs(r_[i]) - std::max(state_tol * storage[i], kFloor * row_abs_[i] * xmax));
    return excess > 0;
  };
  matvec(x.data(), ad_);
#pragma omp parallel for schedule(static) if (n_ > kDicBlock)
  for (Index i = 0; i < n_; ++i) r_[i] = b[i] - ad_[i];
  if (fixed_order_sum(n_, [&](Index i) { return r_[i] * r_[i]; }, scratch_) <= tol2 && !state_unmet()) return 0;
  // Round-off floor of the residual: 16 eps ||A||_inf ||x||_2.
  const Real floor2 = std::pow(kFloor * anorm, 2);
  // AMG guard: a stalled or indefinite AMG-CG (seen once on a closed saturated 3D sample) falls back to
  // DIC from the same start; the aggregates are rebuilt at the next solve.
  const int amg_try = std::min(max_it, kAmgMaxIterations);
  if (pc == Preconditioner::AMG) std::copy(x.begin(), x.end(), x0_.begin());
  auto fallback = [&] {
    ++amg_fallbacks_;
    amg_rebuild_ = true;
    std::copy(x0_.begin(), x0_.end(), x.begin());
    return solve(b, x, Preconditioner::DIC, tol, max_it, storage, state_tol);
  };
  setup_preconditioner(pc);
  apply_preconditioner(pc, r_, z_);
  d_ = z_;
  Real rz = fixed_order_sum(n_, [&](Index i) { return r_[i] * z_[i]; }, scratch_);
  for (int it = 0; it < max_it; ++it) {
    matvec(d_.data(), ad_);
    const Real dad = fixed_order_sum(n_, [&](Index i) { return d_[i] * ad_[i]; }, scratch_);
    if (pc == Preconditioner::AMG && (!(dad > 0) || !(rz > 0) || it >= amg_try)) return fallback();
    const Real alpha = rz / dad;
#pragma omp parallel for schedule(static) if (n_ > kDicBlock)
    for (Index i = 0; i < n_; ++i) {
      x[i] += alpha * d_[i];
      r_[i] -= alpha * ad_[i];
    }
    const Real rr = fixed_order_sum(n_, [&](Index i) { return r_[i] * r_[i]; }, scratch_);
    bool done = rr <= tol2, at_floor = false;
    if (!done && (rr <= 64 * tol2 || (it & 15) == 15)) {  // the floor matters near the end or when stalling
      const Real xx = fixed_order_sum(n_, [&](Index i) { return x[i] * x[i]; }, scratch_);
      done = at_floor = rr <= floor2 * xx;
    }
    if (done && state_unmet()) {
      done = false;
      ++state_iterations_;
    }
    if (done) {
      floor_stops_ += at_floor ? 1 : 0;
      return finished(it + 1);
    }
    apply_preconditioner(pc, r_, z_);
    const Real rz_new = fixed_order_sum(n_, [&](Index i) { return r_[i] * z_[i]; }, scratch_);
    const Real beta = rz_new / rz;
    rz = rz_new;
#pragma omp parallel for schedule(static) if (n_ > kDicBlock)
    for (Index i = 0; i < n_; ++i) d_[i] = z_[i] + beta * d_[i];
  }
  throw NumericalError(fmt::format("porenet: conjugate gradients did not converge in {} iterations{} (the pressure "
                                   "system is too ill-conditioned for the iterative solver)", max_it,
                                   state && state_unmet() ? " (a pore's pressure mismatch above its bound)" : ""));
}

}  // namespace ff::porenet
