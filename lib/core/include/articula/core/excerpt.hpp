#pragma once
// What error messages may show of their input: a short, escaped excerpt,
// never the whole of it (a 100 MB name, escape sequences for the terminal,
// or a 10^5-deep JSON value whose printing would overflow the stack).
#include <cstddef>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace articula {

/// At most `max_chars` characters of `text`, control and non-ASCII bytes
/// as \xNN, with "... (N bytes)" when it was cut.
std::string excerpt(std::string_view text, std::size_t max_chars = 60);

/// A JSON value described without recursion: a scalar as it is (strings by
/// excerpt), an array or object by its kind and size.
std::string describeJson(const nlohmann::json& value);

}  // namespace articula
