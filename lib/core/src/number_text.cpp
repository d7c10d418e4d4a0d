#include "articula/core/number_text.hpp"

#include <array>
#include <charconv>

namespace articula {

void appendNumber(std::string& out, double value, int significant) {
  std::array<char, 64> buffer;
  const auto result =
      std::to_chars(buffer.data(), buffer.data() + buffer.size(), value, std::chars_format::general, significant);
  out.append(buffer.data(), result.ptr);
}

}  // namespace articula
