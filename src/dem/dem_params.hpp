// Scenario keys of the DEM solid ([dem], [dem.group.<name>], [dem.contact.<a>-<b>],
// [dem.bond.<a>-<b>]) and their conversion to Materials and DemSettings.
#pragma once
#include <span>

#include "dem/dem_system.hpp"
#include "io/params.hpp"

namespace ff::dem {

void declare_dem_params(ParamTable& t);
// Groups, pair properties and laws. Every pair of declared groups must have its own
// [dem.contact.a-b] table (and [dem.bond.a-b] when bonds are used): interface properties are
// never guessed. Throws InputError naming the missing table.
Materials build_materials(const Config& cfg);
DemSettings build_settings(const Config& cfg);
// Time step: dem.time_step if set (checked against the critical step unless mass scaling is
// on, which then scales inertial masses), else dem.time_step_safety x critical. The critical step
// counts `extra_stiffness` (critical_time_step's: what a coupled physics module adds per particle).
void choose_time_step(const Config& cfg, DemSystem& sys, std::span<const Real> extra_stiffness = {});

}  // namespace ff::dem
