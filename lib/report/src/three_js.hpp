#pragma once
// The web 3-D library the reports inline (three.js r111 and OrbitControls).
#include <string_view>

namespace articula::report::detail {

std::string_view threeJs();
std::string_view orbitControlsJs();

}  // namespace articula::report::detail
