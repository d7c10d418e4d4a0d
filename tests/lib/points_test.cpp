// Tests for lib/points: point-file reading and writing, and the fittability checks.
#include <gtest/gtest.h>
#include <unistd.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkFloatArray.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataReader.h>
#include <vtkPolyDataWriter.h>
#include <vtkStringArray.h>
#include <vtkTriangleFilter.h>
#include <vtkUnsignedCharArray.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>

#include "articula/core/error.hpp"
#include "articula/points/mesh_file.hpp"
#include "articula/points/ply_writer.hpp"
#include "articula/points/point_io.hpp"

namespace fs = std::filesystem;
using articula::InputError;
using articula::UsageError;
using articula::points::checkFittable;
using articula::points::MeshFile;
using articula::points::readMeshFile;
using articula::points::PointCloud;
using articula::points::readPoints;
using articula::points::writePoints;
namespace points = articula::points;

namespace {

class PointsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("articula_points_test_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path file(const std::string& name) const { return dir_ / name; }

  fs::path writeFile(const std::string& name, const std::string& bytes) const {
    const fs::path path = file(name);
    std::ofstream out(path, std::ios::binary);
    out << bytes;
    return path;
  }

  fs::path dir_;
};

// The InputError message of read(path); fails the test if anything else happens.
std::string inputErrorOf(const fs::path& path, const std::function<void(const fs::path&)>& read) {
  try {
    read(path);
  } catch (const InputError& e) {
    EXPECT_EQ(e.code(), articula::ExitCode::InvalidInput);
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected InputError, got another exception: " << e.what();
    return {};
  }
  ADD_FAILURE() << "expected InputError reading " << path << ", nothing thrown";
  return {};
}
std::string readError(const fs::path& path) {
  return inputErrorOf(path, [](const fs::path& p) { readPoints(p); });
}
std::string meshError(const fs::path& path) {
  return inputErrorOf(path, [](const fs::path& p) { readMeshFile(p); });
}

std::string fittableError(const PointCloud& cloud, int min_points) {
  try {
    checkFittable(cloud, min_points, "femoral head cap");
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("femoral head cap"), std::string::npos) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "expected InputError from checkFittable";
  return {};
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// A cloud with awkward doubles (not representable in float or short decimals) and unit normals.
PointCloud awkwardCloud(bool with_normals) {
  PointCloud cloud;
  cloud.positions.resize(5, 3);
  cloud.positions << 0.1, 1.0 / 3.0, -123.456789012345678,  //
      1e-300, -2.5e7, std::nextafter(1.0, 2.0),             //
      -0.0, 42.0, std::sqrt(2.0),                           //
      M_PI, -M_E, 1e10 / 7.0,                               //
      -17.25, 0.0, 5e-324;
  if (with_normals) {
    cloud.normals.resize(5, 3);
    for (Eigen::Index i = 0; i < 5; ++i)
      cloud.normals.row(i) = Eigen::RowVector3d(std::cos(0.3 * i), std::sin(0.7 * i), 0.2 + i).normalized();
  }
  return cloud;
}

void expectBitwiseEqual(const Eigen::MatrixX3d& a, const Eigen::MatrixX3d& b) {
  ASSERT_EQ(a.rows(), b.rows());
  for (Eigen::Index i = 0; i < a.rows(); ++i)
    for (int k = 0; k < 3; ++k)
      EXPECT_EQ(std::memcmp(&a(i, k), &b(i, k), sizeof(double)), 0)
          << "row " << i << " col " << k << ": " << a(i, k) << " vs " << b(i, k);
}

template <typename T>
void appendBigEndian(std::string& out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  const std::uint16_t one = 1;
  if (*reinterpret_cast<const unsigned char*>(&one) == 1) std::reverse(bytes, bytes + sizeof(T));
  out.append(bytes, sizeof(T));
}

template <typename T>
void appendLittleEndian(std::string& out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  const std::uint16_t one = 1;
  if (*reinterpret_cast<const unsigned char*>(&one) != 1) std::reverse(bytes, bytes + sizeof(T));
  out.append(bytes, sizeof(T));
}

fs::path sharedData() {
  if (const char* env = std::getenv("ARTICULA_SHARED_DATA")) return env;
  return ARTICULA_SHARED_DATA_DEFAULT;
}

// ---- round trips -------------------------------------------------------------------------------------

TEST_F(PointsTest, PlyRoundTripIsBitExactWithAndWithoutNormals) {
  for (bool with_normals : {true, false}) {
    const PointCloud cloud = awkwardCloud(with_normals);
    const fs::path path = file(with_normals ? "n.ply" : "p.ply");
    writePoints(path, cloud);
    const PointCloud back = readPoints(path);
    expectBitwiseEqual(back.positions, cloud.positions);
    EXPECT_EQ(back.normals.rows(), with_normals ? 5 : 0);
    if (with_normals) expectBitwiseEqual(back.normals, cloud.normals);
    // Header + 8-byte doubles per value, nothing more.
    const auto values = static_cast<std::uintmax_t>(with_normals ? 30 : 15);
    std::ifstream in(path, std::ios::binary);
    std::string header, line;
    while (std::getline(in, line) && line != "end_header") header += line + "\n";
    EXPECT_EQ(fs::file_size(path), header.size() + std::string("end_header\n").size() + 8 * values);
  }
}

TEST_F(PointsTest, CsvRoundTripIsExactWithAndWithoutNormals) {
  for (bool with_normals : {true, false}) {
    const PointCloud cloud = awkwardCloud(with_normals);
    const fs::path path = file(with_normals ? "n.csv" : "p.csv");
    writePoints(path, cloud);
    std::ifstream in(path);
    std::string header;
    std::getline(in, header);
    EXPECT_EQ(header, with_normals ? "x_mm,y_mm,z_mm,nx,ny,nz" : "x_mm,y_mm,z_mm");
    const PointCloud back = readPoints(path);
    expectBitwiseEqual(back.positions, cloud.positions);
    EXPECT_EQ(back.normals.rows(), with_normals ? 5 : 0);
    if (with_normals) expectBitwiseEqual(back.normals, cloud.normals);
  }
}

TEST_F(PointsTest, PlyHeaderStatesFrameUnitsAndCallerComments) {
  const fs::path path = file("c.ply");
  writePoints(path, awkwardCloud(false), {"source LHDL_CT_femur_r.stl", "two\nlines"});
  std::ifstream in(path, std::ios::binary);
  std::string header, line;
  while (std::getline(in, line) && line != "end_header") header += line + "\n";
  EXPECT_TRUE(contains(header, "format binary_little_endian 1.0\n")) << header;
  EXPECT_TRUE(contains(header, "comment coordinates LPS, units mm\n")) << header;
  EXPECT_TRUE(contains(header, "comment source LHDL_CT_femur_r.stl\n")) << header;
  EXPECT_TRUE(contains(header, "comment two lines\n")) << header;
  EXPECT_TRUE(contains(header, "property double x\n")) << header;
  EXPECT_EQ(readPoints(path).positions.rows(), 5);
}

TEST_F(PointsTest, WriteRefusesToOverwriteWhenAskedAndRejectsUnknownExtensions) {
  const fs::path path = file("keep.csv");
  writePoints(path, awkwardCloud(false));
  const auto size = fs::file_size(path);
  PointCloud other;
  other.positions = Eigen::MatrixX3d::Ones(2, 3);
  EXPECT_THROW(writePoints(path, other, {}, false), UsageError);
  EXPECT_EQ(fs::file_size(path), size);
  EXPECT_EQ(readPoints(path).positions.rows(), 5);
  writePoints(path, other, {}, true);
  EXPECT_EQ(readPoints(path).positions.rows(), 2);

  EXPECT_THROW(writePoints(file("points.vtk"), other), UsageError);
  EXPECT_FALSE(fs::exists(file("points.vtk")));
  // No temporary files left behind.
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);
}

// ---- PLY written by hand -------------------------------------------------------------------------------

TEST_F(PointsTest, ReadsAsciiPlyWithFloatsExtraPropertiesFacesAndCrlf) {
  const std::string text =
      "ply\r\n"
      "format ascii 1.0\r\n"
      "comment made by hand\r\n"
      "element vertex 3\r\n"
      "property float x\r\n"
      "property float y\r\n"
      "property float z\r\n"
      "property float nx\r\n"
      "property float ny\r\n"
      "property float nz\r\n"
      "property uchar red\r\n"
      "element face 1\r\n"
      "property list uchar int vertex_indices\r\n"
      "end_header\r\n"
      "1.5 -2.25 3 0 0 2 255\r\n"
      "\r\n"
      "4e1 5.0 -6.125 0 3 4 0\r\n"
      "7 8 9 1 0 0 12\r\n"
      "3 0 1 2\r\n";
  const PointCloud cloud = readPoints(writeFile("hand.ply", text));
  Eigen::MatrixX3d positions(3, 3), normals(3, 3);
  positions << 1.5, -2.25, 3, 40, 5, -6.125, 7, 8, 9;
  normals << 0, 0, 1, 0, 0.6, 0.8, 1, 0, 0;  // scaled to unit length
  EXPECT_EQ(cloud.positions, positions);
  ASSERT_EQ(cloud.normals.rows(), 3);
  EXPECT_LT((cloud.normals - normals).cwiseAbs().maxCoeff(), 1e-15);
}

TEST_F(PointsTest, ReadsBinaryBigEndianPlyWithMixedTypesAndAnElementBeforeTheVertices) {
  std::string bytes =
      "ply\n"
      "format binary_big_endian 1.0\n"
      "element material 2\n"
      "property list uchar int ids\n"
      "property float shininess\n"
      "element vertex 2\n"
      "property float x\n"
      "property double y\n"
      "property int z\n"
      "property uchar quality\n"
      "property double nx\n"
      "property double ny\n"
      "property double nz\n"
      "element face 1\n"
      "property list uchar int vertex_indices\n"
      "end_header\n";
  // Two materials with lists of 3 and 0 ids.
  bytes += char(3);
  for (std::int32_t id : {7, 8, 9}) appendBigEndian(bytes, id);
  appendBigEndian(bytes, 0.5f);
  bytes += char(0);
  appendBigEndian(bytes, 0.25f);
  // Vertices.
  appendBigEndian(bytes, 1.25f);
  appendBigEndian(bytes, 0.1);
  appendBigEndian(bytes, std::int32_t{-300});
  bytes += char(200);
  appendBigEndian(bytes, 0.0);
  appendBigEndian(bytes, 1.0);
  appendBigEndian(bytes, 0.0);
  appendBigEndian(bytes, -3.5f);
  appendBigEndian(bytes, 1.0 / 3.0);
  appendBigEndian(bytes, std::int32_t{70000});
  bytes += char(1);
  appendBigEndian(bytes, 0.6);
  appendBigEndian(bytes, 0.0);
  appendBigEndian(bytes, -0.8);
  // A face that we do not need.
  bytes += char(2);
  appendBigEndian(bytes, std::int32_t{0});
  appendBigEndian(bytes, std::int32_t{1});

  const PointCloud cloud = readPoints(writeFile("be.ply", bytes));
  ASSERT_EQ(cloud.positions.rows(), 2);
  EXPECT_EQ(cloud.positions(0, 0), 1.25);
  EXPECT_EQ(cloud.positions(0, 1), 0.1);  // exact double
  EXPECT_EQ(cloud.positions(0, 2), -300.0);
  EXPECT_EQ(cloud.positions(1, 0), -3.5);
  EXPECT_EQ(cloud.positions(1, 1), 1.0 / 3.0);
  EXPECT_EQ(cloud.positions(1, 2), 70000.0);
  ASSERT_EQ(cloud.normals.rows(), 2);
  EXPECT_EQ(cloud.normals.row(0), Eigen::RowVector3d(0, 1, 0));
  EXPECT_LT((cloud.normals.row(1) - Eigen::RowVector3d(0.6, 0, -0.8)).norm(), 1e-15);
}

TEST_F(PointsTest, ReadsBinaryLittleEndianPlyOfFloatsWithoutNormals) {
  std::string bytes =
      "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n";
  for (float v : {1.0f, 2.0f, 3.0f, -0.5f, 1e-3f, 1e6f}) appendLittleEndian(bytes, v);
  const PointCloud cloud = readPoints(writeFile("le.PLY", bytes));
  ASSERT_EQ(cloud.positions.rows(), 2);
  EXPECT_EQ(cloud.normals.rows(), 0);
  EXPECT_EQ(cloud.positions.row(1), Eigen::RowVector3d(-0.5, double(1e-3f), 1e6));
}

// ---- delimited text ---------------------------------------------------------------------------------------

TEST_F(PointsTest, ReadsTextWithAndWithoutHeaderAndEverySeparator) {
  Eigen::MatrixX3d expected(2, 3);
  expected << 1.5, -2, 3e2, 4, 5.25, -6;
  const std::pair<const char*, const char*> cases[] = {
      {"comma.csv", "x,y,z\n1.5,-2,3e2\n4,5.25,-6\n"},
      {"comma_spaces.csv", "x, y, z\r\n1.5, -2, 3e2\r\n4, 5.25, -6\r\n"},
      {"no_header.csv", "1.5,-2,3e2\n4,5.25,-6\n"},
      {"semicolon.csv", "X;Y;Z\n1.5;-2;3e2\n\n4;5.25;-6\n"},
      {"tab.txt", "1.5\t-2\t3e2\n4\t5.25\t-6\n"},
      {"space.xyz", "# exported by hand\n  1.5  -2 3e2\n4 5.25   -6  \n"},
      {"named_columns.csv", "id,z_mm,y_mm,x_mm,quality\n0,3e2,-2,1.5,9\n1,-6,5.25,4,9\n"},
  };
  for (const auto& [name, text] : cases) {
    const PointCloud cloud = readPoints(writeFile(name, text));
    EXPECT_EQ(cloud.positions, expected) << name;
    EXPECT_EQ(cloud.normals.rows(), 0) << name;
  }
}

TEST_F(PointsTest, ReadsTextNormalsPositionallyOrByName) {
  for (const auto& [name, text] :
       {std::pair<const char*, const char*>{"six.csv", "1,2,3,0,0,-5\n4,5,6,0,1,0\n"},
        std::pair<const char*, const char*>{"named.csv", "nz,ny,nx,x,y,z\n-5,0,0,1,2,3\n0,1,0,4,5,6\n"}}) {
    const PointCloud cloud = readPoints(writeFile(name, text));
    ASSERT_EQ(cloud.normals.rows(), 2) << name;
    EXPECT_EQ(cloud.positions.row(1), Eigen::RowVector3d(4, 5, 6)) << name;
    EXPECT_EQ(cloud.normals.row(0), Eigen::RowVector3d(0, 0, -1)) << name;
    EXPECT_EQ(cloud.normals.row(1), Eigen::RowVector3d(0, 1, 0)) << name;
  }
}

// ---- errors -------------------------------------------------------------------------------------------

// The one PLY writer, ASCII and binary, with uchar colours and triangles:
// the reader gets the vertices back (12 digits in ASCII, every bit in
// binary), past the colour properties and the face element.
TEST_F(PointsTest, PlyWriterRoundTripsVerticesPastColoursAndFaces) {
  points::PlyData data;
  data.comments = {"two\nlines"};
  data.vertex_properties = {{"x"}, {"y"}, {"z"}, {"red", true}, {"signed_distance_mm"}};
  data.vertex_values.resize(3, 5);
  data.vertex_values << 1.25, -2.5, 3.0, 255, 0.1, 0.1 / 3.0, 7, -8, 300, -0.2, 4, 5, 6.5, -1, 0;
  data.faces.resize(1, 3);
  data.faces << 0, 1, 2;
  for (const auto format : {points::PlyFormat::Ascii, points::PlyFormat::BinaryLittleEndian}) {
    const std::string bytes = points::plyText(data, format);
    EXPECT_NE(bytes.find("comment SPACE=LPS\ncomment coordinates LPS, units mm\ncomment two lines\n"), std::string::npos);
    EXPECT_NE(bytes.find("property uchar red\n"), std::string::npos);
    EXPECT_NE(bytes.find("element face 1\n"), std::string::npos);
    const points::PointCloud back = points::readPoints(writeFile("round.ply", bytes));
    ASSERT_EQ(back.positions.rows(), 3);
    const double tolerance = format == points::PlyFormat::Ascii ? 1e-12 : 0.0;
    EXPECT_LE((back.positions - data.vertex_values.leftCols(3)).cwiseAbs().maxCoeff(), tolerance);
  }
  const std::string ascii = points::plyText(data, points::PlyFormat::Ascii);
  EXPECT_NE(ascii.find(" 7 -8 255 -0.2\n4 5 6.5 0 0\n"), std::string::npos) << "uchar clamped to 0-255: " << ascii;
  EXPECT_NE(ascii.find("\n3 0 1 2\n"), std::string::npos);
}

TEST_F(PointsTest, MissingEmptyAndUnknownFilesAreInputErrors) {
  std::string m = readError(file("absent.ply"));
  EXPECT_TRUE(contains(m, "absent.ply") && contains(m, "not found")) << m;
  m = readError(writeFile("empty.csv", ""));
  EXPECT_TRUE(contains(m, "empty.csv") && contains(m, "empty")) << m;
  m = readError(writeFile("points.pts", "1 2 3\n"));
  EXPECT_TRUE(contains(m, "points.pts") && contains(m, ".pts") && contains(m, "expected extension")) << m;
  m = readError(writeFile("blank.csv", "\n# only a comment\n\n"));
  EXPECT_TRUE(contains(m, "blank.csv") && contains(m, "found none")) << m;
  m = readError(writeFile("header_only.csv", "x,y,z\n"));
  EXPECT_TRUE(contains(m, "header_only.csv") && contains(m, "found none")) << m;
  m = readError(dir_);
  EXPECT_TRUE(contains(m, "directory")) << m;
}

TEST_F(PointsTest, BadTextRowsNameTheLine) {
  std::string m = readError(writeFile("word.csv", "x,y,z\n1,2,3\n4,5,6\n7,eight,9\n"));
  EXPECT_TRUE(contains(m, "word.csv") && contains(m, "line 4") && contains(m, "'eight'")) << m;
  m = readError(writeFile("nan.csv", "1,2,3\n\n4,nan,6\n"));
  EXPECT_TRUE(contains(m, "nan.csv") && contains(m, "line 3") && contains(m, "NaN or Inf")) << m;
  m = readError(writeFile("inf.xyz", "1 2 3\n4 5 -inf\n"));
  EXPECT_TRUE(contains(m, "line 2") && contains(m, "NaN or Inf")) << m;
  m = readError(writeFile("short.csv", "1,2,3\n4,5\n"));
  EXPECT_TRUE(contains(m, "line 2") && contains(m, "expected 3 columns")) << m;
  m = readError(writeFile("four.csv", "1,2,3,4\n"));
  EXPECT_TRUE(contains(m, "line 1") && contains(m, "found 4")) << m;
  m = readError(writeFile("decimal_comma.csv", "1,5;2,5;3,5\n"));
  EXPECT_TRUE(contains(m, "line 1") && contains(m, "'1,5'")) << m;
  m = readError(writeFile("late_header.csv", "1,2,3\nx,y,z\n"));
  EXPECT_TRUE(contains(m, "line 2") && contains(m, "'x'")) << m;
  m = readError(writeFile("empty_field.csv", "1,2,3\n1,,3\n"));
  EXPECT_TRUE(contains(m, "line 2") && contains(m, "column 2")) << m;
  m = readError(writeFile("zero_normal.csv", "1,2,3,0,0,1\n4,5,6,0,0,0\n"));
  EXPECT_TRUE(contains(m, "line 2") && contains(m, "non-zero length")) << m;
}

TEST_F(PointsTest, BadPlyDataNamesTheLineOrVertex) {
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\n"
      "property double z\nend_header\n";  // data starts on line 8
  std::string m = readError(writeFile("word.ply", header + "1 2 3\n4 five 6\n7 8 9\n"));
  EXPECT_TRUE(contains(m, "word.ply") && contains(m, "line 9") && contains(m, "'five'")) << m;
  m = readError(writeFile("nan.ply", header + "1 2 3\n4 5 6\n7 8 NaN\n"));
  EXPECT_TRUE(contains(m, "line 10") && contains(m, "NaN or Inf")) << m;
  m = readError(writeFile("few.ply", header + "1 2 3\n4 5 6\n"));
  EXPECT_TRUE(contains(m, "few.ply") && contains(m, "end of the file")) << m;
  m = readError(writeFile("many.ply", header + "1 2 3 4\n"));
  EXPECT_TRUE(contains(m, "line 8") && contains(m, "more values")) << m;

  std::string binary =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty double x\n"
      "property double y\nproperty double z\nend_header\n";
  std::string data;
  for (double v : {1.0, 2.0, 3.0, 4.0, std::numeric_limits<double>::infinity(), 6.0, 7.0, 8.0, 9.0})
    appendLittleEndian(data, v);
  m = readError(writeFile("inf.ply", binary + data));
  EXPECT_TRUE(contains(m, "inf.ply") && contains(m, "vertex 1") && contains(m, "NaN or Inf")) << m;
  m = readError(writeFile("truncated.ply", binary + data.substr(0, data.size() - 4)));
  EXPECT_TRUE(contains(m, "truncated.ply") && contains(m, "truncated")) << m;
  m = readError(writeFile("huge.ply",
                          "ply\nformat binary_little_endian 1.0\nelement vertex 99999999999\n"
                          "property double x\nproperty double y\nproperty double z\nend_header\n" +
                              data));
  EXPECT_TRUE(contains(m, "99999999999")) << m;
}

// Found by fuzzing (fuzz/fuzz_ply): a list length of float type read as 5e31 or
// NaN was converted to an integer (undefined behaviour), and a binary element
// without properties declared 2^64-1 times was counted through record by record.
TEST_F(PointsTest, PlyListLengthsAndEmptyElementsAreBounded) {
  std::string data;
  for (double v : {1.0, 2.0, 3.0}) appendLittleEndian(data, v);
  const std::string vertex = "element vertex 1\nproperty double x\nproperty double y\nproperty double z\n";
  std::string m = readError(writeFile("float_count.ply",
                                      "ply\nformat binary_little_endian 1.0\nelement face 1\n"
                                      "property list float int8 vertex_indices\n" +
                                          vertex + "end_header\n" + std::string(4, '\xff') + data));
  EXPECT_TRUE(contains(m, "line 4") && contains(m, "integer type") && contains(m, "'float'")) << m;
  m = readError(writeFile("nan_count.ply",
                          "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int vertex_indices\n" + vertex +
                              "end_header\nnan 1 2\n1 2 3\n"));
  EXPECT_TRUE(contains(m, "line 10") && contains(m, "non-negative integer list length")) << m;

  const PointCloud cloud = readPoints(writeFile(
      "empty_elements.ply", "ply\nformat binary_little_endian 1.0\nelement marker 18446744073709551615\n" + vertex +
                                "end_header\n" + data));
  ASSERT_EQ(cloud.positions.rows(), 1);
  EXPECT_EQ(cloud.positions(0, 2), 3.0);
}

TEST_F(PointsTest, MalformedPlyHeadersNameTheLine) {
  const std::pair<std::string, std::string> cases[] = {
      {"solid x\nformat ascii 1.0\n", "line 1"},
      {"ply\nformat ascii 2.0\nelement vertex 1\nend_header\n", "line 2"},
      {"ply\nformat utf8 1.0\n", "line 2"},
      {"ply\nformat ascii 1.0\nproperty float x\n", "line 3"},
      {"ply\nformat ascii 1.0\nelement vertex -4\n", "line 3"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty real x\n", "line 4"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n1 2 3\n",
       "line 7"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n",
       "end of the file"},
      {"ply\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n",
       "'format'"},
      {"ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n3 0 1 2\n",
       "element vertex"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n1 2\n",
       "x, y and z"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
       "property float nx\nend_header\n1 2 3 1\n",
       "nx, ny, nz"},
  };
  int i = 0;
  for (const auto& [text, where] : cases) {
    const std::string name = "bad" + std::to_string(i++) + ".ply";
    const std::string m = readError(writeFile(name, text));
    EXPECT_TRUE(contains(m, name) && contains(m, where)) << "case " << name << ": " << m;
  }
}

// ---- meshes through VTK --------------------------------------------------------------------------------

TEST_F(PointsTest, ReadsBinaryStlVerticesMergedOnce) {
  // Two triangles sharing an edge: 6 corners, 4 distinct vertices.
  std::string bytes(80, ' ');
  appendLittleEndian(bytes, std::uint32_t{2});
  const float triangles[2][3][3] = {{{0, 0, 0}, {10, 0, 0}, {0, 10, 0}}, {{10, 0, 0}, {10, 10, 5}, {0, 10, 0}}};
  for (const auto& triangle : triangles) {
    for (int k = 0; k < 3; ++k) appendLittleEndian(bytes, 0.0f);  // facet normal (ignored)
    for (const auto& corner : triangle)
      for (float v : corner) appendLittleEndian(bytes, v);
    bytes += std::string(2, '\0');
  }
  const PointCloud cloud = readPoints(writeFile("quad.stl", bytes));
  ASSERT_EQ(cloud.positions.rows(), 4);
  EXPECT_EQ(cloud.normals.rows(), 0);
  EXPECT_EQ(cloud.positions.colwise().maxCoeff(), Eigen::RowVector3d(10, 10, 5));
  EXPECT_EQ(cloud.positions.colwise().sum(), Eigen::RowVector3d(20, 20, 5));

  const PointCloud ascii =
      readPoints(writeFile("tri.stl",
                           "solid tri\n facet normal 0 0 1\n  outer loop\n   vertex 1 2 3\n   vertex 4 5 6.5\n"
                           "   vertex 7 8 9\n  endloop\n endfacet\nendsolid tri\n"));
  ASSERT_EQ(ascii.positions.rows(), 3);
  EXPECT_EQ(ascii.positions.row(1), Eigen::RowVector3d(4, 5, 6.5));
}

TEST_F(PointsTest, ReadsObjVerticesAndNormals) {
  const std::string text =
      "# tetrahedron\n"
      "v 0 0 0\nv 1 0 0\nv 0 2 0\nv 0 0 3\n"
      "vn 0 0 -1\nvn 0 0 -1\nvn 0 0 -1\nvn 0 0 1\n"
      "f 1//1 3//3 2//2\nf 1//1 2//2 4//4\nf 1//1 4//4 3//3\nf 2//2 3//3 4//4\n";
  const PointCloud cloud = readPoints(writeFile("tet.obj", text));
  ASSERT_EQ(cloud.positions.rows(), 4);
  ASSERT_EQ(cloud.normals.rows(), 4);
  EXPECT_EQ(cloud.positions.row(3), Eigen::RowVector3d(0, 0, 3));
  EXPECT_EQ(cloud.normals.row(3), Eigen::RowVector3d(0, 0, 1));
  EXPECT_EQ(cloud.normals.row(0), Eigen::RowVector3d(0, 0, -1));

  const PointCloud no_normals = readPoints(writeFile("tri.obj", "v 1 2 3\nv 4 5 6\nv 7 8 10\nf 1 2 3\n"));
  EXPECT_EQ(no_normals.positions.rows(), 3);
  EXPECT_EQ(no_normals.normals.rows(), 0);
}

// Found by fuzzing (fuzz/fuzz_mesh): VTK's OBJ reader read a face's vertex,
// texture coordinate or normal index out of bounds (a crash) and copied a
// material name into a 100-byte buffer; such files are refused by line.
TEST_F(PointsTest, ObjIndicesOutsideTheFileAreRefusedByLine) {
  const std::string vertices = "v 0 0 0\nv 1 0 0\nv 0 2 0\n";  // lines 1-3
  const std::pair<std::string, std::string> cases[] = {
      {"vn 0 0 1\nf 1 2 3\nf 1//1 2//1 4//1\n", "vertex index"},
      {"vn 0 0 1\nf 1//1 2//1 3//2\n", "normal index"},
      {"vt 0 0\nf 1/1 2/2 3/1\n", "texture coordinate index"},
      {"f 0 1 2\n", "vertex index"},
      {"f -4 1 2\n", "vertex index"},
      {"f 1 2 99999999999\n", "at most 9 digits"},
      {"l 1 2/x\n", "integer indices"},
      {"l 1 2/1/1\n", "indices v or v/t"},
      {"p 1/1\n", "indices v"},
      {"f 1 2 \\\n 7\n", "vertex index"},  // a continued face
      {"usemtl " + std::string(120, 'm') + "\nf 1 2 3\n", "material name"},
  };
  for (const auto& [tail, expected] : cases) {
    const std::string m = readError(writeFile("bad.obj", vertices + tail));
    EXPECT_TRUE(contains(m, "bad.obj") && contains(m, expected) && contains(m, "line ")) << tail << " -> " << m;
  }
  const std::string m = readError(writeFile("late.obj", vertices + "vn 0 0 1\nf 1//1 2//1 3//2\n"));
  EXPECT_TRUE(contains(m, "line 5")) << m;

  // Indices counting back from the last vertex, and normals defined after the faces, are fine.
  const PointCloud cloud = readPoints(writeFile("relative.obj", vertices + "f -3//1 -2//1 -1//1\nvn 0 0 1\n"));
  EXPECT_EQ(cloud.positions.rows(), 3);
}

TEST_F(PointsTest, ReadsVtpVerticesAndNormalsAndRejectsBrokenXml) {
  const std::string text = R"(<?xml version="1.0"?>
<VTKFile type="PolyData" version="0.1" byte_order="LittleEndian">
  <PolyData>
    <Piece NumberOfPoints="3" NumberOfVerts="0" NumberOfLines="0" NumberOfStrips="0" NumberOfPolys="1">
      <PointData Normals="Normals">
        <DataArray type="Float64" Name="Normals" NumberOfComponents="3" format="ascii">0 0 2 0 0 1 0 0 1</DataArray>
      </PointData>
      <Points>
        <DataArray type="Float64" NumberOfComponents="3" format="ascii">0.1 0.2 0.3 10 0 0 0 10 0</DataArray>
      </Points>
      <Polys>
        <DataArray type="Int64" Name="connectivity" format="ascii">0 1 2</DataArray>
        <DataArray type="Int64" Name="offsets" format="ascii">3</DataArray>
      </Polys>
    </Piece>
  </PolyData>
</VTKFile>
)";
  const PointCloud cloud = readPoints(writeFile("tri.vtp", text));
  ASSERT_EQ(cloud.positions.rows(), 3);
  EXPECT_EQ(cloud.positions.row(0), Eigen::RowVector3d(0.1, 0.2, 0.3));  // Float64 kept exactly
  ASSERT_EQ(cloud.normals.rows(), 3);
  EXPECT_EQ(cloud.normals.row(0), Eigen::RowVector3d(0, 0, 1));

