#include "drivers/summary_values.hpp"

#include <fmt/format.h>

#include <cmath>
#include <variant>

namespace ff::drivers {

nlohmann::json params_json(const Config& cfg) {
  nlohmann::json j = nlohmann::json::object();
  for (auto& [k, v] : cfg.resolved_values()) std::visit([&](const auto& x) { j[k] = x; }, v);
  return j;
}

nlohmann::json number_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

std::string peak_problem(double peak, long peak_row, long rows, bool strain_cap_stop, std::string_view max_strain_key) {
  if (rows <= 0) return "the run recorded no stress-strain curve";
  if (!(peak > 0)) return "the stress never rose above zero";
  if (strain_cap_stop && peak_row >= rows - 1)
    return fmt::format("the stress was still rising when the run stopped at {}: the largest stress is not a peak (raise "
                       "{})",
                       max_strain_key, max_strain_key);
  return {};
}

}  // namespace ff::drivers
