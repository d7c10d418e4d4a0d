// Delimited text points (.csv, .xyz, .txt) through readPoints. The first
// byte picks the extension, the rest is the file.
#include "articula/points/point_io.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static const char* const kExtensions[] = {".csv", ".xyz", ".txt"};
  const articula::fuzz::InputFile file(kExtensions[data[0] % 3], data + 1, size - 1);
  articula::fuzz::expectOnlyArticulaErrors([&] { articula::points::readPoints(file.path()); });
  return 0;
}