  const std::string m = readError(writeFile("broken.vtp", text.substr(0, text.size() / 2)));
  EXPECT_TRUE(contains(m, "broken.vtp")) << m;
}

TEST_F(PointsTest, GarbageMeshesAreInputErrors) {
  for (const char* name : {"garbage.stl", "garbage.obj", "garbage.vtp"}) {
    const std::string m = readError(writeFile(name, "this is not a mesh\n"));
    EXPECT_TRUE(contains(m, name)) << m;
  }
  std::string truncated(80, ' ');
  appendLittleEndian(truncated, std::uint32_t{1000});
  truncated += std::string(100, '\0');
  const std::string m = readError(writeFile("truncated.stl", truncated));
  EXPECT_TRUE(contains(m, "truncated.stl")) << m;
}

// Found by fuzzing (fuzz/fuzz_mesh): a file starting with "solid" but holding
// control bytes is binary to VTK, which allocated for the 1.9e9 triangles the
// bytes 80-83 declared (gigabytes); the size check now decides binary as VTK does.
TEST_F(PointsTest, StlThatVtkReadsAsBinaryIsCheckedForItsSize) {
  std::string bytes = "solid tetra\n" + std::string(68, '\x1c');  // text to the eye, binary to VTK
  bytes += "    ";                                                 // 0x20202020 triangles
  bytes += std::string(100, '\x01');
  const std::string m = readError(writeFile("solid_binary.stl", bytes));
  EXPECT_TRUE(contains(m, "solid_binary.stl") && contains(m, "538976288 triangles")) << m;
}

