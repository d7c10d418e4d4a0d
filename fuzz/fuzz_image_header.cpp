// MetaImage and NRRD volumes through readVolume (our header and data-length
// checks, src/image_file_check.cpp, then ITK). The first byte picks the
// extension: .mha, .nrrd.
#include "articula/imaging/io.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const articula::fuzz::InputFile file(data[0] % 2 ? ".nrrd" : ".mha", data + 1, size - 1);
  articula::fuzz::expectOnlyArticulaErrors([&] { articula::imaging::readVolume(file.path(), {}); });
  return 0;
}
