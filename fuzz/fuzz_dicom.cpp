// DICOM series through readVolume: the walk of every file and the check of
// its slice header against the series (src/dicom_check.cpp), then GDCM and
// ITK. Each input is a series of two slices: its first two bytes give the
// first slice's length (little endian), the rest is the second slice.
#include <fstream>

#include "articula/imaging/io.hpp"
#include "fuzz_input.hpp"

namespace {

namespace fs = std::filesystem;

void writeSlice(const fs::path& path, const std::uint8_t* data, std::size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  if (!out) {
    std::fprintf(stderr, "fuzz: cannot write %s\n", path.c_str());
    std::abort();
  }
}

struct SeriesFolder {
  fs::path path = articula::fuzz::scratchFolder() / ("articula-fuzz-" + std::to_string(::getpid()) + "-dicom");
  SeriesFolder() { fs::create_directories(path); }
  ~SeriesFolder() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 2) return 0;
  static const SeriesFolder folder;
  const std::size_t first = std::min<std::size_t>(size - 2, data[0] | std::size_t(data[1]) << 8);
  writeSlice(folder.path / "slice_1.dcm", data + 2, first);
  writeSlice(folder.path / "slice_2.dcm", data + 2 + first, size - 2 - first);
  articula::fuzz::expectOnlyArticulaErrors([&] { articula::imaging::readVolume(folder.path, {}); });
  return 0;
}