// Found by fuzzing (fuzz/fuzz_mesh): VTK took a NumberOfComponents past the
// range of int as the largest int and ran for minutes on the array. Every
// spelling of such a count (and of none at all) is refused, by its element.
TEST_F(PointsTest, VtpComponentCountsOutsideAMeshsArraysAreRefused) {
  const auto vtp = [](const std::string& components) {
    std::string text = R"(<?xml version="1.0"?>
<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian" header_type="UInt32">
  <PolyData>
    <Piece NumberOfPoints="4">
      <Points>
        <DataArray type="Float64" NumberOfComponents=")" +
                       components + R"(" format="appended" offset="0"/>
      </Points>
    </Piece>
  </PolyData>
  <AppendedData encoding="raw">
   _)";
    appendLittleEndian(text, std::uint32_t{96});
    for (int i = 0; i < 12; ++i) appendLittleEndian(text, std::uint64_t{0x4024000000000000});  // 10.0
    return text + "\n  </AppendedData>\n</VTKFile>\n";
  };
  EXPECT_EQ(readPoints(writeFile("appended.vtp", vtp("3"))).positions.rows(), 4);  // the raw data read past
  for (const std::string& bad : {std::string(90, '5'), std::string("&#51;") + std::string(20, '5'),
                                 std::string("0"), std::string("4097"), std::string("-3"), std::string("3x")}) {
    const std::string m = readError(writeFile("components.vtp", vtp(bad)));
    EXPECT_TRUE(contains(m, "components.vtp") && contains(m, "NumberOfComponents of 1 to 4096 on <DataArray>"))
        << bad << ": " << m;
  }
}

