// Issue 14 through the flow drivers: named probes (values, every driver, resume bit for bit,
// refused positions), the units chosen by lbm.mach / lbm.target_error (at most one of the four
// keys), and the steady-state stop (a steady case stops by itself close to its long-run value;
// a vortex street does not stop).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include "core/error.hpp"
#include "flow_driver_runner.hpp"
#include "drivers/flow/flow_runner.hpp"
#include "lbm/units.hpp"
#include "resume_compare.hpp"

using namespace ff::testing;

namespace {

const char* kPoiseuille = R"(
driver = "flow/poiseuille"
[channel]
height = 1.0e-3
length = 1.0e-3
[lbm]
resolution = 10
[run]
end_time = 2.0
steady_tolerance = 0
[output]
samples = 40
snapshots = 0
plots = false
)";

const char* kCavity = R"(
driver = "flow/cavity"
[cavity]
size = 0.1
lid_velocity = 1.0e-3
[fluid]
viscosity = 1.0e-6
[lbm]
resolution = 12
tau = 0.55
[run]
end_time = 1000
[output]
samples = 20
snapshots = 0
plots = false
)";

// D = 6 cells, Re = 10 (uniform inflow U = 0.01 m/s, nu = 1e-5 m^2/s): steady.
const char* kCylinder = R"(
driver = "flow/cylinder"
[channel]
height = 0.04
length = 0.12
[cylinder]
diameter = 0.01
x = 0.03
y = 0.021
[inlet]
velocity = 0.01
[fluid]
viscosity = 1.0e-5
[lbm]
resolution = 6
time_step = 0.01
[run]
end_time = 400
steady_tolerance = 0
[output]
samples = 400
snapshots = 0
plots = false
)";

// The DFG 2D-2 set-up (Schaefer & Turek 1996: channel 2.2 x 0.41 m, D = 0.1 m, parabolic
// inflow, mean speed 1 m/s, nu = 1e-3 m^2/s: Re = 100) on a coarse lattice: it sheds vortices.
const char* kShedding = R"(
driver = "flow/cylinder"
[channel]
height = 0.41
length = 2.2
[cylinder]
diameter = 0.1
x = 0.2
y = 0.2
[inlet]
profile = "parabolic"
velocity = 1.5
[fluid]
density = 1.0
viscosity = 1.0e-3
[lbm]
resolution = 10
mach = 0.1
[run]
end_time = 8
steady_tolerance = 1.0e-4
[output]
samples = 800
snapshots = 0
plots = false
)";

std::string line(const std::filesystem::path& p, int k) {  // k-th line (0: header)
  std::ifstream f(p);
  std::string s;
  for (int i = 0; i <= k && std::getline(f, s); ++i) {
  }
  return s;
}

}  // namespace

TEST(FlowProbes, PoiseuilleProbesFollowTheParabolaUpToTheWall) {
  // Body-force channel, H = 1 mm on 10 cells: a probe at y = H/4 lies on a cell centre
  // (bilinear), one at y = 0 on the plate (least squares, extrapolated half a cell), one at
  // y = 0.37 H between nodes. Halfway bounce-back with TRT (Lambda = 3/16) makes the discrete
  // profile the exact parabola (Ginzburg et al. 2008), so the probes match u(y) = 4 u_max y (H - y) / H^2
  // at the steady state up to its residual (0.1% after 2 s).
  const auto j = run_flow_driver("probes_poiseuille", kPoiseuille,
                                 {"probes.names=[\"quarter\",\"wall\",\"off\"]", "probes.x=[0.5e-3,0.5e-3,0.31e-3]",
                                  "probes.y=[0.25e-3,0.0,0.37e-3]"});
  const auto& p = j["results"]["probes"];
  const double umax = 0.25 * 1.0 / (2 * 1e-6 * 1000) * 1e-6;  // G H^2 / (8 mu): 1 Pa/m, water
  auto u = [&](double y) { return 4 * umax * y * (1e-3 - y) / 1e-6; };
  EXPECT_EQ(p["quarter"]["interpolation"], "bilinear");
  EXPECT_NE(p["wall"]["interpolation"].get<std::string>().find("quadratic least squares"), std::string::npos);
  EXPECT_NEAR(p["quarter"]["ux_m_per_s"].get<double>(), u(0.25e-3), 2e-3 * umax);
  EXPECT_NEAR(p["off"]["ux_m_per_s"].get<double>(), u(0.37e-3), 1e-2 * umax);
  EXPECT_NEAR(p["wall"]["ux_m_per_s"].get<double>(), 0.0, 2e-3 * umax);
  EXPECT_NEAR(p["quarter"]["uy_m_per_s"].get<double>(), 0.0, 1e-9);
  EXPECT_EQ(line(flow_test_dir("probes_poiseuille") / "series.csv", 0).find("p_quarter_Pa,ux_quarter_m_per_s,"
                                                                            "uy_quarter_m_per_s,p_wall_Pa"),
            line(flow_test_dir("probes_poiseuille") / "series.csv", 0).find("p_quarter_Pa"));
}

