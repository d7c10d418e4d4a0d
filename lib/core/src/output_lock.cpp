#include "articula/core/output_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <system_error>

#include "articula/core/error.hpp"
#include "articula/core/excerpt.hpp"

namespace articula {
namespace fs = std::filesystem;

namespace {

std::string holderOf(const fs::path& file) {
  std::ifstream in(file);
  std::string text;
  std::getline(in, text);
  return text.empty() ? "another process" : excerpt(text, 80);
}

}  // namespace

OutputLock::OutputLock(const fs::path& folder, const std::string& command)
    : folder_(folder), state_(folder / ".articula"), file_(state_ / "lock") {
  std::error_code ec;
  made_folder_ = !fs::exists(folder_, ec);
  made_state_ = !fs::exists(state_, ec);
  // A few attempts: a process that failed early may remove the folder or
  // the lock file between our making and our opening them.
  for (int attempt = 0; attempt < 5; ++attempt) {
    fs::create_directories(state_, ec);
    if (ec)
      throw ProcessingError("cannot create '" + state_.string() + "' for the lock on the output folder: " + ec.message());
    fd_ = ::open(file_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0) {
      if (errno == ENOENT) continue;
      throw ProcessingError("cannot open the lock file '" + file_.string() + "': " + std::strerror(errno));
    }
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      const int error = errno;
      ::close(fd_);
      fd_ = -1;
      if (error == EWOULDBLOCK)
        throw ProcessingError("the output folder '" + folder_.string() + "' is in use by " + holderOf(file_) +
                              ": wait for it to finish, or choose another output folder");
      throw ProcessingError("cannot lock '" + file_.string() + "': " + std::strerror(error));
    }
    // Locked; but the file may have been removed (and made anew) meanwhile,
    // and a lock on a removed file guards nothing.
    struct stat held {}, named {};
    if (::fstat(fd_, &held) == 0 && ::stat(file_.c_str(), &named) == 0 && held.st_dev == named.st_dev &&
        held.st_ino == named.st_ino) {
      const std::string holder = command + " (pid " + std::to_string(::getpid()) + ")\n";
      if (::ftruncate(fd_, 0) == 0 && ::write(fd_, holder.data(), holder.size()) < 0) {
        // The pid is for messages only: the lock holds without it.
      }
      return;
    }
    ::close(fd_);
    fd_ = -1;
  }
  throw ProcessingError("cannot lock the output folder '" + folder_.string() +
                        "': its lock file keeps disappearing (another process removing it?)");
}

OutputLock::~OutputLock() {
  if (fd_ < 0) return;
  // An old pid in the file would name the wrong process to the next waiter.
  if (::ftruncate(fd_, 0) != 0) {
  }
  ::close(fd_);
}

void OutputLock::removeIfUnused() {
  std::error_code ec;
  fs::remove(file_, ec);
  // remove() leaves a folder that is not empty.
  if (made_state_) fs::remove(state_, ec);
  if (made_folder_) fs::remove(folder_, ec);
}

}  // namespace articula
