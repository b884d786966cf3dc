// Pore pressure loads the bonds between the grains (issue 16 item 6, seed 004 B26-B27): three
// bonded discs of radius R at the corners of an equilateral triangle (side 2R, touching) enclose
// one pore at gauge pressure P; the outside is dry. The fluid pushes each disc away from the pore
// with |F| = P h R |u2 - u1| = P h R (the arc of 60 degrees, integrated exactly; h the wetted
// height), and at equilibrium the two bonds of each disc, 30 degrees either side of F, carry the
// tension T = |F| / (2 cos 30) = P h R / sqrt(3) (statics of the triangle). The height h is the
// disc thickness t (fracflow's 1 m thick discs, ForceHeight::Thickness) or the seed's literal
// 2 R (ForceHeight::Diameter), which gives 2R/t = 2e-3 of that tension: the measurement behind
// "20 MPa of pore pressure leaves the strength unchanged" (docs/saturated.md).
// The bonds are seed 004's cohesive law (A1-A6). Tolerance 1e-3 relative: the state after 4000
// damped steps is static to ~1e-6, and P is the pore's pressure at that state.
#include <gtest/gtest.h>

#include <cmath>

#include "coupling/porenet/dem_porenet.hpp"
#include "dem/diagnostics.hpp"
#include "porenet/eos.hpp"

