#pragma once
// Small helpers shared by the hand-written SVG figures of this module. The
// figures are written by hand because no plotting library in Debian's C++
// stack fits a headless command-line tool: VTK's charts need an OpenGL
// context to export, matplot++ and sciplot are not packaged and drive
// gnuplot in a subprocess, and the figures are simple (lines, dots, text).
#include <string>

#include "articula/report/markup_text.hpp"

namespace articula::report::svg {

/// A "nice" tick step (1, 2 or 5 times a power of ten) giving about `target`
/// intervals over `range`.
double tickStep(double range, int target);

/// The i-th colour of the series palette (thesis fig. 3.5 colours first).
const char* seriesColour(size_t i);

/// `v` as a short label: up to 3 significant digits, "0" for |v| < 1e-12.
std::string label(double v);


/// The opening <svg> element (sans-serif, 12 px) and a white background.
std::string open(double width, double height);

}  // namespace articula::report::svg
