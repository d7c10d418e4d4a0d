#pragma once
// Shared by the fuzz targets: the readers under test take a path, so each
// input is written to one file per process (in /dev/shm when there is one,
// to keep the disk out of the loop), and articula::Error is the expected
// outcome for bad input. Anything else escaping a reader is a finding.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <typeinfo>

#include "articula/core/error.hpp"

namespace articula::fuzz {

inline std::filesystem::path scratchFolder() {
  std::error_code ec;
  if (std::filesystem::is_directory("/dev/shm", ec) && ::access("/dev/shm", W_OK) == 0) return "/dev/shm";
  return std::filesystem::temp_directory_path();
}

/// The fuzz input as a file named articula-fuzz-<pid><extension>, rewritten for each input.
class InputFile {
 public:
  InputFile(const std::string& extension, const std::uint8_t* data, std::size_t size)
      : path_(scratchFolder() / ("articula-fuzz-" + std::to_string(::getpid()) + extension)) {
    std::ofstream out(path_, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    out.close();
    if (!out) {
      std::fprintf(stderr, "fuzz: cannot write %s\n", path_.c_str());
      std::abort();
    }
  }
  ~InputFile() {
    std::error_code ec;
    std::filesystem::remove(path_, ec);
  }
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

/// Runs `read`; an articula::Error is the reader refusing bad input, any other
/// exception aborts with its type and message so libFuzzer keeps the input.
/// ARTICULA_FUZZ_VERBOSE=1 prints each input's outcome (to check the seeds).
template <class F>
void expectOnlyArticulaErrors(F&& read) {
  static const bool verbose = std::getenv("ARTICULA_FUZZ_VERBOSE") != nullptr;
  try {
    read();
    if (verbose) std::fprintf(stderr, "fuzz: accepted\n");
  } catch (const articula::Error& e) {
    if (verbose) std::fprintf(stderr, "fuzz: refused: %s\n", e.what());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz: exception other than articula::Error: %s: %s\n", typeid(e).name(), e.what());
    std::abort();
  } catch (...) {
    std::fprintf(stderr, "fuzz: exception of an unknown type\n");
    std::abort();
  }
}

}  // namespace articula::fuzz
