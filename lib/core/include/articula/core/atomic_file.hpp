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
  /// Opens temporaryPathFor(path) for writing; throws InputError if it cannot.
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

/// The name a file is written under until it is complete:
/// `<folder>/.articula-tmp-<pid>-<name>` (hidden, named as articula's own,
/// and keeping the extension, from which ITK and VTK writers choose the
/// format).
std::filesystem::path temporaryPathFor(const std::filesystem::path& path);

/// Removes the temporaries (temporaryPathFor) directly in `folder` (not in
/// its subfolders) whose writing process no longer runs: a killed run leaves
/// them behind. Any other file, whatever its name, is left alone. Returns
/// how many were removed.
int removeStaleTemporaries(const std::filesystem::path& folder);

/// Writes `text` to `path` atomically.
void writeFileAtomically(const std::filesystem::path& path, const std::string& text, bool overwrite = true);

}  // namespace articula
