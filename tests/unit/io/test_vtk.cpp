// VTK XML writer: the files are parsed back here independently (XML header, then each
// appended block's 8-byte length and bytes) and compared bit for bit with what was written.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <regex>

#include "core/error.hpp"
#include "io/vtk.hpp"
#include "scratch_dir.hpp"

using namespace ff;

namespace {

struct Parsed {
  struct Array {
    std::string type, name;
    int components = 0;
    std::uint64_t offset = 0;
    std::string bytes;  // payload after the 8-byte header
    template <class T> std::vector<T> as() const {
      std::vector<T> v(bytes.size() / sizeof(T));
      std::memcpy(v.data(), bytes.data(), v.size() * sizeof(T));
      return v;
    }
  };
  std::string xml;                      // everything before <AppendedData
  std::vector<Array> arrays;            // in file order
  std::map<std::string, Array> by_name;  // (last one wins for duplicate names like "connectivity")
};

std::string attr(const std::string& element, const std::string& name) {
  std::smatch m;
  if (!std::regex_search(element, m, std::regex("\\s" + name + "=\"([^\"]*)\""))) return "";
  return m[1];
}

// Independent reader for header_type="UInt64" appended raw data.
Parsed parse(const std::filesystem::path& p) {
  Parsed r;
  const std::string f = test::slurp(p);
  const auto app = f.find("<AppendedData encoding=\"raw\">");
  EXPECT_NE(app, std::string::npos);
  r.xml = f.substr(0, app);
  EXPECT_NE(r.xml.find("header_type=\"UInt64\""), std::string::npos);
  EXPECT_NE(r.xml.find("byte_order=\"LittleEndian\""), std::string::npos);
  const auto start = f.find('_', app) + 1;  // data begin right after the underscore
  std::uint64_t expected_offset = 0;
  std::regex da("<DataArray[^>]*/>");
  for (auto it = std::sregex_iterator(r.xml.begin(), r.xml.end(), da); it != std::sregex_iterator(); ++it) {
    const std::string el = it->str();
    Parsed::Array a;
    a.type = attr(el, "type");
    a.name = attr(el, "Name");
    a.components = std::stoi(attr(el, "NumberOfComponents"));
    a.offset = std::stoull(attr(el, "offset"));
    EXPECT_EQ(attr(el, "format"), "appended");
    EXPECT_EQ(a.offset, expected_offset) << a.name << ": blocks must be contiguous, in header order";
    std::uint64_t n = 0;
    std::memcpy(&n, f.data() + start + a.offset, 8);
    a.bytes = f.substr(start + a.offset + 8, n);
    EXPECT_EQ(a.bytes.size(), n) << a.name << ": block runs past the end of the file";
    expected_offset = a.offset + 8 + n;
    r.arrays.push_back(a);
    r.by_name[a.name] = a;
  }
  EXPECT_EQ(f.substr(start + expected_offset), "\n  </AppendedData>\n</VTKFile>\n");
  return r;
}

}  // namespace

TEST(io_vtk, ThreePointPolyDataRoundTripsExactly) {
  test::ScratchDir d;
  const std::vector<Vec3> pts{{0.1, 0.2, 0.3}, {1.0 / 3.0, -1e-300, 7e300}, {0, -0.0, 5}};
  const std::vector<Vec3> vel{{1, 2, 3}, {std::numeric_limits<double>::quiet_NaN(), 0.5, -4}, {9, 8, 7}};
  const std::vector<double> radius{1e-3, 2e-3, 1.5e-3};
  const std::vector<std::int32_t> id{7, -1, 2147483647};
  const std::vector<std::uint8_t> flag{0, 1, 255};
  const std::vector<VtkArray> point_data{vtk_array("velocity", vel), vtk_array("radius", radius), vtk_array("id", id),
                                         vtk_array("flag", flag)};
  write_vtp(d / "p.vtp", pts, VtpCells{}, point_data, {});
  const Parsed r = parse(d / "p.vtp");
  EXPECT_NE(r.xml.find("type=\"PolyData\""), std::string::npos);
  EXPECT_NE(r.xml.find("NumberOfPoints=\"3\" NumberOfVerts=\"3\" NumberOfLines=\"0\""), std::string::npos) << r.xml;
  ASSERT_EQ(r.arrays.size(), 7u);  // 4 point arrays, Points, connectivity, offsets
  const auto& v = r.by_name.at("velocity");
  EXPECT_EQ(v.type, "Float64");
  EXPECT_EQ(v.components, 3);
  ASSERT_EQ(v.bytes.size(), 9 * sizeof(double));
  EXPECT_EQ(std::memcmp(v.bytes.data(), vel.data(), v.bytes.size()), 0);  // bit-exact, NaN included
  const auto& p = r.by_name.at("Points");
  ASSERT_EQ(p.bytes.size(), 9 * sizeof(double));
  EXPECT_EQ(std::memcmp(p.bytes.data(), pts.data(), p.bytes.size()), 0);
  EXPECT_TRUE(std::signbit(p.as<double>()[7]));  // -0.0 kept
  EXPECT_EQ(r.by_name.at("radius").as<double>(), radius);
  EXPECT_EQ(r.by_name.at("id").type, "Int32");
  EXPECT_EQ(r.by_name.at("id").as<std::int32_t>(), id);
  EXPECT_EQ(r.by_name.at("flag").type, "UInt8");
  EXPECT_EQ(r.by_name.at("flag").as<std::uint8_t>(), flag);
  EXPECT_EQ(r.by_name.at("connectivity").as<std::int64_t>(), (std::vector<std::int64_t>{0, 1, 2}));
  EXPECT_EQ(r.by_name.at("offsets").as<std::int64_t>(), (std::vector<std::int64_t>{1, 2, 3}));
}

