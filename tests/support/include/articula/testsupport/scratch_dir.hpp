#pragma once
// A test program's scratch folders: <temp>/articula-test-<pid>/<name>, made
// fresh by each call; the program's whole folder is removed when it ends
// (failed tests included), so test runs leave nothing in the temp dir. And
// the text of the files a test writes there and reads back.
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>

#include <unistd.h>

namespace articula::testsupport {

inline std::filesystem::path scratchDir(const std::string& name) {
  struct Root {
    pid_t owner;
    std::filesystem::path path;
    ~Root() {  // not in a forked child that returns instead of calling _exit
      std::error_code ignored;
      if (::getpid() == owner) std::filesystem::remove_all(path, ignored);
    }
  };
  static const Root root{::getpid(), std::filesystem::temp_directory_path() / ("articula-test-" + std::to_string(::getpid()))};
  const std::filesystem::path dir = root.path / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

inline void writeText(const std::filesystem::path& path, const std::string& text) { std::ofstream(path) << text; }

/// The whole file, byte for byte.
inline std::string readText(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace articula::testsupport
