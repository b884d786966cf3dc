// What the bonded-particle drivers (ucs, triaxial) share around a run: the sample description
// kept in their checkpoints, and the parts of summary.json that do not depend on the protocol.
#pragma once
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

#include "dem/dem_system.hpp"
#include "dem/sample_builder.hpp"
#include "drivers/summary_values.hpp"  // params_json, shared with the flow drivers
#include "io/checkpoint.hpp"
#include "io/plot.hpp"
#include "io/params.hpp"

namespace ff::drivers {

// SampleInfo without its non-trivial members, stored as raw bytes in checkpoints.
struct SampleRecord {
  int dim, axis, cylinder;
  Real height, width, area, volume, porosity, locked_in_stress, genesis_seconds;
  std::uint64_t bonds, floaters;
};
SampleRecord sample_record(const dem::SampleInfo& info);
dem::SampleInfo sample_info(const SampleRecord& record);

// Crack counts by type and by pair of the first `groups` groups (-1: all; a particle
// membrane's group comes last and is left out).
nlohmann::json cracks_json(const dem::DemSystem& sys, int groups = -1);
// Particles (the first `particles` of the system; -1: all), bonds, porosity, size, locked-in
// stress, floaters, dimension.
nlohmann::json sample_json(const dem::DemSystem& sys, const dem::SampleInfo& info, long particles = -1);

// A curve of series.csv against the axial strain in % (the x axis of every UCS and triaxial
// plot): columns `y` scaled by `y_scale`, drawn into plots/NAME.png of `out`.
PlotJob axial_strain_plot(const std::filesystem::path& out, const std::string& name, const std::string& title,
                          std::vector<std::string> y, double y_scale, const std::string& ylabel);

}  // namespace ff::drivers

namespace ff {
template <> struct is_checkpoint_pod<drivers::SampleRecord> : std::true_type {};
}
