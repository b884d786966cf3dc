// Single-phase compressible flow on a pore network (seed 004 Eqs. B8–B9 with one phase;
// METHODS.md §5.4).
//
// Each pore i holds a fluid mass m_i in its void volume V_i; the channels carry the laminar
// (cubic-law) mass rate F_ij = rho_up g_ij (p_i - p_j), g_ij = h^3 t / (12 mu L), rho_up the density
// of the upstream pore. The mass balance per pore (B8) is
//   m_i^{n+1} = m_i^n - dt sum_j F_ij + dt Q_i,     p_i^{n+1} = EOS(m_i^{n+1} / V_i^{n+1})   (B9, B20)
// which conserves mass to round-off (each F_ij is computed once and given to both pores).
//  - explicit (the seed's scheme): F from p^n. Stable step (derived in docs/porenet.md):
//      dt <= dt_s = min_i S_i / sum_j rho_up g_ij,   S_i = dm_i/dp_i = rho_i V_i / K_i (+ rho_i V_cell,i / M),
//    with K_i = rho dp/drho of the fluid. Above dt_s the update is no longer a convex combination
//    of the neighbours' pressures; above 2 dt_s it diverges.
//  - implicit (backward Euler, for stiff liquids): F from p^{n+1}, linearised about p^n:
//      S_i dp_i + dt sum_j G_ij (dp_i - dp_j) = m_i^n - rho_i^n V_i^{n+1} - dt sum_j G_ij (p_i^n - p_j^n) + dt Q_i
//    with G_ij = rho_up^n g_ij (a symmetric positive definite system), solved by conjugate
//    gradients (porenet/pcg.hpp: DIC or Jacobi preconditioner, warm start from the last step's
//    pressure change; no allocation, fixed-order sums) or Eigen's SimplicialLDLT (allocates per
//    factorisation). Masses are then updated with the same
//    fluxes, so mass stays conserved to round-off and p follows from the EOS.
// Boundary pores: Pressure (Dirichlet p, the fluid crossing it is counted in boundary_mass_in),
// Flux (prescribed mass inflow Q [kg/s]: injection; Q < 0 withdraws), None (no flow: default,
// also on the convex hull).
// Prescribed compressible matrix (standalone, without the DEM): with matrix_modulus M > 0 the
// void volume follows the effective stress, V_i = V0_i - V_cell,i (sigma - p_i - sigma'_0) / M
// (compression positive, grains incompressible, M the constrained modulus), sigma the total
// stress set by set_total_stress(); otherwise V_i is the network's pore_void (DEM motion).
#pragma once
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <span>
#include <vector>

#include "porenet/eos.hpp"
#include "porenet/network.hpp"
#include "porenet/pcg.hpp"

namespace ff::porenet {

enum class PoreBc : std::uint8_t { None = 0, Pressure = 1, Flux = 2 };
enum class LinearSolver : std::uint8_t { ConjugateGradient = 0, LDLT = 1 };

struct SinglePhaseParams {
  Real mu = 1e-3;                              // dynamic viscosity [Pa s]
  Eos fluid = Eos::barotropic(1000, 0, 2.2e9);  // water-like liquid
  Real matrix_modulus = 0;                     // M [Pa]; 0: volumes from the network
  LinearSolver solver = LinearSolver::ConjugateGradient;
  Real cg_tolerance = 1e-13;  // relative residual
  int cg_max_iterations = 20000;
  Preconditioner preconditioner = Preconditioner::DIC;
  bool warm_start = true;  // CG starts from the last step's pressure change
};

class SinglePhaseFlow {
 public:
  // Keeps a reference to net: its pore_void is read as V^{n+1} at each step.
  SinglePhaseFlow(const Network2D& net, const SinglePhaseParams& params);

  // Uniform pressure p; masses from the EOS at the current void volumes; the matrix reference state.
  void init(Real p);
  // Pressure: value = p [Pa]; Flux: value = mass inflow [kg/s]; None clears.
  void set_bc(Index pore, PoreBc kind, Real value);
  void set_total_stress(Real sigma) { sigma_ = sigma; }

  // Replaces the pore masses (after a remeshing) and recomputes pressures and densities; pores at a
  // prescribed pressure keep it.
  void load_masses(std::span<const Real> m);

  Real stable_dt() const;
  void step_explicit(Real dt);
  void step_implicit(Real dt);

  std::span<const Real> pressure() const { return p_; }
  std::span<const Real> mass() const { return m_; }
  std::span<const Real> density() const { return rho_; }
  std::span<const Real> channel_mass_rate() const { return flux_; }  // [kg/s], pore a -> pore b
  std::span<const Real> void_volume() const { return v_; }
  // Net mass rate [kg/s] leaving each Pressure pore into the network at the last step, in
  // ascending pore order (negative: the network drains into it).
  Real pressure_pores_inflow_rate(bool positive_part) const;
  Real boundary_mass_in() const { return bc_mass_in_; }  // cumulative through Pressure pores [kg]
  Real injected_mass() const { return injected_; }       // cumulative through Flux pores [kg]
  Real total_mass();                                     // fixed-order sum over pores [kg]
  int last_cg_iterations() const { return cg_iters_; }
  const PressureSystem& pressure_system() const { return sys_; }

 private:
  Real void_at(Index i, Real p) const;
  Real storage(Index i) const;  // S_i = dm/dp at the current state
  Real pressure_from_mass(Index i, Real m, Real p_guess) const;
  void compute_fluxes(std::span<const Real> p);
  void update_masses(Real dt);

  const Network2D& net_;
  SinglePhaseParams prm_;
  Index np_, nc_;
  std::vector<Real> p_, m_, rho_, v_, v0_, flux_, g_, out_rate_, bc_value_;
  std::vector<PoreBc> bc_;
  std::vector<Index> bc_pressure_pores_;
  Real sigma_ = 0, sigma_eff0_ = 0, bc_mass_in_ = 0, injected_ = 0;
  // implicit system (symmetric; ColMajor storage read as rows)
  PressureSystem sys_;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<Real>> ldlt_;
  bool ldlt_analysed_ = false;
  std::vector<Real> rhs_, x_, pnew_, scratch_, storage_;  // storage_: each row's C_i (the solve's state check)
  int cg_iters_ = 0;
};

}  // namespace ff::porenet
