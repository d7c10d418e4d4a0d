#include "articula/report/ply_writers.hpp"

#include "articula/core/number_text.hpp"
#include "articula/points/ply_writer.hpp"

namespace articula::report {

std::string colouredPointsPly(const Eigen::MatrixX3d& points, const Eigen::VectorXd& d, double band_mm,
                              const std::string& comment) {
  points::PlyData data;
  std::string band;
  appendNumber(band, band_mm);
  data.comments = {comment, "colour: red inside (d < -" + band + " mm), green within +-" + band + " mm, blue outside"};
  data.vertex_properties = {{"x"}, {"y"}, {"z"}, {"red", true}, {"green", true}, {"blue", true}, {"signed_distance_mm"}};
  data.vertex_values.resize(points.rows(), 7);
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const bool inside = d[i] < -band_mm, outside = d[i] > band_mm;
    data.vertex_values.row(i) << points.row(i), inside ? 255 : 0, inside || outside ? 0 : 200, outside ? 255 : 0, d[i];
  }
  return points::plyText(data, points::PlyFormat::Ascii);
}

std::string meshPly(const Eigen::MatrixX3d& vertices, const Eigen::MatrixX3i& triangles, const std::string& comment) {
  points::PlyData data;
  data.comments = {comment};
  data.vertex_properties = {{"x"}, {"y"}, {"z"}};
  data.vertex_values = vertices;
  data.faces = triangles;
  return points::plyText(data, points::PlyFormat::Ascii);
}

}  // namespace articula::report
