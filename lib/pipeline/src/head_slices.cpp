#include "articula/pipeline/head_slices.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "articula/geometry/surface.hpp"
#include "articula/imaging/edges.hpp"
#include "articula/report/slice_image.hpp"

namespace articula::pipeline {
namespace {

constexpr double kWindowLowHu = -200, kWindowHighHu = 1600;  // bone window

struct Plane {
  const char* name;
  Eigen::Vector3d right, down;  // LPS directions of the image's columns and rows
};

// Radiological view: the patient's left on the right of axial and coronal
// images, anterior on the left of the sagittal one, superior up.
const Plane kPlanes[3] = {{"axial", {1, 0, 0}, {0, 1, 0}},
                          {"coronal", {1, 0, 0}, {0, 0, -1}},
                          {"sagittal", {0, 1, 0}, {0, 0, -1}}};

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
  std::string html = "<div class=\"slices\">";
  for (const Plane& plane : kPlanes) {
    std::vector<std::uint8_t> pixels(static_cast<size_t>(n) * static_cast<size_t>(n));
    Eigen::MatrixXd edge(n, n), outline(n, n);
    for (int r = 0; r < n; ++r)
      for (int c = 0; c < n; ++c) {
        const Eigen::Vector3d x = model.center + ((c + 0.5) * step_mm - half_width_mm) * plane.right +
                                  ((r + 0.5) * step_mm - half_width_mm) * plane.down;
        const double hu = imaging::interpolate(ct, x);
        const double grey = std::isnan(hu) ? 0 : std::clamp((hu - kWindowLowHu) / (kWindowHighHu - kWindowLowHu), 0.0, 1.0);
        pixels[static_cast<size_t>(r) * static_cast<size_t>(n) + static_cast<size_t>(c)] =
            static_cast<std::uint8_t>(std::lround(255 * grey));
        edge(r, c) = label ? labelAt(*label, x) : NAN;
        outline(r, c) = surface->evaluate(x, 0).value;
      }
    std::ostringstream svg;
    svg << "<figure><svg xmlns=\"http://www.w3.org/2000/svg\" class=\"slice\" data-plane=\"" << plane.name
        << "\" width=\"320\" height=\"320\" viewBox=\"0 0 " << n << ' ' << n << "\"><image width=\"" << n << "\" height=\""
        << n << "\" style=\"image-rendering:pixelated\" href=\"data:image/png;base64,"
        << report::base64(report::greyPng(pixels, n, n)) << "\"/>";
    if (label)
      svg << "<path class=\"label-edge\" d=\"" << path(report::contourSegments(edge, 0.5))
          << "\" fill=\"none\" stroke=\"#ffd400\" stroke-width=\"" << 0.6 * n / 320.0 * 2 << "\"/>";
    svg << "<path class=\"model-outline\" d=\"" << path(report::contourSegments(outline, 0.0))
        << "\" fill=\"none\" stroke=\"#ff00c8\" stroke-width=\"" << 0.6 * n / 320.0 * 2 << "\"/></svg><figcaption>"
        << plane.name << "</figcaption></figure>";
    html += svg.str();
  }
  return html + "</div>\n";
}

}  // namespace articula::pipeline
