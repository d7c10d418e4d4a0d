#include "articula/report/error_map_svg.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "articula/core/error.hpp"
#include "articula/report/diverging_colour.hpp"
#include "svg.hpp"

namespace articula::report {

void ErrorMapOptions::validate() const {
  if (!(limit_mm >= 0.0) || !std::isfinite(limit_mm)) throw InvalidParameter("limit_mm", ">= 0 (0: automatic)", limit_mm);
  if (max_points < 1) throw InvalidParameter("max_points", ">= 1", max_points);
}

namespace {

constexpr int kHalfSteps = 10;  // colour levels -10 .. 10 (21 steps of limit / 10)

// The smallest of 1, 1.5, 2, 2.5, 3, 4, 5, 6, 8 x 10^k that is >= v.
double niceCeil(double v) {
  if (!(v > 0.0)) return 0.1;
  const double p = std::pow(10.0, std::floor(std::log10(v)));
  for (double m : {1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0})
    if (m * p >= v * (1.0 - 1e-12)) return m * p;
  return 10.0 * p;
}

// The LPS letter a unit direction points to most.
char anatomical(const Eigen::Vector3d& v) {
  Eigen::Index k;
  v.cwiseAbs().maxCoeff(&k);
  static const char positive[] = {'L', 'P', 'S'}, negative[] = {'R', 'A', 'I'};
  return v[k] >= 0.0 ? positive[k] : negative[k];
}

int level(double d, double limit) {
  if (!std::isfinite(d)) return 0;
  return static_cast<int>(std::lround(std::clamp(d / limit, -1.0, 1.0) * kHalfSteps));
}

}  // namespace

double sharedColourLimit(const std::vector<ErrorMapPanel>& panels) {
  std::vector<double> a;
  for (const auto& p : panels)
    for (Eigen::Index i = 0; i < p.d.size(); ++i)
      if (std::isfinite(p.d[i])) a.push_back(std::fabs(p.d[i]));
  if (a.empty()) return niceCeil(0.0);
  const size_t k = std::min(a.size() - 1, static_cast<size_t>(std::ceil(0.98 * static_cast<double>(a.size()))) - 1);
  std::nth_element(a.begin(), a.begin() + static_cast<long>(k), a.end());
  return niceCeil(a[k]);
}

std::string errorMapSvg(const AzimuthalMap& map, const std::vector<ErrorMapPanel>& panels,
                        const ErrorMapOptions& options, const std::string& title) {
  options.validate();
  if (panels.empty()) throw InputError("error map: expected at least one panel");
  const Eigen::Index n = map.xy.rows();
  for (const auto& p : panels)
    if (p.d.size() != n)
      throw InputError("error map: panel '" + p.label + "' has " + std::to_string(p.d.size()) +
                       " distances, expected one per point (" + std::to_string(n) + ")");
  const double limit = options.limit_mm > 0.0 ? options.limit_mm : sharedColourLimit(panels);
  double extent = n ? map.xy.cwiseAbs().maxCoeff() : 0.0;
  if (!(extent > 0.0)) extent = 1.0;
  const double tick = svg::tickStep(extent, 3);
  extent = std::ceil(extent / tick - 1e-9) * tick;
  const Eigen::Index stride = (n + options.max_points - 1) / options.max_points;

  const int cols = std::min<int>(3, static_cast<int>(panels.size()));
  const int rows = (static_cast<int>(panels.size()) + cols - 1) / cols;
  const double cell_w = 290, cell_h = 300, side = 210, left = 20, top = 80;
  const double W = left + cols * cell_w + 160, H = top + rows * cell_h + 10;
  const long drawn = static_cast<long>((n + stride - 1) / std::max<Eigen::Index>(stride, 1));
  const double dot = std::clamp(0.9 * side / std::sqrt(static_cast<double>(std::max(1L, drawn))), 2.5, 6.0);

  std::ostringstream out;
  out << std::fixed << std::setprecision(1);
  out << svg::open(W, H) << "<text x=\"" << W / 2 << "\" y=\"24\" text-anchor=\"middle\" font-size=\"15\">"
      << escapeMarkup(title) << "</text>\n";
  {
    std::ostringstream c1, c2;
    c1 << std::setprecision(2) << std::fixed << "Lambert azimuthal equal-area maps of the " << n
       << " points about the head axis (LPS " << map.axis.x() << ", " << map.axis.y() << ", " << map.axis.z()
       << ") from the centre (" << std::setprecision(1) << map.centre.x() << ", " << map.centre.y() << ", "
       << map.centre.z() << ") mm";
    if (stride > 1) c1 << "; 1 in " << stride << " drawn";
    c2 << std::setprecision(1) << std::fixed << "seen from outside the head: right \u2248 " << anatomical(map.right)
       << ", up \u2248 " << anatomical(map.up) << "; map distances in mm on the sphere of radius " << map.radius_mm
       << " mm (LPS); dashed: 90\u00b0 from the axis";
    out << "<text x=\"" << W / 2 << "\" y=\"46\" text-anchor=\"middle\">" << escapeMarkup(c1.str()) << "</text>\n"
        << "<text x=\"" << W / 2 << "\" y=\"63\" text-anchor=\"middle\">" << escapeMarkup(c2.str()) << "</text>\n";
  }

  for (size_t k = 0; k < panels.size(); ++k) {
    const ErrorMapPanel& panel = panels[k];
    const double x0 = left + static_cast<double>(k % static_cast<size_t>(cols)) * cell_w + 60;
    const double y0 = top + static_cast<double>(k / static_cast<size_t>(cols)) * cell_h + 30;
    auto X = [&](double x) { return x0 + (x + extent) / (2 * extent) * side; };
    auto Y = [&](double y) { return y0 + (extent - y) / (2 * extent) * side; };
    double sse = 0.0;
    for (Eigen::Index i = 0; i < n; ++i) sse += panel.d[i] * panel.d[i];
    const bool best = !options.highlight.empty() && panel.label == options.highlight;
    out << "<g class=\"panel\">\n<text x=\"" << x0 + side / 2 << "\" y=\"" << y0 - 10 << "\" text-anchor=\"middle\""
        << (best ? " font-weight=\"bold\"" : "") << ">" << escapeMarkup(panel.label) << ": RMS "
        << svg::label(n ? std::sqrt(sse / static_cast<double>(n)) : 0.0) << " mm" << (best ? " (least RMS)" : "")
        << "</text>\n<rect x=\"" << x0 << "\" y=\"" << y0 << "\" width=\"" << side << "\" height=\"" << side
        << "\" fill=\"none\" stroke=\"black\"/>\n";
    for (double t = -extent; t <= extent + 1e-9; t += tick)
      out << "<line x1=\"" << X(t) << "\" y1=\"" << y0 + side << "\" x2=\"" << X(t) << "\" y2=\"" << y0 + side + 4
          << "\" stroke=\"black\"/><text x=\"" << X(t) << "\" y=\"" << y0 + side + 16 << "\" text-anchor=\"middle\">"
          << svg::label(t) << "</text>\n<line x1=\"" << x0 - 4 << "\" y1=\"" << Y(t) << "\" x2=\"" << x0 << "\" y2=\""
          << Y(t) << "\" stroke=\"black\"/><text x=\"" << x0 - 6 << "\" y=\"" << Y(t) + 4 << "\" text-anchor=\"end\">"
          << svg::label(t) << "</text>\n";
    out << "<text x=\"" << x0 + side / 2 << "\" y=\"" << y0 + side + 32 << "\" text-anchor=\"middle\">x (mm) \u2192 "
        << anatomical(map.right) << "</text>\n<text x=\"" << x0 - 40 << "\" y=\"" << y0 + side / 2
        << "\" text-anchor=\"middle\" transform=\"rotate(-90 " << x0 - 40 << ' ' << y0 + side / 2 << ")\">y (mm) \u2192 "
        << anatomical(map.up) << "</text>\n";
    const double ring = map.radius_mm * std::sqrt(2.0);
    if (ring < extent)
      out << "<circle cx=\"" << X(0) << "\" cy=\"" << Y(0) << "\" r=\"" << ring / (2 * extent) * side
          << "\" fill=\"none\" stroke=\"#888888\" stroke-dasharray=\"4 3\"/>\n";
    // Dots by colour level, the levels nearest 0 first so that large errors stay visible.
    std::vector<std::vector<Eigen::Index>> by_level(2 * kHalfSteps + 1);
    for (Eigen::Index i = 0; i < n; i += stride)
      by_level[static_cast<size_t>(level(panel.d[i], limit) + kHalfSteps)].push_back(i);
    out << "<g fill=\"none\" stroke-width=\"" << dot << "\" stroke-linecap=\"round\">\n";
    std::vector<int> order = {0};
    for (int a = 1; a <= kHalfSteps; ++a) order.insert(order.end(), {-a, a});
    for (int l : order) {
      const auto& ids = by_level[static_cast<size_t>(l + kHalfSteps)];
      if (ids.empty()) continue;
      out << "<path class=\"pts\" stroke=\"" << divergingColour(static_cast<double>(l) / kHalfSteps) << "\" d=\"";
      for (Eigen::Index i : ids) out << 'M' << X(map.xy(i, 0)) << ' ' << Y(map.xy(i, 1)) << "h0";
      out << "\"/>\n";
    }
    out << "</g>\n<path d=\"M" << X(0) - 5 << ' ' << Y(0) << "h10M" << X(0) << ' ' << Y(0) - 5
        << "v10\" stroke=\"black\"/>\n</g>\n";
  }

  // Colour bar: +limit (outside, blue) at the top, -limit (inside, red) at the bottom.
  const double bx = left + cols * cell_w + 20, by = top + 30, bh = 220, bw = 18, step = bh / (2 * kHalfSteps + 1);
  out << "<g id=\"colour-bar\" data-limit-mm=\"" << svg::label(limit) << "\">\n<text x=\"" << bx << "\" y=\"" << by - 26
      << "\">signed distance (mm)</text>\n<text x=\"" << bx << "\" y=\"" << by - 8 << "\">outside</text>\n";
  for (int l = kHalfSteps; l >= -kHalfSteps; --l)
    out << "<rect x=\"" << bx << "\" y=\"" << by + (kHalfSteps - l) * step << "\" width=\"" << bw << "\" height=\""
        << step + 0.3 << "\" fill=\"" << divergingColour(static_cast<double>(l) / kHalfSteps) << "\"/>\n";
  out << "<rect x=\"" << bx << "\" y=\"" << by << "\" width=\"" << bw << "\" height=\"" << bh
      << "\" fill=\"none\" stroke=\"black\"/>\n";
  for (int q = 2; q >= -2; --q) {
    const double y = by + (kHalfSteps - q * kHalfSteps / 2.0) * step + step / 2;
    out << "<line x1=\"" << bx + bw << "\" y1=\"" << y << "\" x2=\"" << bx + bw + 4 << "\" y2=\"" << y
        << "\" stroke=\"black\"/><text class=\"limit\" x=\"" << bx + bw + 7 << "\" y=\"" << y + 4 << "\">"
        << svg::label(q * limit / 2) << "</text>\n";
  }
  out << "<text x=\"" << bx << "\" y=\"" << by + bh + 16 << "\">inside</text>\n<text x=\"" << bx << "\" y=\""
      << by + bh + 34 << "\" font-size=\"10\">beyond \u00b1" << svg::label(limit) << " mm:</text>\n<text x=\"" << bx
      << "\" y=\"" << by + bh + 47 << "\" font-size=\"10\">end colours</text>\n</g>\n</svg>\n";
  return out.str();
}

}  // namespace articula::report
