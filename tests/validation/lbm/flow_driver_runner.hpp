// Runs a flow driver exactly as `fracflow run` does (scenario text + --set overrides) in a
// scratch folder and returns its summary.json, so the validation tests check the same code
// path as the examples.
#pragma once
#include <omp.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/log.hpp"
#include "drivers/driver.hpp"
#include "io/scenario.hpp"

namespace ff::testing {

inline std::filesystem::path flow_test_dir(const std::string& name) {
  return std::filesystem::temp_directory_path() / "fracflow_lbm_validation" / name;
}

// Runs (or, with resume, continues) the scenario in flow_test_dir(name); max_wall_s > 0 or
// max_steps > 0 stops it early with a checkpoint, as `fracflow run --max-wall/--max-steps` do.
inline RunStatus run_flow_driver_status(const std::string& name, const std::string& scenario,
                                        const std::vector<std::string>& sets, bool resume = false,
                                        double max_wall_s = 0, long max_steps = 0) {
  const Driver& d = find_driver(peek_driver(scenario, name));
  const ParamTable table = parameter_table(d);
  const Config cfg = load_scenario(table, "", scenario, sets);
  RunOptions opt;
  opt.out_dir = flow_test_dir(name);
  if (!resume) {
    std::filesystem::remove_all(opt.out_dir);
    std::filesystem::create_directories(opt.out_dir);
  }
  opt.threads = omp_get_max_threads();
  opt.progress_interval_s = 0;
  opt.resume = resume;
  opt.max_wall_s = max_wall_s;
  opt.max_steps = max_steps;
  log::quiet() = true;
  return d.run(cfg, opt);
}

inline nlohmann::json read_summary(const std::string& name) {
  std::ifstream f(flow_test_dir(name) / "summary.json");
  return nlohmann::json::parse(f);
}

inline nlohmann::json run_flow_driver(const std::string& name, const std::string& scenario,
                                      const std::vector<std::string>& sets) {
  run_flow_driver_status(name, scenario, sets);
  return read_summary(name);
}

}  // namespace ff::testing
