#pragma once
// A JSON file read with the project's error mapping: a file that cannot be
// opened or does not parse is an InputError (exit 3) that names the file and
// what it was read for, with the parser's reason cut to an excerpt.
#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

namespace articula {

/// The document of `path`; `what` says what it was read for ("--bounds",
/// "scene"), first in the messages.
nlohmann::json readJsonFile(const std::filesystem::path& path, const std::string& what);

/// The document, or nothing when the file is missing or does not parse (a
/// status or stamp file whose absence or damage means "not done").
std::optional<nlohmann::json> readJsonFileIfValid(const std::filesystem::path& path);

}  // namespace articula
