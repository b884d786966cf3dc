#include "drivers/brazilian/tensile_plots.hpp"

#include <vector>

#include "io/plot.hpp"

namespace fs = std::filesystem;

namespace ff::drivers {

void tensile_plots(const fs::path& out, const Config& cfg, const std::string& test, const std::string& displacement_column,
                   const std::string& strain_column, const std::string& strain_label,
                   const std::vector<std::string>& stress_columns, const std::string& stress_label, bool per_metre) {
  if (!cfg.boolean("output.plots")) return;
  fs::create_directories(out / "plots");
  const fs::path csv = out / "series.csv";
  PlotJob load{csv, out / "plots" / "load_displacement.png", {}};
  load.spec.title = test + ": load and cracks";
  load.spec.x = displacement_column;
  load.spec.x_scale = 1e3;
  load.spec.xlabel = displacement_column.starts_with("platen") ? "platen approach [mm]" : "grip separation increase [mm]";
  load.spec.y = {"load_N"};
  load.spec.y_scale = 1e-3;
  load.spec.ylabel = per_metre ? "load [kN per m of thickness]" : "load [kN]";
  load.spec.y2 = {"cracks_total", "cracks_tensile", "cracks_shear"};
  load.spec.y2label = "number of cracks";
  PlotJob stress{csv, out / "plots" / "stress_strain.png", {}};
  stress.spec.title = test + ": stress";
  stress.spec.x = strain_column;
  stress.spec.x_scale = 100;
  stress.spec.xlabel = strain_label + " [%]";
  stress.spec.y = stress_columns;
  stress.spec.y_scale = 1e-6;
  stress.spec.ylabel = stress_label + " [MPa]";
  const std::vector<PlotJob> jobs = {load, stress};
  plot_series(jobs);  // one python process for both
}

}  // namespace ff::drivers
