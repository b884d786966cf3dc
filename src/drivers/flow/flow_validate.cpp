// The checks of a flow scenario that need no lattice: run_flow() and each flow driver's
// validate() call this one function, so `fracflow check` refuses what `fracflow run` refuses.
#include "core/error.hpp"
#include "drivers/flow/flow_case.hpp"
#include "drivers/flow/flow_runner.hpp"

namespace ff::drivers {

void validate_flow(const Config& cfg, const FlowCase& fc) {
  if (cfg.string("lbm.lattice") != "D3Q19" && cfg.has("lbm.depth_cells") && cfg.integer("lbm.depth_cells") != 1)
    cfg.fail("lbm.depth_cells", "only D3Q19 has a depth; set lbm.lattice = \"D3Q19\" or remove lbm.depth_cells");
  const lbm::Units units = make_units(cfg, fc.cell_size());  // lbm.tau and lbm.time_step not both
  const bool tau_mode = !(cfg.real("lbm.time_step") > 0);
  const auto chk = units.check(fc.characteristic_speed(), fc.resolution(), fc.resolution_key(), tau_mode,
                               cfg.string("lbm.collision"));
  if (!chk.error.empty()) cfg.fail(tau_mode ? "lbm.tau" : "lbm.time_step", chk.error);
}

}  // namespace ff::drivers
