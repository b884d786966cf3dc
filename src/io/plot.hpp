// PNG plots of CSV time series, drawn by scripts/plot_series.py (matplotlib, Agg backend).
// Plotting is a convenience: when python3 or matplotlib is missing, or the script fails, the
// functions log one warning and return false; they never throw for plotting problems.
#pragma once
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace ff {

struct PlotSpec {
  std::string title, xlabel, ylabel, y2label;
  std::string x;                     // CSV column on the x axis
  std::vector<std::string> y, y2;    // columns on the left and (optional) right axis
  double x_scale = 1, y_scale = 1, y2_scale = 1;  // multiply values (e.g. 1e-6 for Pa -> MPa)
  std::filesystem::path reference_csv;  // optional markers overlaid on the left axis,
  std::string ref_x, ref_y, ref_label;  // scaled by x_scale / y_scale like the data
  bool logx = false, logy = false;
  bool equal_aspect = false;         // one unit as long on both axes (maps, fracture patterns)
  std::vector<std::string> y_labels;  // legend names of the y columns (empty: the column names)
};

// One figure to draw: a CSV, the PNG to write and what to plot.
struct PlotJob {
  std::filesystem::path csv, png;
  PlotSpec spec;
};

// Draws one figure; true when the PNG was written.
bool plot_series(const std::filesystem::path& csv, const std::filesystem::path& png, const PlotSpec& spec);
// Draws several figures in one python process (saves its start-up); returns how many were written.
int plot_series(std::span<const PlotJob> jobs);

// The folder holding plot_series.py: $FRACFLOW_SCRIPTS, else <source dir>/scripts.
std::filesystem::path scripts_dir();

}  // namespace ff
