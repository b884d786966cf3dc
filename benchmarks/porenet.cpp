// Pore-network timings (issue 16, item 8): for a 2D packing of ~10,000 discs, the time of a
// Delaunay triangulation with the network build (CGAL), of a geometry update (particles moved,
// topology kept), of a single-phase explicit and implicit (CG) flow step, of a two-phase explicit
// step (B18–B23 with Peng–Robinson water and air) and of the pressure + shear forces.
// Each figure is the median of repeated runs (the machines are shared). Threads: OMP_NUM_THREADS.
// Usage: porenet [n_target]   (default 10000)
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <string>
#include <fmt/format.h>
#include <vector>

#include "core/error.hpp"
#include "coupling/porenet/dem_porenet3d.hpp"
#include "dem/dem_params.hpp"
#include "dem/sample_builder.hpp"
#include "geometry/packing.hpp"
#include "io/scenario.hpp"
#include "porenet/flow.hpp"
#include "porenet/forces.hpp"
#include "porenet/two_phase.hpp"

using namespace ff;
using namespace ff::porenet;

namespace {
// A bonded sample from the UCS driver's builder ([dem] + [sample] keys), platens at +-v along the axis.
struct DemSample {
  ParamTable table;
  Config cfg;
  dem::DemSystem sys;
  dem::SampleInfo info;
};
std::unique_ptr<DemSample> dem_sample(int dim, Real side, Real v) {
  auto s = std::make_unique<DemSample>();
  dem::declare_dem_params(s->table);
  dem::declare_sample_params(s->table);
  const std::string sc = fmt::format(
      "[dem]\ndim = {0}\nbond_law = \"parallel\"\n[dem.group.matrix]\ndensity = 2400\n"
      "[dem.contact.matrix-matrix]\nemod = 2.0e9\nkratio = 2.5\nfriction = 0.4\n"
      "[dem.bond.matrix-matrix]\nemod = 2.0e9\nkratio = 2.5\ntensile_strength = 17.4e6\ncohesion = 4.35e6\n"
      "[sample]\nshape = \"box\"\nwidth = {1}\ndepth = {1}\nheight = {1}\nradius_min = 0.4e-3\nradius_max = 0.6e-3\n"
      "porosity = {2}\nseed = 5\n", dim, side, dim == 2 ? 0.2 : 0.45);
  s->cfg = load_scenario(s->table, "", sc, {});
  s->sys.settings = dem::build_settings(s->cfg);
  s->sys.materials = dem::build_materials(s->cfg);
  s->info = dem::build_sample(s->cfg, s->sys);
  dem::add_platens(s->sys, s->info, 0.1);
  dem::choose_time_step(s->cfg, s->sys);
  s->sys.walls[0].velocity[s->info.axis] = v;
  s->sys.walls[1].velocity[s->info.axis] = -v;
  return s;
}

double median_ms(int reps, const std::function<void()>& f) {
  std::vector<double> t;
  for (int r = 0; r < reps; ++r) {
    const auto a = std::chrono::steady_clock::now();
    f();
    t.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - a).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}
}  // namespace

