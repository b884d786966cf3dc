#include "drivers/dem_results.hpp"

#include <variant>

namespace ff::drivers {

SampleRecord sample_record(const dem::SampleInfo& i) {
  return {i.dim, i.axis, i.cylinder, i.height, i.width, i.area, i.volume, i.porosity, i.locked_in_stress,
          i.genesis_seconds, i.bonds, i.floaters};
}

dem::SampleInfo sample_info(const SampleRecord& s) {
  dem::SampleInfo i;
  i.dim = s.dim;
  i.axis = s.axis;
  i.cylinder = s.cylinder;
  i.height = s.height;
  i.width = s.width;
  i.area = s.area;
  i.volume = s.volume;
  i.porosity = s.porosity;
  i.locked_in_stress = s.locked_in_stress;
  i.genesis_seconds = s.genesis_seconds;
  i.bonds = s.bonds;
  i.floaters = s.floaters;
  return i;
}

nlohmann::json cracks_json(const dem::DemSystem& sys, int groups) {
  nlohmann::json j = {{"tensile", sys.cracks.tensile}, {"shear", sys.cracks.shear}, {"total", sys.cracks.total()}};
  nlohmann::json by_pair = nlohmann::json::object();
  const auto& g = sys.materials.group_names;
  const int ng = groups < 0 ? sys.materials.groups() : groups;
  for (int a = 0; a < ng; ++a)
    for (int b = a; b < ng; ++b)
      by_pair[g[a] + "-" + g[b]] = {{"tensile", sys.cracks.count(a, b, 1)}, {"shear", sys.cracks.count(a, b, 2)}};
  j["by_group_pair"] = by_pair;
  return j;
}

nlohmann::json sample_json(const dem::DemSystem& sys, const dem::SampleInfo& info, long particles) {
  const long n = particles < 0 ? static_cast<long>(sys.particles.size()) : particles;
  return {{"particles", n},                   {"bonds", info.bonds},        {"porosity", info.porosity},
          {"height_m", info.height},          {"width_m", info.width},      {"locked_in_stress_Pa", info.locked_in_stress},
          {"floaters", info.floaters},        {"dimension", info.dim}};
}

PlotJob axial_strain_plot(const std::filesystem::path& out, const std::string& name, const std::string& title,
                          std::vector<std::string> y, double y_scale, const std::string& ylabel) {
  PlotJob j{out / "series.csv", out / "plots" / (name + ".png"), {}};
  j.spec.title = title;
  j.spec.x = "axial_strain";
  j.spec.x_scale = 100;
  j.spec.xlabel = "axial strain [%]";
  j.spec.y = std::move(y);
  j.spec.y_scale = y_scale;
  j.spec.ylabel = ylabel;
  return j;
}

}  // namespace ff::drivers
