#include "articula/subject/head_slices.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "articula/geometry/surface.hpp"
#include "articula/imaging/edges.hpp"
#include "articula/report/slice_image.hpp"

namespace articula::subject {
namespace {

constexpr double kWindowLowHu = -200, kWindowHighHu = 1600;  // bone window

struct Plane {
  const char* name;
  Eigen::Vector3d right, down;  // LPS directions of the image's columns and rows
  const char *left_letter, *right_letter, *top_letter, *bottom_letter;
  int axis;                     // the LPS axis across the plane
  const char* axis_name;
};

// Radiological view: the patient's left on the right of axial and coronal
// images, anterior on the left of the sagittal one, superior up.
const Plane kPlanes[3] = {{"axial", {1, 0, 0}, {0, 1, 0}, "R", "L", "A", "P", 2, "z"},
                          {"coronal", {1, 0, 0}, {0, 0, -1}, "R", "L", "S", "I", 1, "y"},
                          {"sagittal", {0, 1, 0}, {0, 0, -1}, "A", "P", "S", "I", 0, "x"}};
// Each plane through the centre and half a radius to either side of it.
constexpr double kSliceOffsetsRadii[3] = {-0.5, 0.0, 0.5};
constexpr double kScaleBarMm = 10;

std::string path(const std::vector<report::Segment2>& segments) {
  std::ostringstream d;
  d.precision(4);
  for (const auto& s : segments)  // grid points sit at pixel centres
    d << 'M' << s.a.x() + 0.5 << ' ' << s.a.y() + 0.5 << 'L' << s.b.x() + 0.5 << ' ' << s.b.y() + 0.5;
  return d.str();
}

double labelAt(const imaging::Label& label, const Eigen::Vector3d& x) {
  const Eigen::Vector3d index = label.geometry.toIndex(x);
  Eigen::Vector3i v;
  for (int a = 0; a < 3; ++a) {
    v[a] = static_cast<int>(std::lround(index[a]));
    if (v[a] < 0 || v[a] >= label.geometry.size[a]) return 0;
  }
  return label.at(v[0], v[1], v[2]) ? 1 : 0;
}

}  // namespace

std::string headSlicesHtml(const imaging::Volume& ct, const imaging::Label* label, const geometry::ShapeParameters& model,
                           double half_width_mm, double step_mm) {
  const auto surface = geometry::makeSurface(model);
  const int n = std::clamp(static_cast<int>(std::lround(2 * half_width_mm / step_mm)), 16, 1024);
  const double pixel_mm = 2 * half_width_mm / n, stroke = 0.6 * n / 320.0 * 2, letter = n / 14.0;
  const double radius = model.radii.maxCoeff();
  std::string html;
  for (const Plane& plane : kPlanes) {
    html += "<div class=\"slices\">";
    const Eigen::Vector3d across = plane.right.cross(plane.down);
    for (const double offset_radii : kSliceOffsetsRadii) {
      const Eigen::Vector3d centre = model.center + offset_radii * radius * across;
      std::vector<std::uint8_t> pixels(static_cast<size_t>(n) * static_cast<size_t>(n));
      Eigen::MatrixXd edge(n, n), outline(n, n);
      for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c) {
          const Eigen::Vector3d x = centre + ((c + 0.5) * pixel_mm - half_width_mm) * plane.right +
                                    ((r + 0.5) * pixel_mm - half_width_mm) * plane.down;
          const double hu = imaging::interpolate(ct, x);
          const double grey = std::isnan(hu) ? 0 : std::clamp((hu - kWindowLowHu) / (kWindowHighHu - kWindowLowHu), 0.0, 1.0);
          pixels[static_cast<size_t>(r) * static_cast<size_t>(n) + static_cast<size_t>(c)] =
              static_cast<std::uint8_t>(std::lround(255 * grey));
          edge(r, c) = label ? labelAt(*label, x) : NAN;
          outline(r, c) = surface->evaluate(x, 0).value;
        }
      std::ostringstream svg;
      svg.precision(4);
      svg << "<figure><svg xmlns=\"http://www.w3.org/2000/svg\" class=\"slice\" data-plane=\"" << plane.name
          << "\" width=\"240\" height=\"240\" viewBox=\"0 0 " << n << ' ' << n << "\"><image width=\"" << n << "\" height=\""
          << n << "\" style=\"image-rendering:pixelated\" href=\"data:image/png;base64,"
          << report::base64(report::greyPng(pixels, n, n)) << "\"/>";
      if (label)
        svg << "<path class=\"label-edge\" d=\"" << path(report::contourSegments(edge, 0.5))
            << "\" fill=\"none\" stroke=\"#ffd400\" stroke-width=\"" << stroke << "\"/>";
      svg << "<path class=\"model-outline\" d=\"" << path(report::contourSegments(outline, 0.0))
          << "\" fill=\"none\" stroke=\"#ff00c8\" stroke-width=\"" << stroke << "\"/>";
      // Orientation letters on the four sides, and a 10 mm scale bar.
      svg << "<g class=\"orientation\" fill=\"#7fdcff\" font-family=\"sans-serif\" font-size=\"" << letter << "\">"
          << "<text x=\"" << 0.3 * letter << "\" y=\"" << n / 2.0 << "\" dominant-baseline=\"middle\">" << plane.left_letter
          << "</text><text x=\"" << n - 0.3 * letter << "\" y=\"" << n / 2.0
          << "\" text-anchor=\"end\" dominant-baseline=\"middle\">" << plane.right_letter << "</text><text x=\"" << n / 2.0
          << "\" y=\"" << 1.1 * letter << "\" text-anchor=\"middle\">" << plane.top_letter << "</text><text x=\"" << n / 2.0
          << "\" y=\"" << n - 0.4 * letter << "\" text-anchor=\"middle\">" << plane.bottom_letter << "</text></g>";
      const double bar = kScaleBarMm / pixel_mm;
      svg << "<g class=\"scale-bar\"><line x1=\"" << 0.5 * letter << "\" y1=\"" << n - 0.6 * letter << "\" x2=\""
          << 0.5 * letter + bar << "\" y2=\"" << n - 0.6 * letter << "\" stroke=\"#ffffff\" stroke-width=\"" << 1.5 * stroke
          << "\"/><text x=\"" << 0.5 * letter << "\" y=\"" << n - 0.9 * letter << "\" fill=\"#ffffff\" font-family=\"sans-serif\" "
          << "font-size=\"" << 0.7 * letter << "\">" << kScaleBarMm << " mm</text></g></svg><figcaption>" << plane.name
          << ", " << plane.axis_name << " = ";
      char where[96];
      std::snprintf(where, sizeof where, "%.1f mm (%s)", centre[plane.axis],
                    offset_radii == 0 ? "centre" : offset_radii < 0 ? "centre - r/2" : "centre + r/2");
      svg << where << "</figcaption></figure>";
      html += svg.str();
    }
    html += "</div>\n";
  }
  return html;
}

}  // namespace articula::subject
