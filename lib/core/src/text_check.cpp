#include "articula/core/text_check.hpp"

#include "articula/core/error.hpp"

namespace articula {

void checkTextLine(std::string& line, long line_number, const std::filesystem::path& path) {
  if (line_number == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);
  const bool utf16 = line_number == 1 && (line.rfind("\xFF\xFE", 0) == 0 || line.rfind("\xFE\xFF", 0) == 0);
  if (utf16 || line.find('\0') != std::string::npos)
    throw InputError(path.string() + ":" + std::to_string(line_number) +
                     ": the file is UTF-16 (or has NUL bytes); save it as UTF-8 CSV (in Excel: Save As, 'CSV UTF-8')");
}

}  // namespace articula
