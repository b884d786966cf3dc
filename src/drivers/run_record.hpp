// The part of summary.json that says how a run was made rather than what it found; every
// driver adds it, so a resumed run with an accepted scenario edit is never mistaken for a
// clean one.
#pragma once
#include <nlohmann/json.hpp>

#include "drivers/driver.hpp"

namespace ff::drivers {

inline void add_run_record(nlohmann::json& summary, const RunOptions& opt) {
  if (!opt.accepted_scenario_changes.empty()) summary["resumed_with_edited_scenario"] = opt.accepted_scenario_changes;
}

}  // namespace ff::drivers
