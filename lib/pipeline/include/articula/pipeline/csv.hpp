#pragma once
// A small RFC 4180 CSV reader/writer (quoted fields, embedded commas and
// quotes). Hand-written: none of the project's Debian dependencies offers one,
// and manifests and study tables need nothing more.
#include <filesystem>
#include <string>
#include <vector>

namespace articula::pipeline {

struct CsvTable {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  std::vector<int> row_lines;  // 1-based line number of each row in the file
  /// Index of a header column, or -1.
  int column(const std::string& name) const;
};

/// Reads a CSV file with a header row; blank lines and lines starting with '#'
/// are skipped. Throws InputError (file and line) for unreadable files,
/// unterminated quotes, or rows with more fields than the header.
CsvTable readCsv(const std::filesystem::path& path);

/// One CSV field, quoted when it needs to be.
std::string csvField(const std::string& value);
/// A CSV line (no trailing newline) from fields.
std::string csvLine(const std::vector<std::string>& fields);

}  // namespace articula::pipeline