namespace ff::coupling {
namespace {

constexpr Real kR = 1e-3;

dem::DemSystem triangle() {
  dem::DemSystem s;
  s.settings.dim = 2;
  s.settings.local_damping = 0.7;
  s.settings.skin = 0.3 * kR;
  s.settings.track_energy = false;
  s.materials.group_names = {"m"};
  s.materials.density = {2400};
  s.materials.set_contact_law<dem::CohesiveContact>();
  s.materials.set_bond_law<dem::CohesiveBond>();
  s.materials.contact_params<dem::CohesiveContact>() = {{1e11, 0.3, 0.5}};
  s.materials.bond_params<dem::CohesiveBond>() = {{1e11, 0.3, 0.5, 1e12, 1e12}};  // unbreakable here
  s.particles.resize(3);
  s.particles.radius = {kR, kR, kR};
  s.particles.pos = {Vec3(0, 0, 0), Vec3(2 * kR, 0, 0), Vec3(kR, std::sqrt(3.0) * kR, 0)};
  for (std::size_t i = 0; i < 3; ++i) s.particles.set_mass_from_density(i, 2400, 2);
  s.install_bonds(1e-9);
  s.initialise();
  s.settings.dt = 0.5 * dem::critical_time_step(s);
  return s;
}

PorenetCouplingParams gas(ForceHeight h) {
  PorenetCouplingParams p;
  p.fluid.liquid = porenet::Eos::barotropic(1000, 1e5, 2.2e9);
  p.fluid.gas = porenet::Eos::ideal_gas(293.15, 28.9586);  // soft: the pressure barely moves with the discs
  p.saturation = 0;
  p.ambient_pressure = 1e5;
  p.force_height = h;
  p.drainage = Drainage::Closed;
  return p;
}

// Returns {mean bond tension, the pore's gauge pressure} at equilibrium.
std::pair<Real, Real> equilibrium(ForceHeight h, Real p_abs) {
  dem::DemSystem s = triangle();
  DemPorenetCoupling c;
  c.init(s, gas(h));
  EXPECT_EQ(c.network().n_pores(), 1);
  EXPECT_EQ(s.bonds.size(), 3u);
  c.set_uniform_state(p_abs, 0);
  for (int k = 0; k < 4000; ++k) c.step(s);
  Real t = 0;
  for (std::size_t b = 0; b < s.bonds.size(); ++b) {
    const Vec3 d = (s.particles.pos[s.bonds.j[b]] - s.particles.pos[s.bonds.i[b]]).normalized();
    t -= s.bond_loads()[b].f.dot(d);  // force on j along i->j: tension < 0
  }
  return {t / 3, c.flow().pressure()[0] - 1e5};
}

TEST(PorePressureBonds, BondTensionEqualsPressureForceThickness) {
  const auto [T, P] = equilibrium(ForceHeight::Thickness, 2e5);
  const Real expected = P * 1.0 * kR / std::sqrt(3.0);  // h = t = 1 m
  std::printf("thickness: gauge P %.6g Pa, bond tension %.6g N, P t R/sqrt(3) %.6g N\n", P, T, expected);
  EXPECT_GT(P, 0.9e5);
  EXPECT_NEAR(T, expected, 1e-3 * expected);
}

TEST(PorePressureBonds, SeedDiameterHeightGivesTwoROverTOfIt) {
  const auto [T, P] = equilibrium(ForceHeight::Diameter, 2e5);
  const Real expected = P * 2 * kR * kR / std::sqrt(3.0);  // h = 2R
  std::printf("diameter: gauge P %.6g Pa, bond tension %.6g N, P 2R R/sqrt(3) %.6g N\n", P, T, expected);
  EXPECT_NEAR(T, expected, 1e-3 * expected);
}

// The contact stress of Eq. B1 acts over the same height as the force: suction -|P| in the pore
// pulls the three discs together and each bonded pair carries the compression F = |P| h R / sqrt(3)
// (statics as above), so sigma_n = F / (2 R h) = |P| / (2 sqrt(3)) whichever the height h. With the
// seed's sphere forces (h = 2R) over a 1 m section it would be 2R/t = 2e-3 of that, and B1's
// exp(-1.5e-7 sigma_n) would leave every channel at h0 under any load. Tolerance 1e-3 (statics).
TEST(PorePressureBonds, ContactStressOfB1IsThePorePressuresOverTheSameHeight) {
  for (const ForceHeight h : {ForceHeight::Thickness, ForceHeight::Diameter}) {
    dem::DemSystem s = triangle();
    DemPorenetCoupling c;
    c.init(s, gas(h));
    c.set_uniform_state(5e4, 0);  // gauge -5e4 Pa
    for (int k = 0; k < 4000; ++k) c.step(s);
    const Real P = 1e5 - c.flow().pressure()[0];
    const Real expected = P / (2 * std::sqrt(3.0));
    ASSERT_EQ(c.pairs().size(), 3u);
    for (std::size_t q = 0; q < 3; ++q) {
      std::printf("%s: suction %.6g Pa, sigma_n %.6g Pa, |P|/(2 sqrt 3) %.6g Pa\n",
                  h == ForceHeight::Diameter ? "diameter" : "thickness", P, c.pairs().sigma_n[q], expected);
      EXPECT_NEAR(c.pairs().sigma_n[q], expected, 1e-3 * expected);
    }
  }
}

}  // namespace
}  // namespace ff::coupling