// PLY meshes go through the project's PLY reader, as PLY points do (VTK 9.1's
// reader crashed on a face record shorter than its list, found by fuzzing).
TEST_F(PointsTest, ReadsPlyMeshFacesAndRefusesShortOrStrayFaces) {
  const std::string header = "ply\nformat ascii 1.0\nelement vertex 5\nproperty double x\nproperty double y\n"
                             "property double z\nproperty float nx\nproperty float ny\nproperty float nz\n"
                             "element face 2\nproperty uchar flags\nproperty list uchar int vertex_indices\nend_header\n";
  const std::string vertices = "0 0 0 0 0 2\n10 0 0 0 0 1\n10 10 0 0 0 1\n0 10 0 0 0 1\n5 5 0.125 0 0 1\n";
  const MeshFile mesh = readMeshFile(writeFile("quad.ply", header + vertices + "7 4 0 1 2 3\n0 3 0 1 4\n"));
  ASSERT_EQ(mesh.vertices.rows(), 5);
  EXPECT_EQ(mesh.vertices.row(4), Eigen::RowVector3d(5, 5, 0.125));  // doubles kept
  ASSERT_EQ(mesh.normals.rows(), 5);
  EXPECT_EQ(mesh.normals.row(0), Eigen::RowVector3d(0, 0, 1));  // at unit length
  ASSERT_EQ(mesh.triangles.rows(), 3);  // the quad in two, then the triangle
  EXPECT_EQ(mesh.triangles.row(2), Eigen::RowVector3i(0, 1, 4));
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"7 4 0 1\n0 3 0 1 4\n", "line 19 (face record): expected item 2 of list 'vertex_indices', found the end of the line"},
      {"7 4 0 1 2 5\n0 3 0 1 4\n", "line 19 (face 0, 0-based): expected vertex indices from 0 to 4, found 5"},
      {"7 4 0 1 2 3\n0 3 0 -1 4\n", "(face 1, 0-based): expected vertex indices from 0 to 4, found -1"},
      {"7 4 0 1 2 3\n", "expected 2 face records, found the end of the file after 1"}};
  for (const auto& [faces, expected] : bad) {
    const std::string m = meshError(writeFile("bad.ply", header + vertices + faces));
    EXPECT_TRUE(contains(m, "bad.ply") && contains(m, expected)) << m;
  }
  // Binary, big-endian, the faces' list named vertex_index.
  std::string binary = "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                       "property float z\nelement face 1\nproperty list uchar uint vertex_index\nend_header\n";
  for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) appendBigEndian(binary, v);
  binary += '\x03';
  for (std::uint32_t i : {2u, 1u, 0u}) appendBigEndian(binary, i);
  const MeshFile tri = readMeshFile(writeFile("tri.ply", binary));
  ASSERT_EQ(tri.triangles.rows(), 1);
  EXPECT_EQ(tri.triangles.row(0), Eigen::RowVector3i(2, 1, 0));
  appendBigEndian(binary.erase(binary.size() - 4), std::uint32_t{3});
  const std::string m = meshError(writeFile("stray.ply", binary));
  EXPECT_TRUE(contains(m, "binary data (face 0, 0-based): expected vertex indices from 0 to 2, found 3")) << m;
}

