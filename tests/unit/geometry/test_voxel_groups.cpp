// Groups from a segmented voxel image (sample.voxels.*, src/dem/sample_builder.cpp): grey-value
// windows on known 8- and 16-bit stacks written here, pore removal before bonding, and the errors
// for bad thresholds and stacks (each must name the key).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.hpp"
#include "dem/dem_params.hpp"
#include "dem/sample_builder.hpp"
#include "geometry/voxel_image.hpp"
#include "io/scenario.hpp"

namespace ff::dem {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "fracflow_test_voxel_groups" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

ParamTable sample_table() {
  ParamTable t;
  declare_dem_params(t);
  declare_sample_params(t);
  return t;
}

// Two groups with Table 7-like moduli (the remaining properties keep their defaults).
const char* kGroups = R"(
[dem]
bond_law = "parallel"
[dem.group.matrix]
density = 1390
[dem.group.inclusion]
density = 1810
[dem.contact.matrix-matrix]
emod = 2.09e9
[dem.contact.inclusion-inclusion]
emod = 2.84e9
[dem.contact.matrix-inclusion]
emod = 1.90e9
[dem.bond.matrix-matrix]
emod = 2.09e9
[dem.bond.inclusion-inclusion]
emod = 2.84e9
[dem.bond.matrix-inclusion]
emod = 1.90e9
)";

// A 4 x 3 x 2 stack, 1 mm voxels, origin (0.5, 0.5, 0.5) mm so voxel (i, j, k) covers
// [i, i+1] x [j, j+1] x [k, k+1] mm. Grey values: `lo` everywhere, `hi` in column i = 3,
// `pore` in voxel (0, 0, 1), `odd` (in no window) in voxel (1, 2, 0).
VoxelImage known_stack(std::uint16_t lo, std::uint16_t hi, std::uint16_t pore, std::uint16_t odd) {
  VoxelImage img;
  img.nx = 4;
  img.ny = 3;
  img.nz = 2;
  img.origin = Vec3::Constant(0.5e-3);
  img.spacing = Vec3::Constant(1e-3);
  img.value.assign(24, lo);
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 3; ++j) img.value[img.index(3, j, k)] = hi;
  img.value[img.index(0, 0, 1)] = pore;
  img.value[img.index(1, 2, 0)] = odd;
  return img;
}

struct Scenario {
  ParamTable table = sample_table();
  Config cfg;
  Materials mat;
};

std::unique_ptr<Scenario> load(const fs::path& file, const std::string& extra) {
  auto s = std::make_unique<Scenario>();
  s->cfg = load_scenario(s->table, file.string(), std::string(kGroups) + extra, {});
  s->mat = build_materials(s->cfg);
  return s;
}

std::string voxel_keys(const std::string& folder, int min_incl, int max_incl, int min_pore, int max_pore) {
  return "[sample.voxels]\nfolder = \"" + folder + "\"\norigin = [0.5e-3, 0.5e-3, 0.5e-3]\nspacing = [1e-3, 1e-3, 1e-3]\n" +
         "[sample.voxels.threshold.inclusion]\nmin = " + std::to_string(min_incl) + "\nmax = " + std::to_string(max_incl) +
         "\n[sample.voxels.threshold.pore]\nmin = " + std::to_string(min_pore) + "\nmax = " + std::to_string(max_pore) + "\n";
}

// Labels at voxel centres must follow the windows exactly (no tolerance: integer grey values).
void expect_known_labels(const VoxelGroups& vg, int inclusion) {
  constexpr int kNone = -2;
  const std::vector<Vec3> points = {
      Vec3(0.5e-3, 0.5e-3, 0.5e-3),  // lo: no window -> keeps its group
      Vec3(3.5e-3, 1.5e-3, 0.5e-3),  // hi -> inclusion
      Vec3(3.9e-3, 2.9e-3, 1.9e-3),  // hi, near the image corner
      Vec3(0.5e-3, 0.5e-3, 1.5e-3),  // pore
      Vec3(1.5e-3, 2.5e-3, 0.5e-3),  // odd value, in no window
      Vec3(4.1e-3, 1.5e-3, 0.5e-3),  // outside the image (x > 4 mm)
      Vec3(1.5e-3, 1.5e-3, -0.1e-3)  // outside the image (z < 0)
  };
  const auto label = geom::label_points(vg.image, points, vg.windows, kNone);
  EXPECT_EQ(label, (std::vector<int>{kNone, inclusion, inclusion, kPoreLabel, kNone, kNone, kNone}));
}