namespace {

void expect_probes_resume(const std::string& name, const std::string& text, const std::vector<std::string>& sets) {
  const auto whole = flow_test_dir(name + "_whole"), cut = flow_test_dir(name + "_cut");
  ASSERT_EQ(run_flow_driver_status(name + "_whole", text, sets), ff::RunStatus::Finished);
  const long n = read_summary(name + "_whole")["steps"];
  ASSERT_EQ(run_flow_driver_status(name + "_cut", text, sets, false, 0, n / 2 + 3), ff::RunStatus::Interrupted);
  ASSERT_EQ(run_flow_driver_status(name + "_cut", text, sets, true), ff::RunStatus::Finished);
  ff::test::expect_same_results(whole, cut, name + " with probes, interrupted at half time");
  EXPECT_TRUE(read_summary(name + "_whole")["results"].contains("probes")) << name;
}

}  // namespace

TEST(FlowProbes, EveryDriverWithProbesResumesBitForBit) {
  expect_probes_resume("probes_resume_poiseuille", kPoiseuille,
                       {"probes.names=[\"a\",\"b\"]", "probes.x=[0.2e-3,0.9e-3]", "probes.y=[0.1e-3,0.5e-3]",
                        "probes.delta_p=[\"a\",\"b\"]"});
  expect_probes_resume("probes_resume_cavity", kCavity,
                       {"probes.names=[\"centre\",\"corner\"]", "probes.x=[0.05,0.0]", "probes.y=[0.05,0.1]"});
  // The DFG probe points: front and back of the cylinder surface.
  expect_probes_resume("probes_resume_cylinder", kCylinder,
                       {"run.end_time=100", "probes.names=[\"fore\",\"aft\"]", "probes.x=[0.025,0.035]",
                        "probes.y=[0.021,0.021]", "probes.delta_p=[\"fore\",\"aft\"]"});
  const auto j = read_summary("probes_resume_cylinder_whole");
  EXPECT_GT(j["results"]["delta_p_Pa"].get<double>(), 0) << "stagnation pressure ahead, wake behind";
  EXPECT_DOUBLE_EQ(j["results"]["delta_p_Pa"].get<double>(), j["results"]["probes"]["fore"]["p_Pa"].get<double>() -
                                                                 j["results"]["probes"]["aft"]["p_Pa"].get<double>());
  // flow/cylinder's own Delta p uses the same surface stencils.
  EXPECT_NEAR(j["results"]["dp_final_Pa"].get<double>(), j["results"]["delta_p_Pa"].get<double>(),
              1e-9 * std::abs(j["results"]["delta_p_Pa"].get<double>()));
  // D3Q19: uz columns, z defaults to mid-depth.
  expect_probes_resume("probes_resume_d3q19", kPoiseuille,
                       {"lbm.lattice=\"D3Q19\"", "lbm.depth_cells=2", "probes.names=[\"a\"]", "probes.x=[0.5e-3]",
                        "probes.y=[0.5e-3]"});
  EXPECT_TRUE(read_summary("probes_resume_d3q19_whole")["results"]["probes"]["a"].contains("uz_m_per_s"));
}

TEST(FlowProbes, ProbesOutsideOrInsideASolidAreRefusedBeforeTheRun) {
  const ff::Driver& d = ff::find_driver("flow/cylinder");
  const ff::ParamTable table = ff::parameter_table(d);
  auto refused = [&](const std::vector<std::string>& sets, const std::string& key, const std::string& what) {
    const ff::Config cfg = ff::load_scenario(table, "probes.toml", kCylinder, sets);
    try {
      d.validate(cfg);  // what `fracflow check` calls; run_flow() calls it too
      ADD_FAILURE() << "accepted: " << what;
    } catch (const ff::InputError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find(key), std::string::npos) << m;
      EXPECT_NE(m.find(what), std::string::npos) << m;
    }
  };
  refused({"probes.names=[\"in\",\"out\"]", "probes.x=[0.05,0.13]", "probes.y=[0.02,0.02]"}, "probes.x",
          "probe 1 ('out')");
  refused({"probes.names=[\"centre\"]", "probes.x=[0.03]", "probes.y=[0.021]"}, "probes.names", "inside a solid");
  refused({"probes.names=[\"a\"]", "probes.x=[0.05,0.06]", "probes.y=[0.02]"}, "probes.x", "2 values for 1");
  refused({"probes.names=[\"a b\"]", "probes.x=[0.05]", "probes.y=[0.02]"}, "probes.names", "letters, digits");
  refused({"probes.names=[\"a\"]", "probes.x=[0.05]", "probes.y=[0.02]", "probes.delta_p=[\"a\",\"z\"]"},
          "probes.delta_p", "'z'");
  refused({"probes.names=[\"a\"]", "probes.x=[0.05]", "probes.y=[0.02]", "probes.z=[0.0]"}, "probes.z", "D3Q19");
  // dp_front_back_Pa is flow/cylinder's own column.
  refused({"probes.names=[\"front\",\"back\"]", "probes.x=[0.025,0.035]", "probes.y=[0.021,0.021]",
           "probes.delta_p=[\"front\",\"back\"]"},
          "probes.names", "'dp_front_back_Pa' repeats a column");
}