// ---- legacy .vtk meshes ---------------------------------------------------------------------------------


// Six points, a quad and a triangle, a triangle strip, float point normals (with component
// names, so VTK writes METADATA after them), CutThroughBone as the active scalars or as a
// plain point array, and arrays to read past: scalars, field data, cell data, strings.
vtkSmartPointer<vtkPolyData> legacyTestMesh(bool cut_as_scalars) {
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  for (int i = 0; i < 6; ++i) points->InsertNextPoint(0.1 * i - 12.5, 1.0 / 3.0 + i, std::sqrt(2.0 + i) * 1e3);
  poly->SetPoints(points);
  vtkNew<vtkCellArray> polys, strips;
  polys->InsertNextCell({0, 1, 2, 3});
  polys->InsertNextCell({1, 2, 4});
  strips->InsertNextCell({0, 1, 4, 5, 2});
  poly->SetPolys(polys);
  poly->SetStrips(strips);
  vtkNew<vtkFloatArray> normals;
  normals->SetName("Normals");
  normals->SetNumberOfComponents(3);
  for (int i = 0; i < 6; ++i) {
    const Eigen::Vector3f n = Eigen::Vector3f(std::cos(0.3f * i), std::sin(0.7f * i), 0.2f + i).normalized();
    normals->InsertNextTuple3(n.x(), n.y(), n.z());
  }
  normals->SetComponentName(0, "n x");
  double range[2];
  normals->GetRange(range, -1);  // cached as an information key: written as METADATA INFORMATION
  poly->GetPointData()->SetNormals(normals);
  vtkNew<vtkUnsignedCharArray> cut;
  cut->SetName("CutThroughBone");
  for (int i = 0; i < 6; ++i) cut->InsertNextValue(i % 3 == 1 ? 1 : 0);
  vtkNew<vtkDoubleArray> extra;
  extra->SetName("Extra");
  for (int i = 0; i < 6; ++i) extra->InsertNextValue(i * 0.5);
  poly->GetPointData()->SetScalars(cut_as_scalars ? static_cast<vtkDataArray*>(cut) : extra);
  poly->GetPointData()->AddArray(cut_as_scalars ? static_cast<vtkDataArray*>(extra) : cut);
  vtkNew<vtkIntArray> cell_ids;
  cell_ids->SetName("CellId");
  for (int i = 0; i < 3; ++i) cell_ids->InsertNextValue(i);
  poly->GetCellData()->SetScalars(cell_ids);
  vtkNew<vtkStringArray> names;
  names->SetName("Names");
  names->InsertNextValue("left hip");
  names->InsertNextValue("");
  poly->GetFieldData()->AddArray(names);
  return poly;
}

