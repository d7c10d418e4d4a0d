#include "articula/points/point_io.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <sstream>
#include <stdexcept>

#include "articula/core/atomic_file.hpp"
#include "articula/core/error.hpp"
#include "articula/points/ply_writer.hpp"
#include "readers.hpp"

namespace articula::points {

namespace detail {

std::string quoted(const std::filesystem::path& path) { return "'" + path.string() + "'"; }

std::string lowercase(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return std::tolower(c); });
  return text;
}

void finishCloud(PointCloud& cloud, const std::filesystem::path& path,
                 const std::function<std::string(Eigen::Index)>& where) {
  const bool has_normals = cloud.normals.rows() > 0;
  for (Eigen::Index i = 0; i < cloud.positions.rows(); ++i) {
    if (!cloud.positions.row(i).allFinite() || (has_normals && !cloud.normals.row(i).allFinite()))
      throw InputError(quoted(path) + ", " + where(i) + ": expected finite numbers, found NaN or Inf");
    if (!has_normals) continue;
    const double length = cloud.normals.row(i).norm();
    if (length == 0.0)
      throw InputError(quoted(path) + ", " + where(i) + ": expected a normal of non-zero length, found (0, 0, 0)");
    // Leave normals that are unit to rounding untouched, so written normals read back bit for bit.
    if (std::abs(length - 1.0) > 1e-12) cloud.normals.row(i) /= length;
  }
}

}  // namespace detail

namespace {

// Shortest decimal text that reads back to the same double.
void appendShortest(std::string& out, double value) {
  std::array<char, 32> buffer;
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  out.append(buffer.data(), result.ptr);
}

std::string plyBytes(const PointCloud& cloud, const std::vector<std::string>& comments) {
  const bool has_normals = cloud.normals.rows() > 0;
  PlyData data;
  data.comments = comments;
  for (const char* name : {"x", "y", "z", "nx", "ny", "nz"})
    if (has_normals || data.vertex_properties.size() < 3) data.vertex_properties.push_back({name});
  data.vertex_values.resize(cloud.positions.rows(), has_normals ? 6 : 3);
  data.vertex_values.leftCols(3) = cloud.positions;
  if (has_normals) data.vertex_values.rightCols(3) = cloud.normals;
  return plyText(data, PlyFormat::BinaryLittleEndian);
}

std::string csvText(const PointCloud& cloud) {
  const bool has_normals = cloud.normals.rows() > 0;
  std::string out = has_normals ? "x_mm,y_mm,z_mm,nx,ny,nz\n" : "x_mm,y_mm,z_mm\n";
  for (Eigen::Index i = 0; i < cloud.positions.rows(); ++i) {
    for (int k = 0; k < 3; ++k) {
      if (k > 0) out += ',';
      appendShortest(out, cloud.positions(i, k));
    }
    if (has_normals)
      for (int k = 0; k < 3; ++k) {
        out += ',';
        appendShortest(out, cloud.normals(i, k));
      }
    out += '\n';
  }
  return out;
}

std::string describePoint(const Eigen::RowVector3d& p) {
  std::ostringstream s;
  s.precision(9);
  s << "(" << p.x() << ", " << p.y() << ", " << p.z() << ")";
  return s.str();
}

}  // namespace

PointCloud readPoints(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw InputError("point file " + detail::quoted(path) + " not found");
  if (std::filesystem::is_directory(path, ec))
    throw InputError("expected a point file, found a directory: " + detail::quoted(path));
  if (std::filesystem::file_size(path, ec) == 0 && !ec)
    throw InputError("point file " + detail::quoted(path) + " is empty (0 bytes)");

  const std::string ext = detail::lowercase(path.extension().string());
  if (ext == ".ply") return detail::readPly(path);
  if (ext == ".csv" || ext == ".xyz" || ext == ".txt") return detail::readTable(path);
  if (ext == ".stl" || ext == ".obj" || ext == ".vtp") return detail::readMeshVertices(path);
  throw InputError("point file " + detail::quoted(path) +
                   ": expected extension .ply, .csv, .xyz, .txt, .stl, .obj or .vtp, found '" +
                   path.extension().string() + "'");
}

void writePoints(const std::filesystem::path& path, const PointCloud& cloud,
                 const std::vector<std::string>& comments, bool overwrite) {
  if (cloud.normals.rows() != 0 && cloud.normals.rows() != cloud.positions.rows())
    throw std::invalid_argument("writePoints: " + std::to_string(cloud.normals.rows()) + " normals for " +
                                std::to_string(cloud.positions.rows()) + " points");
  const std::string ext = detail::lowercase(path.extension().string());
  if (ext != ".ply" && ext != ".csv")
    throw UsageError("output " + detail::quoted(path) + ": expected extension .ply or .csv, found '" +
                     path.extension().string() + "'");
  const bool binary = ext == ".ply";
  AtomicFile file(path, overwrite, binary);
  file.stream() << (binary ? plyBytes(cloud, comments) : csvText(cloud));
  file.commit();
}

void checkFittable(const PointCloud& cloud, int min_points, const std::string& where) {
  if (min_points < 1) throw std::invalid_argument("checkFittable: min_points must be >= 1");
  const Eigen::Index n = cloud.positions.rows();
  if (n < min_points)
    throw InputError(where + ": expected at least " + std::to_string(min_points) + " points to fit a model with " +
                     std::to_string(min_points) + " parameters, found " + std::to_string(n));
  for (Eigen::Index i = 0; i < n; ++i)
    if (!cloud.positions.row(i).allFinite())
      throw InputError(where + ": expected finite coordinates, found NaN or Inf at point " + std::to_string(i) +
                       " (0-based)");

  // Singular values of the centred cloud measure its spread along its principal axes. The SVD of the
  // #P x 3 matrix itself (not the covariance, whose squared ratios fall below double precision) keeps
  // a ratio of 1e-9 resolvable.
  const Eigen::RowVector3d centroid = cloud.positions.colwise().mean();
  const Eigen::MatrixX3d centred = cloud.positions.rowwise() - centroid;
  const Eigen::Vector3d s = Eigen::JacobiSVD<Eigen::MatrixX3d>(centred).singularValues();
  const double rms_spread = s(0) / std::sqrt(static_cast<double>(n));
  constexpr double kRelative = 1e-6;
  const double scale = std::max(1.0, centroid.cwiseAbs().maxCoeff());
  if (rms_spread <= 1e-12 * scale)
    throw InputError(where + ": expected distinct points, found all " + std::to_string(n) +
                     " points duplicates of " + describePoint(centroid));
  if (s(1) < kRelative * s(0))
    throw InputError(where + ": expected points spanning a surface, found all " + std::to_string(n) +
                     " points collinear (singular values of the centred cloud: " + describePoint(s.transpose()) +
                     ")");
  if (s(2) < kRelative * s(0))
    throw InputError(where + ": expected points spanning a curved surface, found all " + std::to_string(n) +
                     " points coplanar (singular values of the centred cloud: " + describePoint(s.transpose()) +
                     ")");
}

}  // namespace articula::points