// The expected-error model (lbm/units.hpp, docs/lbm.md): C by equilibrium and regime, as
// measured on the DFG cylinder; lbm.target_error inverts it; flow/cylinder expects a vortex
// street above Re 47; check warns when the channel is not a whole number of cells.
TEST(FlowUnits, ErrorModelFollowsTheEquilibriumAndTheRegime) {
  using ff::lbm::compressibility_coefficient;
  EXPECT_EQ(compressibility_coefficient(false, false), 1.0);
  EXPECT_EQ(compressibility_coefficient(true, false), 0.1);
  EXPECT_EQ(compressibility_coefficient(true, true), 2.2);
  EXPECT_EQ(compressibility_coefficient(false, true), 2.2);
  EXPECT_NEAR(ff::lbm::mach_for_error(ff::lbm::expected_compressibility_error(0.07, 2.2), 2.2), 0.07, 1e-15);
  const ff::Driver& d = ff::find_driver("flow/cylinder");
  const ff::ParamTable table = ff::parameter_table(d);
  auto report = [&](const std::string& scenario, const std::vector<std::string>& sets) {
    ff::drivers::FlowCheckReport r;
    d.validate(ff::load_scenario(table, "c.toml", scenario, sets));
    return r.text();
  };
  // kCylinder: Re = 0.01 * 0.01 / 1e-5 = 10, steady, incompressible equilibrium.
  const std::string steady = report(kCylinder, {});
  EXPECT_NE(steady.find("0.1 Ma^2: incompressible equilibrium, steady flow"), std::string::npos) << steady;
  EXPECT_NE(report(kCylinder, {"lbm.equilibrium=\"compressible\""}).find("1 Ma^2: compressible equilibrium"),
            std::string::npos);
  const std::string street = report(kShedding, {});
  EXPECT_NE(street.find("2.2 Ma^2: vortex shedding expected"), std::string::npos) << street;
  EXPECT_EQ(steady.find("whole number of cells"), std::string::npos) << steady;
  // 0.04 m on cells of 0.01/7 m is 28 cells; 0.041 m is 28.7.
  const std::string rounded = report(kCylinder, {"channel.height=0.041", "lbm.resolution=7"});
  EXPECT_NE(rounded.find("channel.height = 0.041 m is 28.7 cells"), std::string::npos) << rounded;
}

TEST(FlowUnits, MachAndTargetErrorChooseTheTimeStep) {
  // Cavity L = 0.1 m on 12 cells, lid U = 1e-3 m/s: dt = Ma c_s dx / U.
  std::string cavity = kCavity;
  cavity.replace(cavity.find("tau = 0.55\n"), 11, "");
  const double dx = 0.1 / 12, cs = 1 / std::sqrt(3.0);
  const auto m = run_flow_driver("units_mach", cavity, {"lbm.mach=0.05", "run.end_time=20"});
  EXPECT_EQ(m["units"]["chosen_by"], "lbm.mach");
  EXPECT_NEAR(m["units"]["mach"].get<double>(), 0.05, 1e-12);
  EXPECT_NEAR(m["units"]["dt_s"].get<double>(), 0.05 * cs * dx / 1e-3, 1e-12);
  // The cavity settles, and the flow drivers use the incompressible equilibrium: C = 0.1.
  const double C = ff::lbm::compressibility_coefficient(true, false);
  EXPECT_EQ(C, 0.1);
  EXPECT_EQ(m["units"]["compressibility_coefficient"].get<double>(), C);
  EXPECT_NEAR(m["units"]["expected_compressibility_error"].get<double>(), C * 0.05 * 0.05, 1e-15);
  const auto e = run_flow_driver("units_error", cavity,
                                 {"lbm.target_error=" + std::to_string(C * 0.0025),
                                  "run.end_time=20"});
  EXPECT_EQ(e["units"]["chosen_by"], "lbm.target_error");
  EXPECT_NEAR(e["units"]["mach"].get<double>(), 0.05, 1e-9);
  EXPECT_NEAR(e["units"]["tau"].get<double>(), m["units"]["tau"].get<double>(), 1e-9);
  // Nothing set: lbm.tau's default.
  const ff::Driver& d = ff::find_driver("flow/cavity");
  const ff::ParamTable table = ff::parameter_table(d);
  const auto fu = ff::drivers::make_units(ff::load_scenario(table, "c.toml", cavity, {}), dx, 1e-3, false);
  EXPECT_TRUE(fu.by_default);
  EXPECT_EQ(fu.mode, ff::lbm::UnitsMode::Tau);
  EXPECT_EQ(fu.units.tau(), 0.7);
}

