#include "articula/core/atomic_file.hpp"

#include <unistd.h>

#include "articula/core/error.hpp"

namespace articula {

AtomicFile::AtomicFile(std::filesystem::path path, bool overwrite, bool binary) : path_(std::move(path)) {
  if (!overwrite && std::filesystem::exists(path_))
    throw UsageError("output '" + path_.string() + "' exists: pass --force to overwrite it");
  if (path_.has_parent_path() && !std::filesystem::exists(path_.parent_path()))
    std::filesystem::create_directories(path_.parent_path());
  temp_ = path_;
  temp_ += ".tmp-" + std::to_string(::getpid());
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

void writeFileAtomically(const std::filesystem::path& path, const std::string& text, bool overwrite) {
  AtomicFile file(path, overwrite);
  file.stream() << text;
  file.commit();
}

}  // namespace articula