namespace ff::coupling {
namespace {

// Cavitation (DemPorenetCoupling, fluid.cavitation_pressure): a liquid-filled pore pulled below the
// vapour pressure p_v keeps its liquid mass (to round-off, 1e-12) and holds vapour at p_v in the rest
// of its void: S = m_q / (V rho_q(p_v)), vapour mass (1 - S) V rho_v(p_v). Without the floor the
// barotropic liquid stays below p_v (and would go on into tension).
TEST(PorePressureBonds, CavitationHoldsTheVapourPressureAndKeepsTheLiquid) {
  for (const Real pv : {2.34e3, 0.0}) {
    dem::DemSystem s = triangle();
    DemPorenetCoupling c;
    auto prm = gas(ForceHeight::Thickness);
    prm.saturation = 1;
    prm.cavitation_pressure = pv;
    c.init(s, prm);
    c.set_uniform_state(1e3, 1.0);  // liquid below the vapour pressure
    const Real mq0 = c.flow().liquid_mass()[0];
    c.step(s);
    const Real p = c.flow().pressure()[0];
    std::printf("floor %.4g Pa: p %.6g Pa, liquid mass change %.3g, vapour %.3g kg, cavitations %ld\n", pv, p,
                c.flow().liquid_mass()[0] / mq0 - 1, c.flow().gas_mass()[0], c.stats().cavitations);
    EXPECT_NEAR(c.flow().liquid_mass()[0] / mq0, 1.0, 1e-12);
    if (pv > 0) {
      EXPECT_EQ(p, pv);
      EXPECT_EQ(c.stats().cavitations, 1);
      EXPECT_GT(c.flow().gas_mass()[0], 0);
      EXPECT_LT(c.flow().liquid_fraction()[0], 1);
    } else {
      EXPECT_LT(p, 1.5e3);
      EXPECT_EQ(c.stats().cavitations, 0);
    }
  }
}

// Condensation: vapour exists only at the vapour pressure p_v. A cavitated pore (all its gas vapour)
// set above p_v (20 kPa with 10 % vapour; 5 MPa almost all liquid) condenses vapour into
// liquid at constant total mass M: back to p_v with liquid fraction S = (M/V - rho_v) / (rho_q - rho_v)
// (both phases at p_v fill V), or, if M/V exceeds the liquid's density at p_v, all of it, leaving a
// compressed liquid at p = p_liquid(M / V). Closed forms from the EOS; tolerance 1e-12 (round-off).
TEST(PorePressureBonds, CompressedVapourCondensesBackToLiquid) {
  const Real pv = 2.34e3;
  for (const bool all : {false, true}) {
    dem::DemSystem s = triangle();
    DemPorenetCoupling c;
    auto prm = gas(ForceHeight::Thickness);
    prm.saturation = 1;
    prm.cavitation_pressure = pv;
    c.init(s, prm);
    c.set_uniform_state(1e3, 1.0);
    c.step(s);  // cavitates: vapour at p_v
    ASSERT_EQ(c.stats().cavitations, 1);
    ASSERT_GT(c.total_vapour(), 0);
    EXPECT_NEAR(c.total_vapour() / c.flow().gas_mass()[0], 1.0, 1e-12);  // all the gas is vapour
    // Compressed states; the gas that appears is vapour (the sample's gas is all vapour).
    const Real a0 = all ? 1 - 1e-6 : 0.9;
    c.flow().set_pore_state(0, all ? 5e6 : 2e4, a0);
    const Real M = c.flow().liquid_mass()[0] + c.flow().gas_mass()[0];
    c.step(s);
    const Real V = c.network().pore_void[0];
    const Real rq = prm.fluid.liquid.density(pv, true), rv = prm.fluid.gas.density(pv, false);
    const Real M1 = c.flow().liquid_mass()[0] + c.flow().gas_mass()[0];
    std::printf("%s: p %.6g Pa, S %.9f, total mass change %.3g, vapour left %.3g kg, condensed %.3g kg\n",
                all ? "all condenses" : "back to p_v", c.flow().pressure()[0], c.flow().liquid_fraction()[0],
                M1 / M - 1,
                c.total_vapour(), c.stats().condensed_mass);
    EXPECT_NEAR(M1 / M, 1.0, 1e-12);
    EXPECT_EQ(c.stats().condensations, 1);
    if (all) {
      EXPECT_EQ(c.flow().gas_mass()[0], 0);
      EXPECT_EQ(c.total_vapour(), 0);
      EXPECT_NEAR(c.flow().pressure()[0] / prm.fluid.liquid.pressure(M / V), 1.0, 1e-12);
      EXPECT_GT(c.flow().pressure()[0], 1e6);
    } else {
      EXPECT_EQ(c.flow().pressure()[0], pv);
      EXPECT_NEAR(c.flow().liquid_fraction()[0], (M / V - rv) / (rq - rv), 1e-12);
      EXPECT_NEAR(c.total_vapour() / c.flow().gas_mass()[0], 1.0, 1e-12);
      EXPECT_GT(c.flow().liquid_fraction()[0], a0);  // vapour went into the liquid
    }
  }
}

}  // namespace
}  // namespace ff::coupling

