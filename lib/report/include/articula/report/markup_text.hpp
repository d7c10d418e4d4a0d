#pragma once
// Text inside SVG and HTML: the characters markup reserves, escaped, so
// that a file name or a message can never end an element or an attribute.
#include <string>

namespace articula::report {

/// `text` escaped for element content and quoted attribute values (& < > " ').
std::string escapeMarkup(const std::string& text);

}  // namespace articula::report
