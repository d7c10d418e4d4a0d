#pragma once
// Writes a file under a temporary name in the same folder and renames it into
// place on commit(), so a crash or an error never leaves a half-written file
// that looks complete. Destroying an uncommitted AtomicFile removes the temp.
#include <filesystem>
#include <fstream>
#include <string>

namespace articula {

class AtomicFile {
 public:
  /// Opens `<path>.tmp-<pid>` for writing; throws InputError if it cannot.
  /// Refuses to replace an existing `path` unless `overwrite` is true (UsageError).
  explicit AtomicFile(std::filesystem::path path, bool overwrite = true, bool binary = false);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::ofstream& stream() { return out_; }
  /// Flushes, closes and renames to the final path; throws InputError on failure.
  void commit();

 private:
  std::filesystem::path path_, temp_;
  std::ofstream out_;
  bool committed_ = false;
};

/// Writes `text` to `path` atomically.
void writeFileAtomically(const std::filesystem::path& path, const std::string& text, bool overwrite = true);

}  // namespace articula