namespace ff::coupling {
namespace {

// The stiffness the pore fluid adds to a grain (DemPorenetCoupling::fluid_stiffness, used for the DEM's
// critical step) against the force change it predicts: the top disc of the triangle is pushed into the
// closed pore by delta = 1e-5 R; the pore's pressure follows the fluid's state equation at the new void
// (one explicit flow step of 1e-15 s, no channel to anywhere), and the fluid's force on the disc along
// +y grows by k delta. At gauge 0 the arc's change is second order, so k = K h R (t R) / V exactly to
// first order (R the chord of the 60 degree arc, t R the void's change per unit move, equal radii keep
// the sectors' area). Liquid (barotropic K 2.2 GPa) and half gas (ideal, isothermal K = p: the mixture's
// 1/K = S/K_q + (1 - S)/K_p), either height; tolerance 1e-3 (finite difference of O(delta/R)).
TEST(PorePressureBonds, FluidStiffnessIsTheUndrainedForceChangePerMove) {
  for (const Real S : {1.0, 0.5})
    for (const ForceHeight h : {ForceHeight::Thickness, ForceHeight::Diameter}) {
      dem::DemSystem s = triangle();
      DemPorenetCoupling c;
      auto prm = gas(h);
      prm.saturation = S;
      prm.cavitation_pressure = 0;
      c.init(s, prm);
      c.set_uniform_state(1e5, S);  // ambient: gauge 0
      const Real k = c.fluid_stiffness()[2];
      c.compute_fluid_forces(0);
      const Real f0 = c.fluid_fy(2);
      const Real delta = 1e-5 * kR;
      s.particles.pos[2].y() -= delta;
      ASSERT_FALSE(c.sync(s));
      c.flow().step_explicit(1e-15);
      c.compute_fluid_forces(0);
      const Real k_fd = (c.fluid_fy(2) - f0) / delta;
      const Real V = c.network().pore_void[0] + kR * delta;  // before the move
      const Real K = 1 / (S / 2.2e9 + (1 - S) / 1e5);
      const Real hh = h == ForceHeight::Thickness ? 1.0 : 2 * kR;
      std::printf("S %.1f, %s: k %.6g N/m, finite difference %.6g N/m, K h R^2 t / V %.6g N/m\n", S,
                  h == ForceHeight::Diameter ? "diameter" : "thickness", k, k_fd, K * hh * kR * kR / V);
      EXPECT_NEAR(k_fd, k, 1e-3 * k);
      EXPECT_NEAR(k, K * hh * kR * kR / V, 1e-3 * k);
    }
}

// The critical step with that stiffness: sqrt(m / (k_bonds + k_fluid)) for the stiffest grain, below
// the dry one, and the size of the extra stiffness checked (one entry per particle).
TEST(PorePressureBonds, CriticalStepCountsTheFluidStiffness) {
  dem::DemSystem s = triangle();
  DemPorenetCoupling c;
  auto prm = gas(ForceHeight::Thickness);
  prm.saturation = 1;
  c.init(s, prm);
  const auto k = c.fluid_stiffness();
  const Real dry = dem::critical_time_step(s), wet = dem::critical_time_step(s, k);
  Real kmax = 0;
  for (Real x : k) kmax = std::max(kmax, x);
  std::printf("critical step dry %.6g s, with the liquid %.6g s, fluid stiffness %.6g N/m\n", dry, wet, kmax);
  EXPECT_LT(wet, dry);
  EXPECT_GT(kmax, 0);
  const std::vector<Real> wrong(2, 1.0);
  EXPECT_THROW(dem::critical_time_step(s, wrong), Error);
}

}  // namespace
}  // namespace ff::coupling
