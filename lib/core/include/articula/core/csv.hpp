#pragma once
// The project's one CSV reader/writer, RFC 4180 (quoted fields, embedded
// commas, quotes and line breaks), for manifests, contact pairs and study
// tables. Hand-written: none of the project's Debian dependencies offers one.
// (Point tables, which may be separated by spaces or semicolons, have their
// own tolerant reader in lib/points.)
#include <filesystem>
#include <string>
#include <vector>

namespace articula {

struct CsvTable {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  std::vector<int> row_lines;  // 1-based line number of each row in the file
  std::vector<size_t> row_field_counts;  // fields each row had as read
  /// Index of a header column, or -1.
  int column(const std::string& name) const;
};

struct CsvReadOptions {
  /// Rows as read, neither padded to the header's length nor refused when
  /// longer, for a caller that judges each row itself.
  bool rows_as_read = false;
};

/// Reads a CSV file with a header row; blank lines and lines starting with '#'
/// are skipped, unquoted fields trimmed. Throws InputError (file and line) for
/// unreadable files, unterminated quotes, or (unless rows_as_read) rows with
/// more fields than the header; shorter rows are padded with empty fields.
CsvTable readCsv(const std::filesystem::path& path, const CsvReadOptions& options = {});

/// One CSV field, quoted when it needs to be.
std::string csvField(const std::string& value);
/// A CSV line (no trailing newline) from fields.
std::string csvLine(const std::vector<std::string>& fields);

}  // namespace articula
