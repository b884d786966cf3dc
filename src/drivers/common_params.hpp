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
// Seed 004's Eq. B1 closes a contact channel under normal stress, from `<table>.aperture_h0` towards
// `<table>.aperture_hinf`: an aperture at infinite stress above the one at zero stress (the channel
// widening as it is squeezed) is refused, naming both keys (saturated_ucs's fluid, hydrofrac's network).
void refuse_widening_aperture(const Config& cfg, const std::string& table);
}
