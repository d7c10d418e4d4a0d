#include "svg.hpp"

#include <cmath>
#include <sstream>

namespace articula::report::svg {

double tickStep(double range, int target) {
  const double raw = range / target;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * p >= raw) return m * p;
  return 10.0 * p;
}

const char* seriesColour(size_t i) {
  // Colours of thesis fig. 3.5 (yellow darkened to stay readable on white).
  static const char* colours[] = {"#d62728", "#2ca02c", "#1f77b4", "#d4a017", "#000000", "#9467bd", "#8c564b"};
  return colours[i % 7];
}

std::string label(double v) {
  std::ostringstream s;
  s.precision(3);
  s << (std::fabs(v) < 1e-12 ? 0.0 : v);
  return s.str();
}

std::string open(double width, double height) {
  std::ostringstream s;
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height << "\" viewBox=\"0 0 "
    << width << ' ' << height << "\" font-family=\"sans-serif\" font-size=\"12\">\n"
    << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  return s.str();
}

}  // namespace articula::report::svg
