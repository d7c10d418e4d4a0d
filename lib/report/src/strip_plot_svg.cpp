#include "articula/report/strip_plot_svg.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "articula/report/markup_text.hpp"
#include "svg.hpp"

namespace articula::report {

std::string stripPlotSvg(const std::string& title, const std::string& unit, const std::vector<StripPoint>& points) {
  std::vector<std::string> groups;
  for (const auto& p : points)
    if (std::isfinite(p.value) && std::find(groups.begin(), groups.end(), p.group) == groups.end()) groups.push_back(p.group);
  const bool labelled = groups.size() > 1 || (groups.size() == 1 && !groups[0].empty());
  constexpr double kWidth = 700, kRight = 660, kTop = 24, kLane = 44;
  const double left = labelled ? 110 : 40;
  const double axis = kTop + kLane * static_cast<double>(std::max<size_t>(groups.size(), 1)), height = axis + 24;
  std::ostringstream out;
  out << svg::open(kWidth, height) << "<text x=\"40\" y=\"16\" font-size=\"13\">" << escapeMarkup(title) << "</text>\n";
  double lo = INFINITY, hi = -INFINITY;
  for (const auto& p : points)
    if (std::isfinite(p.value)) lo = std::min(lo, p.value), hi = std::max(hi, p.value);
  if (!(lo <= hi)) return out.str() + "<text x=\"40\" y=\"50\">no values</text>\n</svg>\n";
  const double step = svg::tickStep(std::max(hi - lo, 1e-9 * std::max(1.0, std::fabs(hi))), 5);
  const double first = std::floor(lo / step) * step, last = std::ceil(hi / step) * step;
  const double span = std::max(last - first, step);
  const auto x = [&](double v) { return left + (kRight - left) * (v - first) / span; };
  out << "<line x1=\"" << left << "\" y1=\"" << axis << "\" x2=\"" << kRight << "\" y2=\"" << axis
      << "\" stroke=\"black\"/>\n";
  for (double t = first; t <= last + 1e-9 * span; t += step)
    out << "<line x1=\"" << x(t) << "\" y1=\"" << axis << "\" x2=\"" << x(t) << "\" y2=\"" << axis + 4
        << "\" stroke=\"black\"/><text x=\"" << x(t) << "\" y=\"" << axis + 16 << "\" text-anchor=\"middle\">"
        << svg::label(t) << "</text>\n";
  out << "<text x=\"" << kRight + 8 << "\" y=\"" << axis + 4 << "\">" << escapeMarkup(unit) << "</text>\n";
  for (size_t g = 0; g < groups.size(); ++g) {
    const double lane_bottom = kTop + kLane * static_cast<double>(g + 1);
    if (labelled)
      out << "<text class=\"lane\" x=\"4\" y=\"" << lane_bottom - 14 << "\">" << escapeMarkup(groups[g]) << "</text>\n"
          << "<line x1=\"" << left << "\" y1=\"" << lane_bottom << "\" x2=\"" << kRight << "\" y2=\"" << lane_bottom
          << "\" stroke=\"#ddd\"/>\n";
    size_t order = 0;
    for (const StripPoint& p : points) {
      if (!std::isfinite(p.value) || p.group != groups[g]) continue;
      const double y = lane_bottom - 10 - static_cast<double>(order++ % 6) * 5;  // by order: equal values stay apart
      const bool flagged = !p.flag.empty();
      std::ostringstream dot;
      dot << "<circle class=\"subject" << (flagged ? " flagged" : "") << "\" cx=\"" << x(p.value) << "\" cy=\"" << y
          << "\" r=\"" << (flagged ? 5 : 4) << "\" fill=\"" << (flagged ? (p.flag == "fail" ? "#d62728" : "#ff7f0e") : svg::seriesColour(0))
          << "\" fill-opacity=\"0.8\"" << (flagged ? " stroke=\"black\" stroke-width=\"1.5\"" : "") << "><title>"
          << escapeMarkup(p.label) << ": " << svg::label(p.value) << ' ' << escapeMarkup(unit)
          << (flagged ? " (checks: " + escapeMarkup(p.flag) + ")" : "") << "</title></circle>";
      out << (p.link.empty() ? dot.str() : "<a href=\"" + escapeMarkup(p.link) + "\">" + dot.str() + "</a>") << '\n';
    }
  }
  return out.str() + "</svg>\n";
}

}  // namespace articula::report
