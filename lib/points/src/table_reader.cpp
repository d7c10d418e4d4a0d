// Delimited text points (.csv, .xyz, .txt): x,y,z[,nx,ny,nz] per line. Hand-written because no
// library in the dependency set reads CSV, and the line-numbered messages need the parser anyway.
#include <algorithm>
#include <array>
#include <cctype>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <vector>

#include "articula/core/error.hpp"
#include "articula/core/text_check.hpp"
#include "readers.hpp"

namespace articula::points::detail {

namespace {

std::string trim(const std::string& s) {
  const auto first = s.find_first_not_of(" \t\r");
  if (first == std::string::npos) return {};
  return s.substr(first, s.find_last_not_of(" \t\r") - first + 1);
}

// Fields of one (trimmed, non-empty) line. The separator is the first of ; , tab found on the line
// (semicolon first so a decimal comma fails loudly instead of splitting numbers); otherwise runs of spaces.
std::vector<std::string> splitFields(const std::string& line) {
  std::vector<std::string> fields;
  for (char separator : {';', ',', '\t'}) {
    if (line.find(separator) == std::string::npos) continue;
    std::size_t start = 0;
    for (;;) {
      const auto stop = line.find(separator, start);
      fields.push_back(trim(line.substr(start, stop == std::string::npos ? std::string::npos : stop - start)));
      if (stop == std::string::npos) return fields;
      start = stop + 1;
    }
  }
  std::size_t start = 0;
  while ((start = line.find_first_not_of(' ', start)) != std::string::npos) {
    const auto stop = line.find(' ', start);
    fields.push_back(line.substr(start, stop == std::string::npos ? std::string::npos : stop - start));
    start = stop;
  }
  return fields;
}

std::optional<double> parseNumber(const std::string& field) {
  if (field.empty()) return std::nullopt;
  char* end = nullptr;
  const double value = std::strtod(field.c_str(), &end);
  if (end != field.c_str() + field.size()) return std::nullopt;
  return value;
}

// The first content line is a header when it has no field that starts like a number, so that a row
// such as "1,5;2,5;3,5" (decimal commas) is reported as a bad row rather than taken for a header.
bool looksLikeHeader(const std::vector<std::string>& fields) {
  return std::none_of(fields.begin(), fields.end(), [](const std::string& f) {
    return f.empty() || std::isdigit(static_cast<unsigned char>(f[0])) || f[0] == '+' || f[0] == '-' ||
           f[0] == '.';
  });
}

// Column of `name` (also accepted with a unit suffix "_mm" or in quotes) in the header, or -1.
int findColumn(const std::vector<std::string>& header, const std::string& name) {
  for (std::size_t i = 0; i < header.size(); ++i) {
    std::string h = lowercase(header[i]);
    if (h.size() >= 2 && h.front() == '"' && h.back() == '"') h = h.substr(1, h.size() - 2);
    if (h == name || h == name + "_mm") return static_cast<int>(i);
  }
  return -1;
}

struct Columns {
  std::array<int, 3> position{0, 1, 2};
  std::array<int, 3> normal{-1, -1, -1};
  bool has_normals() const { return normal[0] >= 0; }
};

// Named columns when the header names x, y, z; otherwise by position: 3 or 6 columns.
Columns chooseColumns(const std::vector<std::string>* header, std::size_t column_count,
                      const std::filesystem::path& path, long line_number) {
  Columns columns;
  if (header) {
    const std::array<int, 3> xyz{findColumn(*header, "x"), findColumn(*header, "y"), findColumn(*header, "z")};
    if (*std::min_element(xyz.begin(), xyz.end()) >= 0) {
      columns.position = xyz;
      const std::array<int, 3> n{findColumn(*header, "nx"), findColumn(*header, "ny"), findColumn(*header, "nz")};
      if (*std::min_element(n.begin(), n.end()) >= 0) columns.normal = n;
      return columns;
    }
  }
  if (column_count != 3 && column_count != 6)
    throw InputError(quoted(path) + ", line " + std::to_string(line_number) +
                     ": expected 3 columns (x,y,z) or 6 (x,y,z,nx,ny,nz), found " + std::to_string(column_count) +
                     " (a header row naming x,y,z[,nx,ny,nz] selects columns)");
  if (column_count == 6) columns.normal = {3, 4, 5};
  return columns;
}

}  // namespace

PointCloud readTable(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError("cannot open point file " + quoted(path) + " for reading");

  std::optional<std::vector<std::string>> header;
  std::optional<Columns> columns;
  std::size_t column_count = 0;
  long first_row_line = 0;
  std::vector<std::array<double, 6>> rows;
  std::vector<long> lines;

  std::string raw;
  long line_number = 0;
  bool seen_content = false;
  while (std::getline(in, raw)) {
    ++line_number;
    checkTextLine(raw, line_number, path);
    const std::string line = trim(raw);
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> fields = splitFields(line);

    std::vector<double> values(fields.size());
    std::optional<std::size_t> bad;
    for (std::size_t i = 0; i < fields.size() && !bad; ++i) {
      const auto v = parseNumber(fields[i]);
      if (v)
        values[i] = *v;
      else
        bad = i;
    }
    if (bad && !seen_content && looksLikeHeader(fields)) {
      seen_content = true;
      column_count = fields.size();
      header = std::move(fields);
      first_row_line = line_number;
      continue;
    }
    seen_content = true;
    if (bad)
      throw InputError(quoted(path) + ", line " + std::to_string(line_number) + ", column " +
                       std::to_string(*bad + 1) + ": expected a number, found '" + fields[*bad] + "'");
    if (!columns) {
      if (!header) {
        column_count = fields.size();
        first_row_line = line_number;
      }
      columns = chooseColumns(header ? &*header : nullptr, column_count, path, line_number);
    }
    if (fields.size() != column_count)
      throw InputError(quoted(path) + ", line " + std::to_string(line_number) + ": expected " +
                       std::to_string(column_count) + " columns (as on line " + std::to_string(first_row_line) +
                       "), found " + std::to_string(fields.size()));
    std::array<double, 6> row{};
    for (int k = 0; k < 3; ++k) {
      row[static_cast<std::size_t>(k)] = values[static_cast<std::size_t>(columns->position[k])];
      if (columns->has_normals())
        row[static_cast<std::size_t>(k + 3)] = values[static_cast<std::size_t>(columns->normal[k])];
    }
    rows.push_back(row);
    lines.push_back(line_number);
  }
  if (in.bad()) throw InputError("reading point file " + quoted(path) + " failed");
  if (rows.empty())
    throw InputError("point file " + quoted(path) + ": expected rows of x,y,z, found none (" +
                     std::to_string(line_number) + " lines, " + (header ? "a header only" : "no data") + ")");

  PointCloud cloud;
  const auto n = static_cast<Eigen::Index>(rows.size());
  cloud.positions.resize(n, 3);
  cloud.normals.resize(columns->has_normals() ? n : 0, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto& row = rows[static_cast<std::size_t>(i)];
    cloud.positions.row(i) << row[0], row[1], row[2];
    if (columns->has_normals()) cloud.normals.row(i) << row[3], row[4], row[5];
  }
  finishCloud(cloud, path,
              [&](Eigen::Index i) { return "line " + std::to_string(lines[static_cast<std::size_t>(i)]); });
  return cloud;
}

}  // namespace articula::points::detail
