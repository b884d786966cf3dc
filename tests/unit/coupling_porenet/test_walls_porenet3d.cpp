// The DEM's box walls in the 3D network (Porenet3DParams::walls; porenet::BoxWalls, PFV's boundary
// spheres): a bonded sphere specimen between six plane walls (two platens and four side walls).
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "coupling/porenet/dem_porenet3d.hpp"
#include "dem/dem_params.hpp"
#include "dem/sample_builder.hpp"
#include "io/scenario.hpp"
#include "porenet/eos.hpp"
#include "porenet/flow.hpp"
#include "porenet/forces.hpp"
#include "resume_check.hpp"
#include "sphere_specimen.hpp"
#include "side_walls.hpp"

namespace ff::coupling {
namespace {

const std::string& kScenario = test::kSphereSpecimen;

struct Specimen {
  ParamTable table;
  Config cfg;
  dem::DemSystem sys;
  dem::SampleInfo info;
};

// The specimen with its platens (moving together at platen_v) and four frictionless side walls at the
// spheres' extent.
std::unique_ptr<Specimen> boxed(Real platen_v) {
  auto s = std::make_unique<Specimen>();
  dem::declare_dem_params(s->table);
  dem::declare_sample_params(s->table);
  s->cfg = load_scenario(s->table, "", kScenario, {});
  s->sys.settings = dem::build_settings(s->cfg);
  s->sys.settings.parallel_min = 1;
  s->sys.materials = dem::build_materials(s->cfg);
  s->info = dem::build_sample(s->cfg, s->sys);
  dem::add_platens(s->sys, s->info, 0.0);
  test::add_side_walls(s->sys, s->info.axis);
  s->sys.initialise();
  dem::choose_time_step(s->cfg, s->sys);
  s->sys.walls[0].velocity[s->info.axis] = platen_v;
  s->sys.walls[1].velocity[s->info.axis] = -platen_v;
  return s;
}

Porenet3DParams fluid(Real saturation, Real K) {
  Porenet3DParams p;
  p.fluid.liquid = porenet::Eos::barotropic(1000, 1e5, K);
  p.fluid.gas = porenet::Eos::ideal_gas(293.15, 28.9586);
  p.saturation = saturation;
  p.walls = true;
  return p;
}

// The box the walls enclose [m^3] and the area of wall w (2 axis + side) [m^2].
Real box_volume(const dem::DemSystem& sys, const DemPorenet3D& c) {
  Real v = 1;
  for (int a = 0; a < 3; ++a)
    v *= sys.walls[static_cast<std::size_t>(c.wall_index(2 * a + 1))].point[a] -
         sys.walls[static_cast<std::size_t>(c.wall_index(2 * a))].point[a];
  return v;
}
Real wall_area(const dem::DemSystem& sys, const DemPorenet3D& c, int w) {
  Real area = 1;
  for (int a = 0; a < 3; ++a)
    if (a != w / 2)
      area *= sys.walls[static_cast<std::size_t>(c.wall_index(2 * a + 1))].point[a] -
              sys.walls[static_cast<std::size_t>(c.wall_index(2 * a))].point[a];
  return area;
}

std::vector<Real> state_of(const dem::DemSystem& sys, DemPorenet3D& c) {
  std::vector<Real> v;
  for (const auto& p : sys.particles.pos) v.insert(v.end(), {p.x(), p.y(), p.z()});
  for (const auto& w : sys.walls) v.insert(v.end(), {w.force.x(), w.force.y(), w.force.z()});
  for (Real p : c.flow().pressure()) v.push_back(p);
  for (Real p : c.flow().liquid_mass()) v.push_back(p);
  return v;
}

}  // namespace

// Uniform gauge pressure P: no net force on any sphere (with the walls every sphere's cones close, the
// ones against the walls included; without walls only the interior spheres' do), and each wall takes
// P times its area, pushed outward (the DEM wall's force, what a servo reads, gains it). Tolerances:
// 1e-9 P 4 pi R^2 per sphere, 1e-6 of P A per wall (the wall spheres' finite radius).
TEST(CouplingPorenet3DWalls, UniformPressurePushesOnlyTheWalls) {
  auto s = boxed(0);
  DemPorenet3D c;
  auto prm = fluid(1.0, 5e7);
  prm.ambient_pressure = 0;
  c.init(s->sys, prm);
  const Real P = 1e6;
  c.set_uniform_state(P, 1.0);
  c.step(s->sys);
  Real worst = 0;
  for (std::size_t k = 0; k < s->sys.particles.size(); ++k) {
    const Real r = s->sys.particles.radius[k];
    worst = std::max(worst, c.fluid_force(static_cast<Index>(k)).norm() / (P * 4 * M_PI * r * r));
  }
  const auto& net = c.network();
  int wall_pores = 0;
  for (Index i = 0; i < net.n_pores(); ++i) wall_pores += net.pore_walls[i] != 0;
  std::printf("uniform pressure with walls: %zu spheres, %d pores (%d on walls), max |F|/(P 4 pi r^2) = %.3g\n",
              s->sys.particles.size(), net.n_pores(), wall_pores, worst);
  EXPECT_LT(worst, 1e-9);
  for (int w = 0; w < 6; ++w) {
    const auto& wall = s->sys.walls[static_cast<std::size_t>(c.wall_index(w))];
    EXPECT_NEAR(c.wall_fluid_force(w) / (P * wall_area(s->sys, c, w)), 1.0, 1e-6) << "wall " << w;
    // The DEM wall's force (contacts + fluid), outward along -normal: the fluid's part at least.
    EXPECT_GT(-wall.force.dot(wall.normal), 0.99 * c.wall_fluid_force(w)) << "wall " << w;
  }
}

// The pores tile the box, so moving one sphere leaves the total void unchanged: for every sphere whose
// pores are all above the floors, sum over its pore corners of dV_i/dx_j (void_gradient: Reynolds
// transport in the interior pores, central differences of the geometry in the wall pores) is zero.
// Tolerance 1e-6 of 4 pi R^2 (the differences' truncation and round-off); without walls the hull
// spheres' sums are of the order of their surface.
TEST(CouplingPorenet3DWalls, VoidGradientsOfEverySphereSumToZero) {
  auto s = boxed(0);
  DemPorenet3D c;
  c.init(s->sys, fluid(1.0, 5e7));
  const auto& net = c.network();
  int tested = 0, at_walls = 0;
  Real worst = 0;
  for (Index j = 0; j < net.n_particles; ++j) {
    bool floored = false, wall = false;
    Vec3 sum = Vec3::Zero();
    for (Index e = net.pp_start[j]; e < net.pp_start[j + 1]; ++e) {
      const Index i = net.pp_pore[e];
      floored = floored || net.pore_void[i] <= net.void_floor ||
                net.pore_void[i] <= net.params.min_void_fraction * net.pore_cell[i] * (1 + 1e-12);
      wall = wall || net.pore_walls[i] != 0;
      Real a[3];
      porenet::unit_patch_force_3d(net, e, a);
      sum += c.void_gradient(j, e, Vec3(a[0], a[1], a[2]), false);
    }
    if (floored) continue;
    ++tested;
    at_walls += wall;
    const Real r = s->sys.particles.radius[static_cast<std::size_t>(j)];
    worst = std::max(worst, sum.norm() / (4 * M_PI * r * r));
  }
  std::printf("void gradients: %d spheres tested (%d on walls), max |sum dV/dx| / (4 pi R^2) = %.3g\n", tested,
              at_walls, worst);
  EXPECT_GT(at_walls, 20);
  EXPECT_LT(worst, 1e-6);
}

// Undrained compression between the platens (closed: every wall impermeable, liquid K 5e7 Pa): with the
// walls the pores fill the box, so the void the liquid sees shrinks by what the platens sweep, and once
// the pressure has evened out p - p0 = K ln(V0 / V) with V the pores' void (barotropic liquid, mass
// conserved; Wang 2000 with B = 1), within 1 % of the rise; the platens' fluid force is the gauge pressure
// times their area within 2 % (the pores along them hold the mean pressure).
TEST(CouplingPorenet3DWalls, UndrainedCompressionBetweenThePlatens) {
  auto s = boxed(0.02);
  DemPorenet3D c;
  auto prm = fluid(1.0, 5e7);
  prm.pfv_factor = 1.0;
  prm.retriangulation_tolerance = 10;  // one network
  c.init(s->sys, prm);
  Real v0 = 0;
  for (Real v : c.network().pore_void) v0 += v;
  const Real box0 = box_volume(s->sys, c);
  c.run(s->sys, 300);
  s->sys.walls[0].velocity.setZero();
  s->sys.walls[1].velocity.setZero();
  c.run(s->sys, 300);
  const auto& net = c.network();
  Real v = 0, pv = 0;
  const auto p = c.flow().pressure();
  for (Index i = 0; i < net.n_pores(); ++i) {
    v += net.pore_void[i];
    pv += p[i] * net.pore_void[i];
  }
  const Real rise = pv / v - 1e5, expected = 5e7 * std::log(v0 / v);
  const Real box = box_volume(s->sys, c);
  const int ax = s->info.axis;
  const Real platen = 0.5 * (c.wall_fluid_force(2 * ax) + c.wall_fluid_force(2 * ax + 1)) / wall_area(s->sys, c, 2 * ax);
  std::printf("undrained with walls: box %.4g -> %.4g m^3 (%.3g %%), void %.4g -> %.4g m^3; rise %.5g Pa, K ln(V0/V) "
              "%.5g Pa (%+.3f %%); platens' fluid force / area %.5g Pa\n", box0, box, 100 * (box / box0 - 1), v0, v,
              rise, expected, 100 * (rise / expected - 1), platen);
  EXPECT_GT(rise, 1e4);
  EXPECT_NEAR(rise / expected, 1.0, 0.01);
  EXPECT_NEAR(platen / rise, 1.0, 0.02);
}

// Resume from a checkpoint (DEM + network with its walls + fluid) continues bit-for-bit through a
// retriangulation while the platens move; 1 and 2 threads agree.
TEST(CouplingPorenet3DWalls, CheckpointResumeAndThreadsBitIdentical) {
  auto prm = fluid(0.5, 2.2e9);
  prm.retriangulation_tolerance = 0.0015;
  test::expect_resume_and_threads_identical(boxed, prm, 120, 120, state_of, "ff_coupling_porenet3d_walls_test.ckpt",
                                            "3D walls");
}

}  // namespace ff::coupling

