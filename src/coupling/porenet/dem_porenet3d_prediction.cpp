// The held steps' pressure prediction of DemPorenet3D (Porenet3DParams::predict_pressures; the
// equations in dem_porenet3d.hpp): the linearisation at a flow step, its multigrid system, and the
// per-DEM-step advance with the grain forces it adds.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "coupling/porenet/dem_porenet3d.hpp"
#include "core/error.hpp"
#include "porenet/forces.hpp"
#include "porenet/reduce.hpp"

namespace ff::coupling {

void DemPorenet3D::linearise_pressures() {
  const auto& net = *net_;
  const auto np = static_cast<std::size_t>(net.n_pores());
  const auto nc = static_cast<std::size_t>(net.n_channels());
  const auto n = static_cast<std::size_t>(net.n_particles);
  // The void gradients and patch forces (a few atan2 per corner entry: as much as the pressure solve)
  // change by ~(displacement / radius); taken again after choose_every DEM steps or on a new network
  // (which clears pred_g_).
  const bool geometry = pred_g_.size() != 12 * np || pred_geom_age_ >= prm_.choose_every;
  if (geometry) {
    pred_g_.assign(12 * np, 0.0);
    pred_a_.assign(3 * static_cast<std::size_t>(net.pp_start[net.n_particles]), 0.0);
    pred_geom_age_ = 0;
  }
  pred_x0_.resize(3 * n);
  pred_c_.resize(np);
  pred_v0_.assign(net.pore_void.begin(), net.pore_void.begin() + net.n_pores());
  pred_w_.resize(nc);
  pred_q_.resize(np);
  pred_b_.assign(np, 0.0);
  pred_dp_.assign(np, 0.0);
  pred_tmp_.assign(np, 0.0);
  pred_rhs_.assign(np, 0.0);
  pred_z_.assign(np, 0.0);
  for (std::size_t k = 0; k < n; ++k) {  // the positions the network was updated to (sync)
    pred_x0_[3 * k] = x_[k];
    pred_x0_[3 * k + 1] = y_[k];
    pred_x0_[3 * k + 2] = z_[k];
  }
#pragma omp parallel for schedule(static) if (net.n_channels() > porenet::kParallelMin)
  for (Index c = 0; c < net.n_channels(); ++c) pred_w_[static_cast<std::size_t>(c)] = flow_->channel_mobility(c);
  const auto p = flow_->pressure();
#pragma omp parallel for schedule(static) if (net.n_pores() > porenet::kParallelMin)
  for (Index i = 0; i < net.n_pores(); ++i) {
    const auto u = static_cast<std::size_t>(i);
    const Real K = flow_->bc(i) == porenet::PoreBc::Pressure ? 0.0 : flow_->mixture_bulk_modulus(i);
    pred_c_[u] = K > 0 && net.pore_void[i] > 0 ? net.pore_void[i] / K : -1.0;
    Real out = 0;
    for (Index q = net.pc_start[i]; q < net.pc_start[i + 1]; ++q) {
      const Index c = net.pc_ch[q];
      const Index o = net.ch_pore[2 * c] == i ? net.ch_pore[2 * c + 1] : net.ch_pore[2 * c];
      out += pred_w_[static_cast<std::size_t>(c)] * (p[i] - p[o]);
    }
    if (flow_->bc(i) == porenet::PoreBc::Flux)  // an injection (liquid mass rate) flows in
      out -= flow_->bc_value(i) / flow_->liquid_density()[u];
    pred_q_[u] = out;
  }
  // The multigrid: new aggregates with the geometry (the values they were built from are checkpointed,
  // Amg::setup_values, so that a resume builds the same), refreshed coarse matrices at the other flow
  // steps.
  const porenet::CsrView v = fill_prediction_matrix();
  if (geometry) {
    pred_amg_.setup(v);
  } else {
    pred_amg_.refresh(v);
  }
  ++pred_geom_age_;  // this flow step's DEM step
  if (!geometry) return;
  // Each corner entry writes its own slots: no two threads share one.
#pragma omp parallel for schedule(static) if (net.n_particles > porenet::kParallelMin)
  for (Index j = 0; j < net.n_particles; ++j) {
    for (Index e = net.pp_start[j]; e < net.pp_start[j + 1]; ++e) {
      Real a[3];
      porenet::unit_patch_force_3d(net, e, a);
      const Vec3 g = void_gradient(j, e, Vec3(a[0], a[1], a[2]), true);
      const Vec3 force_per_p = prm_.pressure_force == PressureForce::Surface ? Vec3(a[0], a[1], a[2]) : g;
      const auto q = static_cast<std::size_t>(e);
      const std::size_t slot = 3 * (4 * static_cast<std::size_t>(net.pp_pore[e]) + net.pp_corner[e]);
      for (int d = 0; d < 3; ++d) {
        pred_a_[3 * q + d] = force_per_p[d];
        pred_g_[slot + d] = g[d];
      }
    }
  }
}

// The held steps' matrix C + dt L (volume form of the flow's implicit step over one DEM step), its
// rows at a prescribed pressure (or without a modulus) identity rows: dp = 0 there.
porenet::CsrView DemPorenet3D::fill_prediction_matrix() {
  const auto& net = *net_;
  if (!pred_sys_) pred_sys_ = std::make_unique<porenet::PressureSystem>(net);  // the network's pattern
  auto& A = pred_sys_->matrix();
  const auto& ch = pred_sys_->entry_channel();
  const Index* outer = A.outerIndexPtr();
  const auto* inner = A.innerIndexPtr();
  Real* val = A.valuePtr();
  const Real dt = pred_dt_;
#pragma omp parallel for schedule(static) if (net.n_pores() > porenet::kParallelMin)
  for (Index col = 0; col < net.n_pores(); ++col) {
    const auto u = static_cast<std::size_t>(col);
    const bool fixed_col = pred_c_[u] < 0;
    Real ws = 0;  // the pore's channels' mobilities
    for (Index q = net.pc_start[col]; q < net.pc_start[col + 1]; ++q) ws += pred_w_[static_cast<std::size_t>(net.pc_ch[q])];
    for (Index k = outer[col]; k < outer[col + 1]; ++k) {
      const Index row = inner[k];
      if (row == col) {
        const Real d = (fixed_col ? 0.0 : pred_c_[u]) + dt * ws;
        val[k] = d > 0 ? d : 1.0;
      } else {
        const bool fixed = fixed_col || pred_c_[static_cast<std::size_t>(row)] < 0;
        val[k] = fixed ? 0.0 : -dt * pred_w_[static_cast<std::size_t>(ch[static_cast<std::size_t>(k)])];
      }
    }
  }
  return {net.n_pores(), outer, inner, val};
}

void DemPorenet3D::add_predicted_forces(dem::DemSystem& sys, Real p_floor) {
  ++pred_geom_age_;
  const auto& net = *net_;
  const auto& pos = sys.particles.pos;
  const Real dt = sys.settings.dt;
  const bool parallel_pores = net.n_pores() > porenet::kParallelMin;
  // This step's backward-Euler right-hand side C dp_old - (V - V_old) - dt q (pred_b_: -(V_old - V0)),
  // and the largest |V - V0| / V0 (hold_strain: the linearisation's reach; a max, the same on any
  // thread count).
  Real strain = 0;
#pragma omp parallel for schedule(static) reduction(max : strain) if (parallel_pores)
  for (Index i = 0; i < net.n_pores(); ++i) {
    const auto u = static_cast<std::size_t>(i);
    Real dv = 0;  // V - V0
    for (std::size_t c = 0; c < 4; ++c) {
      const auto k = static_cast<std::size_t>(net.pore_v[4 * u + c]);
      if (net.is_wall_vertex(static_cast<Index>(k))) continue;  // the walls' motion is not predicted
      const Real* g = &pred_g_[3 * (4 * u + c)];
      dv += g[0] * (pos[k].x() - pred_x0_[3 * k]) + g[1] * (pos[k].y() - pred_x0_[3 * k + 1]) +
            g[2] * (pos[k].z() - pred_x0_[3 * k + 2]);
    }
    const Real rhs = pred_c_[u] < 0 ? 0.0 : pred_c_[u] * pred_dp_[u] - dv - pred_b_[u] - dt * pred_q_[u];
    pred_b_[u] = -dv;
    pred_rhs_[u] = rhs;
    if (pred_c_[u] >= 0 && pred_v0_[u] > 0) strain = std::max(strain, std::abs(dv) / pred_v0_[u]);
  }
  pred_strain_ = strain;
  // V-cycles on the residual from the last step's dp (warm start).
  const auto& A = pred_sys_->matrix();
  const Index* outer = A.outerIndexPtr();
  const auto* inner = A.innerIndexPtr();
  const Real* val = A.valuePtr();
  for (int cycle = 0; cycle < std::max(prm_.predict_cycles, 1); ++cycle) {
#pragma omp parallel for schedule(static) if (parallel_pores)
    for (Index i = 0; i < net.n_pores(); ++i) {  // the matrix is symmetric: column i = row i
      Real ax = 0;
      for (Index k = outer[i]; k < outer[i + 1]; ++k) ax += val[k] * pred_dp_[static_cast<std::size_t>(inner[k])];
      pred_tmp_[static_cast<std::size_t>(i)] = pred_rhs_[static_cast<std::size_t>(i)] - ax;
    }
    pred_amg_.apply(pred_tmp_.data(), pred_z_.data());
#pragma omp parallel for schedule(static) if (parallel_pores)
    for (Index i = 0; i < net.n_pores(); ++i) {
      const auto u = static_cast<std::size_t>(i);
      pred_dp_[u] = pred_c_[u] < 0 ? 0.0 : pred_dp_[u] + pred_z_[u];
    }
  }
  // The force's pressure change, clamped below as compute_fluid_forces clamps p (cavitation).
  const bool clamp = p_floor > -std::numeric_limits<Real>::infinity();
  if (clamp) {
    const auto p = flow_->pressure();
#pragma omp parallel for schedule(static) if (parallel_pores)
    for (Index i = 0; i < net.n_pores(); ++i) {
      const auto u = static_cast<std::size_t>(i);
      pred_z_[u] = std::max(p[u] + pred_dp_[u], p_floor) - std::max(p[u], p_floor);
    }
  }
  const std::vector<Real>& dp_force = clamp ? pred_z_ : pred_dp_;
#pragma omp parallel for schedule(static) if (net.n_particles > porenet::kParallelMin)
  for (Index j = 0; j < net.n_particles; ++j) {
    Vec3 f = Vec3::Zero();
    for (Index e = net.pp_start[j]; e < net.pp_start[j + 1]; ++e) {
      const Real dp = dp_force[static_cast<std::size_t>(net.pp_pore[e])];
      const Real* a = &pred_a_[3 * static_cast<std::size_t>(e)];
      f += dp * Vec3(a[0], a[1], a[2]);
    }
    sys.particles.ext_force[static_cast<std::size_t>(j)] += f;
  }
}

}  // namespace ff::coupling
