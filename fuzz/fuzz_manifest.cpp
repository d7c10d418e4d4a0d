// Batch manifests through readManifest.
#include "articula/pipeline/manifest.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const articula::fuzz::InputFile file(".csv", data, size);
  articula::fuzz::expectOnlyArticulaErrors([&] { articula::pipeline::readManifest(file.path()); });
  return 0;
}