TEST(io_vtk, LinesAndTrianglesWithCellData) {
  test::ScratchDir d;
  const std::vector<Vec3> pts{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
  const std::vector<std::int64_t> bonds{0, 1, 2, 3};
  const std::vector<double> force{-1.5, 2.5};
  const std::vector<Quat> q{Quat(1, 0, 0, 0), Quat(0.5, 0.5, 0.5, 0.5)};
  write_vtp(d / "b.vtp", pts, {VtpCells::Lines, bonds}, {}, std::vector<VtkArray>{vtk_array("force", force), vtk_array("q", q)});
  Parsed r = parse(d / "b.vtp");
  EXPECT_NE(r.xml.find("NumberOfVerts=\"0\" NumberOfLines=\"2\""), std::string::npos) << r.xml;
  EXPECT_NE(r.xml.find("<Lines>"), std::string::npos);
  EXPECT_EQ(r.by_name.at("connectivity").as<std::int64_t>(), bonds);
  EXPECT_EQ(r.by_name.at("offsets").as<std::int64_t>(), (std::vector<std::int64_t>{2, 4}));
  EXPECT_EQ(r.by_name.at("force").as<double>(), force);
  EXPECT_EQ(r.by_name.at("q").components, 4);
  EXPECT_EQ(r.by_name.at("q").as<double>(), (std::vector<double>{0, 0, 0, 1, 0.5, 0.5, 0.5, 0.5}));  // x y z w

  const std::vector<std::int64_t> tris{0, 1, 2, 1, 3, 2};
  const std::vector<float> area{0.5f, 0.25f};
  write_vtp(d / "t.vtp", pts, {VtpCells::Triangles, tris}, {}, std::vector<VtkArray>{vtk_array("area", area)});
  r = parse(d / "t.vtp");
  EXPECT_NE(r.xml.find("NumberOfPolys=\"2\""), std::string::npos) << r.xml;
  EXPECT_NE(r.xml.find("<Polys>"), std::string::npos);
  EXPECT_EQ(r.by_name.at("offsets").as<std::int64_t>(), (std::vector<std::int64_t>{3, 6}));
  EXPECT_EQ(r.by_name.at("area").type, "Float32");
  EXPECT_EQ(r.by_name.at("area").as<float>(), area);

  write_vtp(d / "empty.vtp", {}, {}, {}, {});  // zero particles is a valid file too
  r = parse(d / "empty.vtp");
  EXPECT_EQ(r.by_name.at("Points").bytes.size(), 0u);
}

TEST(io_vtk, ImageDataHeaderAndCellData) {
  test::ScratchDir d;
  const std::vector<float> rho{1, 2, 3, 4, 5, 6};
  const std::vector<std::uint8_t> solid{0, 0, 1, 0, 1, 1};
  std::vector<Vec3> u(6, Vec3(0.01, -0.02, 0));
  write_vti(d / "f.vti", {3, 2, 1}, Vec3(0.5, -1, 0), Vec3(0.25, 0.25, 0.25),
            std::vector<VtkArray>{vtk_array("rho", rho), vtk_array("solid", solid), vtk_array("u", u)});
  const Parsed r = parse(d / "f.vti");
  EXPECT_NE(r.xml.find("type=\"ImageData\""), std::string::npos);
  EXPECT_NE(r.xml.find("WholeExtent=\"0 3 0 2 0 1\" Origin=\"0.5 -1 0\" Spacing=\"0.25 0.25 0.25\""), std::string::npos) << r.xml;
  EXPECT_NE(r.xml.find("<Piece Extent=\"0 3 0 2 0 1\">"), std::string::npos);
  EXPECT_EQ(r.by_name.at("rho").as<float>(), rho);
  EXPECT_EQ(r.by_name.at("solid").as<std::uint8_t>(), solid);
  EXPECT_EQ(r.by_name.at("u").as<double>().size(), 18u);
}

TEST(io_vtk, SizeMismatchesAreCaught) {
  test::ScratchDir d;
  const std::vector<Vec3> pts{{0, 0, 0}, {1, 0, 0}};
  const std::vector<double> two{1, 2}, three{1, 2, 3};
  auto message = [](auto&& f) -> std::string {
    try {
      f();
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(message([&] { write_vtp(d / "a.vtp", pts, {}, std::vector<VtkArray>{vtk_array("r", three)}, {}); }).find("'r'"),
            std::string::npos);
  const std::vector<std::int64_t> bad{0, 2};
  EXPECT_NE(message([&] { write_vtp(d / "b.vtp", pts, {VtpCells::Lines, bad}, {}, {}); }).find("point 2"), std::string::npos);
  const std::vector<std::int64_t> odd{0, 1, 1};
  EXPECT_THROW(write_vtp(d / "c.vtp", pts, {VtpCells::Lines, odd}, {}, {}), Error);
  EXPECT_THROW(write_vti(d / "d.vti", {2, 2, 1}, Vec3::Zero(), Vec3::Ones(), std::vector<VtkArray>{vtk_array("x", two)}), Error);
  EXPECT_THROW(write_vti(d / "e.vti", {0, 2, 1}, Vec3::Zero(), Vec3::Ones(), {}), Error);
  EXPECT_FALSE(std::filesystem::exists(d / "a.vtp"));  // nothing half-written
}
