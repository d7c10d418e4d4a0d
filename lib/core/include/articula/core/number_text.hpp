#pragma once
// Numbers as text for large tables (10^6 rows): std::to_chars, several times
// faster than iostreams, with the same digits as printf's %.<significant>g.
#include <string>

namespace articula {

/// Appends `value` with `significant` significant digits (printf %g style).
void appendNumber(std::string& out, double value, int significant = 12);

}  // namespace articula
