#include "drivers/driver.hpp"

namespace ff {
std::string_view default_scenario_text() { return ""; }
}
