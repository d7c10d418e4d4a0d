#include "articula/report/histogram_svg.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

#include "articula/core/error.hpp"
#include "svg.hpp"

namespace articula::report {

Histogram histogram(const Eigen::VectorXd& d, double lower, double upper, int bins) {
  if (bins < 1 || !(upper > lower)) throw UsageError("histogram: expected bins >= 1 and upper > lower");
  Histogram h;
  h.lower = lower;
  h.bin_width = (upper - lower) / bins;
  h.counts.assign(static_cast<size_t>(bins), 0);
  for (Eigen::Index i = 0; i < d.size(); ++i) {
    const int b = std::clamp(static_cast<int>(std::floor((d[i] - lower) / h.bin_width)), 0, bins - 1);
    ++h.counts[static_cast<size_t>(b)];
  }
  return h;
}

using svg::tickStep;

std::string histogramSvg(const std::vector<Series>& series, const std::string& title) {
  if (series.empty()) throw UsageError("histogram: expected at least one series");
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  long n_max = 0;
  for (const auto& s : series) {
    if (s.values.size() == 0) throw InputError("histogram: series '" + s.label + "' is empty");
    lo = std::min(lo, s.values.minCoeff());
    hi = std::max(hi, s.values.maxCoeff());
    n_max = std::max<long>(n_max, s.values.size());
  }
  if (!(hi > lo)) {
    lo -= 0.5;
    hi += 0.5;
  }
  const int bins = std::max(5, static_cast<int>(std::ceil(std::sqrt(static_cast<double>(n_max)))));
  std::vector<Histogram> hists;
  double y_max = 1.0;
  for (const auto& s : series) {
    hists.push_back(histogram(s.values, lo, hi, bins));
    y_max = std::max(y_max, static_cast<double>(*std::max_element(hists.back().counts.begin(), hists.back().counts.end())));
    if (s.sigma > 0.0) {
      const double peak = static_cast<double>(s.values.size()) * hists.back().bin_width / (s.sigma * std::sqrt(2.0 * M_PI));
      y_max = std::max(y_max, peak);
    }
  }
  y_max *= 1.05;
  const double W = 800, H = 500, left = 80, right = 20, top = 40, bottom = 60;
  const double pw = W - left - right, ph = H - top - bottom;
  auto X = [&](double v) { return left + (v - lo) / (hi - lo) * pw; };
  auto Y = [&](double c) { return top + ph - c / y_max * ph; };
  std::ostringstream out;
  out << std::fixed << std::setprecision(2);
  out << svg::open(W, H) << "<text x=\"" << W / 2 << "\" y=\"24\" text-anchor=\"middle\" font-size=\"15\">"
      << escapeMarkup(title) << "</text>\n";
  // Axes, ticks and labels.
  out << "<line x1=\"" << left << "\" y1=\"" << top + ph << "\" x2=\"" << left + pw << "\" y2=\"" << top + ph
      << "\" stroke=\"black\"/>\n<line x1=\"" << left << "\" y1=\"" << top << "\" x2=\"" << left << "\" y2=\""
      << top + ph << "\" stroke=\"black\"/>\n";
  const double xs = tickStep(hi - lo, 8);
  for (double t = std::ceil(lo / xs) * xs; t <= hi + 1e-12; t += xs)
    out << "<line x1=\"" << X(t) << "\" y1=\"" << top + ph << "\" x2=\"" << X(t) << "\" y2=\"" << top + ph + 5
        << "\" stroke=\"black\"/><text x=\"" << X(t) << "\" y=\"" << top + ph + 18 << "\" text-anchor=\"middle\">"
        << std::setprecision(3) << std::defaultfloat << (std::fabs(t) < 1e-12 ? 0.0 : t) << std::fixed
        << std::setprecision(2) << "</text>\n";
  const double ys = tickStep(y_max, 6);
  for (double t = 0.0; t <= y_max; t += ys)
    out << "<line x1=\"" << left - 5 << "\" y1=\"" << Y(t) << "\" x2=\"" << left << "\" y2=\"" << Y(t)
        << "\" stroke=\"black\"/><text x=\"" << left - 8 << "\" y=\"" << Y(t) + 4 << "\" text-anchor=\"end\">"
        << std::setprecision(0) << t << std::setprecision(2) << "</text>\n";
  out << "<text x=\"" << left + pw / 2 << "\" y=\"" << H - 15
      << "\" text-anchor=\"middle\">signed Euclidean distance (mm), negative inside</text>\n"
      << "<text x=\"18\" y=\"" << top + ph / 2 << "\" text-anchor=\"middle\" transform=\"rotate(-90 18 " << top + ph / 2
      << ")\">number of points per bin</text>\n";
  // Step histograms and Gaussians.
  for (size_t k = 0; k < series.size(); ++k) {
    const Histogram& h = hists[k];
    out << "<path fill=\"none\" stroke=\"" << svg::seriesColour(k) << "\" stroke-opacity=\"0.6\" d=\"M" << X(lo) << ',' << Y(0);
    for (size_t b = 0; b < h.counts.size(); ++b) {
      const double c = static_cast<double>(h.counts[b]);
      out << " L" << X(lo + b * h.bin_width) << ',' << Y(c) << " L" << X(lo + (b + 1) * h.bin_width) << ',' << Y(c);
    }
    out << " L" << X(hi) << ',' << Y(0) << "\"/>\n";
    const Series& s = series[k];
    if (s.sigma > 0.0) {
      out << "<polyline fill=\"none\" stroke-width=\"2\" stroke=\"" << svg::seriesColour(k) << "\" points=\"";
      const double scale = static_cast<double>(s.values.size()) * h.bin_width / (s.sigma * std::sqrt(2.0 * M_PI));
      for (int i = 0; i <= 200; ++i) {
        const double v = lo + (hi - lo) * i / 200.0;
        out << X(v) << ',' << Y(scale * std::exp(-0.5 * std::pow((v - s.mu) / s.sigma, 2))) << ' ';
      }
      out << "\"/>\n";
    }
    const double ly = top + 10 + 18.0 * static_cast<double>(k);
    out << "<line x1=\"" << left + pw - 320 << "\" y1=\"" << ly << "\" x2=\"" << left + pw - 295 << "\" y2=\"" << ly
        << "\" stroke-width=\"2\" stroke=\"" << svg::seriesColour(k) << "\"/><text x=\"" << left + pw - 290 << "\" y=\"" << ly + 4
        << "\">" << escapeMarkup(s.label) << std::setprecision(3) << " (\u03bc " << (std::fabs(s.mu) < 5e-4 ? 0.0 : s.mu)
        << ", \u03c3 " << s.sigma << " mm)"
        << std::setprecision(2) << "</text>\n";
  }
  out << "</svg>\n";
  return out.str();
}

}  // namespace articula::report
