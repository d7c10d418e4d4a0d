// NIfTI volumes through readVolume (our header checks, then ITK). The first
// byte picks .nii or .nii.gz (the rest is then the gzip stream as stored).
#include "articula/imaging/io.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const articula::fuzz::InputFile file(data[0] % 2 ? ".nii.gz" : ".nii", data + 1, size - 1);
  articula::fuzz::expectOnlyArticulaErrors([&] { articula::imaging::readVolume(file.path(), {}); });
  return 0;
}
