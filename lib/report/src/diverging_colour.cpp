#include "articula/report/diverging_colour.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

namespace articula::report {

std::array<std::uint8_t, 3> divergingRgb(double t) {
  static const std::array<std::array<double, 3>, 5> stops = {
      {{178, 24, 43}, {239, 138, 98}, {221, 221, 221}, {103, 169, 207}, {33, 102, 172}}};
  if (std::isnan(t)) t = 0.0;
  const double x = (std::clamp(t, -1.0, 1.0) + 1.0) * 2.0;  // 0 .. 4 over the stops
  const int i = std::min(3, static_cast<int>(std::floor(x)));
  const double f = x - i;
  std::array<std::uint8_t, 3> rgb{};
  for (size_t k = 0; k < 3; ++k)
    rgb[k] = static_cast<std::uint8_t>(std::lround((1.0 - f) * stops[static_cast<size_t>(i)][k] +
                                                   f * stops[static_cast<size_t>(i + 1)][k]));
  return rgb;
}

std::string divergingColour(double t) {
  const std::array<std::uint8_t, 3> rgb = divergingRgb(t);
  char hex[8];
  std::snprintf(hex, sizeof hex, "#%02x%02x%02x", rgb[0], rgb[1], rgb[2]);
  return hex;
}

}  // namespace articula::report
