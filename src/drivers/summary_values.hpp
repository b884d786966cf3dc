// Parts of summary.json that every driver writes the same way: the resolved parameters with
// their types (numbers as numbers, booleans as booleans), and headline numbers that may be
// undefined, which are written as null with the reason beside them, never as a stand-in 0.
#pragma once
#include <nlohmann/json.hpp>

#include <string>
#include <string_view>

#include "io/params.hpp"

namespace ff::drivers {

// Every resolved parameter, key -> value, each with its own JSON type.
nlohmann::json params_json(const Config& cfg);

// `v` as a JSON number, or null when it is not finite (NaN marks "no value" in the drivers).
nlohmann::json number_or_null(double v);

// Why the largest value of a loading curve is not a peak (empty when it is one): it is not
// positive, or it is the last row of a run that stopped at its strain cap while still rising.
// `rows` counts the curve's rows, `peak_row` indexes the largest; `strain_cap_stop` says the run
// stopped at `max_strain_key`.
std::string peak_problem(double peak, long peak_row, long rows, bool strain_cap_stop, std::string_view max_strain_key);

}  // namespace ff::drivers
