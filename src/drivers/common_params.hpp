// Keys shared by every driver.
#pragma once
#include "io/params.hpp"

namespace ff {
void declare_common_params(ParamTable& t);
}
