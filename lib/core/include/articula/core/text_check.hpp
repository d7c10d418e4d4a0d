#pragma once
// What a reader of text tables (CSV manifests, contact pairs, point tables)
// checks of each line before parsing it: spreadsheets save "Unicode text" as
// UTF-16, whose NUL bytes would cut messages short or show as noise.
#include <filesystem>
#include <string>

namespace articula {

/// Throws InputError "<path>:<line>: the file is UTF-16 (or has NUL bytes);
/// save it as UTF-8 CSV" when `line` starts with a UTF-16 byte-order mark
/// (line 1) or holds a NUL byte; removes a UTF-8 byte-order mark from line 1
/// (Excel writes one).
void checkTextLine(std::string& line, long line_number, const std::filesystem::path& path);

}  // namespace articula
