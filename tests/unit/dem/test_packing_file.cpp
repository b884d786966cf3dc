// Packing files (src/dem/packing_file.*, read by benchmarks/dem_ucs --packing): a good file with
// comments, blank lines and a bond list; every bad case with the file name and line number in the
// message; a write/read round trip that keeps every bit; and placing a packing in a DemSystem,
// with its bond list or by the sample.bond_gap rule, in file order or in the spatial order.
#include <gtest/gtest.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>
#include <string>

#include "core/error.hpp"
#include "dem/dem_params.hpp"
#include "dem/packing_file.hpp"
#include "dem/sample_builder.hpp"
#include "io/scenario.hpp"
#include "dem/diagnostics.hpp"

namespace ff::dem {
namespace {

namespace fs = std::filesystem;

PackingFile parse(const std::string& text) {
  std::istringstream in(text);
  return parse_packing(in, "pack.txt");
}

// The message of the InputError that parsing `text` throws ("" when it does not throw).
std::string error_of(const std::string& text) {
  try {
    parse(text);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

#define EXPECT_ERROR(text, where, what)                                   \
  do {                                                                    \
    const std::string msg = error_of(text);                               \
    EXPECT_NE(msg.find(where), std::string::npos) << "message: " << msg;  \
    EXPECT_NE(msg.find(what), std::string::npos) << "message: " << msg;   \
  } while (0)

const char* kGood =
    "# exported from a peer code\n"
    "\n"
    "0 0 0 1e-3\n"
    "  2e-3\t0 0 1.0E-3   # trailing comment\n"
    "+4e-3 0.0 -0 0.001\r\n"
    "bonds  # from here, pairs\n"
    "0 1\n"
    "2 1\n"
    "\n";

TEST(PackingFile, ReadsParticlesCommentsAndBonds) {
  const PackingFile p = parse(kGood);
  ASSERT_EQ(p.pos.size(), 3u);
  ASSERT_EQ(p.radius.size(), 3u);
  EXPECT_EQ(p.pos[1], Vec3(2e-3, 0, 0));
  EXPECT_EQ(p.pos[2], Vec3(4e-3, 0, 0));
  EXPECT_EQ(p.radius[1], 1e-3);
  EXPECT_EQ(p.radius[2], 1e-3);
  EXPECT_TRUE(p.has_bond_list);
  ASSERT_EQ(p.bonds.size(), 2u);
  EXPECT_EQ(p.bonds[0], std::make_pair(Index(0), Index(1)));
  EXPECT_EQ(p.bonds[1], std::make_pair(Index(1), Index(2)));  // stored with i < j
}

TEST(PackingFile, WithoutABondsLineThereIsNoListAndAnEmptyListIsAList) {
  const PackingFile a = parse("0 0 0 1\n1 0 0 1\n");
  EXPECT_FALSE(a.has_bond_list);
  EXPECT_TRUE(a.bonds.empty());
  const PackingFile b = parse("0 0 0 1\n1 0 0 1\nbonds\n# none\n");
  EXPECT_TRUE(b.has_bond_list);
  EXPECT_TRUE(b.bonds.empty());
}

TEST(PackingFile, EveryBadLineIsNamedWithItsNumber) {
  EXPECT_ERROR("0 0 0 1\n0 0 1\n", "pack.txt:2:", "expected a particle 'x y z r' (4 numbers), got 3 fields");
  EXPECT_ERROR("0 0 0 1 7\n", "pack.txt:1:", "got 5 fields");
  EXPECT_ERROR("# c\n0 0 zero 1\n", "pack.txt:2:", "z = 'zero' is not a finite number");
  EXPECT_ERROR("0 0 0 1e-3x\n", "pack.txt:1:", "r = '1e-3x' is not a finite number");
  EXPECT_ERROR("nan 0 0 1\n", "pack.txt:1:", "x = 'nan' is not a finite number");
  EXPECT_ERROR("0 inf 0 1\n", "pack.txt:1:", "y = 'inf' is not a finite number");
  EXPECT_ERROR("0 0 0 1\n\n1 0 0 -1e-3\n", "pack.txt:3:", "radius r = -1e-3 must be positive");
  EXPECT_ERROR("0 0 0 0\n", "pack.txt:1:", "radius r = 0 must be positive");
  EXPECT_ERROR("0 0 0 1\n1 0 0 1\nbonds\n0 2\n", "pack.txt:4:",
               "bond index 2 is out of range: the file has 2 particles, indices 0 to 1");
  EXPECT_ERROR("0 0 0 1\n1 0 0 1\nbonds\n-1 1\n", "pack.txt:4:", "bond index -1 is out of range");
  EXPECT_ERROR("0 0 0 1\n1 0 0 1\nbonds\n0 1.0\n", "pack.txt:4:", "bond index '1.0' is not an integer");
  EXPECT_ERROR("0 0 0 1\n1 0 0 1\nbonds\n0 1 1\n", "pack.txt:4:", "expected a bond 'i j'");
  EXPECT_ERROR("0 0 0 1\n1 0 0 1\nbonds\n1 1\n", "pack.txt:4:", "bond of particle 1 with itself");
  EXPECT_ERROR("0 0 0 1\n1 0 0 1\nbonds\n0 1\n1 0\n", "pack.txt:5:", "bond 0 1 is listed twice");
  EXPECT_ERROR("0 0 0 1\nbonds\nbonds\n", "pack.txt:3:", "a second 'bonds' line (the first is line 2)");
  EXPECT_ERROR("bonds\n0 0 0 1\n", "pack.txt:1:", "'bonds' before any particle line");
  EXPECT_ERROR("0 0 0 1\n1 0 0 1\nbonds\n2 0 0 1\n", "pack.txt:4:", "expected a bond 'i j'");
  EXPECT_ERROR("", "pack.txt", "no particle lines 'x y z r'");
  EXPECT_ERROR("# only a comment\n\n", "pack.txt", "no particle lines");
}

TEST(PackingFile, MissingFileIsNamed) {
  const std::string path = (fs::temp_directory_path() / "fracflow_no_such_packing.txt").string();
  fs::remove(path);
  try {
    read_packing_file(path);
    FAIL() << "no error for a missing file";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot open packing file '" + path + "'"), std::string::npos) << e.what();
  }
}

TEST(PackingFile, WriteThenReadKeepsEveryBit) {
  PackingFile p;
  p.pos = {Vec3(0.1, 1.0 / 3.0, -2e-7), Vec3(1e-3 + 1e-19, 7.123456789012345e-4, 0), Vec3(5, 6, 7)};
  p.radius = {1.0 / 7.0, 4.4e-4, 0.6e-3};
  p.has_bond_list = true;
  p.bonds = {{0, 1}, {1, 2}};
  const std::string path = (fs::temp_directory_path() / "fracflow_test_packing_roundtrip.txt").string();
  write_packing_file(path, p, "test packing\nsecond comment line");
  const PackingFile q = read_packing_file(path);
  EXPECT_EQ(q.pos, p.pos);
  EXPECT_EQ(q.radius, p.radius);
  EXPECT_TRUE(q.has_bond_list);
  EXPECT_EQ(q.bonds, p.bonds);
  fs::remove(path);
}

// A 4 x 3 x 2 simple-cubic lattice of touching 1 mm spheres, listed in reverse raster order (so
// the spatial sort must reorder it): 3*3*2 + 4*2*2 + 4*3*1 = 46 touching pairs.
PackingFile lattice() {
  PackingFile p;
  for (int k = 1; k >= 0; --k)
    for (int j = 2; j >= 0; --j)
      for (int i = 3; i >= 0; --i) {
        p.pos.emplace_back(2e-3 * i, 2e-3 * j, 2e-3 * k);
        p.radius.push_back(1e-3);
      }
  return p;
}
constexpr std::size_t kLatticeBonds = 46;

struct Placed {
  ParamTable table;
  Config cfg;
  DemSystem sys;
};

std::unique_ptr<Placed> system_for(const std::string& bond_law) {
  auto s = std::make_unique<Placed>();
  declare_dem_params(s->table);
  declare_sample_params(s->table);
  s->cfg = load_scenario(s->table, "<test>",
                         "[dem]\nbond_law = \"" + bond_law + "\"\n[sample]\nbond_gap = 0\n[dem.group.matrix]\ndensity = 1390\n"
                         "[dem.contact.matrix-matrix]\nemod = 2.09e9\n" +
                             (bond_law == "none" ? "" : "[dem.bond.matrix-matrix]\nemod = 2.09e9\n"),
                         {});
  s->sys.settings = build_settings(s->cfg);
  s->sys.materials = build_materials(s->cfg);
  return s;
}

// The bonds as pairs of centres, independent of the particle order.
std::set<std::pair<std::array<Real, 3>, std::array<Real, 3>>> bond_centres(const DemSystem& sys) {
  std::set<std::pair<std::array<Real, 3>, std::array<Real, 3>>> out;
  for (std::size_t b = 0; b < sys.bonds.i.size(); ++b) {
    const Vec3 a = sys.particles.pos[sys.bonds.i[b]], c = sys.particles.pos[sys.bonds.j[b]];
    std::array<Real, 3> x{a.x(), a.y(), a.z()}, y{c.x(), c.y(), c.z()};
    out.insert(std::minmax(x, y));
  }
  return out;
}

TEST(PackingFile, PlacedByTheBondGapRuleWithoutAList) {
  auto s = system_for("parallel");
  const SampleInfo info = place_packing(lattice(), s->cfg, s->sys, 0, false);
  EXPECT_EQ(s->sys.particles.size(), 24u);
  EXPECT_EQ(info.bonds, kLatticeBonds);
  EXPECT_EQ(intact_bonds(s->sys), kLatticeBonds);
  EXPECT_EQ(info.floaters, 0u);  // corners have 3 bonds
  EXPECT_EQ(info.axis, 2);
  EXPECT_DOUBLE_EQ(info.height, 4e-3);
  EXPECT_DOUBLE_EQ(info.width, 8e-3);
  EXPECT_EQ(s->sys.particles.pos[0], Vec3(6e-3, 4e-3, 2e-3));  // file order kept
  EXPECT_DOUBLE_EQ(s->sys.particles.mass[0], 1390 * 4.0 / 3.0 * kPi * 1e-9);
  EXPECT_NEAR(s->sys.settings.skin, 0.3e-3, 1e-18);  // dem.skin_ratio x mean radius
  add_platens(s->sys, info, 0.1);
  EXPECT_DOUBLE_EQ(s->sys.walls[0].point.z(), -1e-3);
  EXPECT_DOUBLE_EQ(s->sys.walls[1].point.z(), 3e-3);
}

TEST(PackingFile, BondListIsInstalledAsGivenAndFollowsTheSpatialOrder) {
  PackingFile p = lattice();
  p.has_bond_list = true;
  p.bonds = {{0, 1}, {0, 4}, {5, 17}};  // two touching pairs and one 2 mm apart (a list is taken as given)
  auto plain = system_for("parallel");
  place_packing(p, plain->cfg, plain->sys, 0, false);
  auto sorted = system_for("parallel");
  const SampleInfo info = place_packing(p, sorted->cfg, sorted->sys, 0, true);
  EXPECT_EQ(info.bonds, 3u);
  EXPECT_EQ(info.floaters, 24u);  // no particle has 3 bonds
  // Cells of 2 mm (two max radii), one sphere each, in raster order z-y-x from the lowest corner.
  EXPECT_EQ(sorted->sys.particles.pos[0], Vec3(0, 0, 0));
  EXPECT_EQ(sorted->sys.particles.pos[7], Vec3(6e-3, 2e-3, 0));
  EXPECT_EQ(sorted->sys.particles.pos[23], Vec3(6e-3, 4e-3, 2e-3));
  EXPECT_EQ(bond_centres(plain->sys), bond_centres(sorted->sys));
  for (std::size_t b = 0; b < sorted->sys.bonds.i.size(); ++b) EXPECT_LT(sorted->sys.bonds.i[b], sorted->sys.bonds.j[b]);

  auto gap_rule = system_for("parallel");
  const SampleInfo all = place_packing(lattice(), gap_rule->cfg, gap_rule->sys, 0, true);
  EXPECT_EQ(all.bonds, kLatticeBonds);
}

TEST(PackingFile, BondListWithoutABondLawIsRefused) {
  PackingFile p = lattice();
  p.has_bond_list = true;
  p.bonds = {{0, 1}};
  auto s = system_for("none");
  EXPECT_THROW(place_packing(p, s->cfg, s->sys, 0, false), InputError);
  p.bonds.clear();  // an empty list is fine
  EXPECT_EQ(place_packing(p, s->cfg, s->sys, 0, false).bonds, 0u);
}

}  // namespace
}  // namespace ff::dem
