// The --pairs CSV of `articula contact` through readPairsCsv.
#include "articula/contact/pairs_csv.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const articula::fuzz::InputFile file(".csv", data, size);
  articula::fuzz::expectOnlyArticulaErrors([&] { articula::contact::readPairsCsv(file.path()); });
  return 0;
}
