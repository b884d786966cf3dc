// libFuzzer target for the scenario parser. Any byte string must either give a Config or an
// ff::InputError; any other exception, a crash or a sanitizer report is a failure.
// Input layout: the TOML text, then optional `--set` overrides, each after a 0x01 byte
// (0x01 is never valid in TOML, so no scenario text is lost to this convention).
// Property checked on every accepted input: the resolved TOML written into each run's
// output folder parses back, without error, to the same resolved configuration.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.hpp"
#include "io/scenario.hpp"

namespace {

// A small table with every parameter type, range kind, choices, list sizes and a wildcard.
const ff::ParamTable& table() {
  static const ff::ParamTable t = [] {
    ff::ParamTable p;
    p.string("driver", "ucs", "driver").one_of({"ucs", "lbm"});
    p.real("dem.damping", 0.7, "-", "local damping").range(0, 1);
    p.real("sample.radius_min", 0.4e-3, "m", "smallest radius").positive();
    p.real("sample.porosity", 0.1, "-", "porosity").open_range(0, 1);
    p.real("lbm.tau", 0.8, "-", "relaxation time").open_range(0.5, 2);
    p.integer("sample.seed", 1, "-", "random seed").non_negative();
    p.integer("output.every", 100, "-", "steps between outputs").at_least(1);
    p.boolean("output.vtk", true, "write VTK");
    p.string("output.name", "run", "name");
    p.real("dem.group.*.density", 2600, "kg/m^3", "particle density").positive();
    p.string("dem.contact.*.law", "linear/coulomb", "contact law").one_of({"linear/coulomb", "hertz/material"});
    p.real_list("load.pressures", {1e6}, "Pa", "pressures").positive().size_between(1, 8);
    p.real_list("sample.size", {0.05, 0.1, 0.05}, "m", "box").positive().size(3);
    p.string_list("output.fields", {"velocity"}, "fields").one_of({"velocity", "force", "damage"});
    p.string_list("notes", {}, "free text");
    return p;
  }();
  return t;
}

void split(std::string_view in, std::string& text, std::vector<std::string>& sets) {
  const auto first = in.find('\x01');
  text.assign(in.substr(0, first));
  while (first != std::string_view::npos && !in.empty()) {
    in.remove_prefix(in.find('\x01') + 1);
    const auto next = in.find('\x01');
    sets.emplace_back(in.substr(0, next));
    if (next == std::string_view::npos) break;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string text;
  std::vector<std::string> sets;
  split(std::string_view(reinterpret_cast<const char*>(data), size), text, sets);
  try {
    (void)ff::peek_driver(text, "fuzz.toml");
  } catch (const ff::InputError&) {
  }
  std::optional<ff::Config> cfg;
  try {
    cfg = ff::build_config(table(), "fuzz.toml", ff::parse_toml_flat(text, "fuzz.toml"), sets);
  } catch (const ff::InputError&) {
    return 0;
  }
  // Accepted input: nothing below may throw.
  (void)cfg->describe();
  const std::string resolved = cfg->resolved_toml();
  const ff::Config back = ff::build_config(table(), "fuzz.toml", ff::parse_toml_flat(resolved, "fuzz.toml"), {});
  if (back.resolved_toml() != resolved) __builtin_trap();  // the round trip changed a value
  return 0;
}
