// STL reading/writing, vertex merging, closedness and volume.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.hpp"
#include "geometry/point_in_mesh.hpp"
#include "geometry/stl.hpp"

namespace ff::geom {
namespace {

namespace fs = std::filesystem;
const fs::path kData = fs::path(FRACFLOW_TEST_DATA) / "geometry";

fs::path temp_file(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "fracflow_test_geometry_stl";
  fs::create_directories(dir);
  return dir / name;
}

// Message of the InputError thrown by f (empty if none).
template <class F>
std::string input_error(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

void expect_same_mesh(const TriangleMesh& a, const TriangleMesh& b, Real tol) {
  ASSERT_EQ(a.vertices.size(), b.vertices.size());
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  // Vertex order may change with merging: compare triangle corners.
  for (std::size_t t = 0; t < a.triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      ASSERT_LE((a.vertices[a.triangles[t][k]] - b.vertices[b.triangles[t][k]]).norm(), tol) << "triangle " << t;
    }
  }
}

TEST(Stl, BinaryRoundTripOfEllipsoid) {
  const TriangleMesh m = make_ellipsoid_mesh(Vec3(1, 2, 3), Vec3(3, 2, 1), Quat::Identity(), 3);
  const fs::path f = temp_file("ellipsoid_binary.stl");
  write_stl_binary(f, m);
  EXPECT_EQ(fs::file_size(f), 84 + 50 * m.triangles.size());
  const TriangleMesh r = read_stl(f);
  expect_same_mesh(m, r, 1e-6);  // float32 storage
  EXPECT_TRUE(is_closed(r));
  EXPECT_NEAR(mesh_volume(r), mesh_volume(m), 1e-5 * mesh_volume(m));
}

TEST(Stl, AsciiRoundTripOfCylinder) {
  const TriangleMesh m = make_cylinder_mesh(Vec3(0, 0, -1), Vec3(0, 1, 1).normalized(), 0.5, 2.0, 24, 3);
  const fs::path f = temp_file("cylinder_ascii.stl");
  write_stl_ascii(f, m);
  const TriangleMesh r = read_stl(f);
  expect_same_mesh(m, r, 1e-6);
  EXPECT_TRUE(is_closed(r));
  // Prism volume: polygon area (n/2) R^2 sin(2 pi / n) times the length.
  const Real exact = 12 * 0.25 * std::sin(2 * kPi / 24) * 2.0;
  EXPECT_NEAR(mesh_volume(r), exact, 1e-6);
}

TEST(Stl, ReadsAsciiCubeAndMergesVertices) {
  const TriangleMesh m = read_stl(kData / "unit_cube_ascii.stl");
  EXPECT_EQ(m.triangles.size(), 12u);
  EXPECT_EQ(m.vertices.size(), 8u);
  EXPECT_TRUE(is_closed(m));
  EXPECT_DOUBLE_EQ(mesh_volume(m), 1.0);
}

TEST(Stl, BinaryStartingWithSolidIsDetectedBySize) {
  const TriangleMesh m = read_stl(kData / "unit_cube_solid_header.stl");
  EXPECT_EQ(m.triangles.size(), 12u);
  EXPECT_EQ(m.vertices.size(), 8u);
  EXPECT_DOUBLE_EQ(mesh_volume(m), 1.0);
}

TEST(Stl, OpenMeshIsDetectedAndRefusedAsRegion) {
  const fs::path f = kData / "open_box_binary.stl";
  const TriangleMesh m = read_stl(f);
  EXPECT_FALSE(is_closed(m));
  EXPECT_EQ(open_edge_count(m), 4);
  const std::string msg = input_error([&] { load_mesh_region(f); });
  EXPECT_NE(msg.find("not closed: 4 open edges"), std::string::npos) << msg;
  EXPECT_NE(msg.find("open_box_binary.stl"), std::string::npos) << msg;
}

TEST(Stl, ErrorsNameTheFileAndTheProblem) {
  const struct {
    const char* file;
    const char* what;
  } cases[] = {{"truncated_binary.stl", "truncated"},
               {"truncated_ascii.stl", "truncated"},
               {"nan_ascii.stl", "NaN"},
               {"empty_ascii.stl", "zero triangles"},
               {"does_not_exist.stl", "cannot be opened"}};
  for (const auto& c : cases) {
    const std::string msg = input_error([&] { read_stl(kData / c.file); });
    EXPECT_NE(msg.find(c.file), std::string::npos) << msg;
    EXPECT_NE(msg.find(c.what), std::string::npos) << msg;
  }
}

TEST(Stl, EmptyBinaryAndNanBinaryAreRejected) {
  TriangleMesh none;
  const fs::path empty = temp_file("empty_binary.stl");
  write_stl_binary(empty, none);
  EXPECT_NE(input_error([&] { read_stl(empty); }).find("zero triangles"), std::string::npos);

  TriangleMesh bad = make_box_mesh(Vec3::Zero(), Vec3::Ones());
  bad.vertices[3].y() = std::nan("");
  const fs::path nan_file = temp_file("nan_binary.stl");
  write_stl_binary(nan_file, bad);
  const std::string msg = input_error([&] { read_stl(nan_file); });
  EXPECT_NE(msg.find("NaN"), std::string::npos) << msg;
}

TEST(Stl, PrimitiveMeshesAreClosedAndOutward) {
  const TriangleMesh box = make_box_mesh(Vec3(-1, 0, 2), Vec3(1, 3, 2.5), 3);
  EXPECT_TRUE(is_closed(box));
  EXPECT_NEAR(mesh_volume(box), 2 * 3 * 0.5, 1e-12);
  const TriangleMesh sph = make_ellipsoid_mesh(Vec3::Zero(), Vec3::Constant(2), Quat::Identity(), 4);
  EXPECT_TRUE(is_closed(sph));
  EXPECT_EQ(sph.triangles.size(), 20u * 256u);
  // The inscribed polyhedron is a little smaller than the sphere (< 1% at 5120 facets).
  const Real exact = 4.0 / 3.0 * kPi * 8;
  EXPECT_LT(mesh_volume(sph), exact);
  EXPECT_GT(mesh_volume(sph), 0.99 * exact);
}

}  // namespace
}  // namespace ff::geom