namespace ff::coupling {

// Crack channels (Porenet3DParams::crack_channels): a bond in the crack log (radius r_b) opened by w adds
// w^3 r_b / (12 L) to exactly the throats whose facet holds both of its spheres, over what the same
// positions give without the crack (to round-off), and nothing elsewhere.
TEST(CouplingPorenet3DWalls, BrokenBondOpensItsThroats) {
  auto s = boxed(0);
  auto& sys = s->sys;
  // An interior bond: both spheres away from every wall.
  std::size_t bond = sys.bonds.size();
  for (std::size_t b = 0; b < sys.bonds.size() && bond == sys.bonds.size(); ++b) {
    const Vec3 m = 0.5 * (sys.particles.pos[sys.bonds.i[b]] + sys.particles.pos[sys.bonds.j[b]]);
    if ((m - Vec3(3e-3, 3e-3, 3e-3)).norm() < 1e-3) bond = b;
  }
  ASSERT_LT(bond, sys.bonds.size());
  const Index a = sys.bonds.i[bond], c = sys.bonds.j[bond];
  const Real w = 2e-6;
  const Vec3 n = (sys.particles.pos[c] - sys.particles.pos[a]).normalized();
  const Real d = (sys.particles.pos[c] - sys.particles.pos[a]).norm();
  sys.particles.pos[c] += (sys.particles.radius[a] + sys.particles.radius[c] + w - d) * n;  // opened by w
  DemPorenet3D intact, cracked;
  auto prm = fluid(1.0, 5e7);
  prm.crack_channels = true;
  intact.init(sys, prm);
  intact.sync(sys);
  const Real rb = 0.8 * std::min(sys.particles.radius[a], sys.particles.radius[c]);  // the bond's radius
  sys.cracks.add(dem::CrackEvent{0, sys.particles.pos[a], n, rb, 1, 0, 0, sys.particles.id[a], sys.particles.id[c]});
  cracked.init(sys, prm);
  cracked.sync(sys);
  const auto& ni = intact.network();
  const auto& nc = cracked.network();
  ASSERT_EQ(ni.n_channels(), nc.n_channels());
  int opened = 0;
  Real worst = 0;
  for (Index ch = 0; ch < nc.n_channels(); ++ch) {
    const Index* v = &nc.ch_part[3 * static_cast<std::size_t>(ch)];
    const bool edge = (v[0] == a || v[1] == a || v[2] == a) && (v[0] == c || v[1] == c || v[2] == c);
    const Real expected = edge ? w * w * w * rb / (12 * nc.ch_length[ch]) : 0.0;
    opened += edge;
    worst = std::max(worst, std::abs(nc.ch_cond[ch] - ni.ch_cond[ch] - expected) / std::max(expected, ni.ch_cond[ch]));
  }
  std::printf("crack channel: bond %zu opened by %.1e m: %d throats around it; largest relative deviation %.2e\n", bond,
              w, opened, worst);
  EXPECT_GE(opened, 3);
  EXPECT_LT(worst, 1e-12);
}

}  // namespace ff::coupling

