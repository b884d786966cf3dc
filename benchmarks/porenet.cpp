// Pore-network timings (issue 16, item 8): for a 2D packing of ~10,000 discs, the time of a
// Delaunay triangulation with the network build (CGAL), of a geometry update (particles moved,
// topology kept), of a single-phase explicit and implicit (CG) flow step, of a two-phase explicit
// step (B18–B23 with Peng–Robinson water and air) and of the pressure + shear forces; the same for a
// 3D packing of ~30,000 spheres (regular triangulation), with the implicit solves preconditioned by
// block DIC (the earlier default) and by AMG (porenet/amg.hpp), the DEM step of a bonded sample of the
// same size, a closed saturated sample compacted at the DEM step, sub-cycling (one implicit flow step
// per N DEM steps: its error and its cost per DEM step) and coupled DEM + flow runs.
// Figures that are compared are measured interleaved (one round: each variant once; the median over
// rounds): the machines are shared and their speed drifts. Threads: OMP_NUM_THREADS.
// Usage: porenet [n2d] [n3d] [quick|nodem|geometry]   (defaults 10000, 30000; quick: no 3D implicit/
// coupled runs; nodem: no DEM and coupled runs; geometry: stop after the 3D geometry update and forces)
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
#include "dem/diagnostics.hpp"
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

double ms_since(std::chrono::steady_clock::time_point a) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - a).count();
}
double median(std::vector<double> t) {
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}
// Interleaved timing: `rounds` rounds, each calling every variant once; medians [ms].
std::vector<double> interleaved_ms(int rounds, const std::vector<std::function<void()>>& fs) {
  std::vector<std::vector<double>> t(fs.size());
  for (int r = 0; r < rounds; ++r)
    for (std::size_t k = 0; k < fs.size(); ++k) {
      const auto a = std::chrono::steady_clock::now();
      fs[k]();
      t[k].push_back(ms_since(a));
    }
  std::vector<double> m;
  for (auto& v : t) m.push_back(median(v));
  return m;
}

// Why CG needs many iterations: per row, the storage (compressibility) part of the diagonal,
// C_i = a_ii - sum_j |a_ij|, against the coupling sum_j |a_ij| = dt sum_j W_ij; the spread of the
// diagonal (row scaling); and the symmetry of the stored matrix.
void matrix_diagnostics(const char* name, const PressureSystem& ps) {
  const auto& A = ps.matrix();
  std::vector<double> ratio, diag;
  double asym = 0, amax = 0;
  for (Index i = 0; i < A.outerSize(); ++i) {
    double d = 0, off = 0;
    for (Eigen::SparseMatrix<Real>::InnerIterator it(A, i); it; ++it) {
      if (it.row() == i) d = it.value();
      else off += std::abs(it.value());
      asym = std::max(asym, std::abs(it.value() - A.coeff(i, it.row())));
      amax = std::max(amax, std::abs(it.value()));
    }
    if (off > 0) {
      ratio.push_back((d - off) / off);
      diag.push_back(d);
    }
  }
  std::sort(ratio.begin(), ratio.end());
  std::sort(diag.begin(), diag.end());
  auto q = [](const std::vector<double>& v, double f) { return v[static_cast<std::size_t>(f * (v.size() - 1))]; };
  std::printf("  matrix %s: C_i / (dt sum W) min %.2e, median %.2e, max %.2e; diagonal spread max/min %.2e "
              "(median/min %.2e); max |a_ij - a_ji| / max |a| = %.1e\n", name, q(ratio, 0), q(ratio, 0.5),
              q(ratio, 1), q(diag, 1) / q(diag, 0), q(diag, 0.5) / q(diag, 0), asym / amax);
}

