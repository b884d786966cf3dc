#include "batch/sweep.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <fstream>
#include <mutex>
#include <set>
#include <thread>

#include "batch/jobs.hpp"
#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "core/log.hpp"
#include "io/csv.hpp"
#include "io/json_out.hpp"
#include "io/plot.hpp"
#include "io/run_folder.hpp"

namespace fs = std::filesystem;

namespace ff::batch {

SweepAxis parse_vary(const std::string& option) {
  const auto eq = option.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError(fmt::format("--vary '{}': expected key=v1,v2,..., e.g. --vary triaxial.confining_pressure=2.5e6,5e6",
                                 option));
  SweepAxis axis;
  axis.key = option.substr(0, eq);
  while (!axis.key.empty() && axis.key.back() == ' ') axis.key.pop_back();
  if (axis.key.empty()) throw InputError(fmt::format("--vary '{}': the key is empty", option));
  const std::string list = option.substr(eq + 1);
  std::string current;
  int depth = 0;
  auto push = [&] {
    const auto b = current.find_first_not_of(' '), e = current.find_last_not_of(' ');
    if (b == std::string::npos)
      throw InputError(fmt::format("--vary '{}': empty value in the list (allowed: comma-separated values, "
                                   "e.g. {}=1,2,3)", option, axis.key));
    axis.values.push_back(current.substr(b, e - b + 1));
    current.clear();
  };
  for (char ch : list) {
    if (ch == '[') ++depth;
    if (ch == ']') --depth;
    if (ch == ',' && depth == 0) {
      push();
      continue;
    }
    current += ch;
  }
  push();
  // A value given twice (as written, or the same number: 0.4 and 4e-1) ran the same case twice
  // under two names, without a word.
  for (std::size_t i = 0; i < axis.values.size(); ++i)
    for (std::size_t j = 0; j < i; ++j) {
      const std::string& vi = axis.values[i];
      const std::string& vj = axis.values[j];
      if (vi == vj || to_number(vi) == to_number(vj))  // NaN (not a number) equals nothing
        throw InputError(fmt::format("--vary '{}': values {} and {} ('{}', '{}') are the same: each case would run "
                                     "twice; give each value once",
                                     option, j + 1, i + 1, vj, vi));
    }
  return axis;
}

std::vector<std::vector<std::pair<std::string, std::string>>> cartesian_product(std::span<const SweepAxis> axes) {
  std::set<std::string> seen;
  for (auto& a : axes) {
    if (!seen.insert(a.key).second)
      throw InputError(fmt::format("--vary {}: the key is varied twice; give all its values in one --vary", a.key));
    if (a.values.empty()) throw InputError(fmt::format("--vary {}: no values", a.key));
  }
  std::vector<std::vector<std::pair<std::string, std::string>>> cases{{}};
  for (auto& a : axes) {  // each axis multiplies the cases so far: the first axis varies slowest
    std::vector<std::vector<std::pair<std::string, std::string>>> next;
    next.reserve(cases.size() * a.values.size());
    for (auto& c : cases)
      for (auto& v : a.values) {
        next.push_back(c);
        next.back().emplace_back(a.key, v);
      }
    cases = std::move(next);
  }
  return cases;
}

std::string case_name(std::size_t index, std::size_t count) {
  const int digits = std::max<int>(3, static_cast<int>(fmt::format("{}", count > 0 ? count - 1 : 0).size()));
  return fmt::format("case_{:0{}}", index, digits);
}

namespace {

std::string key_of(const std::string& override_text) { return override_text.substr(0, override_text.find('=')); }

// A cell of sweep.csv: the CSV readers of this project split on every comma, so commas inside
// list values become spaces.
std::string csv_cell(std::string s) {
  std::replace(s.begin(), s.end(), ',', ' ');
  return s;
}

std::string num(double v) { return std::isfinite(v) ? fmt::format("{}", v) : "nan"; }

const std::vector<std::string> kNumberColumns = {
    "sigma3_Pa",      "sigma_p_Pa",       "ucs_Pa",         "peak_differential_stress_Pa", "confining_pressure_Pa",
    "youngs_modulus_Pa", "poisson_ratio", "strain_at_peak", "cracks_tensile",              "cracks_shear",
    "cracks_total",   "wall_time_s"};

std::vector<double> numbers_of(const SweepCase& c) {
  const double nan = std::nan("");
  if (!c.summary) return std::vector<double>(kNumberColumns.size(), nan);
  const RunSummary& s = *c.summary;
  const auto p = peak_strength(s);
  return {p ? p->sigma3 : nan,        p ? p->sigma_p : nan, s.ucs_Pa,           s.peak_differential_stress_Pa,
          s.confining_pressure_Pa,    s.youngs_modulus_Pa,  s.poisson_ratio,    s.strain_at_peak,
          s.cracks_tensile,           s.cracks_shear,       s.cracks_total,     s.wall_time_s};
}

nlohmann::json fit_json(const MohrCoulombFit& f) {
  return {{"criterion", "sigma_p = a + b sigma3, b = (1 + sin phi)/(1 - sin phi), a = 2 c cos phi/(1 - sin phi)"},
          {"source", "Jaeger, Cook & Zimmerman, Fundamentals of Rock Mechanics, 4th ed., Sec. 4.5; "
                     "Labuz & Zang 2012, Rock Mech. Rock Eng. 45:975"},
          {"intercept_Pa", f.intercept_Pa},
          {"slope", f.slope},
          {"friction_angle_deg", f.friction_angle_deg},
          {"cohesion_Pa", f.cohesion_Pa},
          {"r_squared", f.r_squared},
          {"points", f.points}};
}

// What makes the cases of a sweep: --resume must be given the same.
nlohmann::json options_json(const SweepOptions& opt) {
  nlohmann::json j;
  j["scenario"] = opt.scenario.empty() ? "<built-in default scenario>" : opt.scenario;
  j["sets"] = opt.sets;
  j["vary"] = nlohmann::json::array();
  for (auto& a : opt.axes) j["vary"].push_back({{"key", a.key}, {"values", a.values}});
  return j;
}

// --resume: `out` must hold a sweep of ours made with the same scenario, --set and --vary.
void check_resumable(const fs::path& out, const SweepOptions& opt) {
  const fs::path file = out / "sweep.json";
  if (!is_fracflow_run(out) || !fs::exists(file))
    throw InputError(fmt::format("sweep --resume: '{}' holds no sweep to continue (no {} or no sweep.json); start it "
                                 "without --resume", out.string(), run_marker_file(out).string()));
  nlohmann::json before;
  try {
    std::ifstream f(file);
    before = nlohmann::json::parse(f);
  } catch (const std::exception& e) {
    throw InputError(fmt::format("sweep --resume: '{}' is not valid JSON ({})", file.string(), e.what()));
  }
  const nlohmann::json now = options_json(opt);
  for (const char* k : {"scenario", "sets", "vary"})
    if (!before.contains(k) || before[k] != now[k])
      throw InputError(fmt::format("sweep --resume: the sweep in '{}' was started with other options ({}: {} then, {} "
                                   "now); give the same scenario, --set and --vary, or a new --out",
                                   out.string(), k, before.contains(k) ? before[k].dump() : "absent", now[k].dump()));
}

void write_outputs(const SweepOptions& opt, const SweepResult& r) {
  {
    std::ofstream f(opt.out_dir / "sweep.csv");
    f << "case";
    for (auto& a : opt.axes) f << ',' << csv_cell(a.key);
    f << ",status,exit_code";
    for (auto& c : kNumberColumns) f << ',' << c;
    f << '\n';
    for (auto& c : r.cases) {
      f << c.name;
      for (auto& kv : c.values) f << ',' << csv_cell(kv.second);
      f << ',' << c.status << ',' << c.exit_code;
      for (double v : numbers_of(c)) f << ',' << num(v);
      f << '\n';
    }
    if (!f) throw Error(fmt::format("cannot write '{}'", (opt.out_dir / "sweep.csv").string()));
  }
  nlohmann::json j = options_json(opt);
  j["jobs"] = opt.jobs;
  j["threads_per_job"] = opt.threads_per_job;
  j["failed"] = r.failed;
  j["interrupted"] = r.interrupted;
  j["not_started"] = r.not_started;
  j["cases"] = nlohmann::json::array();
  for (auto& c : r.cases) {
    nlohmann::json cj;
    cj["case"] = c.name;
    cj["dir"] = c.dir.string();
    cj["log"] = c.log.string();
    cj["values"] = nlohmann::json::object();
    for (auto& kv : c.values) cj["values"][kv.first] = kv.second;
    cj["overrides"] = c.overrides;
    cj["status"] = c.status;
    cj["exit_code"] = c.exit_code;
    if (!c.error.empty()) cj["error"] = c.error;
    const auto nums = numbers_of(c);
    for (std::size_t i = 0; i < kNumberColumns.size(); ++i) cj[kNumberColumns[i]] = nums[i];  // NaN -> null
    if (c.summary) cj["driver"] = c.summary->driver;
    if (c.summary && !c.summary->missing.empty()) cj["missing"] = c.summary->missing;  // why numbers are null
    j["cases"].push_back(cj);
  }
  if (r.fit)
    j["mohr_coulomb"] = fit_json(*r.fit);
  else
    j["mohr_coulomb"] = nullptr;
  if (!r.fit_note.empty()) j["mohr_coulomb_note"] = r.fit_note;
  write_json_atomic(opt.out_dir / "sweep.json", j);
}

}  // namespace

// plots/peak_vs_confinement.png: the runs' peak strengths as markers and the fitted envelope as
// a line, drawn by scripts/plot_series.py from a small CSV beside the PNG.
bool plot_peak_vs_confinement(const fs::path& out_dir, std::span<const StrengthPoint> points, const MohrCoulombFit& fit) {
  std::vector<StrengthPoint> pts(points.begin(), points.end());
  std::sort(pts.begin(), pts.end(), [](auto& a, auto& b) { return a.sigma3 < b.sigma3; });
  const fs::path csv = out_dir / "plots" / "peak_vs_confinement.csv";
  fs::create_directories(csv.parent_path());
  {
    std::ofstream f(csv);
    f << "sigma3_Pa,peak_sigma_p_Pa,Mohr-Coulomb fit\n";
    for (auto& p : pts)
      f << num(p.sigma3) << ',' << num(p.sigma_p) << ',' << num(fit.intercept_Pa + fit.slope * p.sigma3) << '\n';
  }
  PlotSpec s;
  s.title = fmt::format("Mohr-Coulomb fit: phi = {:.1f} deg, c = {:.2f} MPa, R^2 = {:.3f}", fit.friction_angle_deg,
                        1e-6 * fit.cohesion_Pa, fit.r_squared);
  s.xlabel = "confining pressure sigma3 [MPa]";
  s.ylabel = "peak sigma_p = sigma3 + peak diff. stress [MPa]";
  s.x = "sigma3_Pa";
  s.y = {"Mohr-Coulomb fit"};
  s.x_scale = s.y_scale = 1e-6;
  s.reference_csv = csv;
  s.ref_x = "sigma3_Pa";
  s.ref_y = "peak_sigma_p_Pa";
  s.ref_label = "runs (peak)";
  return plot_series(csv, out_dir / "plots" / "peak_vs_confinement.png", s);
}

SweepResult run_sweep(const SweepOptions& opt) {
  if (opt.axes.empty())
    throw InputError("sweep: nothing to vary; give at least one --vary key=v1,v2,... (e.g. --vary ucs.platen_velocity=0.1,0.2)");
  if (opt.threads_per_job < 1)
    throw InputError(fmt::format("--threads-per-job {}: must be at least 1", opt.threads_per_job));
  if (opt.jobs < 0) throw InputError(fmt::format("--jobs {}: must be at least 1 (0: as many as the cores allow)", opt.jobs));
  for (auto& a : opt.axes)
    for (auto& s : opt.sets)
      if (key_of(s) == a.key)
        throw InputError(fmt::format("--set {} and --vary {} name the same key; keep one of them", s, a.key));
  const auto combos = cartesian_product(opt.axes);

  SweepResult r;
  r.cases.resize(combos.size());
  for (std::size_t i = 0; i < combos.size(); ++i) {
    SweepCase& c = r.cases[i];
    c.name = case_name(i, combos.size());
    c.values = combos[i];
    c.overrides = opt.sets;
    for (auto& kv : c.values) c.overrides.push_back(kv.first + "=" + kv.second);
    try {  // every case validated before any folder is written
      load_scenario_for_run(opt.scenario, c.overrides);
    } catch (const InputError& e) {
      std::string vals;
      for (auto& kv : c.values) vals += fmt::format(" {}={}", kv.first, kv.second);
      throw InputError(fmt::format("sweep {} ({}): {}", c.name, vals.substr(1), e.what()));
    }
  }
  if (!fs::exists(opt.executable))
    throw InputError(fmt::format("sweep: the fracflow program '{}' does not exist", opt.executable.string()));
  if (opt.resume && opt.overwrite)
    throw InputError("sweep: --resume continues the sweep in --out, --overwrite replaces it: not both");
  const fs::path out = fs::absolute(opt.out_dir);
  SweepOptions resolved = opt;
  resolved.out_dir = out;
  if (resolved.jobs == 0)
    resolved.jobs = std::max(1, static_cast<int>(std::thread::hardware_concurrency()) / opt.threads_per_job);
  resolved.jobs = std::min<int>(resolved.jobs, static_cast<int>(r.cases.size()));
  // Replaces only a folder of ours; held locked while the sweep writes it.
  FolderLock out_lock;
  if (opt.resume) {
    check_resumable(out, resolved);
    out_lock = FolderLock::acquire(out);
  } else {
    out_lock = prepare_batch_folder(opt.out_dir, opt.overwrite, "sweep folder");
  }
  fs::create_directories(out / "logs");
  for (auto& c : r.cases) {
    c.dir = out / c.name;
    c.log = out / "logs" / (c.name + ".log");
    c.status = "not started";
  }
  if (!opt.resume) write_outputs(resolved, r);  // the options on record before the first case (--resume checks them)
  if (!opt.quiet)
    log::info("sweep: {} cases, {} at a time with {} thread(s) each, in {}", r.cases.size(), resolved.jobs,
              opt.threads_per_job, out.string());

  // From here on SIGINT/SIGTERM stop the sweep with checkpoints (run_child_process passes the
  // request on); before, nothing but the options is written.
  install_stop_signal_handlers();
  // Workers take the next case; each case is one child process that the worker waits for.
  std::atomic<int> done{0}, read_before{0}, continued{0};
  std::mutex print;
  run_jobs(r.cases.size(), resolved.jobs, [&](std::size_t i) {
    SweepCase& c = r.cases[i];
    if (stop_requested()) return;  // "not started"
    std::vector<std::string> args;
    bool read = false;
    if (opt.resume && fs::exists(c.dir / "summary.json")) {
      read = true;  // finished before: read as it is
      c.exit_code = 0;
      ++read_before;
    } else if (opt.resume && fs::exists(c.dir / "checkpoint")) {
      args = {"resume", c.dir.string(), "--threads", std::to_string(opt.threads_per_job)};
      ++continued;
    } else {
      args = {"run"};
      if (!opt.scenario.empty()) args.push_back(opt.scenario);
      args.insert(args.end(), {"--out", c.dir.string(), "--threads", std::to_string(opt.threads_per_job)});
      // --resume: a case stopped before its first checkpoint starts again (a folder of ours only).
      if (opt.resume && fs::exists(c.dir)) args.push_back("--overwrite");
      for (auto& o : c.overrides) args.insert(args.end(), {"--set", o});
    }
    if (!read) c.exit_code = run_child_process(opt.executable, args, c.log, c.dir);
    if (c.exit_code == 0 && fs::exists(c.dir / "summary.json")) {
      try {
        c.summary = read_run_summary(c.dir);
        c.status = "ok";
      } catch (const Error& e) {
        c.status = "no summary";
        c.error = e.what();
      }
    } else if (c.exit_code == 0 && fs::exists(c.dir / "checkpoint")) {
      c.status = "interrupted";  // stopped with a checkpoint (our stop request, or an ABORT file)
    } else if (stop_requested() && !fs::exists(c.dir)) {
      c.status = "not started";  // ended by the passed-on SIGTERM before its folder existed
    } else {
      c.status = c.exit_code == 0 ? "no summary" : "failed";
      c.error = tail_of_file(c.log, 5);
      if (c.exit_code == -1 && c.error.empty()) c.error = "could not start " + opt.executable.string();
    }
    std::lock_guard lock(print);
    const int n = ++done;
    if (opt.quiet) return;
    std::string vals;
    for (auto& kv : c.values) vals += fmt::format(" {}={}", kv.first, kv.second);
    if (c.status == "ok") {
      const auto p = peak_strength(*c.summary);
      log::info("[{}/{}] {}{}: {}peak {:.3f} MPa, E {:.3f} GPa, nu {:.3f}", n, r.cases.size(), c.name, vals,
                read ? "(finished before) " : "", p ? 1e-6 * p->sigma_p : std::nan(""),
                1e-9 * c.summary->youngs_modulus_Pa, c.summary->poisson_ratio);
    } else if (c.stopped()) {
      log::warn("[{}/{}] {}{}: {}", n, r.cases.size(), c.name, vals, c.status);
    } else {
      log::warn("[{}/{}] {}{}: {} (exit code {}); log {}:\n{}", n, r.cases.size(), c.name, vals, c.status, c.exit_code,
                c.log.string(), c.error);
    }
  });
  r.read_before = read_before;
  r.continued = continued;

  std::set<double> pressures;
  for (auto& c : r.cases) {
    if (c.stopped()) {
      ++(c.status == "interrupted" ? r.interrupted : r.not_started);
      continue;
    }
    if (c.status != "ok") {
      ++r.failed;
      continue;
    }
    if (auto p = peak_strength(*c.summary)) {
      r.strength_points.push_back(*p);
      pressures.insert(p->sigma3);
    }
  }
  if (r.interrupted + r.not_started > 0) {
    r.fit_note = fmt::format("no Mohr-Coulomb fit: the sweep was stopped ({} case(s) interrupted, {} not started); "
                             "continue it with --resume", r.interrupted, r.not_started);
  } else if (pressures.size() >= 2) {
    try {
      r.fit = fit_mohr_coulomb(r.strength_points);
    } catch (const InputError& e) {
      r.fit_note = e.what();
    }
  } else {
    r.fit_note = fmt::format("no Mohr-Coulomb fit: {} successful UCS/triaxial case(s) at {} confining pressure(s); "
                             "a fit needs two or more", r.strength_points.size(), pressures.size());
  }
  write_outputs(resolved, r);
  if (r.fit && opt.plots) plot_peak_vs_confinement(out, r.strength_points, *r.fit);
  return r;
}

}  // namespace ff::batch