// What VTK's own reader and triangle filter made of a file.
MeshFile readWithVtk(const fs::path& path) {
  vtkNew<vtkPolyDataReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  vtkNew<vtkTriangleFilter> triangulate;
  triangulate->SetInputConnection(reader->GetOutputPort());
  triangulate->PassVertsOff();
  triangulate->PassLinesOff();
  triangulate->Update();
  vtkPolyData* poly = reader->GetOutput();
  MeshFile out;
  const vtkIdType n = poly->GetNumberOfPoints();
  out.vertices.resize(n, 3);
  out.normals.resize(n, 3);
  for (vtkIdType i = 0; i < n; ++i) {
    double p[3], v[3];
    poly->GetPoint(i, p);
    poly->GetPointData()->GetNormals()->GetTuple(i, v);
    out.vertices.row(i) << p[0], p[1], p[2];
    out.normals.row(i) << v[0], v[1], v[2];
    out.cut_through_bone.push_back(poly->GetPointData()->GetArray("CutThroughBone")->GetTuple1(i) != 0 ? 1 : 0);
  }
  vtkCellArray* triangles = triangulate->GetOutput()->GetPolys();
  out.triangles.resize(triangles->GetNumberOfCells(), 3);
  vtkIdType row = 0, count = 0;
  const vtkIdType* ids = nullptr;
  for (triangles->InitTraversal(); triangles->GetNextCell(count, ids); ++row)
    out.triangles.row(row) << static_cast<int>(ids[0]), static_cast<int>(ids[1]), static_cast<int>(ids[2]);
  return out;
}

// Legacy .vtk meshes go through the project's reader (VTK 9.1's crashed on a malformed
// header): what vtkPolyDataWriter writes, ASCII and binary, in the 5.1 layout (offsets and
// connectivity) and the 4.2 one (counts and ids), reads as VTK's own reader reads it.
TEST_F(PointsTest, ReadsLegacyVtkAsVtkDoesInEveryLayout) {
  const vtkSmartPointer<vtkPolyData> written = legacyTestMesh(false);
  for (const bool cut_as_scalars : {false, true}) {
    const vtkSmartPointer<vtkPolyData> source = legacyTestMesh(cut_as_scalars);
    for (const int version : {int{vtkPolyDataWriter::VTK_LEGACY_READER_VERSION_5_1},
                              int{vtkPolyDataWriter::VTK_LEGACY_READER_VERSION_4_2}}) {
      for (const bool binary : {false, true}) {
        const std::string label = std::string(binary ? "binary" : "ascii") + "_" + std::to_string(version) +
                                  (cut_as_scalars ? "_scalars" : "_field");
        const fs::path path = file(label + ".vtk");
        vtkNew<vtkPolyDataWriter> writer;
        writer->SetInputData(source);
        writer->SetFileVersion(version);
        if (binary) writer->SetFileTypeToBinary();
        writer->SetFileName(path.c_str());
        ASSERT_EQ(writer->Write(), 1) << label;

        const MeshFile mesh = readMeshFile(path);
        const MeshFile vtk = readWithVtk(path);
        SCOPED_TRACE(label);
        expectBitwiseEqual(mesh.vertices, vtk.vertices);
        expectBitwiseEqual(mesh.normals, vtk.normals);
        EXPECT_EQ(mesh.triangles, vtk.triangles);
        EXPECT_EQ(mesh.cut_through_bone, vtk.cut_through_bone);
        // And the known values: binary doubles exactly, the quad in two, then the strip's triangles.
        if (binary) {
          for (vtkIdType i = 0; i < 6; ++i) {
            double p[3];
            written->GetPoint(i, p);
            EXPECT_EQ(mesh.vertices.row(i), Eigen::RowVector3d(p[0], p[1], p[2])) << i;
          }
        }
        ASSERT_EQ(mesh.triangles.rows(), 6);
        EXPECT_EQ(mesh.triangles.row(2), Eigen::RowVector3i(1, 2, 4));
        EXPECT_EQ(mesh.triangles.row(3), Eigen::RowVector3i(0, 1, 4));
        EXPECT_EQ(mesh.triangles.row(4), Eigen::RowVector3i(4, 1, 5));
        EXPECT_EQ(mesh.triangles.row(5), Eigen::RowVector3i(4, 5, 2));
        EXPECT_EQ(mesh.cut_through_bone, (std::vector<unsigned char>{0, 1, 0, 0, 1, 0}));
      }
    }
  }
}