TEST(VoxelGroups, EightBitStackMapsWindowsToGroupsAndPore) {
  const fs::path dir = fresh_dir("eight_bit");
  write_pgm_stack(dir / "slices", known_stack(100, 200, 30, 250), 8);
  const auto s = load(dir / "scenario.toml", voxel_keys("slices", 150, 220, 1, 60));  // relative to the scenario
  const VoxelGroups vg = read_voxel_groups(s->cfg, s->mat);
  ASSERT_EQ(vg.image.nx, 4);
  ASSERT_EQ(vg.image.nz, 2);
  expect_known_labels(vg, s->mat.group_index("inclusion"));
}

TEST(VoxelGroups, SixteenBitStackMapsWindowsToGroupsAndPore) {
  const fs::path dir = fresh_dir("sixteen_bit");
  write_pgm_stack(dir / "slices", known_stack(20000, 50000, 300, 65535), 16);
  const auto s = load(dir / "scenario.toml", voxel_keys((dir / "slices").string(), 40000, 60000, 1, 1000));  // absolute
  expect_known_labels(read_voxel_groups(s->cfg, s->mat), s->mat.group_index("inclusion"));
}

TEST(VoxelGroups, NoFolderMeansNoImage) {
  const auto s = load(fresh_dir("none") / "scenario.toml", "");
  EXPECT_TRUE(read_voxel_groups(s->cfg, s->mat).empty());
}

