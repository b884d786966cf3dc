#include "porenet/two_phase.hpp"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cmath>
#include <fmt/format.h>
#include <limits>
#include <numeric>

#include "core/error.hpp"
#include "porenet/reduce.hpp"

namespace ff::porenet {
namespace {

// std::nextafter(x, toward) inline (two libm calls per pore and step were 2.5 % of a two-phase
// step): the neighbouring double, by its bit pattern; the same bits as std::nextafter.
Real next_toward(Real x, Real toward) {
  if (!std::isfinite(x) || !(x != toward)) return std::nextafter(x, toward);
  if (x == 0) return toward > 0 ? std::numeric_limits<Real>::denorm_min() : -std::numeric_limits<Real>::denorm_min();
  const auto u = std::bit_cast<std::uint64_t>(x);
  return std::bit_cast<Real>((x < toward) == (x > 0) ? u + 1 : u - 1);  // away from zero when moving outwards
}

// A phase below this share of a pore's void is a trace: under 1e-9 of gas in a liquid pore adds
// 1e-14 1/Pa to the liquid's 4.5e-10 1/Pa compressibility at 0.1 MPa.
constexpr Real kTraceFraction = 1e-9;
}  // namespace

StratifiedRates stratified_channel_flow(Real G, Real hq, Real hp, Real muq, Real mup) {
  StratifiedRates r;
  if (hq <= 0 && hp <= 0) return r;
  if (hq <= 0) {
    r.q_gas = G * hp * hp * hp / (12 * mup);
    return r;
  }
  if (hp <= 0) {
    r.q_liquid = G * hq * hq * hq / (12 * muq);
    return r;
  }
  // Momentum (B4, steady, fully developed) in each layer: mu u'' = -G; B5–B7 fix the constants.
  // (Fluidities 1 / mu: three divisions instead of twelve, a tenth of a two-phase step.)
  const Real fq = 1 / muq, fp = 1 / mup;
  const Real tau0 = G * (hp * hp * fp - hq * hq * fq) / (2 * (hq * fq + hp * fp));
  const Real C = 0.5 * G * hq * hq * fq + tau0 * hq * fq;
  r.q_liquid = (-G * hq * hq * hq / 6 - 0.5 * tau0 * hq * hq) * fq + C * hq;
  r.q_gas = (-G * hp * hp * hp / 6 + 0.5 * tau0 * hp * hp) * fp + C * hp;
  r.tau_interface = tau0;
  return r;
}

TwoPhaseFlow::TwoPhaseFlow(const Network2D& net, const TwoPhaseParams& params)
    : net_(net), prm_(params), np_(net.n_pores()), nc_(net.n_channels()) {
  if (!(params.mu_liquid > 0 && params.mu_gas > 0))
    throw InputError(fmt::format("porenet: viscosities must be > 0 (liquid {}, gas {} Pa s)", params.mu_liquid,
                                 params.mu_gas));
  if (params.max_halvings < 0 || params.max_halvings > 30)
    throw InputError(fmt::format("porenet: max_halvings = {}; allowed 0..30", params.max_halvings));
  const auto n = static_cast<std::size_t>(np_);
  p_.assign(n, 0);
  alpha_ = mq_ = mp_ = rq_ = rp_ = bc_value_ = bc_alpha_ = p_;
  bc_.assign(n, PoreBc::None);
  fq_.assign(static_cast<std::size_t>(nc_), 0);
  fp_ = fq_;
  lim_q_.assign(n, 1);
  lim_p_ = lim_q_;
  gross_q_.assign(n, 0);
  net_bound_.assign(n, 0);
  switch_.assign(n, 0);
  net_q_.assign(n, 0);
  net_p_ = net_q_;
  scratch_.assign(static_cast<std::size_t>(std::max<Index>(reduce_blocks(std::max(np_, nc_)), 1)), 0);
  liquid_max_density_ = prm_.liquid.max_density();
  gas_max_density_ = prm_.gas.max_density();
  liquid_min_density_ = prm_.liquid.min_liquid_density();
}

void TwoPhaseFlow::set_pore_state(Index i, Real p, Real S) {
  if (i < 0 || i >= np_) throw InputError(fmt::format("porenet: pore {} out of range 0..{}", i, np_ - 1));
  if (!(S >= 0 && S <= 1)) throw InputError(fmt::format("porenet: saturation {} outside [0, 1]", S));
  const Real V = net_.pore_void[i];
  p_[i] = p;
  alpha_[i] = S;
  rq_[i] = prm_.liquid.density(p, true);
  rp_[i] = prm_.gas.density(p, false);
  mq_[i] = S * V * rq_[i];
  mp_[i] = (1 - S) * V * rp_[i];
}

void TwoPhaseFlow::init(Real p, Real S, LiquidPlacement placement) {
  if (!(S >= 0 && S <= 1)) throw InputError(fmt::format("porenet: saturation {} outside [0, 1]", S));
  injected_ = 0;
  if (placement == LiquidPlacement::Uniform || S == 0 || S == 1) {
    for (Index i = 0; i < np_; ++i) set_pore_state(i, p, S);
    return;
  }
  std::vector<Index> order(static_cast<std::size_t>(np_));
  std::iota(order.begin(), order.end(), Index{0});
  const auto& V = net_.pore_void;
  std::stable_sort(order.begin(), order.end(), [&](Index a, Index b) { return V[a] < V[b]; });
  Real total = 0;
  for (Index i = 0; i < np_; ++i) total += std::max(V[i], Real{0});
  Real left = S * total;  // liquid volume still to place
  for (const Index i : order) {
    const Real v = std::max(V[i], Real{0});
    const Real a = left <= 0 ? 0.0 : v <= left ? 1.0 : left / v;
    left -= a * v;
    set_pore_state(i, p, a);
  }
}

void TwoPhaseFlow::set_bc(Index pore, PoreBc kind, Real value, Real alpha_bc) {
  if (pore < 0 || pore >= np_) throw InputError(fmt::format("porenet: pore {} out of range 0..{}", pore, np_ - 1));
  bc_[pore] = kind;
  bc_value_[pore] = value;
  bc_alpha_[pore] = alpha_bc;
  if (kind == PoreBc::Pressure) set_pore_state(pore, value, alpha_bc);
}

void TwoPhaseFlow::load_masses(std::span<const Real> mq, std::span<const Real> mp) {
  if (mq.size() != static_cast<std::size_t>(np_) || mp.size() != static_cast<std::size_t>(np_))
    throw InputError(fmt::format("porenet: {} / {} phase masses for a network of {} pores", mq.size(), mp.size(), np_));
  for (Index i = 0; i < np_; ++i) {
    mq_[i] = mq[i];
    mp_[i] = mp[i];
    const Real V = net_.pore_void[i];
    Real p;
    const Real a = solve_shared_pressure(mq_[i], mp_[i], V, 0.5, p);
    alpha_[i] = a;
    p_[i] = p;
    rq_[i] = a > 0 ? mq_[i] / (a * V) : prm_.liquid.density(p > 0 ? p : 1.0, true);
    rp_[i] = a < 1 ? mp_[i] / ((1 - a) * V) : prm_.gas.density(p > 0 ? p : 1.0, false);
  }
  // A prescribed pressure stays prescribed: the implicit step holds such a pore at its state (it
  // never writes p there) and the explicit rates read it, so a remapped state would stay for the run
  // (after a retriangulation drained hull pores held the interior's pressure, pushing it into the sample).
  for (Index i = 0; i < np_; ++i)
    if (bc_[i] == PoreBc::Pressure) set_pore_state(i, bc_value_[i], bc_alpha_[i]);
}

Real TwoPhaseFlow::solve_shared_pressure(Real mq, Real mp, Real V, Real a0, Real& p, int* iterations) const {
  const Eos& L = prm_.liquid;
  const Eos& Gs = prm_.gas;
  // A phase under 1e-30 of the other's mass takes no part (its volume share, ~1e-27, is below what
  // a double resolves next to the other's): a liquid trace that the outflow limiter shrank step by
  // step reached 5e-324 kg, its alpha 1e-316, and its density m / (alpha V) overflowed to inf (3D,
  // the smallest pores liquid-full). It stays in the pore, immobile (no volume, no mobility).
  if (mp <= 0 || mp < 1e-30 * mq) {
    p = L.pressure(mq / V);
    return 1;
  }
  if (mq <= 0 || mq < 1e-30 * mp) {
    p = Gs.pressure(mp / V);
    return 0;
  }
  // Bracket: liquid denser than its maximum below lo; above hi the gas is over-compressed or the
  // liquid is past its spinodal (PR loop).
  Real lo = mq / (V * liquid_max_density_);
  Real hi = 1 - mp / (V * gas_max_density_);
  if (liquid_min_density_ > 0) hi = std::min(hi, mq / (V * liquid_min_density_));
  lo = next_toward(lo, 2.0);
  hi = next_toward(hi, -1.0);
  auto f = [&](Real a, Real& df) {
    const Real rq = mq / (a * V), rp = mp / ((1 - a) * V);
    Real Kq, Kp;
    const Real pq = L.pressure_and_modulus(rq, Kq), pp = Gs.pressure_and_modulus(rp, Kp);
    // d/dalpha: dp/drho = K/rho; drho_q/dalpha = -rho_q/alpha, drho_p/dalpha = rho_p/(1-alpha).
    df = -Kq / a - Kp / (1 - a);
    return pq - pp;
  };
  Real a = std::clamp(a0, lo, hi);
  if (!(a > lo && a < hi)) a = 0.5 * (lo + hi);
  // A trace of one phase (a pore that held the other phase only: the last alpha within 1e-6 of 0 or
  // 1) starts at the trace's volume at the pressure of the other phase alone, next to the root: Newton
  // from 0 or 1 crept up by a factor (1 + ln) per iteration and stopped far from a root near 1e-30
  // (p = -1.6e11 Pa in a gas pore that had received 1e-25 kg of a barotropic liquid).
  // A trace below alpha's resolution (1 - alpha under one ulp: 1e-24 kg of gas beside 1e-4 kg of
  // water) starts at the bracket's end: one evaluation confirms the root lies past it. Started at
  // the midpoint instead, such a pore took 31-200 bisections per step (test
  // GasTraceBelowAlphaResolutionStopsAtOnce).
  if (a0 < 1e-6) {
    const Real aq = mq / (V * L.density(Gs.pressure(mp / V), true));
    if (aq > lo && aq < hi) a = aq;
    else if (aq <= lo) a = lo;
  } else if (a0 > 1 - 1e-6) {
    const Real pl = L.pressure(mq / V);
    if (pl > 0 && std::isfinite(pl)) {
      const Real ag = 1 - mp / (V * Gs.density(pl, false));
      if (ag > lo && ag < hi) a = ag;
      else if (ag >= hi) a = hi;
    }
  }
  int it = 0;
  for (; it < 200; ++it) {
    Real df;
    const Real fa = f(a, df);
    if (fa > 0)
      lo = a;
    else
      hi = a;
    Real an = a - fa / df;
    // Newton has converged: accept before the bracket test (a step that lands on the bracket's end,
    // as a converged one does, was sent to a bisection, and from there back: 128 iterations per pore
    // with the geometric bisection, 80 % of a partly saturated specimen's step).
    if (std::isfinite(an) && std::abs(an - a) <= 1e-15 * a) {
      a = std::clamp(an, lo, hi);  // (a step next to 1 can round to 1: no gas volume left)
      break;
    }
    // Bisection, geometric where the bracket spans decades (a root near a trace's 1e-30).
    if (!(an > lo && an < hi) || !std::isfinite(an)) an = lo > 0 && hi > 1e3 * lo ? std::sqrt(lo * hi) : 0.5 * (lo + hi);
    // Relative bracket width: a trace of liquid in a gas pore has its root near mq / (rho_q V),
    // far below 1e-16 (an absolute width stopped there at alpha ~ 3e-17: the liquid's density, and
    // with it its pressure, a factor 1e-8 off, p = -4e10 Pa with a barotropic liquid).
    if (hi - lo <= 1e-16 * a) {
      a = an;
      break;
    }
    a = an;
  }
  if (iterations) *iterations = std::min(it + 1, 200);
  p = L.pressure(mq / (a * V));
  return a;
}

void TwoPhaseFlow::channel_mobilities(Index c, Index u, Real& lq, Real& lp) const {
  if (net_.dim == 2) {
    const Real h = net_.ch_aperture[c], w = net_.params.thickness / net_.ch_length[c];
    const StratifiedRates r = stratified_channel_flow(1.0, alpha_[u] * h, (1 - alpha_[u]) * h, prm_.mu_liquid, prm_.mu_gas);
    lq = r.q_liquid * w;
    lp = r.q_gas * w;
  } else {
    const StratifiedRates r = stratified_channel_flow(1.0, alpha_[u], 1 - alpha_[u], prm_.mu_liquid, prm_.mu_gas);
    lq = 12 * net_.ch_cond[c] * r.q_liquid;
    lp = 12 * net_.ch_cond[c] * r.q_gas;
  }
}

Real TwoPhaseFlow::channel_mobility(Index c) const {
  const Index a = net_.ch_pore[2 * c], b = net_.ch_pore[2 * c + 1];
  Real lq, lp;
  channel_mobilities(c, p_[a] >= p_[b] ? a : b, lq, lp);
  return lq + lp;
}

void TwoPhaseFlow::compute_rates() {
  const Real t = net_.params.thickness;
  if (net_.dim != 2) {
#pragma omp parallel for schedule(static) if (nc_ > kParallelMin)
    for (Index c = 0; c < nc_; ++c) {
      const Index a = net_.ch_pore[2 * c], b = net_.ch_pore[2 * c + 1];
      const Index u = p_[a] >= p_[b] ? a : b;
      Real lq, lp;
      channel_mobilities(c, u, lq, lp);
      fq_[c] = rq_[u] * lq * (p_[a] - p_[b]);
      fp_[c] = rp_[u] * lp * (p_[a] - p_[b]);
    }
    return;
  }
#pragma omp parallel for schedule(static) if (nc_ > kParallelMin)
  for (Index c = 0; c < nc_; ++c) {
    const Index a = net_.ch_pore[2 * c], b = net_.ch_pore[2 * c + 1];
    const Index u = p_[a] >= p_[b] ? a : b;  // upstream pore: face values (B8)
    const Real h = net_.ch_aperture[c];
    const Real G = (p_[a] - p_[b]) / net_.ch_length[c];
    const StratifiedRates r =
        stratified_channel_flow(G, alpha_[u] * h, (1 - alpha_[u]) * h, prm_.mu_liquid, prm_.mu_gas);
    fq_[c] = rq_[u] * r.q_liquid * t;  // M_q,f [kg/s], a -> b
    fp_[c] = rp_[u] * r.q_gas * t;
  }
}

Real TwoPhaseFlow::stable_dt() {
  compute_rates();
  Real dt = std::numeric_limits<Real>::infinity();
#pragma omp parallel for schedule(static) reduction(min : dt) if (np_ > kParallelMin)
  for (Index i = 0; i < np_; ++i) {
    if (bc_[i] == PoreBc::Pressure) continue;
    Real mob = 0, outq = 0, outp = 0;
    for (Index e = net_.pc_start[i]; e < net_.pc_start[i + 1]; ++e) {
      const Index c = net_.pc_ch[e];
      const Index a = net_.ch_pore[2 * c], b = net_.ch_pore[2 * c + 1];
      // The larger mobility of the two upstream choices: within a DEM step the flow can turn, and a
      // gas pore next to a liquid-full one then pushes its gas (55 x more mobile) into it.
      Real lqa, lpa, lqb, lpb;
      channel_mobilities(c, a, lqa, lpa);
      channel_mobilities(c, b, lqb, lpb);
      mob += std::max(lqa + lpa, lqb + lpb);
      const Real sgn = a == i ? 1 : -1;
      outq += std::max(sgn * fq_[c], 0.0);
      outp += std::max(sgn * fp_[c], 0.0);
    }
    Real comp = 0;  // V dalpha-weighted compressibility
    if (alpha_[i] > 0) comp += alpha_[i] / prm_.liquid.bulk_modulus(rq_[i]);
    if (alpha_[i] < 1) comp += (1 - alpha_[i]) / prm_.gas.bulk_modulus(rp_[i]);
    if (mob > 0) dt = std::min(dt, net_.pore_void[i] * comp / mob);
    if (outq > 0) dt = std::min(dt, mq_[i] / outq);
    if (outp > 0) dt = std::min(dt, mp_[i] / outp);
  }
  return dt;
}

void TwoPhaseFlow::step_explicit(Real dt) {
  compute_rates();
  limited_ = find_outflow_limits(dt);
  if (limited_ > 0) apply_outflow_limits();
  update_pore_states(dt, "explicit", limited_ == 0);  // unlimited: the net outflows found stand
}

// Transport limiter: where a pore would give away more of a phase in dt than it holds (a step above
// the transport bound of stable_dt(): the rates changed since it was evaluated, e.g. the sub-steps of
// a DEM step), its outgoing rates of that phase are scaled down to its mass (1 - 1e-12). Each channel's
// rate is scaled once, by its upstream pore (apply_outflow_limits): conservative to round-off.
Index TwoPhaseFlow::find_outflow_limits(Real dt, Index* bulk) {
#pragma omp parallel for schedule(static) if (np_ > kParallelMin)
  for (Index i = 0; i < np_; ++i) {
    lim_q_[i] = lim_p_[i] = 1;
    net_bound_[i] = 0;
    if (bc_[i] == PoreBc::Pressure) continue;
    Real oq = 0, op = 0, nq = 0, np = 0, gas_in = 0;
    for (Index e = net_.pc_start[i]; e < net_.pc_start[i + 1]; ++e) {
      const Index c = net_.pc_ch[e];
      const bool first = net_.ch_pore[2 * c] == i;
      const Real sg = first ? 1.0 : -1.0;
      oq += std::max(sg * fq_[c], 0.0);
      op += std::max(sg * fp_[c], 0.0);
      gas_in += std::max(-sg * fp_[c], 0.0);
      nq += first ? fq_[c] : -fq_[c];  // the net outflow, as update_pore_states sums it
      np += first ? fp_[c] : -fp_[c];
    }
    net_q_[i] = nq;
    net_p_[i] = np;
    gross_q_[i] = oq * dt;
    // A liquid-full pore that takes in no gas has no saturation to keep in [0, 1]: what it must not
    // exceed is its net loss of liquid, not its gross outflow. Liquid flowing through it (the pores along
    // a crack) would otherwise trip the limit every step: the 30,000-sphere hydrofrac example with crack
    // channels halved its steps thousands of times (docs/hydrofrac.md). Such a pore stays unlimited while
    // its net outflow fits (net_bound_; checked again below with its neighbours' limits on its inflow);
    // otherwise it takes the gross bound, which holds whatever its inflow.
    if (1 - alpha_[i] <= kTraceFraction && gas_in == 0 && std::max(nq, 0.0) * dt <= mq_[i]) net_bound_[i] = 1;
    else if (gross_q_[i] > mq_[i]) lim_q_[i] = (1 - 1e-12) * mq_[i] / gross_q_[i];
    op *= dt;
    if (op > mp_[i]) lim_p_[i] = (1 - 1e-12) * mp_[i] / op;
  }
  // A net-bound pore whose inflow the limits upstream cut may now lose more than it holds: it takes the
  // gross bound, which cuts the inflow of the pores downstream of it in turn. Jacobi rounds (each reads
  // the limits of the round before: the same on any thread count) until none switches.
  for (;;) {
    Index switched = 0;
#pragma omp parallel for schedule(static) reduction(+ : switched) if (np_ > kParallelMin)
    for (Index i = 0; i < np_; ++i) {
      switch_[i] = 0;
      if (!net_bound_[i]) continue;
      Real in = 0;
      for (Index e = net_.pc_start[i]; e < net_.pc_start[i + 1]; ++e) {
        const Index c = net_.pc_ch[e];
        const Index a = net_.ch_pore[2 * c], b = net_.ch_pore[2 * c + 1];
        const Real into = a == i ? -fq_[c] : fq_[c];  // > 0: from the other pore into i
        if (into > 0) in += into * lim_q_[a == i ? b : a];
      }
      if (gross_q_[i] - in * dt > mq_[i]) {
        switch_[i] = 1;
        ++switched;
      }
    }
    if (switched == 0) break;
#pragma omp parallel for schedule(static) if (np_ > kParallelMin)
    for (Index i = 0; i < np_; ++i) {
      if (!switch_[i]) continue;
      net_bound_[i] = 0;
      if (gross_q_[i] > mq_[i]) lim_q_[i] = (1 - 1e-12) * mq_[i] / gross_q_[i];
    }
  }
  Index limited = 0, limited_bulk = 0;
#pragma omp parallel for schedule(static) reduction(+ : limited, limited_bulk) if (np_ > kParallelMin)
  for (Index i = 0; i < np_; ++i) {
    const bool lq = lim_q_[i] < 1, lp = lim_p_[i] < 1;
    limited += (lq || lp) ? 1 : 0;
    // A trace (a phase under kTraceFraction of the void) is limited but never asks for a halving:
    // it changes neither the pore's pressure nor its other phase.
    limited_bulk += ((lq && alpha_[i] > kTraceFraction) || (lp && 1 - alpha_[i] > kTraceFraction)) ? 1 : 0;
  }
  if (bulk) *bulk = limited_bulk;
  return limited;
}

void TwoPhaseFlow::apply_outflow_limits() {
#pragma omp parallel for schedule(static) if (nc_ > kParallelMin)
  for (Index c = 0; c < nc_; ++c) {
    const Index a = net_.ch_pore[2 * c], b = net_.ch_pore[2 * c + 1];
    fq_[c] *= fq_[c] > 0 ? lim_q_[a] : lim_q_[b];
    fp_[c] *= fp_[c] > 0 ? lim_p_[a] : lim_p_[b];
  }
}

// Phase masses from the channel rates fq_, fp_ (B18), then the shared pressure (B23) at the new void
// volume (B19) and the phase densities (B20).
void TwoPhaseFlow::update_pore_states(Real dt, const char* scheme, bool net_outflow_ready) {
  Index bad = -1;
#pragma omp parallel for schedule(static) reduction(max : bad) if (np_ > kParallelMin)
  for (Index i = 0; i < np_; ++i) {
    if (bc_[i] == PoreBc::Pressure) {
      // Fixed state at the new void volume.
      const Real V = net_.pore_void[i];
      mq_[i] = bc_alpha_[i] * V * rq_[i];
      mp_[i] = (1 - bc_alpha_[i]) * V * rp_[i];
      continue;
    }
    Real outq = 0, outp = 0;
    if (net_outflow_ready) {
      outq = net_q_[i];
      outp = net_p_[i];
    } else {
      for (Index e = net_.pc_start[i]; e < net_.pc_start[i + 1]; ++e) {
        const Index c = net_.pc_ch[e];
        const bool first = net_.ch_pore[2 * c] == i;
        outq += first ? fq_[c] : -fq_[c];
        outp += first ? fp_[c] : -fp_[c];
      }
    }
    mq_[i] -= dt * outq;  // B18
    mp_[i] -= dt * outp;
    if (bc_[i] == PoreBc::Flux) mq_[i] += dt * bc_value_[i];
    // Round-off can leave a drained phase at -eps: a mass below 1e-14 of the pore's total is none.
    const Real tiny = 1e-14 * (std::abs(mq_[i]) + std::abs(mp_[i]));
    if (mq_[i] < -tiny || mp_[i] < -tiny || mq_[i] + mp_[i] <= 0) {
      bad = std::max(bad, i);
      continue;
    }
    const Real V = net_.pore_void[i];  // B19: the new void volume
    Real p;
    const Real a = solve_shared_pressure(std::max(mq_[i], 0.0), std::max(mp_[i], 0.0), V, alpha_[i], p);
    alpha_[i] = a;
    p_[i] = p;
    // B20; an absent phase keeps the density of the pore's pressure (the implicit step's weights),
    // found from its last one. A liquid-full pore's gas density is read only where the pore holds a
    // trace of gas (vp = mp / rp in the implicit step); nowhere else (a liquid-full upstream pore has
    // no gas mobility; pressure pores keep theirs, above): kept otherwise (its PR Newton solve per
    // pore and step was ~4 % of a saturated 3D network run).
    rq_[i] = a > 0 ? mq_[i] / (a * V) : prm_.liquid.density_near(p > 0 ? p : 1.0, true, rq_[i]);
    if (a < 1)
      rp_[i] = mp_[i] / ((1 - a) * V);
    else if (mp_[i] > 0)
      rp_[i] = prm_.gas.density_near(p > 0 ? p : 1.0, false, rp_[i]);
  }
  if (bad >= 0)
    throw NumericalError(fmt::format("porenet: pore {} phase masses ({}, {}) kg after an {} step of {} s (a step "
                                     "above the flow's stable step, or non-finite conductances)", bad, mq_[bad], mp_[bad],
                                     scheme, dt));
  for (Index i = 0; i < np_; ++i)
    if (bc_[i] == PoreBc::Flux) injected_ += dt * bc_value_[i];
}

void TwoPhaseFlow::prepare_implicit() {
  if (sys_) return;
  sys_ = std::make_unique<PressureSystem>(net_);
  const auto n = static_cast<std::size_t>(np_), m = static_cast<std::size_t>(nc_);
  tq_.assign(m, 0);
  tp_ = tq_;
  rhs_.assign(n, 0);
  dp_ = pnew_ = lim_q_ = lim_p_ = storage_ = rhs_;
}

void TwoPhaseFlow::step_implicit(Real dt) {
  prepare_implicit();
  substeps_ = 0;
  implicit_substep(dt, 0);
}

// One backward-Euler step; if a pore would give away more of a phase than it holds (the explicit
// transport limit, far above the pressure-diffusion limit for liquids), two half steps instead
// (nothing has been changed yet); past max_halvings the outflow limiter below applies.
void TwoPhaseFlow::implicit_substep(Real dt, int depth) {
  auto& A = sys_->matrix();
  const auto& entry_channel = sys_->entry_channel();
  Real* val = A.valuePtr();
  const auto* outer = A.outerIndexPtr();
  const auto* inner = A.innerIndexPtr();
  // Mass mobilities at t^n (upstream pore of p^n): tq_, tp_ [kg/(Pa s)]; volumetric ones in the matrix.
#pragma omp parallel for schedule(static) if (nc_ > kParallelMin)
  for (Index c = 0; c < nc_; ++c) {
    const Index a = net_.ch_pore[2 * c], b = net_.ch_pore[2 * c + 1];
    const Index u = p_[a] >= p_[b] ? a : b;
    Real lq, lp;
    channel_mobilities(c, u, lq, lp);
    tq_[c] = lq;  // volumetric for now; densities applied below
    tp_[c] = lp;
  }
  Index unstable = -1;  // a pore whose phase has dp/drho <= 0: its storage, and the matrix, indefinite
  Real p_scale = 0;     // largest |p|: the scale of the solve's state check
#pragma omp parallel for schedule(static) reduction(max : unstable, p_scale) if (np_ > kParallelMin)
  for (Index i = 0; i < np_; ++i) {
    const bool fixed_i = bc_[i] == PoreBc::Pressure;
    const Real vq = mq_[i] / rq_[i], vp = mp_[i] / rp_[i];  // phase volumes at t^n
    // The volume balance times the pore's liquid density (mass units): with the channel's upstream
    // liquid density in W the liquid part is the exact liquid mass balance and stays symmetric.
    const Real rq = rq_[i];
    const Real Kq = vq > 0 ? prm_.liquid.bulk_modulus(rq_[i]) : 1, Kp = vp > 0 ? prm_.gas.bulk_modulus(rp_[i]) : 1;
    if (!fixed_i && !(Kq > 0 && Kp > 0)) unstable = std::max(unstable, i);
    Real diag = rq * ((vq > 0 ? vq / Kq : 0) + (vp > 0 ? vp / Kp : 0));
    storage_[i] = fixed_i ? 0 : diag;
    p_scale = std::max(p_scale, std::abs(p_[i]));
    Real rhs = 0;
    if (!fixed_i) rhs = rq * (vq + vp - net_.pore_void[i]) + (bc_[i] == PoreBc::Flux ? dt * bc_value_[i] : 0);
    // Pressure pores: a diagonal row at the scale of a free row [kg/Pa] (see flow.cpp).
    for (Index k = outer[i]; k < outer[i + 1]; ++k) {
      const Index c = entry_channel[k];
      if (c < 0) continue;
      const Index j = inner[k];
      const Index a = net_.ch_pore[2 * c], b = net_.ch_pore[2 * c + 1];
      const Real W = dt * rq_[p_[a] >= p_[b] ? a : b] * (tq_[c] + tp_[c]);
      diag += W;
      if (fixed_i) {
        val[k] = 0;
        continue;
      }
      rhs -= W * (p_[i] - p_[j]);
      if (bc_[j] == PoreBc::Pressure) {
        rhs += W * (bc_value_[j] - p_[j]);
        val[k] = 0;
      } else {
        val[k] = -W;
      }
    }
    if (!(diag > 0)) diag = 1;  // an empty, unconnected pore
    for (Index k = outer[i]; k < outer[i + 1]; ++k)
      if (inner[k] == i) val[k] = diag;
    rhs_[i] = fixed_i ? diag * (bc_value_[i] - p_[i]) : rhs;
  }
  if (unstable >= 0) throw_unstable_state(unstable);
  cg_iters_ = sys_->solve(rhs_, dp_, prm_.preconditioner, prm_.cg_tolerance, prm_.cg_max_iterations, storage_,
                          kStateTolerance * p_scale);
#pragma omp parallel for schedule(static) if (np_ > kParallelMin)
  for (Index i = 0; i < np_; ++i) pnew_[i] = p_[i] + dp_[i];
  // Mass rates with p^{n+1} and the t^n upstream densities.
#pragma omp parallel for schedule(static) if (nc_ > kParallelMin)
  for (Index c = 0; c < nc_; ++c) {
    const Index a = net_.ch_pore[2 * c], b = net_.ch_pore[2 * c + 1];
    const Index u = p_[a] >= p_[b] ? a : b;
    fq_[c] = rq_[u] * tq_[c] * (pnew_[a] - pnew_[b]);
    fp_[c] = rp_[u] * tp_[c] * (pnew_[a] - pnew_[b]);
  }
  // Outflow limit: a pore gives away at most the mass of each phase it holds (the transport bound of
  // the frozen mobilities: also what keeps IMPES stable; a net-outflow bound let the 3D test diverge).
  Index bulk = 0;
  const Index limited = find_outflow_limits(dt, &bulk);
  if (bulk > 0 && depth < prm_.max_halvings) {
    implicit_substep(0.5 * dt, depth + 1);
    implicit_substep(0.5 * dt, depth + 1);
    return;
  }
  limited_ = limited;
  ++substeps_;
  if (limited > 0) apply_outflow_limits();  // the limits just found: nothing has changed since
  update_pore_states(dt, "implicit", limited == 0);
}

void TwoPhaseFlow::throw_unstable_state(Index i) const {
  const auto k = static_cast<std::size_t>(i);
  const bool liquid = mq_[k] > 0 && !(prm_.liquid.bulk_modulus(rq_[k]) > 0);
  throw NumericalError(fmt::format(
      "porenet: pore {} at {:.4g} Pa: its {} ({:.6g} kg/m^3) lies in the equation of state's unstable region "
      "(dp/drho <= 0{}): the pore pressures have gone unstable. In a coupled run either the DEM time step is above "
      "the critical step with the pore fluid's stiffness (keep that stiffness in the time step, saturated_ucs: "
      "fluid.stiffness_in_time_step = true, or lower dem.time_step / dem.time_step_safety), or the throats conduct "
      "so much more than the pores store that the pressure solve cannot resolve the storage (lower the conductance)",
      i, p_[k], liquid ? "liquid" : "gas", liquid ? rq_[k] : rp_[k],
      liquid ? ": stretched past the spinodal; cavitation is not modelled" : ""));
}

Real TwoPhaseFlow::total_liquid_mass() { return fixed_order_sum(np_, [&](Index i) { return mq_[i]; }, scratch_); }
Real TwoPhaseFlow::total_gas_mass() { return fixed_order_sum(np_, [&](Index i) { return mp_[i]; }, scratch_); }
Real TwoPhaseFlow::saturation() {
  const Real lv = fixed_order_sum(np_, [&](Index i) { return alpha_[i] * net_.pore_void[i]; }, scratch_);
  const Real v = fixed_order_sum(np_, [&](Index i) { return net_.pore_void[i]; }, scratch_);
  return lv / v;
}

Real TwoPhaseFlow::mixture_bulk_modulus(Index pore) const {
  const auto i = static_cast<std::size_t>(pore);
  const Real a = alpha_[i];
  const Real Kq = a > 0 ? prm_.liquid.bulk_modulus(rq_[i]) : 1.0;
  const Real Kp = a < 1 ? prm_.gas.bulk_modulus(rp_[i]) : 1.0;
  if (!(Kq > 0 && Kp > 0)) return 0;
  const Real compliance = (a > 0 ? a / Kq : 0.0) + (a < 1 ? (1 - a) / Kp : 0.0);
  return compliance > 0 ? 1 / compliance : 0;
}

}  // namespace ff::porenet
