// Two-phase (liquid q / gas p) compressible flow on the pore network, seed 004 Appendix B:
//  - channels: stratified laminar two-layer flow between parallel plates (B3–B7; Barmak et al.
//    2016, Phys. Fluids 28:044101): the liquid layer h_q = alpha_f h below the gas layer
//    h_p = (1 - alpha_f) h, one pressure gradient G = (p_i - p_j)/L, no slip at the walls (B5),
//    continuous velocity and shear stress at the interface (B6–B7). alpha_f is the liquid
//    fraction of the upstream pore (the face value of B8/B18), the densities those of the
//    upstream pore. Closed form (per unit depth, derived in docs/porenet.md):
//      tau_0 = G (h_p^2/mu_p - h_q^2/mu_q) / (2 (h_q/mu_q + h_p/mu_p)),
//      C = G h_q^2 / (2 mu_q) + tau_0 h_q / mu_q   (interface velocity),
//      Q_q = -G h_q^3/(6 mu_q) - tau_0 h_q^2/(2 mu_q) + C h_q,
//      Q_p = -G h_p^3/(6 mu_p) + tau_0 h_p^2/(2 mu_p) + C h_p.
//  - pores: explicit mass balance of each phase (B18–B20) with the new void volume (B19), then the
//    shared pressure (B23): the liquid fraction alpha solves p_q(m_q / (alpha V)) = p_p(m_p / ((1 - alpha) V))
//    with the phases' EOS (Peng–Robinson + Peneloux for water, B10–B22; or ideal gas), by
//    safeguarded Newton on the liquid branch (the PR liquid density is kept above its spinodal).
// Both phase masses are conserved to round-off: each channel's two mass rates are computed once.
// 3D networks (throats, no slit aperture): the throat's single-phase conductance ch_cond shared by
// the phases in the proportions of the same two-layer slit, lambda_k = 12 ch_cond q_k(G = 1, alpha,
// 1 - alpha) [m^3/(Pa s)] (q_k scales with h^3: in 2D this is exactly B3–B7 with t / L).
// Implicit step (step_implicit; IMPES, for stiff liquids): pressure backward Euler with the EOS
// linearised per pore and the phase mobilities, upstream directions and densities frozen at t^n.
// Dividing each phase's balance by its density and summing (sum_k m_k / rho_k = V), times rho_q,i:
//   rho_q,i C_i dp_i + dt sum_j W_ij (dp_i - dp_j) = rho_q,i (sum_k m_k^n / rho_k^n - V_i^{n+1})
//                                                    - dt sum_j W_ij (p_i^n - p_j^n) + dt Q_i,
//   C_i = V_i^n (alpha_i / K_q + (1 - alpha_i) / K_p),  W_ij = rho_q,up (lambda_q,ij + lambda_p,ij)
// (the liquid part is the exact liquid mass balance; the gas density ratio rho_q,up rho_p,i /
// (rho_q,i rho_p,up) of the exact volume balance set to 1: a symmetric M-matrix, solved by
// porenet/pcg.hpp). Setting the liquid density ratio rho_q,up / rho_q,i to 1 as well (the first
// version) made the liquid mass update inconsistent with the solve by (dt W / C) (dp / K): in a
// closed saturated 3D sample that error grew tenfold per step at dt = 1e-5 s.) The phase masses are then updated with the mass rates
// rho_k,up lambda_k (p_i^{n+1} - p_j^{n+1}), each computed once (conservative to round-off), and B23
// gives p and alpha. Volume errors of the linearisation are corrected at the next step (the
// sum m/rho - V term). A pore cannot give away more of a phase than it holds (the transport limit of
// the frozen mobilities): such a step is split in two halves, recursively (last_substeps()); after
// max_halvings (12) halvings the pore's outgoing rates of that phase are scaled down to its mass instead
// (still conservative; counted in last_limited_pores()). With max_halvings = 0 every step is one solve
// and the limiter acts per pore: the volume that the limited pores did not pass on enters the next
// step's right-hand side (the sum m/rho - V term), as any linearisation error does.
// Isothermal (T of the EOS); no capillarity, no phase change (seed 004: mass transfer ignored).
#pragma once
#include <memory>
#include <span>
#include <vector>

#include "core/error.hpp"
#include "porenet/eos.hpp"
#include "porenet/flow.hpp"
#include "porenet/network.hpp"
#include "porenet/pcg.hpp"

