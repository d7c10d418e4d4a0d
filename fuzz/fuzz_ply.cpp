// PLY point files (ascii, binary little and big endian) through readPoints.
#include "articula/points/point_io.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const articula::fuzz::InputFile file(".ply", data, size);
  articula::fuzz::expectOnlyArticulaErrors([&] { articula::points::readPoints(file.path()); });
  return 0;
}
