#include "articula/report/ply_writers.hpp"

#include <iomanip>
#include <sstream>

#include "articula/core/number_text.hpp"

namespace articula::report {

std::string colouredPointsPly(const Eigen::MatrixX3d& points, const Eigen::VectorXd& d, double band_mm,
                              const std::string& comment) {
  std::ostringstream out;
  out << "ply\nformat ascii 1.0\ncomment " << comment << "\ncomment coordinates LPS, units mm; colour: red inside (d < -"
      << band_mm << " mm), green within +-" << band_mm << " mm, blue outside\n"
      << "element vertex " << points.rows() << "\nproperty double x\nproperty double y\nproperty double z\n"
      << "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty double signed_distance_mm\n"
      << "end_header\n"
      << std::setprecision(12);
  std::string text = out.str();
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    for (int k = 0; k < 3; ++k) {
      appendNumber(text, points(i, k));
      text += ' ';
    }
    text += d[i] < -band_mm ? "255 0 0 " : d[i] > band_mm ? "0 0 255 " : "0 200 0 ";
    appendNumber(text, d[i]);
    text += '\n';
  }
  return text;
}

std::string meshPly(const Eigen::MatrixX3d& vertices, const Eigen::MatrixX3i& triangles, const std::string& comment) {
  std::ostringstream out;
  out << "ply\nformat ascii 1.0\ncomment " << comment << "\ncomment coordinates LPS, units mm\n"
      << "element vertex " << vertices.rows() << "\nproperty double x\nproperty double y\nproperty double z\n"
      << "element face " << triangles.rows() << "\nproperty list uchar int vertex_indices\nend_header\n"
      << std::setprecision(12);
  for (Eigen::Index i = 0; i < vertices.rows(); ++i)
    out << vertices(i, 0) << ' ' << vertices(i, 1) << ' ' << vertices(i, 2) << '\n';  // a patch: few vertices
  for (Eigen::Index i = 0; i < triangles.rows(); ++i)
    out << "3 " << triangles(i, 0) << ' ' << triangles(i, 1) << ' ' << triangles(i, 2) << '\n';
  return out.str();
}

}  // namespace articula::report