namespace ff::porenet {

struct StratifiedRates {
  Real q_liquid = 0, q_gas = 0;  // volumetric rate per unit depth [m^2/s], positive along G
  Real tau_interface = 0;        // shear stress at the interface [Pa]
};
// G = -dp/dx [Pa/m]; layer thicknesses h_q, h_p >= 0 [m]; viscosities [Pa s].
StratifiedRates stratified_channel_flow(Real G, Real h_q, Real h_p, Real mu_q, Real mu_p);

// Where an initial saturation S below 1 puts the liquid.
//  Uniform: every pore holds the fraction S.
//  SmallestPoresFirst: the capillary-equilibrium arrangement of a wetting liquid (Young-Laplace:
//    the entry pressure of a pore falls with its size, so at rest the liquid fills the smallest
//    pores and the gas the largest; the quasi-static drainage picture of pore-network models,
//    Blunt 2017, Multiphase Flow in Permeable Media, ch. 4). Pores are taken by void volume, ascending
//    (ties by index), filled with liquid until S x the total void is placed; the pore where that
//    happens keeps the remainder as a fraction, the rest hold gas only.
enum class LiquidPlacement : std::uint8_t { Uniform = 0, SmallestPoresFirst = 1 };

struct TwoPhaseParams {
  Eos liquid = Eos::water_pr(293.15);
  Eos gas = Eos::air_pr(293.15);
  Real mu_liquid = 1.0e-3;  // [Pa s]
  Real mu_gas = 1.8e-5;     // [Pa s]
  // implicit step
  Preconditioner preconditioner = Preconditioner::DIC;
  Real cg_tolerance = 1e-12;  // relative residual
  int cg_max_iterations = 20000;
  // Transport limit: halvings of the whole step before the per-pore outflow limiter takes over
  // (0: the limiter at once, one pressure solve per step; each halving re-solves the system).
  int max_halvings = 12;
};

class TwoPhaseFlow {
 public:
  TwoPhaseFlow(const Network2D& net, const TwoPhaseParams& params);

  // Pressure p everywhere and liquid saturation S (0..1) of the whole void, placed as `placement`
  // says; masses from the EOS at the current voids. Boundary conditions set afterwards override
  // their pores.
  void init(Real p, Real saturation, LiquidPlacement placement = LiquidPlacement::Uniform);
  // Sets one pore's state (before stepping), e.g. a non-uniform initial field.
  void set_pore_state(Index pore, Real p, Real saturation);
  // Pressure: value = p [Pa] with liquid fraction alpha_bc; Flux: value = liquid mass inflow [kg/s].
  void set_bc(Index pore, PoreBc kind, Real value, Real alpha_bc = 1.0);

  // Explicit limit: min over pores of the pressure-diffusion bound V (alpha/K_q + (1-alpha)/K_p) / sum_j lambda_ij
  // (lambda the channel's total volumetric mobility) and of the transport bound m / outflow per phase.
  // Replaces the phase masses (after a remeshing); solves B23 for every pore. Pores at a prescribed
  // pressure keep their prescribed state (set_bc), whatever masses they were given.
  void load_masses(std::span<const Real> mq, std::span<const Real> mp);

  Real stable_dt();
  // Explicit step (B18-B23). A pore that would lose more of a phase than it holds (dt above the
  // transport bound of the current rates) has its outgoing rates of that phase scaled to its mass
  // (conservative; counted in last_limited_pores()).
  void step_explicit(Real dt);
  // Backward-Euler pressure, conservative phase update (see above). The first call allocates the
  // pressure system (call prepare_implicit() beforehand to keep the time loop allocation free).
  void step_implicit(Real dt);
  void prepare_implicit();
  int last_cg_iterations() const { return cg_iters_; }
  // The implicit pressure system (null before the first implicit step or prepare_implicit()).
  const PressureSystem* pressure_system() const { return sys_.get(); }
  Index last_limited_pores() const { return limited_; }
  int last_substeps() const { return substeps_; }
  // The AMG preconditioner's state (PressureSystem::amg_state; empty without an AMG setup): part of a
  // checkpoint where the implicit step uses AMG.
  std::vector<Real> amg_state() const { return sys_ ? sys_->amg_state() : std::vector<Real>{}; }
  void restore_amg_state(std::span<const Real> state) {
    prepare_implicit();
    sys_->restore_amg_state(state);
  }
  // The CG start of the next implicit step (the last pressure change): part of a checkpoint.
  std::span<const Real> implicit_guess() const { return dp_; }
  void restore_implicit_guess(std::span<const Real> g) {
    prepare_implicit();
    if (g.size() != dp_.size()) throw InputError("porenet: restore_implicit_guess needs one value per pore");
    dp_.assign(g.begin(), g.end());
  }
  // Checkpoint resume (src/coupling/porenet): the full per-pore state as it was, so a resumed run
  // continues bit-for-bit (load_masses would re-solve B23 from another guess: last-bit differences).
  void restore_state(std::span<const Real> p, std::span<const Real> alpha, std::span<const Real> mq,
                     std::span<const Real> mp, std::span<const Real> rq, std::span<const Real> rp) {
    const auto n = static_cast<std::size_t>(np_);
    if (p.size() != n || alpha.size() != n || mq.size() != n || mp.size() != n || rq.size() != n || rp.size() != n)
      throw InputError("porenet: restore_state needs one value per pore in each array");
    p_.assign(p.begin(), p.end());
    alpha_.assign(alpha.begin(), alpha.end());
    mq_.assign(mq.begin(), mq.end());
    mp_.assign(mp.begin(), mp.end());
    rq_.assign(rq.begin(), rq.end());
    rp_.assign(rp.begin(), rp.end());
  }