namespace ff::coupling {
namespace {
// The specimen cut across its loading axis at mid-height (every bond crossing the plane broken), its top
// half and top platen lifted by w; the steady flow [m^3/s] along a lateral axis between the walls' pores
// at 1e5 + 100 Pa and 1e5 Pa (water, mu 1e-3 Pa s), the matrix throats scaled by 1e-12 (a tight rock);
// and the parallel-plate cubic law for the same gap, w^3 W dp / (12 mu L).
struct CrackFlow {
  Real q, q_cubic;
  int cut, edges;  // bonds broken; the triangulation's sphere pairs across the plane
};
CrackFlow planar_crack_flow(Real w, bool crack_channels) {
  auto s = boxed(0);
  auto& sys = s->sys;
  const int ax = s->info.axis;
  Real lo = 1e9, hi = -1e9;
  for (const auto& x : sys.particles.pos) lo = std::min(lo, x[ax]), hi = std::max(hi, x[ax]);
  const Real mid = 0.5 * (lo + hi);
  CrackFlow out{0, 0, 0, 0};
  for (std::size_t b = 0; b < sys.bonds.size(); ++b) {
    const Index i = sys.bonds.i[b], j = sys.bonds.j[b];
    if ((sys.particles.pos[i][ax] < mid) == (sys.particles.pos[j][ax] < mid)) continue;
    sys.bonds.broken[b] = 1;  // a crack event with the bond's radius (radius_multiplier 1: the smaller sphere's)
    const Vec3 n = (sys.particles.pos[j] - sys.particles.pos[i]).normalized();
    sys.cracks.add(dem::CrackEvent{0, sys.particles.pos[i], n, std::min(sys.particles.radius[i], sys.particles.radius[j]),
                                   1, 0, 0, sys.particles.id[i], sys.particles.id[j]});
    ++out.cut;
  }
  for (auto& x : sys.particles.pos)
    if (x[ax] > mid) x[ax] += w;
  sys.walls[1].point[ax] += w;
  DemPorenet3D c;
  auto prm = fluid(1.0, 5e7);
  prm.pfv_factor = 1e-12;
  prm.crack_channels = crack_channels;
  c.init(sys, prm);
  c.sync(sys);
  const auto& net = c.network();
  std::vector<std::pair<Index, Index>> across;
  for (Index k = 0; k < net.n_pores(); ++k)
    for (int u = 0; u < 4; ++u)
      for (int v = u + 1; v < 4; ++v) {
        const Index a = net.pore_v[4 * k + u], b = net.pore_v[4 * k + v];
        if (net.is_wall_vertex(a) || net.is_wall_vertex(b)) continue;
        if ((sys.particles.pos[a][ax] < mid) != (sys.particles.pos[b][ax] < mid)) across.emplace_back(std::min(a, b), std::max(a, b));
      }
  std::sort(across.begin(), across.end());
  out.edges = static_cast<int>(std::unique(across.begin(), across.end()) - across.begin());
  const int fa = ax == 0 ? 1 : 0, oa = 3 - ax - fa;  // flow axis, crack width axis
  porenet::SinglePhaseParams sp;
  sp.mu = 1e-3;
  sp.fluid = porenet::Eos::barotropic(1000, 1e5, 2.2e9);
  sp.solver = porenet::LinearSolver::ConjugateGradient;
  porenet::SinglePhaseFlow f(net, sp);
  for (Index i = 0; i < net.n_pores(); ++i) {
    if (net.pore_walls[i] & (1u << (2 * fa))) f.set_bc(i, porenet::PoreBc::Pressure, 1e5 + 100);
    else if (net.pore_walls[i] & (1u << (2 * fa + 1))) f.set_bc(i, porenet::PoreBc::Pressure, 1e5);
  }
  f.init(1e5);
  for (int k = 0; k < 30; ++k) f.step_implicit(10.0);
  out.q = f.pressure_pores_inflow_rate(true) / 1000;
  auto span = [&](int a) {
    return sys.walls[static_cast<std::size_t>(c.wall_index(2 * a + 1))].point[a] -
           sys.walls[static_cast<std::size_t>(c.wall_index(2 * a))].point[a];
  };
  out.q_cubic = w * w * w * span(oa) * 100 / (12 * sp.mu * span(fa));
  return out;
}
}  // namespace

// A planar crack through a tight bonded block (above): the crack channels carry the flow (1e3 x the
// matrix's and more at w = 4 um), their flow grows as w^3 (16 um against 4 um: 64 x, within 20 %: the
// bonds' initial overlaps and their tilt to the plane open them by a little less than w), and it is of
// the order of the parallel-plate cubic law's: measured 2026-11-30 0.120 / 0.112 / 0.103 of it at w = 1 /
// 4 / 16 um (56 bonds cut). Below 1 because the slits lie on the broken bonds' edges only (56 of the 144
// sphere pairs of the triangulation across the plane were bonds; the others, gaps, keep the matrix's
// conductance) and each is one bond radius long; asserted within [0.05, 1].
TEST(CouplingPorenet3DWalls, PlanarCrackConductsAsItsOpeningCubed) {
  const CrackFlow m = planar_crack_flow(4e-6, false), c4 = planar_crack_flow(4e-6, true),
                  c16 = planar_crack_flow(16e-6, true), c1 = planar_crack_flow(1e-6, true);
  std::printf("planar crack, %d bonds cut of %d triangulation edges across: Q / cubic law %.3f / %.3f / %.3f at w = 1 / 4 / 16 um; matrix alone at 4 um "
              "%.3e of it; Q(16) / Q(4) = %.2f\n", c4.cut, c4.edges, c1.q / c1.q_cubic, c4.q / c4.q_cubic, c16.q / c16.q_cubic,
              m.q / c4.q_cubic, c16.q / c4.q);
  EXPECT_GT(c4.q, 1e3 * m.q);
  EXPECT_NEAR(c16.q / c4.q / 64, 1.0, 0.2);
  for (const CrackFlow& c : {c1, c4, c16}) {
    EXPECT_GT(c.q / c.q_cubic, 0.05);
    EXPECT_LT(c.q / c.q_cubic, 1.0);
  }
}

}  // namespace ff::coupling
