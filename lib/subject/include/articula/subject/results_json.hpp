#pragma once
// Reading results.json documents for the pages (the subject's report.html,
// the study's study.html): members by reference, absent ones as null, so that a page
// shows a dash where a value is missing instead of failing; nlohmann's
// value() returns copies whose items() would dangle in a range-for.
#include <cmath>
#include <string>

#include <nlohmann/json.hpp>

namespace articula::subject::results_json {

inline const nlohmann::json& member(const nlohmann::json& object, const std::string& key) {
  static const nlohmann::json kAbsent;
  if (!object.is_object()) return kAbsent;
  const auto it = object.find(key);
  return it == object.end() ? kAbsent : *it;
}

/// A member as text ("" when absent; numbers as JSON writes them).
inline std::string text(const nlohmann::json& object, const std::string& key) {
  const nlohmann::json& v = member(object, key);
  return v.is_string() ? v.get<std::string>() : v.is_null() ? "" : v.dump();
}

/// A number, or NaN.
inline double numberAt(const nlohmann::json& object, const std::string& key) {
  const nlohmann::json& v = member(object, key);
  return v.is_number() ? v.get<double>() : NAN;
}

/// The entry of results.json "models" for `name`, or null.
inline const nlohmann::json* modelNamed(const nlohmann::json& results, const std::string& name) {
  for (const auto& m : member(results, "models"))
    if (text(m, "model") == name) return &m;
  return nullptr;
}

}  // namespace articula::subject::results_json
