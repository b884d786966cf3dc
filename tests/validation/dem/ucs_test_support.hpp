// Runs the UCS driver in-process on a scenario text, for the validation and reliability tests.
#pragma once
#include <omp.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "core/log.hpp"
#include "dem/presets.hpp"
#include "drivers/driver.hpp"
#include "io/csv.hpp"
#include "io/scenario.hpp"

namespace ff::test {

// A small sample so a whole test takes seconds: 2D 10 x 20 mm rectangle (~200 disks) or a
// 3D 7 x 14 mm cylinder (~600 spheres), seed 000 Table 7 coal-matrix micro-parameters.
inline std::string small_ucs_scenario(int dim) {
  std::string s = "driver = \"ucs\"\n[dem]\nbond_law = \"parallel\"\ndim = " + std::to_string(dim) + R"(
[ucs]
platen_velocity = 0.1
series_interval = 50
[output]
vtk = false
plots = false
progress_interval = 0
)" + std::string(dem::kCoalMatrixTable7Toml);
  if (dim == 2) s += "[sample]\nshape = \"box\"\nwidth = 10e-3\nheight = 20e-3\nporosity = 0.2\n";
  else s += "[sample]\nshape = \"cylinder\"\ndiameter = 7e-3\nheight = 14e-3\nporosity = 0.42\n";
  return s;
}

struct UcsRun {
  nlohmann::json summary;
  CsvTable series;
  std::string series_text, cracks_text;
};

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// Runs (or resumes) the scenario in `out`; returns the run's files once finished.
inline RunStatus run_scenario(const std::string& text, const std::vector<std::string>& sets, const std::filesystem::path& out,
                              int threads, long max_steps = 0, bool resume = false) {
  log::quiet() = true;
  const Driver& d = find_driver(peek_driver(text, "test"));
  const ParamTable table = parameter_table(d);
  const Config cfg = load_scenario(table, "test.toml", text, sets);
  if (!resume) {
    std::filesystem::remove_all(out);
    std::filesystem::create_directories(out);
    std::ofstream(out / "scenario.toml") << cfg.resolved_toml();
  }
  RunOptions opt;
  opt.out_dir = out;
  opt.threads = threads;
  opt.max_steps = max_steps;
  opt.resume = resume;
  opt.progress_interval_s = 0;
  omp_set_num_threads(threads);
  return d.run(cfg, opt);
}

inline UcsRun collect(const std::filesystem::path& out) {
  UcsRun r;
  r.summary = nlohmann::json::parse(slurp(out / "summary.json"));
  r.series = read_csv(out / "series.csv");
  r.series_text = slurp(out / "series.csv");
  r.cracks_text = slurp(out / "cracks.csv");
  return r;
}

inline std::filesystem::path scratch(const std::string& name) {
  return std::filesystem::temp_directory_path() / ("fracflow_test_" + name + "_" + std::to_string(::getpid()));
}

}  // namespace ff::test
