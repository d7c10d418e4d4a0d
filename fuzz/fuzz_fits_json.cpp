// fits.json as `articula errors --fits` reads it: readFitsJson, then shapesFromFitsJson.
#include "articula/fit/fits_json.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const articula::fuzz::InputFile file(".json", data, size);
  articula::fuzz::expectOnlyArticulaErrors([&] {
    const nlohmann::json doc = articula::fit::readFitsJson(file.path(), "--fits");
    articula::fit::shapesFromFitsJson(doc, file.path().string());
  });
  return 0;
}
