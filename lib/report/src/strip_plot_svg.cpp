#include "articula/report/strip_plot_svg.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "articula/report/markup_text.hpp"
#include "svg.hpp"

namespace articula::report {

std::string stripPlotSvg(const std::string& title, const std::string& unit, const std::vector<StripPoint>& points) {
  constexpr double kWidth = 700, kHeight = 90, kLeft = 40, kRight = 660, kAxis = 66;
  std::ostringstream out;
  out << svg::open(kWidth, kHeight) << "<text x=\"" << kLeft << "\" y=\"16\" font-size=\"13\">" << escapeMarkup(title)
      << "</text>\n";
  double lo = INFINITY, hi = -INFINITY;
  for (const auto& p : points)
    if (std::isfinite(p.value)) lo = std::min(lo, p.value), hi = std::max(hi, p.value);
  if (!(lo <= hi)) return out.str() + "<text x=\"40\" y=\"50\">no values</text>\n</svg>\n";
  const double step = svg::tickStep(std::max(hi - lo, 1e-9 * std::max(1.0, std::fabs(hi))), 5);
  const double first = std::floor(lo / step) * step, last = std::ceil(hi / step) * step;
  const double span = std::max(last - first, step);
  const auto x = [&](double v) { return kLeft + (kRight - kLeft) * (v - first) / span; };
  out << "<line x1=\"" << kLeft << "\" y1=\"" << kAxis << "\" x2=\"" << kRight << "\" y2=\"" << kAxis
      << "\" stroke=\"black\"/>\n";
  for (double t = first; t <= last + 1e-9 * span; t += step)
    out << "<line x1=\"" << x(t) << "\" y1=\"" << kAxis << "\" x2=\"" << x(t) << "\" y2=\"" << kAxis + 4
        << "\" stroke=\"black\"/><text x=\"" << x(t) << "\" y=\"" << kAxis + 16 << "\" text-anchor=\"middle\">"
        << svg::label(t) << "</text>\n";
  out << "<text x=\"" << kRight + 8 << "\" y=\"" << kAxis + 4 << "\">" << escapeMarkup(unit) << "</text>\n";
  for (size_t i = 0; i < points.size(); ++i) {
    const StripPoint& p = points[i];
    if (!std::isfinite(p.value)) continue;
    const double y = kAxis - 10 - static_cast<double>(i % 7) * 5;  // by order: equal values stay apart
    std::ostringstream dot;
    dot << "<circle class=\"subject\" cx=\"" << x(p.value) << "\" cy=\"" << y << "\" r=\"4\" fill=\""
        << svg::seriesColour(0) << "\" fill-opacity=\"0.8\"><title>" << escapeMarkup(p.label) << ": " << svg::label(p.value)
        << ' ' << escapeMarkup(unit) << "</title></circle>";
    out << (p.link.empty() ? dot.str() : "<a href=\"" + escapeMarkup(p.link) + "\">" + dot.str() + "</a>") << '\n';
  }
  return out.str() + "</svg>\n";
}

}  // namespace articula::report
