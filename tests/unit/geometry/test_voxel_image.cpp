// PGM slice stacks: round trips, nearest-voxel lookup, and errors that name the file.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.hpp"
#include "geometry/voxel_image.hpp"

namespace ff::geom {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "fracflow_test_voxel" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

VoxelImage pattern(int nx, int ny, int nz, int modulus) {
  VoxelImage img;
  img.nx = nx;
  img.ny = ny;
  img.nz = nz;
  img.origin = Vec3(-1, 0.5, 2);
  img.spacing = Vec3(0.1, 0.2, 0.3);
  img.value.resize(static_cast<std::size_t>(nx) * ny * nz);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) img.value[img.index(i, j, k)] = static_cast<std::uint16_t>((i + 7 * j + 31 * k * k) % modulus);
  return img;
}

template <class F>
std::string input_error(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(VoxelImage, RoundTrip8And16Bit) {
  for (const int bits : {8, 16}) {
    const VoxelImage img = pattern(7, 5, 12, bits == 8 ? 256 : 65536);
    const fs::path dir = fresh_dir("roundtrip" + std::to_string(bits));
    write_pgm_stack(dir, img, bits);
    const VoxelImage back = read_pgm_stack(dir, img.origin, img.spacing);
    EXPECT_EQ(back.nx, 7);
    EXPECT_EQ(back.ny, 5);
    EXPECT_EQ(back.nz, 12);  // slice_00010 sorts after slice_00009
    EXPECT_EQ(back.value, img.value) << bits << " bits";
  }
}

TEST(VoxelImage, NearestVoxelAndZeroOutside) {
  const VoxelImage img = pattern(4, 3, 2, 1000);
  // origin is the centre of voxel (0,0,0); voxel (i,j,k) spans +- half a spacing around its centre.
  const auto centre = [&](int i, int j, int k) { return Vec3(img.origin + Vec3(i, j, k).cwiseProduct(img.spacing)); };
  EXPECT_EQ(img.at(centre(2, 1, 1)), img.value[img.index(2, 1, 1)]);
  EXPECT_EQ(img.at(centre(2, 1, 1) + 0.49 * img.spacing), img.value[img.index(2, 1, 1)]);
  EXPECT_EQ(img.at(centre(2, 1, 1) + Vec3(0.51 * img.spacing.x(), 0, 0)), img.value[img.index(3, 1, 1)]);
  EXPECT_EQ(img.at(centre(3, 2, 1) + 0.51 * img.spacing), 0);  // beyond the last voxel
  EXPECT_EQ(img.at(centre(0, 0, 0) - 0.51 * img.spacing), 0);
  EXPECT_NE(img.at(centre(3, 2, 1)), 0);
}

TEST(VoxelImage, HeaderCommentsAndMaxvalAreHonoured) {
  const fs::path dir = fresh_dir("comments");
  {
    std::ofstream f(dir / "a.pgm", std::ios::binary);
    f << "P5\n# made by hand\n3 # width\n2\n# maxval next\n1000\n";
    const unsigned char px[12] = {0, 1, 0, 2, 3, 232, 0, 0, 0, 7, 0, 9};  // 16-bit big-endian
    f.write(reinterpret_cast<const char*>(px), 12);
  }
  const VoxelImage img = read_pgm_stack(dir, Vec3::Zero(), Vec3::Ones());
  EXPECT_EQ(img.value, (std::vector<std::uint16_t>{1, 2, 1000, 0, 7, 9}));
}

TEST(VoxelImage, ErrorsNameTheFile) {
  {
    const fs::path dir = fresh_dir("ascii_pgm");
    std::ofstream(dir / "slice_0.pgm") << "P2\n2 2\n255\n1 2 3 4\n";
    const std::string msg = input_error([&] { read_pgm_stack(dir, Vec3::Zero(), Vec3::Ones()); });
    EXPECT_NE(msg.find("slice_0.pgm"), std::string::npos) << msg;
    EXPECT_NE(msg.find("P5"), std::string::npos) << msg;
  }
  {
    const fs::path dir = fresh_dir("truncated");
    std::ofstream(dir / "s0.pgm", std::ios::binary) << "P5\n4 4\n255\n" << std::string(10, 'x');
    const std::string msg = input_error([&] { read_pgm_stack(dir, Vec3::Zero(), Vec3::Ones()); });
    EXPECT_NE(msg.find("s0.pgm"), std::string::npos) << msg;
    EXPECT_NE(msg.find("truncated"), std::string::npos) << msg;
  }
  {
    const fs::path dir = fresh_dir("sizes");
    std::ofstream(dir / "s0.pgm", std::ios::binary) << "P5\n2 2\n255\n" << std::string(4, 'x');
    std::ofstream(dir / "s1.pgm", std::ios::binary) << "P5\n3 2\n255\n" << std::string(6, 'x');
    const std::string msg = input_error([&] { read_pgm_stack(dir, Vec3::Zero(), Vec3::Ones()); });
    EXPECT_NE(msg.find("s1.pgm"), std::string::npos) << msg;
  }
  {
    const fs::path dir = fresh_dir("empty");
    EXPECT_NE(input_error([&] { read_pgm_stack(dir, Vec3::Zero(), Vec3::Ones()); }).find("no *.pgm"),
              std::string::npos);
  }
  VoxelImage big = pattern(3, 3, 1, 1000);
  big.value[4] = 300;
  EXPECT_NE(input_error([&] { write_pgm_stack(fresh_dir("too_big"), big, 8); }).find("does not fit in 8 bits"),
            std::string::npos);
}

}  // namespace
}  // namespace ff::geom
