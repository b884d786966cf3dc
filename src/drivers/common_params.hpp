// Keys shared by every driver.
#pragma once
#include <string>

#include "io/params.hpp"

namespace ff {
void declare_common_params(ParamTable& t);
// `<table>.series_interval` of a DEM driver, steps between rows of series.csv (what else happens at a
// row: `also`, e.g. " (and stage checks)"): at most 100,000, since stops, signals, --max-steps and
// --max-wall are honoured at rows.
void declare_series_interval(ParamTable& t, const std::string& table, const std::string& also = "");
}
