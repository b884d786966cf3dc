// Scenario keys of the DEM solid ([dem], [dem.group.<name>], [dem.contact.<a>-<b>],
// [dem.bond.<a>-<b>]) and their conversion to Materials and DemSettings.
#pragma once
#include <span>
#include <string>
#include <string_view>

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
// critical_time_step, refused (InputError naming the stiffness and density keys) when it is 0: a
// stiffness that overflows (inf, or NaN from 0 x inf) or a mass that underflows. `what` names the
// step in the message ("critical time step", "genesis's time step").
Real checked_critical_time_step(const Config& cfg, const DemSystem& sys, std::string_view what,
                                std::span<const Real> extra_stiffness = {});
// A boundary (platen, grip, servo wall) that moves a good part of a grain in one step is an impact:
// its contacts jump through each other. Largest travel per time step, as a fraction of the smallest radius.
constexpr double kMaxWallStep = 0.05;
// Refuses (InputError naming `key`) the speed cfg.real(key) [m/s] when it moves `wall` by more than
// kMaxWallStep x the smallest radius in one of sys's time steps; `usual` ends the message (what is usual).
void refuse_wall_jump(const Config& cfg, const std::string& key, const DemSystem& sys, std::string_view wall,
                      std::string_view usual);
// Refuses dem.gravity when it alone moves a grain at rest by more than kMaxWallStep x the smallest
// radius in one of sys's time steps (|g| dt^2): the grains then fall through each other.
void refuse_gravity_jump(const Config& cfg, const DemSystem& sys);

}  // namespace ff::dem
