// The one list of drivers. A new loading protocol = one folder + one line here.
#include <fmt/format.h>

#include <vector>

#include "core/error.hpp"
#include "drivers/brazilian/brazilian_driver.hpp"
#include "drivers/common_params.hpp"
#include "drivers/driver.hpp"
#include "drivers/triaxial/triaxial_driver.hpp"
#include "drivers/ucs/ucs_driver.hpp"
#include "drivers/flow/flow_drivers.hpp"
#include "drivers/hydrofrac/hydrofrac_driver.hpp"
#include "drivers/sedimentation/sedimentation_driver.hpp"
#include "drivers/saturated/saturated_ucs_driver.hpp"
// Each driver's header declares one function returning its Driver record.
// (Add the include and the entry below; the first entry is the default driver.)

namespace ff {

namespace {
const std::vector<Driver>& driver_list() {
  static const std::vector<Driver> list = {
      drivers::ucs_driver(),
      drivers::triaxial_driver(),
      drivers::brazilian_driver(),
      drivers::direct_tension_driver(),
      drivers::flow_poiseuille_driver(),
      drivers::flow_cavity_driver(),
      drivers::flow_cylinder_driver(),
      drivers::hydrofrac_driver(),
      drivers::sedimentation_driver(),
      drivers::saturated_ucs_driver(),
  };
  return list;
}
}  // namespace

std::span<const Driver> all_drivers() { return driver_list(); }

const Driver& find_driver(const std::string& name) {
  for (auto& d : driver_list())
    if (d.name == name) return d;
  std::string known;
  for (auto& d : driver_list()) known += fmt::format("\n  {:<20} {}", d.name, d.summary);
  throw InputError(fmt::format("unknown driver '{}'; the known drivers are:{}", name, known));
}

void declare_common_params(ParamTable& t) {
  std::vector<std::string> names;
  for (auto& d : driver_list()) names.emplace_back(d.name);
  t.string("driver", names.empty() ? std::string() : names.front(), "loading protocol / simulation type").one_of(names);
  t.string("title", "", "free text copied into summary.json");
  t.boolean("output.vtk", true, "write VTK (ParaView) files under vtk/");
  t.boolean("output.plots", true, "draw the headline plots under plots/ (matplotlib via /usr/bin/python3)");
  t.real("output.progress_interval", 5.0, "s", "wall-clock seconds between status lines (0: none)").non_negative();
  t.real("output.checkpoint_wall_interval", 60.0, "s",
         "wall-clock seconds between checkpoints, so a killed run (kill -9, power loss) loses at most this much work; "
         "there is also one at the end of each stage and of the run, and on SIGINT/SIGTERM/ABORT (0: none by wall clock)")
      .non_negative();
}

void declare_series_interval(ParamTable& t, const std::string& table, const std::string& also) {
  t.integer(table + ".series_interval", 100, "steps",
            "steps between rows of series.csv" + also +
                "; at most 100,000 (stops, signals, --max-steps and --max-wall are honoured at rows)")
      .positive()
      .at_most(100000);
}

void refuse_widening_aperture(const Config& cfg, const std::string& table) {
  const double h0 = cfg.real(table + ".aperture_h0"), hinf = cfg.real(table + ".aperture_hinf");
  if (hinf > h0)
    cfg.fail(table + ".aperture_hinf",
             fmt::format("{} m is above {}.aperture_h0 = {} m: Eq. B1's aperture would widen as the contact is "
                         "squeezed; the aperture at infinite stress must be at most the one at zero stress",
                         hinf, table, h0));
}

ParamTable parameter_table(const Driver& d) {
  ParamTable t;
  declare_common_params(t);
  d.declare(t);
  return t;
}

}  // namespace ff
