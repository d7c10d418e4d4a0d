#include "articula/report/line_chart_svg.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "articula/core/error.hpp"
#include "svg.hpp"

namespace articula::report {

std::string lineChartSvg(const std::vector<LineSeries>& series, const LineChart& chart) {
  constexpr double W = 720, H = 420, left = 80, right = 20, top = 40, bottom = 60;
  const auto value = [&](double y) { return chart.log_y ? (y > 0 ? std::log10(y) : NAN) : y; };
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  for (const LineSeries& s : series) {
    if (s.x.size() != s.y.size())
      throw InvalidParameter("line chart series '" + s.label + "'", "as many x as y values", static_cast<double>(s.y.size()));
    for (size_t i = 0; i < s.x.size(); ++i) {
      const double v = value(s.y[i]);
      if (!std::isfinite(s.x[i]) || !std::isfinite(v)) continue;
      x0 = std::min(x0, s.x[i]), x1 = std::max(x1, s.x[i]), y0 = std::min(y0, v), y1 = std::max(y1, v);
    }
  }
  if (!(x1 >= x0)) x0 = 0, x1 = 1, y0 = 0, y1 = 1;  // nothing to draw: empty axes
  if (x1 == x0) x0 -= 0.5, x1 += 0.5;
  if (y1 == y0) y0 -= 0.5, y1 += 0.5;
  const double pad = 0.05 * (y1 - y0);
  y0 -= pad, y1 += pad;
  const auto px = [&](double x) { return left + (x - x0) / (x1 - x0) * (W - left - right); };
  const auto py = [&](double v) { return H - bottom - (v - y0) / (y1 - y0) * (H - top - bottom); };

  std::ostringstream out;
  out << svg::open(W, H);
  out << "<text x=\"" << W / 2 << "\" y=\"22\" text-anchor=\"middle\" font-size=\"14\">" << escapeMarkup(chart.title)
      << "</text>\n";
  out << "<rect x=\"" << left << "\" y=\"" << top << "\" width=\"" << W - left - right << "\" height=\"" << H - top - bottom
      << "\" fill=\"none\" stroke=\"#444\"/>\n";
  const double xs = svg::tickStep(x1 - x0, 8);
  for (double t = std::ceil(x0 / xs) * xs; t <= x1 + 1e-9 * xs; t += xs)
    out << "<line x1=\"" << px(t) << "\" x2=\"" << px(t) << "\" y1=\"" << H - bottom << "\" y2=\"" << H - bottom + 5
        << "\" stroke=\"#444\"/><text x=\"" << px(t) << "\" y=\"" << H - bottom + 18 << "\" text-anchor=\"middle\">"
        << svg::label(t) << "</text>\n";
  const double ys = chart.log_y ? std::max(1.0, std::round(svg::tickStep(y1 - y0, 6))) : svg::tickStep(y1 - y0, 6);
  for (double t = std::ceil(y0 / ys) * ys; t <= y1 + 1e-9 * ys; t += ys)
    out << "<line x1=\"" << left - 5 << "\" x2=\"" << left << "\" y1=\"" << py(t) << "\" y2=\"" << py(t)
        << "\" stroke=\"#444\"/><text x=\"" << left - 8 << "\" y=\"" << py(t) + 4 << "\" text-anchor=\"end\">"
        << (chart.log_y ? "1e" + svg::label(t) : svg::label(t)) << "</text>\n";
  out << "<text x=\"" << (left + W - right) / 2 << "\" y=\"" << H - 15 << "\" text-anchor=\"middle\">"
      << escapeMarkup(chart.x_label) << "</text>\n";
  out << "<text transform=\"translate(18," << (top + H - bottom) / 2 << ") rotate(-90)\" text-anchor=\"middle\">"
      << escapeMarkup(chart.y_label) << "</text>\n";
  for (size_t k = 0; k < series.size(); ++k) {
    const LineSeries& s = series[k];
    out << "<g class=\"series\"><title>" << escapeMarkup(s.label) << "</title>";
    std::ostringstream points;
    bool open = false;
    const auto flush = [&] {
      if (open) out << "<polyline fill=\"none\" stroke=\"" << svg::seriesColour(k) << "\" stroke-width=\"1.5\" points=\""
                    << points.str() << "\"/>";
      points.str("");
      open = false;
    };
    for (size_t i = 0; i < s.x.size(); ++i) {
      const double v = value(s.y[i]);
      if (!std::isfinite(s.x[i]) || !std::isfinite(v)) {
        flush();
        continue;
      }
      points << (open ? " " : "") << px(s.x[i]) << "," << py(v);
      open = true;
    }
    flush();
    out << "</g>\n";
    out << "<text x=\"" << left + 10 << "\" y=\"" << top + 16 + 16 * static_cast<double>(k) << "\" fill=\""
        << svg::seriesColour(k) << "\">" << escapeMarkup(s.label) << "</text>\n";
  }
  out << "</svg>\n";
  return out.str();
}

}  // namespace articula::report
