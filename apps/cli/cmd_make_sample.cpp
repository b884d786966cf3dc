// `fracflow make-sample c1|c4`: writes a synthetic heterogeneous coal core (src/geometry/
// synthetic_coal.hpp) as a closed STL of its inclusions and/or an 8-bit PGM voxel stack, plus
// keys.toml with the scenario keys that read it back, and prints the inclusion volume fraction.
#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "commands.hpp"
#include "core/error.hpp"
#include "geometry/stl.hpp"
#include "geometry/synthetic_coal.hpp"

namespace {

struct MakeSampleOptions {
  std::string kind;
  double diameter = 25e-3;
  double height = 50e-3;
  std::uint64_t seed = 1;
  std::string out;
  std::string format = "both";
  double voxel_size = 0;  // 0: diameter / 40
};

// Scenario keys for the files just written (paths as given with --out, i.e. relative to the
// folder the command ran in; adjust them to the scenario file's folder).
std::string scenario_keys(const MakeSampleOptions& o, const ff::geom::VoxelImage* img) {
  using G = ff::geom::CoalGreyValues;
  const std::string dir = std::filesystem::path(o.out).generic_string();
  std::string s = fmt::format(
      "# fracflow make-sample {} --diameter {} --height {} --seed {}\n"
      "# Paths are relative to the folder the command ran in: make them relative to the scenario file.\n"
      "[sample]\nshape = \"cylinder\"\ndiameter = {}\nheight = {}\ndefault_group = \"matrix\"\n",
      o.kind, o.diameter, o.height, o.seed, o.diameter, o.height);
  if (o.format != "voxels") {
    s += fmt::format("\n[[sample.region]]\ngroup = \"inclusion\"\nshape = \"stl\"\nfile = \"{}/inclusions.stl\"\n", dir);
  }
  if (img) {
    s += fmt::format(
        "\n[sample.voxels]\nfolder = \"{}/voxels\"\norigin = [{}, {}, {}]\nspacing = [{}, {}, {}]\n"
        "[sample.voxels.threshold.pore]\nmin = {}\nmax = {}\n"
        "[sample.voxels.threshold.inclusion]\nmin = {}\nmax = {}\n",
        dir, img->origin.x(), img->origin.y(), img->origin.z(), img->spacing.x(), img->spacing.y(), img->spacing.z(),
        G::outside + 1, (G::pore + G::matrix) / 2, (G::matrix + G::inclusion) / 2 + 1, 255);
  }
  return s;
}

int make_sample(const MakeSampleOptions& o) {
  namespace fs = std::filesystem;
  using namespace ff::geom;
  SyntheticCoalSpec spec;
  spec.kind = o.kind == "c1" ? CoalSampleKind::C1 : CoalSampleKind::C4;
  spec.diameter = o.diameter;
  spec.height = o.height;
  spec.seed = o.seed;
  const SyntheticCoal coal = make_synthetic_coal(spec);
  std::error_code ec;
  fs::create_directories(o.out, ec);
  if (ec) throw ff::InputError(fmt::format("--out '{}' cannot be created: {}", o.out, ec.message()));

  fmt::print("{}-like coal sample: diameter {} m, height {} m, seed {}: {} inclusions, {} pores\n", o.kind,
             o.diameter, o.height, o.seed, coal.inclusions.size(), coal.pores.size());
  fmt::print("inclusion volume fraction: {:.2f}% (ellipsoids)\n", 100 * coal.inclusion_fraction());
  if (o.format != "voxels") {
    const TriangleMesh mesh = inclusion_surface(coal);
    const fs::path file = fs::path(o.out) / "inclusions.stl";
    write_stl_binary(file, mesh);
    fmt::print("wrote {} ({} triangles, {:.2f}% of the cylinder by enclosed volume)\n", file.string(),
               mesh.triangles.size(), 100 * mesh_volume(mesh) / (ff::kPi * 0.25 * o.diameter * o.diameter * o.height));
  }
  std::unique_ptr<VoxelImage> img;
  if (o.format != "stl") {
    const double h = o.voxel_size > 0 ? o.voxel_size : o.diameter / 40;
    img = std::make_unique<VoxelImage>(voxelize(coal, h));
    const fs::path folder = fs::path(o.out) / "voxels";
    if (fs::is_directory(folder)) {  // stale slices of a taller stack would be read back
      for (const auto& entry : fs::directory_iterator(folder))
        if (entry.path().extension() == ".pgm") fs::remove(entry.path());
    }
    write_pgm_stack(folder, *img, 8);
    fmt::print("wrote {} ({} x {} x {} voxels of {:.4g} x {:.4g} x {:.4g} m; {:.2f}% inclusion voxels)\n",
               folder.string(), img->nx, img->ny, img->nz, img->spacing.x(), img->spacing.y(), img->spacing.z(),
               100 * voxel_inclusion_fraction(*img));
  }
  const fs::path keys = fs::path(o.out) / "keys.toml";
  std::ofstream(keys) << scenario_keys(o, img.get());
  fmt::print("wrote {} (scenario keys)\n", keys.string());
  return 0;
}

const bool registered = ff::cli::register_command({"make-sample", [](CLI::App& app) {
  auto o = std::make_shared<MakeSampleOptions>();
  auto* sub = app.add_subcommand("make-sample", "write a synthetic heterogeneous coal core (STL inclusions, PGM voxel stack)");
  sub->add_option("kind", o->kind, "c1: ~20% vertical veins (seed 000 C1); c4: ~10% blobs near the surface (C4)")
      ->required()
      ->check(CLI::IsMember({"c1", "c4"}));
  sub->add_option("--diameter", o->diameter, "cylinder diameter [m]")->capture_default_str()->check(CLI::PositiveNumber);
  sub->add_option("--height", o->height, "cylinder height [m]")->capture_default_str()->check(CLI::PositiveNumber);
  sub->add_option("--seed", o->seed, "random seed (same seed, same sample)")->capture_default_str();
  sub->add_option("--out,-o", o->out, "output folder")->required();
  sub->add_option("--format", o->format, "what to write")->capture_default_str()->check(CLI::IsMember({"stl", "voxels", "both"}));
  sub->add_option("--voxel-size", o->voxel_size, "voxel edge [m] (default: diameter / 40)")->check(CLI::PositiveNumber);
  return ff::cli::Command::Run([o] { return make_sample(*o); });
}});

}  // namespace
