#include "articula/core/atomic_file.hpp"

#include <cerrno>
#include <charconv>
#include <csignal>
#include <vector>

#include <unistd.h>

#include "articula/core/error.hpp"

namespace articula {

AtomicFile::AtomicFile(std::filesystem::path path, bool overwrite, bool binary) : path_(std::move(path)) {
  if (!overwrite && std::filesystem::exists(path_))
    throw UsageError("output '" + path_.string() + "' exists: pass --force to overwrite it");
  if (path_.has_parent_path() && !std::filesystem::exists(path_.parent_path()))
    std::filesystem::create_directories(path_.parent_path());
  temp_ = temporaryPathFor(path_);
  out_.open(temp_, binary ? std::ios::out | std::ios::binary : std::ios::out);
  if (!out_) throw InputError("cannot open '" + temp_.string() + "' for writing");
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    out_.close();
    std::error_code ec;
    std::filesystem::remove(temp_, ec);
  }
}

void AtomicFile::commit() {
  out_.flush();
  if (!out_) throw InputError("writing '" + temp_.string() + "' failed (disk full?)");
  out_.close();
  std::error_code ec;
  std::filesystem::rename(temp_, path_, ec);
  if (ec) throw InputError("cannot rename '" + temp_.string() + "' to '" + path_.string() + "': " + ec.message());
  committed_ = true;
}

namespace {
const std::string kTemporaryPrefix = ".articula-tmp-";
}  // namespace

std::filesystem::path temporaryPathFor(const std::filesystem::path& path) {
  const std::filesystem::path folder = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  return folder / (kTemporaryPrefix + std::to_string(::getpid()) + "-" + path.filename().string());
}

int removeStaleTemporaries(const std::filesystem::path& folder) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) return 0;
  std::vector<fs::path> stale;
  for (auto it = fs::directory_iterator(folder, ec); !ec && it != fs::directory_iterator(); it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.rfind(kTemporaryPrefix, 0) != 0 || !it->is_regular_file(ec)) continue;
    // The writer's pid: digits up to the next '-', within pid_t's range.
    const char* first = name.data() + kTemporaryPrefix.size();
    const char* end = name.data() + name.size();
    pid_t pid = 0;
    const auto [next, error] = std::from_chars(first, end, pid);
    if (error != std::errc() || next == first || next == end || *next != '-' || pid <= 0) continue;
    if (::kill(pid, 0) == 0 || errno != ESRCH) continue;  // its writer still runs (or is not ours to ask)
    stale.push_back(it->path());
  }
  int removed = 0;
  for (const fs::path& p : stale) removed += fs::remove(p, ec) ? 1 : 0;
  return removed;
}

void writeFileAtomically(const std::filesystem::path& path, const std::string& text, bool overwrite) {
  AtomicFile file(path, overwrite);
  file.stream() << text;
  file.commit();
}

}  // namespace articula