// Every error names the key and says what is allowed.
std::string error_of(const fs::path& dir, const std::string& extra) {
  try {
    const auto s = load(dir / "scenario.toml", extra);
    read_voxel_groups(s->cfg, s->mat);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(VoxelGroups, BadThresholdsAndStacksNameTheKey) {
  const fs::path dir = fresh_dir("errors");
  write_pgm_stack(dir / "slices", known_stack(100, 200, 30, 250), 8);
  std::string e = error_of(dir, voxel_keys("slices", 150, 220, 1, 150));  // pore [1,150] overlaps [150,220]
  EXPECT_NE(e.find("sample.voxels.threshold.inclusion.min"), std::string::npos) << e;
  EXPECT_NE(e.find("overlaps"), std::string::npos) << e;
  EXPECT_NE(e.find("disjoint"), std::string::npos) << e;

  e = error_of(dir, voxel_keys("slices", 220, 150, 1, 60));  // min > max
  EXPECT_NE(e.find("sample.voxels.threshold.inclusion.max"), std::string::npos) << e;

  e = error_of(dir, voxel_keys("slices", 150, 220, 1, 60) + "[sample.voxels.threshold.quartz]\nmin = 230\n");
  EXPECT_NE(e.find("sample.voxels.threshold.quartz.min"), std::string::npos) << e;
  EXPECT_NE(e.find("(inclusion, matrix)"), std::string::npos) << e;  // the allowed names

  e = error_of(dir, voxel_keys("missing_folder", 150, 220, 1, 60));
  EXPECT_NE(e.find("sample.voxels.folder"), std::string::npos) << e;
  EXPECT_NE(e.find("does not exist"), std::string::npos) << e;

  e = error_of(dir, "[sample.voxels.threshold.inclusion]\nmin = 150\n");  // windows without an image
  EXPECT_NE(e.find("sample.voxels.threshold.inclusion.min"), std::string::npos) << e;
  EXPECT_NE(e.find("sample.voxels.folder"), std::string::npos) << e;

  e = error_of(dir, "[sample.voxels]\nfolder = \"slices\"\n");  // an image without windows
  EXPECT_NE(e.find("sample.voxels.folder"), std::string::npos) << e;
  EXPECT_NE(e.find("at least one"), std::string::npos) << e;

  // Slices of different sizes.
  VoxelImage small = known_stack(100, 200, 30, 250);
  small.nx = 3;
  small.nz = 1;
  small.value.assign(9, 100);
  write_pgm_stack(dir / "mixed", known_stack(100, 200, 30, 250), 8);
  write_pgm_stack(dir / "tmp", small, 8);
  fs::copy_file(dir / "tmp" / "slice_00000.pgm", dir / "mixed" / "slice_00002.pgm");
  e = error_of(dir, voxel_keys("mixed", 150, 220, 1, 60));
  EXPECT_NE(e.find("sample.voxels.folder"), std::string::npos) << e;
  EXPECT_NE(e.find("differs from the first slice"), std::string::npos) << e;
}

// Genesis of a tiny 3D box sample (~150 particles) with and without a pore window over the
// image's upper half: with it, no particle centre may lie in a pore voxel and particles must be
// missing; groups from the image override the default. Exact checks (counts, labels).
TEST(VoxelGroups, PoreVoxelsRemoveParticlesBeforeBonding) {
  const fs::path dir = fresh_dir("pore");
  VoxelImage img;  // 2 x 2 x 2 voxels of 2 mm over the 4 x 4 x 4 mm box; top layer pore (30)
  img.nx = img.ny = img.nz = 2;
  img.origin = Vec3::Constant(1e-3);
  img.spacing = Vec3::Constant(2e-3);
  img.value = {200, 100, 100, 100, 30, 30, 30, 30};  // voxel (0,0,0) inclusion (200)
  write_pgm_stack(dir / "slices", img, 8);
  const std::string box =
      "[sample]\nshape = \"box\"\nwidth = 4e-3\ndepth = 4e-3\nheight = 4e-3\nradius_min = 0.3e-3\nradius_max = 0.4e-3\n"
      "porosity = 0.45\ngenesis_max_steps = 200\ndefault_group = \"matrix\"\n";
  const std::string voxels =
      "[sample.voxels]\nfolder = \"slices\"\norigin = [1e-3, 1e-3, 1e-3]\nspacing = [2e-3, 2e-3, 2e-3]\n"
      "[sample.voxels.threshold.inclusion]\nmin = 150\nmax = 255\n";
  auto build = [&](const std::string& extra, DemSystem& sys) {
    const auto s = load(dir / "scenario.toml", box + voxels + extra);
    sys.settings = build_settings(s->cfg);
    sys.materials = s->mat;
    return build_sample(s->cfg, sys);
  };
  DemSystem full, holed;
  const SampleInfo a = build(std::string(), full);
  const SampleInfo b = build("[sample.voxels.threshold.pore]\nmin = 1\nmax = 60\n", holed);
  EXPECT_EQ(a.pore_particles, 0u);
  EXPECT_GT(b.pore_particles, 0u);
  EXPECT_LT(holed.particles.size(), full.particles.size());
  const int inclusion = holed.materials.group_index("inclusion");
  std::size_t in_inclusion_voxel = 0;
  for (std::size_t i = 0; i < holed.particles.size(); ++i) {
    const Vec3& p = holed.particles.pos[i];
    EXPECT_NE(img.at(p), 30) << "particle " << i << " left in a pore voxel at z = " << p.z();
    // Groups come from the packing's positions; genesis moves particles by far less than 0.3 mm.
    if ((p.array() > 0.3e-3).all() && (p.array() < 1.7e-3).all()) {
      ++in_inclusion_voxel;
      EXPECT_EQ(holed.particles.group[i], inclusion);
    }
  }
  EXPECT_GT(in_inclusion_voxel, 0u);
  for (std::size_t n = 0; n < holed.bonds.i.size(); ++n) {  // bonds only between kept particles
    ASSERT_LT(holed.bonds.i[n], static_cast<Index>(holed.particles.size()));
    ASSERT_LT(holed.bonds.j[n], static_cast<Index>(holed.particles.size()));
  }
}

}  // namespace
}  // namespace ff::dem
