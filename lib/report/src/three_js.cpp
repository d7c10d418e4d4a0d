// three.js and its orbit controls (Debian's libjs-three), built into the
// library so that a report inlines them wherever articula runs: a cluster's
// compute node need not have the package. The assembler's .incbin copies the
// files at build time; 850 KB of source would be slow to compile as a
// string literal.
#include "three_js.hpp"

__asm__(".section .rodata\n"
        ".balign 16\n"
        "articula_three_js_begin:\n"
        ".incbin \"" ARTICULA_THREE_JS "\"\n"
        "articula_three_js_end:\n"
        ".balign 16\n"
        "articula_orbit_controls_js_begin:\n"
        ".incbin \"" ARTICULA_ORBIT_CONTROLS_JS "\"\n"
        "articula_orbit_controls_js_end:\n"
        ".previous\n");

extern "C" {
extern const char articula_three_js_begin[], articula_three_js_end[];
extern const char articula_orbit_controls_js_begin[], articula_orbit_controls_js_end[];
}

namespace articula::report::detail {

std::string_view threeJs() {
  return {articula_three_js_begin, static_cast<size_t>(articula_three_js_end - articula_three_js_begin)};
}

std::string_view orbitControlsJs() {
  return {articula_orbit_controls_js_begin,
          static_cast<size_t>(articula_orbit_controls_js_end - articula_orbit_controls_js_begin)};
}

}  // namespace articula::report::detail
