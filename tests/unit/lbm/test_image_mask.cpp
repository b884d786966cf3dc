// Solid cells from a PGM image (ASCII P2 and binary P5), sampled onto the lattice, and the
// resulting cells bounce back like any other solid.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/error.hpp"
#include "lbm/image_mask.hpp"
#include "lbm/solver.hpp"

using namespace ff;
using namespace ff::lbm;

namespace {
std::filesystem::path scratch(const std::string& name) {
  const auto d = std::filesystem::temp_directory_path() / "fracflow_lbm_unit";
  std::filesystem::create_directories(d);
  return d / name;
}
}  // namespace

TEST(LbmImageMask, ReadsAsciiAndBinaryPgm) {
  // 4 x 2 image: top row dark on the left half.
  {
    std::ofstream f(scratch("a.pgm"));
    f << "P2\n# a comment\n4 2\n15\n0 0 15 15\n15 15 15 15\n";
  }
  {
    std::ofstream f(scratch("b.pgm"), std::ios::binary);
    f << "P5 4 2 255\n";
    const unsigned char px[8] = {0, 0, 255, 255, 255, 255, 255, 255};
    f.write(reinterpret_cast<const char*>(px), 8);
  }
  for (const char* name : {"a.pgm", "b.pgm"}) {
    const GreyImage img = read_pgm(scratch(name));
    ASSERT_EQ(img.width, 4);
    ASSERT_EQ(img.height, 2);
    EXPECT_EQ(img.pixels[0], 0);
    EXPECT_EQ(img.pixels[2], 255);
    // On an 8 x 4 lattice the dark quarter is x < 4, y >= 2 (the image's top row is y = ny - 1).
    const auto cells = solid_cells(img, 8, 4);
    EXPECT_EQ(cells.size(), 8u);
    for (auto& c : cells) {
      EXPECT_LT(c[0], 4);
      EXPECT_GE(c[1], 2);
    }
  }
}

TEST(LbmImageMask, RejectsBadFiles) {
  {
    std::ofstream f(scratch("bad.pgm"));
    f << "P3\n1 1\n255\n0 0 0\n";
  }
  EXPECT_THROW(read_pgm(scratch("bad.pgm")), InputError);
  EXPECT_THROW(read_pgm(scratch("missing.pgm")), InputError);
  {
    std::ofstream f(scratch("short.pgm"), std::ios::binary);
    f << "P5 4 4 255\n" << "abc";
  }
  EXPECT_THROW(read_pgm(scratch("short.pgm")), InputError);
}

// Pixels outside 0 .. maxval, or not numbers (fuzzed 2026-11-30): -5 wrapped round to a light grey and
// 999 to a dark one without a word, and a word ended the program with "error: stol". Each is now an
// input error that names the pixel and its value; 16-bit P5 values above the maxval too.
TEST(LbmImageMask, PixelsOutsideTheMaxvalAreNamed) {
  auto message = [](const std::string& name, const std::string& text) {
    {
      std::ofstream f(scratch(name), std::ios::binary);
      f << text;
    }
    try {
      (void)read_pgm(scratch(name));
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message("neg.pgm", "P2 3 1 255\n0 -5 0\n").find("pixel 2 (row 1, column 2) is -5"), std::string::npos);
  EXPECT_NE(message("over.pgm", "P2 2 2 15\n0 0\n16 0\n").find("pixel 3 (row 2, column 1) is 16"), std::string::npos);
  EXPECT_NE(message("word.pgm", "P2 2 1 255\n0 grey\n").find("is 'grey', not a whole number"), std::string::npos);
  EXPECT_NE(message("frac.pgm", "P2 2 1 255\n0 2.5\n").find("is '2.5'"), std::string::npos);
  // 16-bit binary: 0x01 0x2C = 300 above maxval 299.
  EXPECT_NE(message("p5.pgm", std::string("P5 1 1 299\n") + char(0x01) + char(0x2C)).find("is 300"), std::string::npos);
  EXPECT_EQ(message("ok.pgm", "P2 2 1 255\n0 255\n"), "accepted");
}

TEST(LbmImageMask, ImageCellsAreSolid) {
  GreyImage img;
  img.width = img.height = 2;
  img.pixels = {255, 0, 255, 255};  // dark top-right quarter
  Grid g(2, 6, 6, 1, {true, true, true});
  Solver<D2Q9, double> s(g, SolverSettings{});
  const int id = s.add_object("image", WallScheme::HalfwayBounceBack, Vec3::Zero());
  for (auto& c : solid_cells(img, 6, 6)) s.set_solid(c[0], c[1], 0, id);
  s.finalize();
  EXPECT_TRUE(s.is_solid(4, 4, 0));
  EXPECT_FALSE(s.is_solid(1, 1, 0));
  EXPECT_EQ(s.num_fluid_cells(), 27u);
  EXPECT_GT(s.objects()[id].links, 0);
}
