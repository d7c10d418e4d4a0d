#include "articula/report/study_svg.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "articula/core/error.hpp"
#include "svg.hpp"

namespace articula::report {

std::string studyRmsSvg(const StudyRms& study, const std::string& title) {
  const Eigen::Index S = static_cast<Eigen::Index>(study.subjects.size()), M = static_cast<Eigen::Index>(study.models.size());
  if (S == 0 || M == 0) throw InputError("study figure: expected at least one subject and one model");
  if (study.rms_mm.rows() != S || study.rms_mm.cols() != M)
    throw InputError("study figure: expected RMS as " + std::to_string(S) + " x " + std::to_string(M) + ", found " +
                     std::to_string(study.rms_mm.rows()) + " x " + std::to_string(study.rms_mm.cols()));
  double y_max = 0.0;
  std::vector<double> mean(static_cast<size_t>(M), NAN);
  std::vector<int> count(static_cast<size_t>(M), 0);
  for (Eigen::Index m = 0; m < M; ++m) {
    double sum = 0.0;
    for (Eigen::Index s = 0; s < S; ++s)
      if (std::isfinite(study.rms_mm(s, m))) {
        sum += study.rms_mm(s, m);
        ++count[static_cast<size_t>(m)];
        y_max = std::max(y_max, study.rms_mm(s, m));
      }
    if (count[static_cast<size_t>(m)]) mean[static_cast<size_t>(m)] = sum / count[static_cast<size_t>(m)];
  }
  if (!(y_max > 0.0)) y_max = 1.0;
  const double ys = svg::tickStep(y_max, 5);
  y_max = std::ceil(y_max * 1.02 / ys) * ys;

  const double left = 80, right = 140, top = 50, bottom = 60, slot = 130;
  const double W = left + slot * static_cast<double>(M) + right, H = 460, ph = H - top - bottom;
  auto X = [&](Eigen::Index m) { return left + slot * (static_cast<double>(m) + 0.5); };
  auto Y = [&](double v) { return top + ph - v / y_max * ph; };
  std::ostringstream out;
  out << std::fixed << std::setprecision(1);
  out << svg::open(W, H) << "<text x=\"" << W / 2 << "\" y=\"26\" text-anchor=\"middle\" font-size=\"15\">"
      << escapeMarkup(title) << "</text>\n";
  // Axes, grid, ticks and labels.
  out << "<line x1=\"" << left << "\" y1=\"" << top + ph << "\" x2=\"" << left + slot * static_cast<double>(M)
      << "\" y2=\"" << top + ph << "\" stroke=\"black\"/>\n<line x1=\"" << left << "\" y1=\"" << top << "\" x2=\""
      << left << "\" y2=\"" << top + ph << "\" stroke=\"black\"/>\n";
  for (double t = 0.0; t <= y_max + 1e-12; t += ys)
    out << "<line x1=\"" << left - 5 << "\" y1=\"" << Y(t) << "\" x2=\"" << left + slot * static_cast<double>(M)
        << "\" y2=\"" << Y(t) << "\" stroke=\"#e5e5e5\"/><line x1=\"" << left - 5 << "\" y1=\"" << Y(t) << "\" x2=\""
        << left << "\" y2=\"" << Y(t) << "\" stroke=\"black\"/><text x=\"" << left - 8 << "\" y=\"" << Y(t) + 4
        << "\" text-anchor=\"end\">" << svg::label(t) << "</text>\n";
  for (Eigen::Index m = 0; m < M; ++m)
    out << "<text x=\"" << X(m) << "\" y=\"" << top + ph + 20 << "\" text-anchor=\"middle\">"
        << escapeMarkup(study.models[static_cast<size_t>(m)]) << "</text>\n";
  out << "<text x=\"" << left + slot * static_cast<double>(M) / 2 << "\" y=\"" << H - 15
      << "\" text-anchor=\"middle\">model (more parameters to the right)</text>\n<text x=\"20\" y=\"" << top + ph / 2
      << "\" text-anchor=\"middle\" transform=\"rotate(-90 20 " << top + ph / 2
      << ")\">RMS of the signed distances (mm)</text>\n";

  // One grey line per subject; its least-RMS model filled.
  for (Eigen::Index s = 0; s < S; ++s) {
    const std::string& id = study.subjects[static_cast<size_t>(s)];
    Eigen::Index best = -1;
    for (Eigen::Index m = 0; m < M; ++m)
      if (std::isfinite(study.rms_mm(s, m)) && (best < 0 || study.rms_mm(s, m) < study.rms_mm(s, best))) best = m;
    out << "<g class=\"subject\">\n<path fill=\"none\" stroke=\"#9a9a9a\" d=\"";
    bool pen_down = false;
    Eigen::Index last = -1;
    for (Eigen::Index m = 0; m < M; ++m) {
      if (!std::isfinite(study.rms_mm(s, m))) {
        pen_down = false;
        continue;
      }
      out << (pen_down ? 'L' : 'M') << X(m) << ' ' << Y(study.rms_mm(s, m));
      pen_down = true;
      last = m;
    }
    out << "\"/>\n";
    for (Eigen::Index m = 0; m < M; ++m) {
      const double v = study.rms_mm(s, m);
      if (!std::isfinite(v)) continue;
      out << "<circle cx=\"" << X(m) << "\" cy=\"" << Y(v) << "\" r=\"3.5\" stroke=\"#555555\" fill=\""
          << (m == best ? "#555555" : "white") << "\"><title>" << escapeMarkup(id) << ' '
          << escapeMarkup(study.models[static_cast<size_t>(m)]) << ": " << svg::label(v) << " mm</title></circle>\n";
    }
    if (last >= 0 && S <= 30)
      out << "<text x=\"" << X(last) + 10 << "\" y=\"" << Y(study.rms_mm(s, last)) + 4
          << "\" font-size=\"10\" fill=\"#555555\">" << escapeMarkup(id) << "</text>\n";
    out << "</g>\n";
  }
  // Per-model means, joined.
  out << "<g class=\"means\">\n<path fill=\"none\" stroke=\"black\" stroke-width=\"2.5\" d=\"";
  bool pen_down = false;
  for (Eigen::Index m = 0; m < M; ++m) {
    if (!std::isfinite(mean[static_cast<size_t>(m)])) {
      pen_down = false;
      continue;
    }
    out << (pen_down ? 'L' : 'M') << X(m) << ' ' << Y(mean[static_cast<size_t>(m)]);
    pen_down = true;
  }
  out << "\"/>\n";
  for (Eigen::Index m = 0; m < M; ++m) {
    const double v = mean[static_cast<size_t>(m)];
    if (!std::isfinite(v)) continue;
    const std::string name = escapeMarkup(study.models[static_cast<size_t>(m)]);
    out << "<rect class=\"mean\" x=\"" << X(m) - 18 << "\" y=\"" << Y(v) - 2 << "\" width=\"36\" height=\"4\" fill=\"black\"><title>mean "
        << name << ": " << svg::label(v) << " mm (" << count[static_cast<size_t>(m)] << " subjects)</title></rect>\n"
        << "<text x=\"" << X(m) - 22 << "\" y=\"" << Y(v) + 4
        << "\" text-anchor=\"end\" font-weight=\"bold\" stroke=\"white\" stroke-width=\"3\" paint-order=\"stroke\">"
        << svg::label(v) << "</text>\n";
  }
  // Legend.
  const double lx = left + slot * static_cast<double>(M) + 20;
  out << "</g>\n<rect x=\"" << lx << "\" y=\"" << top + 4 << "\" width=\"24\" height=\"4\" fill=\"black\"/><text x=\""
      << lx + 30 << "\" y=\"" << top + 10 << "\">mean</text>\n<circle cx=\"" << lx + 12 << "\" cy=\""
      << top + 26 << "\" r=\"3.5\" stroke=\"#555555\" fill=\"white\"/><text x=\"" << lx + 30 << "\" y=\"" << top + 30
      << "\">one subject</text>\n<circle cx=\"" << lx + 12 << "\" cy=\"" << top + 46
      << "\" r=\"3.5\" fill=\"#555555\"/><text x=\"" << lx + 30 << "\" y=\"" << top + 50
      << "\">its least RMS</text>\n</svg>\n";
  return out.str();
}

}  // namespace articula::report
