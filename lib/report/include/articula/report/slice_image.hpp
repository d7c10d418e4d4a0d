#pragma once
// Pieces of the report's CT slices: a grey image as PNG bytes (to inline as a
// data: address), base64, and the contour of a sampled field (marching
// squares) as line segments, for a label's edge and a fitted surface's outline.
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace articula::report {

/// An 8-bit grey PNG of `width` x `height` pixels, rows top first.
/// Hand-written over zlib: libpng is not among the dependencies, and ITK's
/// and VTK's PNG writers would bring an imaging toolkit into the report.
std::string greyPng(const std::vector<std::uint8_t>& pixels, int width, int height);

/// RFC 4648 base64.
std::string base64(const std::string& bytes);

struct Segment2 {
  Eigen::Vector2d a, b;  // in grid coordinates (column, row)
};

/// The level set field = level of a grid sampled at integer (column, row)
/// points, as segments (marching squares, linear along cell edges; the
/// ambiguous saddle taken by the cell's mean). Cells with a NaN corner are
/// skipped.
std::vector<Segment2> contourSegments(const Eigen::MatrixXd& field, double level);

}  // namespace articula::report
