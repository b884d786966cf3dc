// `fracflow sweep`: run a scenario over the Cartesian product of --vary values, each case a
// child `fracflow run`, and gather the results (src/batch/sweep.hpp).
#include <fmt/format.h>

#include <filesystem>
#include <memory>

#include "batch/sweep.hpp"
#include "commands.hpp"
#include "core/interrupt.hpp"
#include "core/log.hpp"

namespace fs = std::filesystem;

namespace {

struct SweepArgs {
  std::string scenario, out;
  std::vector<std::string> vary, sets;
  int jobs = 0, threads_per_job = 1;
  bool overwrite = false, resume = false, quiet = false, no_plots = false;
};

int run_sweep_command(const SweepArgs& a) {
  ff::log::quiet() = a.quiet;
  ff::batch::SweepOptions opt;
  opt.scenario = a.scenario;
  opt.sets = a.sets;
  for (auto& v : a.vary) opt.axes.push_back(ff::batch::parse_vary(v));
  opt.out_dir = a.out.empty() ? fs::path("runs") / ("sweep_" + (a.scenario.empty() ? std::string("default")
                                                                                     : fs::path(a.scenario).stem().string()))
                              : fs::path(a.out);
  opt.executable = fs::read_symlink("/proc/self/exe");  // the children run this very program
  opt.jobs = a.jobs;
  opt.threads_per_job = a.threads_per_job;
  opt.overwrite = a.overwrite;
  opt.resume = a.resume;
  opt.plots = !a.no_plots;
  opt.quiet = a.quiet;
  const auto r = ff::batch::run_sweep(opt);
  if (r.fit)
    ff::log::info("Mohr-Coulomb fit over {} runs: friction angle {:.2f} deg, cohesion {:.3f} MPa, UCS of the envelope "
                  "{:.3f} MPa, R^2 {:.4f}",
                  r.fit->points, r.fit->friction_angle_deg, 1e-6 * r.fit->cohesion_Pa, 1e-6 * r.fit->intercept_Pa,
                  r.fit->r_squared);
  const std::size_t finished = r.cases.size() - r.failed - r.interrupted - r.not_started;
  ff::log::info("sweep: {} of {} cases finished{}; results in {}/sweep.csv and sweep.json", finished, r.cases.size(),
                opt.resume ? fmt::format(" ({} read as finished before, {} continued from a checkpoint)", r.read_before,
                                         r.continued)
                           : std::string(),
                fs::absolute(opt.out_dir).string());
  if (r.failed > 0) ff::log::error("{} case(s) failed; see the logs named in sweep.json", r.failed);
  if (r.interrupted + r.not_started > 0)
    ff::log::error("sweep stopped by {}: {} case(s) interrupted after a checkpoint, {} not started; continue with "
                   "the same command and --resume",
                   ff::stop_cause_or("ABORT files in the case folders"),
                   r.interrupted, r.not_started);
  return r.failed + r.interrupted + r.not_started > 0 ? 1 : 0;
}

const bool registered = ff::cli::register_command({"sweep", [](CLI::App& app) {
  auto a = std::make_shared<SweepArgs>();
  auto* sub = app.add_subcommand("sweep",
                                 "run a scenario for every combination of --vary values (each case a separate "
                                 "`fracflow run`) and collect the results; UCS/triaxial cases at several confining "
                                 "pressures also get a Mohr-Coulomb fit");
  sub->add_option("scenario", a->scenario, "scenario file (TOML); none: the built-in default");
  sub->add_option("--vary", a->vary, "key=v1,v2,... (repeatable; cases are every combination)")->required();
  sub->add_option("--set,-s", a->sets, "override a parameter in every case: --set key=value (repeatable)");
  sub->add_option("--out,-o", a->out, "sweep folder (default: runs/sweep_<scenario name>)");
  sub->add_option("--jobs,-J", a->jobs, "cases run at the same time (default: cores / threads per job)")
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--threads-per-job", a->threads_per_job, "OpenMP threads of each case (default 1)")
      ->check(CLI::PositiveNumber);
  sub->add_flag("--overwrite", a->overwrite, "replace an existing sweep folder");
  sub->add_flag("--resume", a->resume,
                "continue a stopped sweep in --out (same scenario, --set and --vary): finished cases are read, "
                "interrupted ones continue from their checkpoints, the rest run");
  sub->add_flag("--no-plots", a->no_plots, "do not draw plots/peak_vs_confinement.png");
  sub->add_flag("--quiet,-q", a->quiet, "no line per finished case");
  return ff::cli::Command::Run([a] { return run_sweep_command(*a); });
}});

}  // namespace