// Hand-written: lower-case keywords, CRLF line ends, and every attribute VTK knows, read past.
TEST_F(PointsTest, ReadsLegacyVtkPastEveryAttribute) {
  const std::string text =
      "# vtk DataFile Version 3.0\r\nany title at all\r\nascii\r\ndataset polydata\r\n"
      "points 4 float\r\n0 0 0 1 0 0 1 1 0 0 1 0.5\r\nvertices 1 2\r\n1 3\r\nlines 1 3\r\n2 0 2\r\n"
      "polygons 1 5\r\n4 0 1 2 3\r\ncell_data 3\r\ncolor_scalars rgb 3\r\n1 0 0 0 1 0 0 0 1\r\n"
      "point_data 4\r\nscalars temperature%20C float 2\r\nlookup_table heat\r\n1 2 3 4 5 6 7 8\r\n"
      "lookup_table heat 2\r\n0 0 0 1 1 1 1 1\r\nvectors v double\r\n1 2 3 4 5 6 7 8 9 10 11 12\r\n"
      "texture_coordinates uv 2 float\r\n0 0 1 0 1 1 0 1\r\ntensors6 t float\r\n"
      "1 2 3 4 5 6 1 2 3 4 5 6 1 2 3 4 5 6 1 2 3 4 5 6\r\nglobal_ids ids vtkidtype\r\n0 1 2 3\r\n"
      "field extras 3\r\nNULL_ARRAY\r\nnames 1 4 string\r\na\r\nb c\r\n\r\nd\r\n"
      "CutThroughBone 1 4 int\r\n0 1 1 0\r\nMETADATA\r\nINFORMATION 1\r\nNAME L2_NORM_RANGE LOCATION vtkDataArray\r\n"
      "DATA 2 0 1\r\n\r\nnormals n float\r\n0 0 1 0 0 1 0 0 1 0 0 1\r\n";
  const fs::path path = writeFile("every.vtk", text);
  const MeshFile mesh = readMeshFile(path);
  ASSERT_EQ(mesh.vertices.rows(), 4);
  EXPECT_EQ(mesh.vertices.row(3), Eigen::RowVector3d(0, 1, 0.5));
  ASSERT_EQ(mesh.normals.rows(), 4);
  EXPECT_EQ(mesh.normals.row(2), Eigen::RowVector3d(0, 0, 1));
  EXPECT_EQ(mesh.triangles.rows(), 2);
  EXPECT_EQ(mesh.cut_through_bone, (std::vector<unsigned char>{0, 1, 1, 0}));
  const MeshFile vtk = readWithVtk(path);  // VTK reads the same file the same way
  EXPECT_EQ(mesh.vertices, vtk.vertices);
  EXPECT_EQ(mesh.triangles, vtk.triangles);
  EXPECT_EQ(mesh.cut_through_bone, vtk.cut_through_bone);
}

// Found by fuzzing (fuzz/fuzz_mesh): VTK 9.1's reader crashed (in vtkDataReader::ReadString)
// on this file, whose version line is malformed and whose polygons hold NUL bytes.
TEST_F(PointsTest, LegacyVtkThatCrashedVtksReaderIsRefused) {
  const std::string head = "# vtk DataFile Version\xff\xff 4.2\ntetrahedron\n";
  const std::string body =
      "ASCII\nDATASET POLYDATA\nPOINTS 4 float\n0 0 0\n10 0 0\n0 10 0\n0 0 10\nPOLYGONS 4 16\n3 0 2 1\n3 0 1 3\n" +
      std::string(43, '\0') +
      "3 0 3 2\n3 1 2 3\nPOINT_DATA 4\nNORMend_headerA\xff\xff\xff\xff\xff\xff\xff\xffL1\nf 1/1/<VTKFile2 -1\n"
      "vn 0 -10 1 0\n0.6 0.8 0\n";
  std::string m = meshError(writeFile("crash.vtk", head + body));
  EXPECT_TRUE(contains(m,
                       "crash.vtk', line 1: expected '# vtk DataFile Version x.y' of 1.0 to 5.1, found "
                       "'# vtk DataFile Version\\xff\\xff 4.2'"))
      << m;
  m = meshError(writeFile("nul.vtk", "# vtk DataFile Version 4.2\ntetrahedron\n" + body));
  EXPECT_TRUE(contains(m,
                       "nul.vtk', line 13: expected an integer in the range of its type for POLYGONS, found "
                       "'\\x00\\x00"))
      << m;
}

// Truncated files, indices past the points, counts past the file and inconsistent cells are
// refused by line (ASCII) or byte (BINARY), before anything is allocated for them.
TEST_F(PointsTest, MalformedLegacyVtkIsRefusedWithWhereAndWhat) {
  const std::string head = "# vtk DataFile Version 4.2\nmesh\nASCII\nDATASET POLYDATA\n";
  const std::string points = "POINTS 4 float\n0 0 0\n10 0 0\n0 10 0\n0 0 10\n";
  const std::vector<std::pair<std::string, std::string>> bad = {
      {head + points + "POLYGONS 1 4\n3 0 1 7\n",
       "line 10 (POLYGONS, cell 0, 0-based): expected point indices from 0 "
       "to 3, found 7"},
      {head + "POINTS 4000000000 float\n0 0 0\n" + std::string(150, ' '),
       "line 5: expected 12000000000 values for POINTS within the 157 bytes left, found too few bytes"},
      {head + points.substr(0, 30),
       "line 5: expected 12 values for POINTS within the 16 bytes left, found too few bytes (truncated file?)"},
      {head + points + "POLYGONS 2 8\n3 0 1 2\n3 0 1\n",
       "line 13: expected an integer for POLYGONS, found the end of the "
       "file"},
      {head + points + "POLYGONS 2 8\n3 0 1 2\n4 0 1 2\n",
       "line 10 (POLYGONS): expected cell 1 (0-based) to list at "
       "most the 3 integers left of 8, found a point count of 4"},
      {head + points + "POLYGONS 3 8\n3 0 1 2\n3 0 1 3\n", "expected 3 cells as declared, found 2"},
      {head + "POINTS 1 float\n0 0.5x 0\n", "line 6: expected a finite number for POINTS, found '0.5x'"},
      {head + "POINTS 1 double\n0 1e999 0\n", "line 6: expected a finite number for POINTS, found '1e999'"},
      {head + "POINTS 1 bit\n0 1 0\n", "line 5: expected a points type (unsigned_char"},
      {head + points + "POINT_DATA 5\n", "line 10: expected POINT_DATA 4 (the number of points), found 5"},
      {head + points + "POINT_DATA 4\nNORMALS n float\n0 0 1\n",
       "line 11: expected 12 values for NORMALS n within the 7 bytes left"},
      {head + points + "POINT_DATA 4\nFIELD f 1\nCutThroughBone 1 999999999999 int\n",
       "expected 999999999999 values for FIELD array CutThroughBone within"},
      {"# vtk DataFile Version 4.2\nmesh\nASCII\nDATASET UNSTRUCTURED_GRID\n",
       "line 4: expected DATASET POLYDATA, found DATASET UNSTRUCTURED_GRID"},
      {"# vtk DataFile Version 6.0\nmesh\nASCII\n", "line 1: expected '# vtk DataFile Version x.y' of 1.0 to 5.1"},
      {"# vtk DataFile Version 4.2\nmesh\nUTF8\n", "line 3: expected ASCII or BINARY, found 'UTF8'"},
      {"# vtk DataFile Version 4.2\n" + std::string(300, 't') + "\nASCII\n",
       "line 2: expected a title line of at most 256 characters, found 300"},
      {"# vtk DataFile Version 5.1\nmesh\nASCII\nDATASET POLYDATA\n" + points +
           "POLYGONS 3 6\nOFFSETS vtktypeint64\n0 3 2\nCONNECTIVITY vtktypeint64\n0 1 2 0 1 3\n",
       "line 10 (POLYGONS): expected offsets rising from 0 to 6 (the connectivity's size), found 2 at offset 2"},
      {"# vtk DataFile Version 5.1\nmesh\nASCII\nDATASET POLYDATA\n" + points + "POLYGONS 2 3\nOFFSETS float\n0 3\n",
       "line 11: expected an offsets type vtktypeint64 or vtktypeint32, found 'float'"},
  };
  for (const auto& [text, expected] : bad) {
    const std::string m = meshError(writeFile("bad.vtk", text));
    EXPECT_TRUE(contains(m, "legacy VTK file '") && contains(m, "bad.vtk', ") && contains(m, expected))
        << expected << "\n  got: " << m;
  }

  // Binary: big-endian, places by byte.
  std::string binary = "# vtk DataFile Version 4.2\nmesh\nBINARY\nDATASET POLYDATA\nPOINTS 3 float\n";
  for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) appendBigEndian(binary, v);
  binary += "\nPOLYGONS 1 4\n";
  for (std::int32_t v : {3, 2, 1, 0}) appendBigEndian(binary, v);
  binary += "\n";
  const MeshFile tri = readMeshFile(writeFile("tri.vtk", binary));
  ASSERT_EQ(tri.triangles.rows(), 1);
  EXPECT_EQ(tri.triangles.row(0), Eigen::RowVector3i(2, 1, 0));
  std::string m = meshError(writeFile("short.vtk", binary.substr(0, 90)));
  EXPECT_TRUE(contains(m, "short.vtk', byte 71: expected 9 values for POINTS within the 19 bytes left")) << m;
  std::string nan = binary;
  nan.replace(71 + 4 * 4, 4, "\x7f\xc0\x00\x00", 4);
  m = meshError(writeFile("nan.vtk", nan));
  EXPECT_TRUE(contains(m, "nan.vtk', byte 87: expected finite coordinates, found nan in point 1 (0-based)")) << m;
  std::string stray = binary;
  stray.replace(stray.size() - 5, 4, "\x00\x00\x00\x03", 4);
  m = meshError(writeFile("stray.vtk", stray));
  EXPECT_TRUE(contains(m,
                       "stray.vtk', byte 108 (POLYGONS, cell 0, 0-based): expected point indices from 0 to 2, "
                       "found 3"))
      << m;
  m = meshError(writeFile("huge.vtk",
                          "# vtk DataFile Version 4.2\nmesh\nBINARY\nDATASET POLYDATA\n"
                          "POINTS 4000000000 float\n" +
                              std::string(150, '\0')));
  EXPECT_TRUE(contains(m, "byte 80: expected 12000000000 values for POINTS within the 150 bytes left")) << m;
}

