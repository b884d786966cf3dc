#include "porenet/flow.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>

#include "core/error.hpp"
#include "porenet/reduce.hpp"

namespace ff::porenet {

SinglePhaseFlow::SinglePhaseFlow(const Network2D& net, const SinglePhaseParams& params)
    : net_(net), prm_(params), np_(net.n_pores()), nc_(net.n_channels()), sys_(net) {
  if (!(params.mu > 0)) throw InputError(fmt::format("porenet: viscosity mu = {} Pa s; must be > 0", params.mu));
  if (params.matrix_modulus < 0)
    throw InputError(fmt::format("porenet: matrix_modulus = {} Pa; must be >= 0 (0: rigid/DEM-driven)",
                                 params.matrix_modulus));
  const auto n = static_cast<std::size_t>(np_);
  p_.assign(n, 0);
  m_.assign(n, 0);
  rho_.assign(n, 0);
  v_.assign(net.pore_void.begin(), net.pore_void.end());
  v0_ = v_;
  out_rate_.assign(n, 0);
  bc_value_.assign(n, 0);
  bc_.assign(n, PoreBc::None);
  flux_.assign(static_cast<std::size_t>(nc_), 0);
  g_.assign(static_cast<std::size_t>(nc_), 0);
  rhs_.assign(n, 0);
  x_ = pnew_ = storage_ = rhs_;
  scratch_.assign(static_cast<std::size_t>(std::max<Index>(reduce_blocks(np_), 1)), 0);
}

void SinglePhaseFlow::init(Real p) {
  v_.assign(net_.pore_void.begin(), net_.pore_void.end());
  v0_ = v_;
  sigma_eff0_ = sigma_ - p;
  const Real rho = prm_.fluid.density(p, true);
  for (Index i = 0; i < np_; ++i) {
    p_[i] = bc_[i] == PoreBc::Pressure ? bc_value_[i] : p;
    rho_[i] = bc_[i] == PoreBc::Pressure ? prm_.fluid.density(p_[i], true) : rho;
    m_[i] = rho_[i] * v_[i];
  }
  bc_mass_in_ = injected_ = 0;
}

void SinglePhaseFlow::set_bc(Index pore, PoreBc kind, Real value) {
  if (pore < 0 || pore >= np_)
    throw InputError(fmt::format("porenet: boundary condition on pore {}; pores are 0..{}", pore, np_ - 1));
  bc_[pore] = kind;
  bc_value_[pore] = value;
  if (kind == PoreBc::Pressure) {
    p_[pore] = value;
    rho_[pore] = prm_.fluid.density(value, true);
    m_[pore] = rho_[pore] * v_[pore];
  }
  bc_pressure_pores_.clear();
  for (Index i = 0; i < np_; ++i)
    if (bc_[i] == PoreBc::Pressure) bc_pressure_pores_.push_back(i);
}

void SinglePhaseFlow::load_masses(std::span<const Real> m) {
  if (m.size() != static_cast<std::size_t>(np_))
    throw InputError(fmt::format("porenet: {} masses for a network of {} pores", m.size(), np_));
  v_.assign(net_.pore_void.begin(), net_.pore_void.end());
  for (Index i = 0; i < np_; ++i) {
    m_[i] = m[i];
    p_[i] = pressure_from_mass(i, m_[i], p_[i]);
    v_[i] = void_at(i, p_[i]);
    rho_[i] = m_[i] / v_[i];
  }
  for (Index i : bc_pressure_pores_) {  // a prescribed pressure stays prescribed (as TwoPhaseFlow::load_masses)
    p_[i] = bc_value_[i];
    rho_[i] = prm_.fluid.density(p_[i], true);
    v_[i] = void_at(i, p_[i]);
    m_[i] = rho_[i] * v_[i];
  }
}

Real SinglePhaseFlow::void_at(Index i, Real p) const {
  if (prm_.matrix_modulus <= 0) return net_.pore_void[i];
  return v0_[i] - net_.pore_cell[i] * (sigma_ - p - sigma_eff0_) / prm_.matrix_modulus;
}

Real SinglePhaseFlow::storage(Index i) const {
  Real s = rho_[i] * v_[i] / prm_.fluid.bulk_modulus(rho_[i]);
  if (prm_.matrix_modulus > 0) s += rho_[i] * net_.pore_cell[i] / prm_.matrix_modulus;
  return s;
}

Real SinglePhaseFlow::pressure_from_mass(Index i, Real m, Real p_guess) const {
  if (prm_.matrix_modulus <= 0) return prm_.fluid.pressure(m / net_.pore_void[i]);
  // rho(p) V(p) = m: increasing and convex in p; Newton from the previous pressure.
  Real p = p_guess;
  for (int it = 0; it < 50; ++it) {
    const Real rho = prm_.fluid.density(p, true);
    const Real V = void_at(i, p);
    const Real f = rho * V - m;
    const Real df = rho * V / prm_.fluid.bulk_modulus(rho) + rho * net_.pore_cell[i] / prm_.matrix_modulus;
    const Real dp = f / df;
    p -= dp;
    if (std::abs(dp) <= 1e-14 * (std::abs(p) + 1)) break;
  }
  return p;
}

void SinglePhaseFlow::compute_fluxes(std::span<const Real> p) {
#pragma omp parallel for schedule(static) if (nc_ > kParallelMin)
  for (Index c = 0; c < nc_; ++c) {
    const Index a = net_.ch_pore[2 * c], b = net_.ch_pore[2 * c + 1];
    flux_[c] = g_[c] * (p[a] - p[b]);
  }
}

// Mass update (B8) with the fluxes in flux_, then pressure from the EOS (B20 analogue).
void SinglePhaseFlow::update_masses(Real dt) {
  Index bad = -1;  // no exception may leave an OpenMP region
#pragma omp parallel for schedule(static) reduction(max : bad) if (np_ > kParallelMin)
  for (Index i = 0; i < np_; ++i) {
    Real out = 0;
    for (Index e = net_.pc_start[i]; e < net_.pc_start[i + 1]; ++e) {
      const Index c = net_.pc_ch[e];
      out += net_.ch_pore[2 * c] == i ? flux_[c] : -flux_[c];
    }
    out_rate_[i] = out;
    const Real Vn = void_at(i, p_[i]);
    if (bc_[i] == PoreBc::Pressure) {
      p_[i] = bc_value_[i];
      rho_[i] = prm_.fluid.density(p_[i], true);
      v_[i] = Vn;
      m_[i] = rho_[i] * v_[i];
      continue;
    }
    const Real q = bc_[i] == PoreBc::Flux ? bc_value_[i] : 0;
    m_[i] += dt * (q - out);
    if (!(m_[i] > 0)) {
      bad = std::max(bad, i);
      continue;
    }
    p_[i] = pressure_from_mass(i, m_[i], p_[i]);
    v_[i] = void_at(i, p_[i]);
    rho_[i] = m_[i] / v_[i];
  }
  if (bad >= 0)
    throw NumericalError(fmt::format("porenet: pore {} mass {} kg after a step of {} s; reduce dt below the "
                                     "stable step {} s or use the implicit solver", bad, m_[bad], dt, stable_dt()));
  for (Index i : bc_pressure_pores_) bc_mass_in_ += dt * out_rate_[i];
  for (Index i = 0; i < np_; ++i)
    if (bc_[i] == PoreBc::Flux) injected_ += dt * bc_value_[i];
}

Real SinglePhaseFlow::stable_dt() const {
  Real dt = std::numeric_limits<Real>::infinity();
  const Real inv_mu = 1.0 / prm_.mu;
#pragma omp parallel for schedule(static) reduction(min : dt) if (np_ > kParallelMin)
  for (Index i = 0; i < np_; ++i) {
    if (bc_[i] == PoreBc::Pressure) continue;
    Real gsum = 0;
    for (Index e = net_.pc_start[i]; e < net_.pc_start[i + 1]; ++e) {
      const Index c = net_.pc_ch[e];
      const Index a = net_.ch_pore[2 * c], b = net_.ch_pore[2 * c + 1];
      gsum += std::max(rho_[a], rho_[b]) * net_.ch_cond[c] * inv_mu;
    }
    if (gsum > 0) dt = std::min(dt, storage(i) / gsum);
  }
  return dt;
}

void SinglePhaseFlow::step_explicit(Real dt) {
  const Real inv_mu = 1.0 / prm_.mu;
#pragma omp parallel for schedule(static) if (nc_ > kParallelMin)
  for (Index c = 0; c < nc_; ++c) {
    const Index a = net_.ch_pore[2 * c], b = net_.ch_pore[2 * c + 1];
    g_[c] = (p_[a] >= p_[b] ? rho_[a] : rho_[b]) * net_.ch_cond[c] * inv_mu;  // upwind density
  }
  compute_fluxes(p_);
  update_masses(dt);
}

void SinglePhaseFlow::step_implicit(Real dt) {
  const Real inv_mu = 1.0 / prm_.mu;
#pragma omp parallel for schedule(static) if (nc_ > kParallelMin)
  for (Index c = 0; c < nc_; ++c) {
    const Index a = net_.ch_pore[2 * c], b = net_.ch_pore[2 * c + 1];
    g_[c] = (p_[a] >= p_[b] ? rho_[a] : rho_[b]) * net_.ch_cond[c] * inv_mu;
  }
  auto& A = sys_.matrix();
  const auto& entry_channel = sys_.entry_channel();
  Real* val = A.valuePtr();
  const auto* outer = A.outerIndexPtr();
  const auto* inner = A.innerIndexPtr();
  // Rows (= columns: symmetric). Pressure pores: diagonal rows, their columns moved to the rhs; the
  // row keeps the scale of a free row (storage + dt sum G, in kg/Pa), so that the residual norm
  // weighs it like the others (an identity row with rhs in Pa would dominate ||b|| and stop CG early).
  Index unstable = -1;  // a pore with dp/drho <= 0: negative storage, an indefinite matrix
  Real p_scale = 0;     // largest |p|: the scale of the solve's state check
#pragma omp parallel for schedule(static) reduction(max : unstable, p_scale) if (np_ > kParallelMin)
  for (Index i = 0; i < np_; ++i) {
    const bool fixed_i = bc_[i] == PoreBc::Pressure;
    Real diag = storage(i), rhs = 0;
    storage_[i] = fixed_i ? 0 : diag;
    p_scale = std::max(p_scale, std::abs(p_[i]));
    if (!fixed_i && !(prm_.fluid.bulk_modulus(rho_[i]) > 0)) unstable = std::max(unstable, i);
    if (!fixed_i) {
      const Real Vnew = void_at(i, p_[i]);
      rhs = m_[i] - rho_[i] * Vnew + (bc_[i] == PoreBc::Flux ? dt * bc_value_[i] : 0);
    }
    for (Index k = outer[i]; k < outer[i + 1]; ++k) {
      const Index j = inner[k];
      const Index c = entry_channel[k];
      if (c < 0) continue;
      const Real G = dt * g_[c];
      const bool fixed_j = bc_[j] == PoreBc::Pressure;
      diag += G;
      if (fixed_i) {
        val[k] = 0;
        continue;
      }
      rhs -= G * (p_[i] - p_[j]);
      if (fixed_j) {
        rhs += G * (bc_value_[j] - p_[j]);
        val[k] = 0;
      } else {
        val[k] = -G;
      }
    }
    for (Index k = outer[i]; k < outer[i + 1]; ++k)
      if (inner[k] == i) val[k] = diag;
    rhs_[i] = fixed_i ? diag * (bc_value_[i] - p_[i]) : rhs;
  }
  if (unstable >= 0)
    throw NumericalError(fmt::format(
        "porenet: pore {} at {:.4g} Pa: its fluid ({:.6g} kg/m^3) lies in the equation of state's unstable region "
        "(dp/drho <= 0: a liquid stretched past the spinodal; cavitation is not modelled): the pore pressures have "
        "gone unstable; in a coupled run lower the DEM time step (dem.time_step / dem.time_step_safety)",
        unstable, p_[unstable], rho_[unstable]));
  if (prm_.solver == LinearSolver::LDLT) {
    if (!ldlt_analysed_) {
      ldlt_.analyzePattern(A);
      ldlt_analysed_ = true;
    }
    ldlt_.factorize(A);
    if (ldlt_.info() != Eigen::Success) throw NumericalError("porenet: LDLT factorisation of the pressure system failed");
    Eigen::Map<Eigen::VectorXd> b(rhs_.data(), np_), x(x_.data(), np_);
    x = ldlt_.solve(b);
  } else {
    if (!prm_.warm_start) std::fill(x_.begin(), x_.end(), 0.0);
    cg_iters_ = sys_.solve(rhs_, x_, prm_.preconditioner, prm_.cg_tolerance, prm_.cg_max_iterations, storage_,
                           kStateTolerance * p_scale);
  }
#pragma omp parallel for schedule(static) if (np_ > kParallelMin)
  for (Index i = 0; i < np_; ++i) pnew_[i] = p_[i] + x_[i];
  compute_fluxes(pnew_);
  update_masses(dt);
}

Real SinglePhaseFlow::pressure_pores_inflow_rate(bool positive_part) const {
  Real s = 0;
  for (Index i : bc_pressure_pores_) s += positive_part ? std::max(out_rate_[i], 0.0) : std::min(out_rate_[i], 0.0);
  return s;
}

Real SinglePhaseFlow::total_mass() {
  return fixed_order_sum(np_, [&](Index i) { return m_[i]; }, scratch_);
}

}  // namespace ff::porenet
