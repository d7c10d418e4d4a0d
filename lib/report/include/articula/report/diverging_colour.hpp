#pragma once
// The diverging colour scale of the error maps.
#include <array>
#include <cstdint>
#include <string>

namespace articula::report {

/// The colour ("#rrggbb") of `t` in [-1, 1] (clamped) on a red - grey - blue
/// diverging scale: -1 dark red (inside the surface, as the red of thesis
/// fig. 3.4), 0 light grey, +1 dark blue (outside). Piecewise linear in sRGB
/// through the five stops of ColorBrewer's RdBu, with a grey middle so that
/// points near 0 stay visible on white.
std::string divergingColour(double t);
/// The same colour as red, green, blue bytes (for vertex colours and colour tables).
std::array<std::uint8_t, 3> divergingRgb(double t);

}  // namespace articula::report
