#include "articula/core/excerpt.hpp"

#include <cstdio>

namespace articula {

std::string excerpt(std::string_view text, std::size_t max_chars) {
  std::string out;
  std::size_t shown = 0;
  for (; shown < text.size() && out.size() < max_chars; ++shown) {
    const auto c = static_cast<unsigned char>(text[shown]);
    if (c >= 0x20 && c < 0x7f && c != '\\') {
      out += static_cast<char>(c);
    } else {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\x%02x", c);
      out += escaped;
    }
  }
  if (shown < text.size()) out += "... (" + std::to_string(text.size()) + " bytes)";
  return out;
}

std::string describeJson(const nlohmann::json& value) {
  switch (value.type()) {
    case nlohmann::json::value_t::array: {
      // A short flat array (a vector of numbers) as it is; others by size.
      bool flat = value.size() <= 8;
      for (const auto& element : value) flat = flat && element.is_primitive() && !element.is_string();
      if (flat) return excerpt(value.dump());
      return "an array of " + std::to_string(value.size()) + " element(s)";
    }
    case nlohmann::json::value_t::object:
      return "an object of " + std::to_string(value.size()) + " key(s)";
    case nlohmann::json::value_t::string:
      return "\"" + excerpt(value.get_ref<const std::string&>()) + "\"";
    default:
      return excerpt(value.dump());  // a scalar: short and flat
  }
}

}  // namespace articula
