// Sample genesis (src/dem/sample_builder.cpp): the 2D disc sample (Brazilian test) and the
// shape checks; the packing a genesis reports.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include "core/error.hpp"
#include "dem/dem_params.hpp"
#include "dem/sample_builder.hpp"
#include "io/scenario.hpp"

namespace ff::dem {
namespace {

ParamTable sample_table() {
  ParamTable t;
  declare_dem_params(t);
  declare_sample_params(t);
  return t;
}

struct Built {
  ParamTable table = sample_table();
  Config cfg;
  DemSystem sys;
  SampleInfo info;
};

std::unique_ptr<Built> build(const std::string& text) {
  auto b = std::make_unique<Built>();
  b->cfg = load_scenario(b->table, "", text, {});
  b->sys.settings = build_settings(b->cfg);
  b->sys.materials = build_materials(b->cfg);
  b->info = build_sample(b->cfg, b->sys);
  return b;
}

std::string error_of(const std::string& text) {
  try {
    build(text);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

// One group with the default scenario's coal-matrix micro-parameters, then the [sample] keys.
std::string scenario(int dim, const std::string& sample) {
  return "[dem]\ndim = " + std::to_string(dim) + "\nbond_law = \"parallel\"\n[dem.group.matrix]\ndensity = 1390\n" +
         "[dem.contact.matrix-matrix]\nemod = 2.09e9\nkratio = 14.65\nfriction = 0.4\n" +
         "[dem.bond.matrix-matrix]\nemod = 2.09e9\nkratio = 14.65\ntensile_strength = 17.4e6\ncohesion = 4.35e6\n" +
         "[sample]\n" + sample;
}

const std::string kDisc2D = scenario(
    2, "shape = \"disc\"\ndiameter = 20e-3\nradius_min = 0.4e-3\nradius_max = 0.6e-3\nporosity = 0.2\nseed = 3\n");

// Every disk inside the circle: |x| <= D/2 - r (the vessel pushes a disk back once it overlaps
// it; the genesis contact overlaps are below 1% of a radius, so allow 1% of r_max), z = 0; the
// porosity is the request to the packer's tolerance (0.01, test_packing.cpp) once the
// locked-in-stress shrink (radii shrink by well under 1%) is allowed for.
TEST(SampleGenesis, DiscSampleLiesInTheCircle) {
  const auto b = build(kDisc2D);
  const auto& P = b->sys.particles;
  ASSERT_GT(P.size(), 200u);
  const Real R = 10e-3;
  for (std::size_t i = 0; i < P.size(); ++i) {
    ASSERT_LE(std::hypot(P.pos[i].x(), P.pos[i].y()), R - P.radius[i] + 0.01 * 0.6e-3) << i;
    ASSERT_EQ(P.pos[i].z(), 0.0) << i;
  }
  const SampleInfo& s = b->info;
  EXPECT_EQ(s.dim, 2);
  EXPECT_EQ(s.axis, 1);
  EXPECT_TRUE(s.cylinder);
  EXPECT_DOUBLE_EQ(s.width, 20e-3);
  EXPECT_DOUBLE_EQ(s.height, 20e-3);
  EXPECT_DOUBLE_EQ(s.area, 20e-3);
  EXPECT_DOUBLE_EQ(s.volume, kPi * 1e-4);
  EXPECT_NEAR(s.porosity, 0.2, 0.015);
  EXPECT_GT(s.bonds, P.size());  // a bonded 2D packing has about 2 bonds per disk
  EXPECT_TRUE(b->sys.walls.empty());
}

TEST(SampleGenesis, ShapeErrorsNameTheKeyAndTheAllowedShapes) {
  std::string e = error_of(scenario(3, "shape = \"disc\"\n"));  // 3D
  EXPECT_NE(e.find("sample.shape"), std::string::npos) << e;
  EXPECT_NE(e.find("\"cylinder\" or \"box\""), std::string::npos) << e;
  e = error_of(scenario(2, "shape = \"cylinder\"\n"));
  EXPECT_NE(e.find("sample.shape"), std::string::npos) << e;
  EXPECT_NE(e.find("\"disc\""), std::string::npos) << e;
  e = error_of(scenario(2, "shape = \"disc\"\ndiameter = 1e-3\n"));
  EXPECT_NE(e.find("sample.diameter"), std::string::npos) << e;
}

}  // namespace
}  // namespace ff::dem
