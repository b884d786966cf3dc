// The headline plots of the two tensile tests (plots/ of the results folder).
#pragma once
#include <filesystem>
#include <string>

#include "io/params.hpp"

namespace ff::drivers {

// load_displacement.png: load [kN] against the platen or grip displacement [mm], cracks on the
// right axis; stress_strain.png: `stress_columns` [MPa] against `strain_column` [%].
void tensile_plots(const std::filesystem::path& out, const Config& cfg, const std::string& test,
                   const std::string& displacement_column, const std::string& strain_column,
                   const std::string& strain_label, const std::vector<std::string>& stress_columns,
                   const std::string& stress_label, bool per_metre);

}  // namespace ff::drivers