int main(int argc, char** argv) {
  const int target = argc > 1 ? std::atoi(argv[1]) : 10000;
  PackingSpec spec;
  spec.dim = 2;
  spec.container = PackingSpec::Container::Box;
  spec.radius_min = 0.4e-3;
  spec.radius_max = 0.6e-3;
  spec.porosity = 0.2;
  // Square box holding about `target` discs of mean radius 0.5 mm.
  const Real side = std::sqrt(target * kPi * 0.25e-6 / (1 - spec.porosity) * (1 + 0.04 / 3));
  spec.box_lo = {0, 0, 0};
  spec.box_hi = {side, side, 0};
  const auto t0 = std::chrono::steady_clock::now();
  const Packing pk = dense_random_packing(spec);
  const double t_pack = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::vector<Real> x, y;
  for (const Vec3& c : pk.position) {
    x.push_back(c.x());
    y.push_back(c.y());
  }
  const Particles2D parts{x, y, pk.radius, {}};
  // Contacts as bonds: every pair closer than 1.02 (r_i + r_j) (brute force on a cell grid is not
  // needed for the benchmark's purpose: pairs come from the Delaunay edges of a first build).
  Network2D net0 = build_network_2d(parts, {});
  PairList pairs;
  for (Index c = 0; c < net0.n_channels(); ++c) {
    const Index a = net0.ch_part[2 * c], b = net0.ch_part[2 * c + 1];
    if (net0.ch_edge[c] < 1.02 * (pk.radius[a] + pk.radius[b])) pairs.add(a, b, PairState::Bond, 1e6, 0);
  }
  Network2D net;
  const double t_build = median_ms(5, [&] { net = build_network_2d(parts, pairs); });
  const double t_update = median_ms(11, [&] { update_network_2d(net, parts, pairs); });

  SinglePhaseParams sp;
  sp.fluid = Eos::barotropic(1000, 1e5, 2.2e9);
  SinglePhaseFlow f(net, sp);
  for (Index k = 0; k < net.n_pores(); ++k)
    if (net.pore_cx[k] < 1e-3) f.set_bc(k, PoreBc::Pressure, 2e5);
  f.init(1e5);
  const Real dt = 0.5 * f.stable_dt();
  const double t_expl = median_ms(51, [&] { f.step_explicit(dt); });
  const double t_impl = median_ms(11, [&] { f.step_implicit(1000 * dt); });
  const int cg_it = f.last_cg_iterations();
  TwoPhaseFlow tp(net, {});
  tp.init(1e5, 0.5);
  for (Index k = 0; k < net.n_pores(); ++k)
    if (net.pore_cx[k] < 2e-3) tp.set_pore_state(k, 2e5, 0.9);
  const Real dt2 = 0.5 * tp.stable_dt();
  const double t_two = median_ms(21, [&] { tp.step_explicit(dt2); });
  std::vector<Real> fx(x.size()), fy(x.size());
  const double t_force = median_ms(51, [&] {
    add_pressure_forces(net, parts, f.pressure(), fx, fy);
    add_shear_forces(net, parts, f.pressure(), fx, fy);
  });
  std::printf("porenet 2D benchmark, %d OpenMP thread(s)\n", omp_get_max_threads());
  std::printf("  packing: %zu discs (porosity %.3f, generated in %.1f s), %zu bonds\n", x.size(),
              pk.achieved_porosity, t_pack, pairs.size());
  std::printf("  network: %d pores, %d channels (%d unmatched pairs)\n", net.n_pores(), net.n_channels(),
              net.unmatched_pairs);
  std::printf("  triangulation + network build   %9.2f ms\n", t_build);
  std::printf("  geometry/aperture update        %9.3f ms\n", t_update);
  std::printf("  single-phase explicit step      %9.3f ms  (stable dt %.3e s, water)\n", t_expl, 2 * dt);
  std::printf("  single-phase implicit step (CG) %9.3f ms  (dt = 500 stable steps, %d CG iterations)\n", t_impl,
              cg_it);
  std::printf("  two-phase explicit step (PR)    %9.3f ms  (stable dt %.3e s)\n", t_two, 2 * dt2);
  std::printf("  pressure + shear forces         %9.3f ms\n", t_force);

  // 3D: ~30,000 spheres in a box, regular triangulation (PFV style) and a single-phase step.
  const int target3 = argc > 2 ? std::atoi(argv[2]) : 30000;
  PackingSpec s3;
  s3.dim = 3;
  s3.container = PackingSpec::Container::Box;
  s3.radius_min = 0.4e-3;
  s3.radius_max = 0.6e-3;
  s3.porosity = 0.40;
  const Real side3 = std::cbrt(target3 * 4.0 / 3 * kPi * 0.13e-9 / (1 - s3.porosity));
  s3.box_lo = {0, 0, 0};
  s3.box_hi = {side3, side3, side3};
  const auto t3 = std::chrono::steady_clock::now();
  const Packing pk3 = dense_random_packing(s3);
  const double t_pack3 = std::chrono::duration<double>(std::chrono::steady_clock::now() - t3).count();
  std::vector<Real> x3, y3, z3;
  for (const Vec3& c : pk3.position) {
    x3.push_back(c.x());
    y3.push_back(c.y());
    z3.push_back(c.z());
  }
  Network2D net3;
  const double t_build3 = median_ms(3, [&] { net3 = build_network_3d({x3, y3, z3, pk3.radius, {}}); });
  SinglePhaseFlow f3(net3, sp);
  for (Index k = 0; k < net3.n_pores(); ++k)
    if (net3.pore_cx[k] < 1e-3) f3.set_bc(k, PoreBc::Pressure, 2e5);
  f3.init(1e5);
  const Real dt3 = 0.5 * f3.stable_dt();
  const double t_expl3 = median_ms(21, [&] { f3.step_explicit(dt3); });
  const bool quick = argc > 3 && std::string(argv[3]) == "quick";  // skip the long 3D implicit timings
  if (!quick) {
  // Implicit: the earlier Jacobi-PCG from zero ("before") and DIC-PCG with warm start (default).
  SinglePhaseParams spj = sp;
  spj.preconditioner = Preconditioner::Jacobi;
  spj.warm_start = false;
  SinglePhaseFlow f3j(net3, spj);
  for (Index k = 0; k < net3.n_pores(); ++k)
    if (net3.pore_cx[k] < 1e-3) f3j.set_bc(k, PoreBc::Pressure, 2e5);
  f3j.init(1e5);
  const double t_impl3j = median_ms(5, [&] { f3j.step_implicit(1e-7); });
  const double t_impl3 = median_ms(5, [&] { f3.step_implicit(1e-7); });
  // Two-phase implicit (PR water + air, S = 0.5, a 2:1 pressure step) at 100 x its explicit step.
  TwoPhaseFlow tp3(net3, {});
  tp3.init(1e5, 0.5);
  for (Index k = 0; k < net3.n_pores(); ++k)
    if (net3.pore_cx[k] < 1e-3) tp3.set_pore_state(k, 2e5, 0.5);
  const Real dt3e = tp3.stable_dt();
  tp3.prepare_implicit();
  const double t_tp3 = median_ms(5, [&] { tp3.step_implicit(100 * dt3e); });
  std::printf("porenet 3D: %zu spheres (porosity %.3f, generated in %.1f s), %d pores, %d throats, %d hidden\n",
              x3.size(), pk3.achieved_porosity, t_pack3, net3.n_pores(), net3.n_channels(), net3.hidden_particles);
  std::printf("  regular triangulation + network %9.2f ms\n", t_build3);
  std::printf("  single-phase explicit step      %9.3f ms  (stable dt %.3e s, water)\n", t_expl3, 2 * dt3);
  std::printf("  single-phase implicit, Jacobi-CG %9.3f ms  (dt 1e-7 s, %d CG iterations, from zero)\n", t_impl3j,
              f3j.last_cg_iterations());
  std::printf("  single-phase implicit, DIC-CG    %9.3f ms  (dt 1e-7 s, %d CG iterations, warm start)\n", t_impl3,
              f3.last_cg_iterations());
  std::printf("  two-phase implicit step (PR)    %9.3f ms  (dt 100 x explicit %.3e s, %d CG iterations, %d sub-steps)\n",
              t_tp3, dt3e, tp3.last_cg_iterations(), tp3.last_substeps());
  }
  // DEM step and a coupled 3D run (item 8): the same sizes as above, bonded samples, UCS platens at
  // 0.05 m/s each (the UCS driver's default); water (PR) and air at S = 0.5, implicit flow.
  if (argc > 3 && std::string(argv[3]) == "nodem") return 0;
  std::fflush(stdout);
  const Real v = 0.05;
  auto d2 = dem_sample(2, std::sqrt(target * kPi * 0.25e-6 / 0.8 * (1 + 0.04 / 3)), v);
  d2->sys.run(5);
  const double t_dem2 = median_ms(21, [&] { d2->sys.step(); });
  std::printf("DEM 2D: %zu discs, %zu bonds, dt %.3e s: DEM step %9.3f ms\n", d2->sys.particles.size(),
              d2->sys.bonds.size(), d2->sys.settings.dt, t_dem2);
  auto d3 = dem_sample(3, std::cbrt(target3 * 4.0 / 3 * kPi * 0.13e-9 / 0.55), v);
  d3->sys.run(5);
  const double t_dem3 = median_ms(11, [&] { d3->sys.step(); });
  std::printf("DEM 3D: %zu spheres, %zu bonds, dt %.3e s: DEM step %9.3f ms\n", d3->sys.particles.size(),
              d3->sys.bonds.size(), d3->sys.settings.dt, t_dem3);
  for (const Real S : {1.0, 0.5}) {
  coupling::Porenet3DParams cp;
  cp.saturation = S;
  // Masses are conserved whatever the CG residual, and the volume residual enters the next step's
  // right-hand side: a looser tolerance costs pressure accuracy only (1e-8 of the source term).
  cp.fluid.cg_tolerance = 1e-8;
  coupling::DemPorenet3D cpl;
  cpl.init(d3->sys, cp);
  const int nc = S == 1.0 ? 10 : 3;
  const auto tc = std::chrono::steady_clock::now();
  try {
    cpl.run(d3->sys, nc);
  } catch (const NumericalError& e) {  // reported, not hidden: the 3D saturated solve can stall (docs §8)
    std::printf("coupled 3D, S %.1f: stopped: %s\n", S, e.what());
    continue;
  }
  const double t_run = std::chrono::duration<double>(std::chrono::steady_clock::now() - tc).count();
  const auto& st = cpl.stats();
  const double per_step = t_run / nc;
  // Retriangulation after a displacement of tolerance x mean radius: at the platen speed that is
  // 0.25 x 0.5 mm / (v dt) steps (the platen moves fastest of all particles).
  const double steps_between = cp.retriangulation_tolerance * 0.5e-3 / (v * d3->sys.settings.dt);
  const double t_tri = st.t_triangulation;  // the initial build (+ any retriangulation)
  std::printf("coupled 3D (%d pores, implicit, S %.1f): %d steps in %.2f s: %.1f ms per step = DEM + "
              "update %.1f ms + flow %.1f ms + forces %.1f ms; triangulation + remap %.0f ms (%ld retriangulations)\n",
              cpl.network().n_pores(), S, nc, t_run, 1e3 * per_step, 1e3 * st.t_update / nc, 1e3 * st.t_flow / nc,
              1e3 * st.t_forces / nc, 1e3 * t_tri, st.retriangulations);
  std::printf("  last step: %d CG iterations, %ld flow sub-steps; max pore pressure %.4e Pa\n",
              cpl.flow().last_cg_iterations(), st.last_substeps, cpl.max_pressure());
  std::printf("  flow step / DEM step = %.2f; retriangulation every %.0f steps at %.2f m/s: share of the run %.3f%%\n",
              st.t_flow / nc / (t_dem3 * 1e-3), steps_between, v,
              100 * t_tri / (t_tri + steps_between * per_step));
  }
  return 0;
}