// Repetitions of the 2D timings (and the coupled 3D S 1 case's steps), times FF_BENCH_REPEAT (default 1;
// larger for a profiler).
int reps(int n) {
  static const int k = std::getenv("FF_BENCH_REPEAT") ? std::max(1, std::atoi(std::getenv("FF_BENCH_REPEAT"))) : 1;
  return n * k;
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
  const double t_update = median_ms(reps(11), [&] { update_network_2d(net, parts, pairs); });

  SinglePhaseParams sp;
  sp.fluid = Eos::barotropic(1000, 1e5, 2.2e9);
  SinglePhaseFlow f(net, sp);
  for (Index k = 0; k < net.n_pores(); ++k)
    if (net.pore_cx[k] < 1e-3) f.set_bc(k, PoreBc::Pressure, 2e5);
  f.init(1e5);
  const Real dt = 0.5 * f.stable_dt();
  const double t_expl = median_ms(reps(51), [&] { f.step_explicit(dt); });
  SinglePhaseParams spa = sp;
  spa.preconditioner = Preconditioner::AMG;
  SinglePhaseFlow fa(net, spa);
  for (Index k = 0; k < net.n_pores(); ++k)
    if (net.pore_cx[k] < 1e-3) fa.set_bc(k, PoreBc::Pressure, 2e5);
  fa.init(1e5);
  for (int k = 0; k < 30; ++k) f.step_explicit(dt);  // the same state as f
  int it_dic = 0, it_amg = 0;
  const auto t2i = interleaved_ms(11, {[&] { f.step_implicit(1000 * dt); it_dic = f.last_cg_iterations(); },
                                       [&] { fa.step_implicit(1000 * dt); it_amg = fa.last_cg_iterations(); }});
  const double t_impl = t2i[0];
  const int cg_it = it_dic;
  TwoPhaseFlow tp(net, {});
  tp.init(1e5, 0.5);
  for (Index k = 0; k < net.n_pores(); ++k)
    if (net.pore_cx[k] < 2e-3) tp.set_pore_state(k, 2e5, 0.9);
  const Real dt2 = 0.5 * tp.stable_dt();
  const double t_two = median_ms(reps(21), [&] { tp.step_explicit(dt2); });
  std::vector<Real> fx(x.size()), fy(x.size());
  const double t_force = median_ms(reps(51), [&] {
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
  std::printf("  single-phase implicit, DIC-CG    %9.3f ms  (dt = 500 stable steps, %d CG iterations, warm start)\n",
              t_impl, cg_it);
  std::printf("  single-phase implicit, AMG-CG    %9.3f ms  (%d CG iterations, %d levels; interleaved with DIC)\n",
              t2i[1], it_amg, fa.pressure_system().amg().n_levels());
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
  // The per-step geometry (pores, throats) and the pressure on the spheres' patches: what a coupled
  // step adds to the flow (DemPorenet3D::sync and compute_fluid_forces).
  const Particles3D parts3{x3, y3, z3, pk3.radius, {}};
  const double t_update3 = median_ms(11, [&] { update_network_3d(net3, parts3); });
  std::vector<Real> p3(static_cast<std::size_t>(net3.n_pores()));
  for (Index k = 0; k < net3.n_pores(); ++k) p3[static_cast<std::size_t>(k)] = 1e5 * (1 + 1e-3 * (k % 7));
  std::vector<Real> fx3(x3.size()), fy3(x3.size()), fz3(x3.size());
  const double t_force3 = median_ms(11, [&] { add_pressure_forces_3d(net3, parts3, p3, fx3, fy3, fz3); });
  // The same packing with the box's walls in the triangulation (BoxWalls: wall pores and throats, PFV's
  // hydraulic radius for every throat): build, then the geometry update interleaved with the one without
  // walls (pairs of calls, medians of each).
  BoxWalls box3;
  box3.lo = {0, 0, 0};
  box3.hi = {side3, side3, side3};
  Network2D net3w;
  const double t_build3w = median_ms(3, [&] { net3w = build_network_3d({x3, y3, z3, pk3.radius, {}}, {}, 1.0, &box3); });
  std::vector<double> t_plain, t_walls;
  for (int rep = 0; rep < 11; ++rep) {
    t_plain.push_back(median_ms(1, [&] { update_network_3d(net3, parts3); }));
    t_walls.push_back(median_ms(1, [&] { update_network_3d(net3w, parts3); }));
  }
  std::sort(t_plain.begin(), t_plain.end());
  std::sort(t_walls.begin(), t_walls.end());
  const std::string mode = argc > 3 ? argv[3] : "";
  const bool quick = mode == "quick", nodem = mode == "nodem";
  std::printf("porenet 3D: %zu spheres (porosity %.3f, generated in %.1f s), %d pores, %d throats, %d hidden\n",
              x3.size(), pk3.achieved_porosity, t_pack3, net3.n_pores(), net3.n_channels(), net3.hidden_particles);
  std::printf("  regular triangulation + network %9.2f ms\n", t_build3);
  std::printf("  single-phase explicit step      %9.3f ms  (stable dt %.3e s, water)\n", t_expl3, 2 * dt3);
  std::printf("  geometry update (pores, throats) %8.3f ms\n", t_update3);
  std::printf("  pressure forces (patches)       %9.3f ms\n", t_force3);
  std::printf("  with walls: %d pores (%zu on walls), %d throats; build %.2f ms; geometry update %.3f ms against %.3f ms "
              "without (interleaved, x %.2f)\n", net3w.n_pores(), net3w.wall_pores.size(), net3w.n_channels(), t_build3w,
              t_walls[5], t_plain[5], t_walls[5] / t_plain[5]);
  std::fflush(stdout);
  if (mode == "geometry") return 0;  // the 3D network's per-step geometry and forces only
  // The DEM sample of the same size: its step is the reference (and interleaved with the flow steps).
  const Real v = 0.05;
  const Real side_dem3 = std::cbrt(target3 * 4.0 / 3 * kPi * 0.13e-9 / 0.55);
  std::unique_ptr<DemSample> d3;
  Real dt_dem = 1e-7;
  if (!nodem) {
    d3 = dem_sample(3, side_dem3, v);
    d3->sys.run(5);
    dt_dem = d3->sys.settings.dt;
  }
  auto dem_step = [&] {
    if (d3) d3->sys.step();
  };
  double t_dem3 = 0;
  if (!quick) {
    // Single phase at the DEM step, block DIC (the earlier default) against AMG, both warm-started;
    // two-phase (PR water + air, S = 0.5, a 2:1 pressure step) at 100 x its explicit step.
    SinglePhaseParams spd = sp, spa3 = sp;
    spd.preconditioner = Preconditioner::DIC;
    spa3.preconditioner = Preconditioner::AMG;
    SinglePhaseFlow f3d(net3, spd), f3a(net3, spa3);
    for (SinglePhaseFlow* g : {&f3d, &f3a}) {
      for (Index k = 0; k < net3.n_pores(); ++k)
        if (net3.pore_cx[k] < 1e-3) g->set_bc(k, PoreBc::Pressure, 2e5);
      g->init(1e5);
    }
    TwoPhaseParams tpd, tpa;
    tpd.preconditioner = Preconditioner::DIC;
    tpa.preconditioner = Preconditioner::AMG;
    TwoPhaseFlow tp3d(net3, tpd), tp3a(net3, tpa);
    Real dt3e = 0;
    for (TwoPhaseFlow* g : {&tp3d, &tp3a}) {
      g->init(1e5, 0.5);
      for (Index k = 0; k < net3.n_pores(); ++k)
        if (net3.pore_cx[k] < 1e-3) g->set_pore_state(k, 2e5, 0.5);
      dt3e = g->stable_dt();
      g->prepare_implicit();
    }
    // First solves (from zero, AMG setup included), then interleaved rounds.
    auto first = [](auto& fn) {
      const auto a = std::chrono::steady_clock::now();
      fn();
      return ms_since(a);
    };
    std::function<void()> s1d = [&] { f3d.step_implicit(dt_dem); }, s1a = [&] { f3a.step_implicit(dt_dem); },
                          s2d = [&] { tp3d.step_implicit(100 * dt3e); }, s2a = [&] { tp3a.step_implicit(100 * dt3e); };
    const double f1d = first(s1d), f1a = first(s1a);
    const int i1d = f3d.last_cg_iterations(), i1a = f3a.last_cg_iterations();
    const auto tr = interleaved_ms(5, {dem_step, s1d, s1a, s2d, s2a});
    t_dem3 = tr[0];
    std::printf("  single-phase implicit, DIC-CG    %9.3f ms  (dt %.3e s = DEM step, %d CG iterations, warm start; "
                "first solve %.0f ms, %d it)\n", tr[1], dt_dem, f3d.last_cg_iterations(), f1d, i1d);
    const Amg& amg = f3a.pressure_system().amg();
    std::printf("  single-phase implicit, AMG-CG    %9.3f ms  (%d CG iterations, warm start; first solve with setup "
                "%.0f ms, %d it; %d levels, coarsest %d, operator complexity %.2f)\n", tr[2],
                f3a.last_cg_iterations(), f1a, i1a, amg.n_levels(), amg.level_size(amg.n_levels() - 1),
                amg.operator_complexity());
    matrix_diagnostics("single phase, dt = DEM step", f3a.pressure_system());
    matrix_diagnostics("two-phase S 0.5, 100 x explicit", *tp3a.pressure_system());
    std::printf("  two-phase implicit (PR), DIC-CG  %9.3f ms  (dt 100 x explicit %.3e s, %d CG iterations, %d sub-steps)\n",
                tr[3], dt3e, tp3d.last_cg_iterations(), tp3d.last_substeps());
    std::printf("  two-phase implicit (PR), AMG-CG  %9.3f ms  (%d CG iterations, %d sub-steps)\n", tr[4],
                tp3a.last_cg_iterations(), tp3a.last_substeps());
    if (d3)
      std::printf("  DEM step (bonded, %zu spheres)   %9.3f ms  (interleaved with the four above); flow/DEM: "
                  "single-phase DIC %.1f, AMG %.1f; two-phase DIC %.1f, AMG %.1f\n", d3->sys.particles.size(), t_dem3,
                  tr[1] / t_dem3, tr[2] / t_dem3, tr[3] / t_dem3, tr[4] / t_dem3);
    std::fflush(stdout);

    // Closed sample (no-flow hull) of Peng-Robinson water (S = 1) or water and air (S = 0.5),
    // compacted at the UCS platen rate (2 v / side per second) with a +-50 % random pore-to-pore
    // variation, one implicit step per DEM step; then sub-cycling: one step of N dt_DEM per N DEM
    // steps with the same compaction history, against N = 1.
    Network2D net3c = net3;
    const std::vector<Real> void0(net3.pore_void.begin(), net3.pore_void.end());
    std::vector<Real> w(void0.size());
    {
      std::uint64_t st = 12345;
      for (auto& wi : w) {
        st = st * 6364136223846793005ULL + 1442695040888963407ULL;
        wi = 0.5 + static_cast<Real>(st >> 11) * (1.0 / 9007199254740992.0);
      }
    }
    const Real deps = 2 * v * dt_dem / side3;  // volumetric strain per DEM step (uniaxial)
    for (const Real S : {1.0, 0.5}) {
      const int M = 20;
      std::vector<Real> pref;
      for (const int N : {1, 5, 20}) {
        for (const Preconditioner pc : {Preconditioner::AMG, Preconditioner::DIC}) {
          if (pc == Preconditioner::DIC && N != 1) continue;
          std::copy(void0.begin(), void0.end(), net3c.pore_void.begin());
          TwoPhaseParams tq;
          tq.preconditioner = pc;
          tq.cg_tolerance = 1e-8;
          tq.cg_max_iterations = pc == Preconditioner::DIC ? 2000 : 20000;
          TwoPhaseFlow g(net3c, tq);
          g.init(1e5, S);
          g.prepare_implicit();
          const Real m0 = g.total_liquid_mass();
          std::vector<double> ts;
          int its = 0;
          long subs = 0;
          std::string fail;
          const int Mk = pc == Preconditioner::DIC ? 3 : M;  // DIC: the first 3 DEM steps only (slow)
          for (int k = 1; k <= Mk && fail.empty(); ++k) {
            for (Index i = 0; i < net3c.n_pores(); ++i) net3c.pore_void[i] -= void0[i] * deps * w[i];
            if (k % N) continue;
            const auto a = std::chrono::steady_clock::now();
            try {
              g.step_implicit(N * dt_dem);
            } catch (const NumericalError& e) {
              fail = e.what();
            }
            ts.push_back(ms_since(a));
            its = std::max(its, g.last_cg_iterations());
            subs = std::max<long>(subs, g.last_substeps());
          }
          if (!fail.empty()) {
            std::printf("  closed S %.1f, %s, N %d: stopped: %s\n", S, pc == Preconditioner::AMG ? "AMG" : "DIC", N,
                        fail.c_str());
            continue;
          }
          if (N == 1 && pc == Preconditioner::AMG) matrix_diagnostics(S == 1.0 ? "closed S 1" : "closed S 0.5",
                                                                      *g.pressure_system());
          const auto [lo, hi] = std::minmax_element(g.pressure().begin(), g.pressure().end());
          Real err = 0;
          if (N == 1 && pc == Preconditioner::AMG) pref.assign(g.pressure().begin(), g.pressure().end());
          for (Index i = 0; i < net3c.n_pores() && !pref.empty() && Mk == M; ++i)
            err = std::max(err, std::abs(g.pressure()[i] - pref[i]));
          std::printf("  closed S %.1f, %s, flow every %2d DEM steps (dt %.2e s): solve %8.1f ms (median), per DEM "
                      "step %7.1f ms = %.2f DEM steps; max %d CG it, %ld sub-steps; after %d DEM steps p in [%.4e, "
                      "%.4e] Pa, max |p - p(N=1)| %.3e Pa; liquid mass error %.1e\n",
                      S, pc == Preconditioner::AMG ? "AMG" : "DIC", N, N * dt_dem, median(ts), median(ts) / N,
                      t_dem3 > 0 ? median(ts) / N / t_dem3 : 0.0, its, subs, Mk, *lo, *hi, err,
                      std::abs(g.total_liquid_mass() - m0) / m0);
          std::fflush(stdout);
        }
      }
    }
  }
  // DEM step (2D) and coupled 3D runs (item 8): the same sizes as above, bonded samples, UCS platens at
  // 0.05 m/s each (the UCS driver's default); water (PR) and air at S = 1 and 0.5, implicit flow.
  if (nodem) return 0;
  std::fflush(stdout);
  auto d2 = dem_sample(2, std::sqrt(target * kPi * 0.25e-6 / 0.8 * (1 + 0.04 / 3)), v);
  d2->sys.run(5);
  const double t_dem2 = median_ms(21, [&] { d2->sys.step(); });
  std::printf("DEM 2D: %zu discs, %zu bonds, dt %.3e s: DEM step %9.3f ms\n", d2->sys.particles.size(),
              d2->sys.bonds.size(), d2->sys.settings.dt, t_dem2);
  if (quick) t_dem3 = median_ms(11, [&] { d3->sys.step(); });
  std::printf("DEM 3D: %zu spheres, %zu bonds, dt %.3e s: DEM step %9.3f ms\n", d3->sys.particles.size(),
              d3->sys.bonds.size(), d3->sys.settings.dt, t_dem3);
  // The last two cases stride: one flow step per N DEM steps (Porenet3DParams::flow_every = 0): soft gas
  // pores, N up to 20 from the stiffness (and the flow's transport halvings); water-full, N = 20 with the
  // held steps' pressure prediction (Porenet3DParams::predict_pressures; without it the stiffness allows N = 1).
  struct CoupledCase {
    double S;
    int halvings;
    long flow_every;
  };
  for (const auto& [S, halvings, flow_every] :
       {CoupledCase{1.0, 12, 1}, CoupledCase{0.5, 0, 1}, CoupledCase{0.5, 12, 1}, CoupledCase{0.5, 12, 0},
        CoupledCase{1.0, 12, 0}}) {
  coupling::Porenet3DParams cp;
  cp.saturation = S;
  cp.fluid.max_halvings = halvings;
  cp.flow_every = flow_every;
  cp.fluid.preconditioner = Preconditioner::AMG;  // the default stays DIC (API unchanged)
  // Masses are conserved whatever the CG residual, and the volume residual enters the next step's
  // right-hand side: a looser tolerance costs pressure accuracy only (1e-8 of the source term).
  cp.fluid.cg_tolerance = 1e-8;
  coupling::DemPorenet3D cpl;
  cpl.init(d3->sys, cp);
  // The DEM step counts the stiffness the pore fluid adds to each sphere, as the saturated_ucs driver
  // does (fluid.stiffness_in_time_step): at the dry sample's step a liquid-full sample is unstable (the
  // pore pressures oscillate and grow ~10x per step until the pressure system is indefinite).
  const Real dt_dry = d3->sys.settings.dt;
  const Real dt_wet = dt_dry * dem::critical_time_step(d3->sys, cpl.fluid_stiffness(!cp.implicit)) /
                      dem::critical_time_step(d3->sys);
  d3->sys.settings.dt = std::min(dt_dry, dt_wet);
  // Strided: the water-full case over 400 DEM steps (two geometry refreshes of the prediction at
  // choose_every = 200); the S 0.5 one over 40 (its wide throats' transport limit keeps N at 1-2: on the
  // 30,000-sphere sample 400 steps took 650 s).
  const int nc = flow_every == 0 ? (S == 1.0 ? 400 : 40) : S == 1.0 ? 10 * reps(1) : 3;
  const auto tc = std::chrono::steady_clock::now();
  try {
    cpl.run(d3->sys, nc);
  } catch (const NumericalError& e) {  // reported, not hidden: the 3D saturated solve can stall (docs §8)
    std::printf("coupled 3D, S %.1f: stopped: %s\n", S, e.what());
    d3->sys.settings.dt = dt_dry;
    continue;
  }
  const double t_run = std::chrono::duration<double>(std::chrono::steady_clock::now() - tc).count();
  const auto& st = cpl.stats();
  const double per_step = t_run / nc;
  // Retriangulation after a displacement of tolerance x mean radius: at the platen speed that is
  // 0.25 x 0.5 mm / (v dt) steps (the platen moves fastest of all particles).
  const double steps_between = cp.retriangulation_tolerance * 0.5e-3 / (v * d3->sys.settings.dt);
  const double t_tri = st.t_triangulation;  // the initial build (+ any retriangulation)
  std::printf("coupled 3D (%d pores, implicit, S %.1f, max_halvings %d, flow every %ld DEM steps): %d steps in %.2f s: "
              "%.1f ms per step = DEM + update %.1f ms + flow %.1f ms + forces %.1f ms (of which held-step prediction %.2f ms); "
              "triangulation + remap %.0f ms (%ld retriangulations)\n",
              cpl.network().n_pores(), S, halvings, st.flow_every, nc, t_run, 1e3 * per_step, 1e3 * st.t_update / nc,
              1e3 * st.t_flow / nc, 1e3 * st.t_forces / nc, 1e3 * cpl.prediction_seconds() / nc, 1e3 * t_tri, st.retriangulations);
  std::printf("  last step: %d CG iterations (%s), %ld flow sub-steps; max pore pressure %.4e Pa\n",
              cpl.flow().last_cg_iterations(), cp.fluid.preconditioner == Preconditioner::AMG ? "AMG" : "DIC",
              st.last_substeps, cpl.max_pressure());
  std::printf("  flow step / DEM step = %.2f (per DEM step, over %ld flow steps; the whole fluid side, update + flow + "
              "forces and prediction: %.2f); retriangulation every %.0f steps at %.2f m/s: share of the run %.3f%%\n",
              st.t_flow / nc / (t_dem3 * 1e-3), st.flow_steps, (st.t_update + st.t_flow + st.t_forces) / nc / (t_dem3 * 1e-3),
              steps_between, v, 100 * t_tri / (t_tri + steps_between * per_step));
  if (dt_wet < dt_dry)
    std::printf("  DEM step %.3e s with the pore fluid's stiffness (%.3e s dry): %.2f dry DEM steps per unit time\n",
                dt_wet, dt_dry, dt_dry / dt_wet);
  d3->sys.settings.dt = dt_dry;
  }
  return 0;
}
