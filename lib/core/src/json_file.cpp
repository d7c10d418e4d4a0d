#include "articula/core/json_file.hpp"

#include <fstream>

#include "articula/core/error.hpp"
#include "articula/core/excerpt.hpp"

namespace articula {

nlohmann::json readJsonFile(const std::filesystem::path& path, const std::string& what) {
  std::ifstream in(path);
  if (!in) throw InputError(what + ": cannot open '" + path.string() + "'");
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(what + ": '" + path.string() + "' is not valid JSON: " + excerpt(e.what(), 160));
  }
}

std::optional<nlohmann::json> readJsonFileIfValid(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) return std::nullopt;
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;
  }
}

}  // namespace articula
