// The checks of a flow scenario that need no lattice: run_flow() and each flow driver's
// validate() call this one function, so `fracflow check` refuses what `fracflow run` refuses.
#include <fmt/format.h>

#include <set>

#include "core/error.hpp"
#include "drivers/flow/flow_case.hpp"
#include "drivers/flow/flow_runner.hpp"
#include "drivers/flow/probes.hpp"

namespace ff::drivers {

void validate_flow(const Config& cfg, const FlowCase& fc) {
  const bool d3 = cfg.string("lbm.lattice") == "D3Q19";
  if (!d3 && cfg.has("lbm.depth_cells") && cfg.integer("lbm.depth_cells") != 1)
    cfg.fail("lbm.depth_cells", "only D3Q19 has a depth; set lbm.lattice = \"D3Q19\" or remove lbm.depth_cells");
  // At most one of lbm.tau, lbm.time_step, lbm.mach, lbm.target_error; then the limits.
  const FlowUnits fu = make_units(cfg, fc.cell_size(), fc.characteristic_speed(), fc.unsteady());
  const auto chk = fu.units.check(fc.characteristic_speed(), fc.resolution(), fc.resolution_key(), fu.mode,
                                  cfg.string("lbm.collision"), fu.coefficient);
  if (!chk.error.empty()) cfg.fail(fu.key(), chk.error);
  const int nz = d3 ? int(cfg.integer("lbm.depth_cells")) : 1;
  const ProbeSet probes = read_probes(cfg, d3, nz * fc.cell_size());
  series_columns(cfg, fc, Probes(probes, fc.cell_size()));  // refuses probe columns that repeat the case's
  if (!probes.empty()) {
    // The lattice's extent and solids from the case's domain (no solver is built). domain()
    // only caches the units in the case, which run() sets again.
    const DomainSpec dom = const_cast<FlowCase&>(fc).domain(fu.units);
    std::set<std::pair<int, int>> cells;
    for (auto& o : dom.objects)
      for (auto& c : o.cells) cells.insert({c[0], c[1]});
    const auto solid = [&](int x, int y, int z) {
      if (cells.count({x, y})) return true;
      for (auto& o : dom.objects)
        if (o.shape && lbm::inside(*o.shape, Vec3(x, y, z))) return true;
      return false;
    };
    check_probe_positions(cfg, probes, fc.cell_size(), dom.nx, dom.ny, nz, solid);
  }
  std::string report = "Derived LBM units: " + describe_flow_units(fu, fc) + "\n";
  if (!probes.empty()) report += fmt::format("{} probe(s) checked against the lattice\n", probes.points.size());
  for (auto& w : chk.warnings) report += "warning: " + w + "\n";
  for (auto& w : fc.warnings()) report += "warning: " + w + "\n";
  FlowCheckReport::append(report);
}

}  // namespace ff::drivers