TEST(FlowUnits, AtMostOneOfTheFourKeysAndTheSavedScenarioResumes) {
  const ff::Driver& d = ff::find_driver("flow/cylinder");
  const ff::ParamTable table = ff::parameter_table(d);
  const std::vector<std::pair<std::vector<std::string>, std::array<const char*, 2>>> pairs = {
      {{"lbm.tau=0.6"}, {"lbm.tau", "lbm.time_step"}},
      {{"lbm.mach=0.05"}, {"lbm.time_step", "lbm.mach"}},
      {{"lbm.time_step=0", "lbm.mach=0.05", "lbm.target_error=0.001"}, {"lbm.mach", "lbm.target_error"}},
      {{"lbm.time_step=0", "lbm.tau=0.6", "lbm.target_error=0.001"}, {"lbm.tau", "lbm.target_error"}}};
  for (auto& [sets, keys] : pairs) {
    const ff::Config cfg = ff::load_scenario(table, "units.toml", kCylinder, sets);
    try {
      d.validate(cfg);
      ADD_FAILURE() << keys[0] << " and " << keys[1] << " accepted together";
    } catch (const ff::InputError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find(std::string(keys[0]) + " and " + keys[1] + " are both set"), std::string::npos) << m;
    }
  }
  // Bug of issue 14: the scenario a run saves (every key resolved, defaults included) held
  // lbm.tau's default next to lbm.time_step, and `fracflow resume` refused it. The saved text
  // keeps the default as a comment, so read back it is the same run.
  const ff::Config cfg = ff::load_scenario(table, "units.toml", kCylinder, {});
  const std::string saved = cfg.resolved_toml();
  EXPECT_NE(saved.find("# (default, not set) lbm.tau = 0.53"), std::string::npos) << saved;
  const ff::Config back = ff::load_scenario(table, "scenario.toml", saved, {});
  EXPECT_FALSE(back.has("lbm.tau"));
  EXPECT_NO_THROW(d.validate(back));
  EXPECT_EQ(back.resolved_toml().substr(back.resolved_toml().find('\n')), saved.substr(saved.find('\n')));
  EXPECT_EQ(back.real("lbm.tau"), 0.53);  // the value is still there for whoever reads it
}

TEST(FlowSteady, ASteadyFlowStopsByItselfCloseToItsLongRunValue) {
  const double tol = 1e-4;
  const auto full = run_flow_driver("steady_full", kCylinder, {});
  const auto stop = run_flow_driver("steady_stop", kCylinder, {"run.steady_tolerance=" + std::to_string(tol)});
  EXPECT_NE(stop["stop_reason"].get<std::string>().find("steady state"), std::string::npos) << stop["stop_reason"];
  const double t_stop = stop["simulated_time_s"];
  EXPECT_LT(t_stop, 0.5 * 400) << "well before run.end_time";  // measured: 108 s of 400
  const double cd_long = full["results"]["cd_final"], cd = stop["results"]["cd_final"];
  EXPECT_LT(std::abs(cd - cd_long) / cd_long, tol) << cd << " vs " << cd_long;  // measured: 2.4e-6
  EXPECT_LT(stop["steady_state"]["final_drift"].get<double>(), tol);
  std::printf("steady stop at t = %.4g s of 400: Cd %.7g, long-run %.7g (rel. %.2g)\n", t_stop, cd, cd_long,
              std::abs(cd - cd_long) / cd_long);
}

TEST(FlowSteady, AVortexStreetDoesNotStop) {
  const auto j = run_flow_driver("steady_shedding", kShedding, {});
  EXPECT_TRUE(j["results"]["shedding"].get<bool>());
  EXPECT_EQ(j["stop_reason"], "reached run.end_time = 8 s");
  EXPECT_GT(j["steady_state"]["final_drift"].get<double>(), 1e-4);  // measured: 2.6e-2
}