// Prefixes of what VTK's writer wrote (ASCII and binary, both layouts; every 47th length, to stay
// fast) read or are InputErrors.
TEST_F(PointsTest, EveryTruncationOfALegacyVtkMeshIsAnInputErrorOrReads) {
  const vtkSmartPointer<vtkPolyData> source = legacyTestMesh(false);
  for (const int version :
       {int{vtkPolyDataWriter::VTK_LEGACY_READER_VERSION_5_1}, int{vtkPolyDataWriter::VTK_LEGACY_READER_VERSION_4_2}}) {
    for (const bool binary : {false, true}) {
      vtkNew<vtkPolyDataWriter> writer;
      writer->SetInputData(source);
      writer->SetFileVersion(version);
      if (binary) writer->SetFileTypeToBinary();
      writer->WriteToOutputStringOn();
      ASSERT_EQ(writer->Write(), 1);
      const std::string whole = writer->GetOutputStdString();
      EXPECT_NO_THROW(readMeshFile(writeFile("whole.vtk", whole)));
      for (std::size_t size = 0; size < whole.size(); size += 47) {
        try {
          readMeshFile(writeFile("cut.vtk", whole.substr(0, size)));
        } catch (const InputError&) {
        }
      }
    }
  }
}

TEST_F(PointsTest, ReadsTheRealFemurMesh) {
  const fs::path path = sharedData() / "meshes/femur/LHDL_CT_femur_r.stl";
  if (!fs::exists(path)) GTEST_SKIP() << "real data absent: " << path;
  const PointCloud cloud = readPoints(path);
  EXPECT_GT(cloud.positions.rows(), 30000);
  EXPECT_EQ(cloud.normals.rows(), 0);
  const Eigen::RowVector3d extent = cloud.positions.colwise().maxCoeff() - cloud.positions.colwise().minCoeff();
  // An adult femur in millimetres: 35-55 cm long, a few centimetres across.
  EXPECT_GT(extent.maxCoeff(), 350.0) << extent;
  EXPECT_LT(extent.maxCoeff(), 550.0) << extent;
  EXPECT_GT(extent.minCoeff(), 30.0) << extent;
  EXPECT_LT(extent.minCoeff(), 150.0) << extent;
  EXPECT_NO_THROW(checkFittable(cloud, 15, "femur"));
  std::cout << "femur: " << cloud.positions.rows() << " vertices, extent " << extent << " mm\n";
}

// ---- fittability ---------------------------------------------------------------------------------------

PointCloud posed(const Eigen::MatrixX3d& local) {
  const Eigen::Matrix3d rotation = (Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()) *
                                    Eigen::AngleAxisd(-1.1, Eigen::Vector3d(1, 2, 3).normalized()))
                                       .toRotationMatrix();
  PointCloud cloud;
  cloud.positions = (local * rotation.transpose()).rowwise() + Eigen::RowVector3d(-120.5, 88.25, 310.0);
  return cloud;
}

TEST(CheckFittable, AcceptsASphereCap) {
  Eigen::MatrixX3d local(40, 3);
  for (int i = 0; i < 40; ++i) {
    const double polar = 0.9 * (i % 8) / 8.0, azimuth = 2 * M_PI * (i / 8) / 5.0;
    local.row(i) << 22 * std::sin(polar) * std::cos(azimuth), 22 * std::sin(polar) * std::sin(azimuth),
        22 * std::cos(polar);
  }
  EXPECT_NO_THROW(checkFittable(posed(local), 15, "cap"));
  const std::string m = fittableError(posed(local), 41);
  EXPECT_TRUE(contains(m, "at least 41") && contains(m, "found 40")) << m;
}

TEST(CheckFittable, RejectsNonFiniteDuplicateCollinearAndCoplanarClouds) {
  Eigen::MatrixX3d local = Eigen::MatrixX3d::Random(30, 3) * 10.0;
  PointCloud bad = posed(local);
  bad.positions(17, 1) = std::numeric_limits<double>::quiet_NaN();
  std::string m = fittableError(bad, 10);
  EXPECT_TRUE(contains(m, "point 17")) << m;

  PointCloud same;
  same.positions = Eigen::RowVector3d(-120.5, 88.25, 310.1).replicate(30, 1);
  m = fittableError(same, 10);
  EXPECT_TRUE(contains(m, "duplicates")) << m;

  Eigen::MatrixX3d line = Eigen::MatrixX3d::Zero(30, 3);
  line.col(0) = Eigen::VectorXd::LinSpaced(30, -15.0, 15.0);
  m = fittableError(posed(line), 10);
  EXPECT_TRUE(contains(m, "collinear")) << m;

  Eigen::MatrixX3d plane = local;
  plane.col(2).setZero();
  m = fittableError(posed(plane), 10);
  EXPECT_TRUE(contains(m, "coplanar")) << m;

  // A thin but genuinely curved cap (sagitta 0.05 mm over 20 mm) is accepted.
  Eigen::MatrixX3d shallow = plane;
  for (Eigen::Index i = 0; i < shallow.rows(); ++i) shallow(i, 2) = 0.05 * (shallow.row(i).squaredNorm() / 200.0);
  EXPECT_NO_THROW(checkFittable(posed(shallow), 10, "shallow cap"));
}

}  // namespace
