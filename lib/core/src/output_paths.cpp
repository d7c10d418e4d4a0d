#include "articula/core/output_paths.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <system_error>

#include <unistd.h>

#include "articula/core/error.hpp"

namespace articula {
namespace fs = std::filesystem;

namespace {

bool sameFile(const fs::path& a, const fs::path& b) {
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec) && fs::equivalent(a, b, ec)) return true;
  return fs::weakly_canonical(a, ec) == fs::weakly_canonical(b, ec);
}

bool inside(const fs::path& file, const fs::path& folder) {
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) return false;
  const fs::path f = fs::weakly_canonical(file, ec), d = fs::weakly_canonical(folder, ec);
  const auto [end, unused] = std::mismatch(d.begin(), d.end(), f.begin(), f.end());
  return end == d.end();
}

}  // namespace

void refuseOutputsOverInputs(const std::vector<fs::path>& outputs, const std::vector<fs::path>& inputs) {
  for (const fs::path& out : outputs)
    for (const fs::path& in : inputs) {
      if (in.empty() || out.empty()) continue;
      if (sameFile(out, in) || inside(out, in))
        throw UsageError("output '" + out.string() + "' would overwrite the input '" + in.string() +
                         "': choose another output name");
    }
}

void checkOutputTarget(const fs::path& output) {
  std::error_code ec;
  if (fs::is_directory(output, ec))
    throw ProcessingError("cannot write '" + output.string() + "': it is a folder, expected a file name");
  fs::path folder = output.parent_path();
  if (folder.empty()) folder = ".";
  fs::create_directories(folder, ec);
  if (ec) throw ProcessingError("cannot create the folder '" + folder.string() + "' for '" + output.string() + "': " + ec.message());
  if (::access(folder.c_str(), W_OK) != 0)
    throw ProcessingError("cannot write into '" + folder.string() + "' (for '" + output.string() + "'): " + std::strerror(errno));
}

}  // namespace articula