  std::span<const Real> pressure() const { return p_; }
  PoreBc bc(Index pore) const { return bc_[static_cast<std::size_t>(pore)]; }
  // The condition's value: Pressure [Pa], Flux: liquid mass inflow [kg/s].
  Real bc_value(Index pore) const { return bc_value_[static_cast<std::size_t>(pore)]; }
  // rho dp/drho of pore i's liquid-gas mixture at its state, 1/K = alpha/K_q + (1 - alpha)/K_p [Pa];
  // 0 where a present phase has a non-positive modulus (Peng-Robinson's unstable branch).
  Real mixture_bulk_modulus(Index pore) const;
  // Total volumetric mobility lambda_q + lambda_p of channel c [m^3/(Pa s)], its upstream pore by the
  // current pressures (as the rates take it).
  Real channel_mobility(Index c) const;
  std::span<const Real> liquid_fraction() const { return alpha_; }
  std::span<const Real> liquid_mass() const { return mq_; }
  std::span<const Real> gas_mass() const { return mp_; }
  std::span<const Real> liquid_density() const { return rq_; }
  std::span<const Real> gas_density() const { return rp_; }
  Real total_liquid_mass();
  Real total_gas_mass();
  Real saturation();  // sum alpha V / sum V
  Real injected_liquid() const { return injected_; }

  // Shared pressure (B23) for masses m_q, m_p in a void V: returns alpha, writes p (and, if asked,
  // the iterations it took).
  Real solve_shared_pressure(Real mq, Real mp, Real V, Real alpha_guess, Real& p, int* iterations = nullptr) const;

 private:
  void compute_rates();
  void channel_mobilities(Index c, Index u, Real& lq, Real& lp) const;
  // net_outflow_ready: the rates are those find_outflow_limits() summed (no limit applied since).
  void update_pore_states(Real dt, const char* scheme, bool net_outflow_ready);
  void implicit_substep(Real dt, int depth);
  [[noreturn]] void throw_unstable_state(Index pore) const;
  // Each pore's outflow limit per phase over dt (lim_q_, lim_p_: the share of its rates it may pass
  // on). Returns the pores limited; `bulk` (optional) counts those limited in a phase above a trace
  // (kTraceFraction). apply_outflow_limits() scales the channel rates by them.
  Index find_outflow_limits(Real dt, Index* bulk = nullptr);
  void apply_outflow_limits();

  const Network2D& net_;
  TwoPhaseParams prm_;
  Index np_, nc_;
  std::vector<Real> p_, alpha_, mq_, mp_, rq_, rp_, fq_, fp_, bc_value_, bc_alpha_, scratch_;
  std::vector<PoreBc> bc_;
  Real injected_ = 0;
  // implicit
  std::unique_ptr<PressureSystem> sys_;
  Real liquid_max_density_ = 0, gas_max_density_ = 0, liquid_min_density_ = 0;  // the laws' bounds (B23's bracket)
  std::vector<Real> tq_, tp_, rhs_, dp_, pnew_, lim_q_, lim_p_, storage_;  // storage_: each row's C_i (state check)
  std::vector<Real> gross_q_;                     // find_outflow_limits: each pore's gross liquid outflow over dt
  std::vector<std::uint8_t> net_bound_, switch_;  // find_outflow_limits: liquid bounded by the net outflow
  std::vector<Real> net_q_, net_p_;  // each pore's net outflow rate per phase [kg/s] (find_outflow_limits)
  int cg_iters_ = 0, substeps_ = 0;
  Index limited_ = 0;
};

}  // namespace ff::porenet
