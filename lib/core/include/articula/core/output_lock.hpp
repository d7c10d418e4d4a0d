#pragma once
// One command at a time per output folder: an exclusive advisory lock
// (flock) on `<folder>/.articula/lock`, held while the command runs. The
// kernel releases it when the process ends, however it ends, so a killed
// run leaves no lock that blocks the next.
#include <filesystem>
#include <string>

namespace articula {

class OutputLock {
 public:
  /// Creates `folder` and `folder/.articula` as needed and takes the lock.
  /// Throws ProcessingError (exit 1) naming the folder and the process that
  /// holds it (its pid, written in the lock file) when another one does,
  /// and when the folder cannot be made or the lock file opened.
  OutputLock(const std::filesystem::path& folder, const std::string& command);
  ~OutputLock();
  OutputLock(const OutputLock&) = delete;
  OutputLock& operator=(const OutputLock&) = delete;

  /// For a command that failed before writing any output: removes the lock
  /// file, and `.articula` and the folder when this lock created them and
  /// they hold nothing else. Keeps the lock held until destruction.
  void removeIfUnused();

  const std::filesystem::path& folder() const { return folder_; }

 private:
  std::filesystem::path folder_, state_, file_;
  int fd_ = -1;
  bool made_folder_ = false, made_state_ = false;
};

}  // namespace articula
