#include "articula/core/csv.hpp"

#include <fstream>

#include "articula/core/error.hpp"
#include "articula/core/text_check.hpp"

namespace articula {

int CsvTable::column(const std::string& name) const {
  for (size_t i = 0; i < header.size(); ++i)
    if (header[i] == name) return static_cast<int>(i);
  return -1;
}

namespace {
std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

// Splits one record; a quoted field may span lines, so more lines are pulled from `in`.
std::vector<std::string> splitRecord(std::string line, std::istream& in, int& line_number,
                                     const std::filesystem::path& path) {
  std::vector<std::string> fields;
  std::string field;
  bool quoted = false, was_quoted = false;
  const int start_line = line_number;
  for (size_t i = 0;; ++i) {
    if (i == line.size()) {
      if (!quoted) break;
      std::string next;
      if (!std::getline(in, next))
        throw InputError(path.string() + ":" + std::to_string(start_line) + ": unterminated quoted field");
      ++line_number;
      checkTextLine(next, line_number, path);
      field += '\n';
      line = next;
      i = static_cast<size_t>(-1);
      continue;
    }
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        field += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        field += c;
      }
    } else if (c == '"') {
      quoted = was_quoted = true;
    } else if (c == ',') {
      fields.push_back(was_quoted ? field : trim(field));
      field.clear();
      was_quoted = false;
    } else {
      field += c;
    }
  }
  fields.push_back(was_quoted ? field : trim(field));
  return fields;
}
}  // namespace

CsvTable readCsv(const std::filesystem::path& path, const CsvReadOptions& options) {
  std::ifstream in(path);
  if (!in) throw InputError("cannot read '" + path.string() + "': expected a CSV file");
  CsvTable table;
  std::string line;
  int line_number = 0;
  bool have_header = false;
  while (std::getline(in, line)) {
    ++line_number;
    checkTextLine(line, line_number, path);
    const std::string t = trim(line);
    if (t.empty() || t[0] == '#') continue;
    const int record_line = line_number;
    auto fields = splitRecord(line, in, line_number, path);
    if (!have_header) {
      table.header = fields;
      have_header = true;
      continue;
    }
    table.row_field_counts.push_back(fields.size());
    if (!options.rows_as_read && fields.size() > table.header.size())
      throw InputError(path.string() + ":" + std::to_string(record_line) + ": expected at most " +
                       std::to_string(table.header.size()) + " fields (the header's), found " +
                       std::to_string(fields.size()));
    if (!options.rows_as_read) fields.resize(table.header.size());
    table.rows.push_back(std::move(fields));
    table.row_lines.push_back(record_line);
  }
  if (!have_header) throw InputError("'" + path.string() + "' is empty: expected a header row");
  return table;
}

std::string csvField(const std::string& v) {
  if (v.find_first_of(",\"\n\r") == std::string::npos) return v;
  std::string out = "\"";
  for (char c : v) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

std::string csvLine(const std::vector<std::string>& fields) {
  std::string out;
  for (size_t i = 0; i < fields.size(); ++i) {
    if (i) out += ',';
    out += csvField(fields[i]);
  }
  return out;
}

}  // namespace articula
