// fits.json as `articula errors --fits` reads it: readJsonFile, then shapesFromFitsJson.
#include "articula/core/json_file.hpp"
#include "articula/fit/fits_json.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const articula::fuzz::InputFile file(".json", data, size);
  articula::fuzz::expectOnlyArticulaErrors([&] {
    const nlohmann::json doc = articula::readJsonFile(file.path(), "--fits");
    articula::fit::shapesFromFitsJson(doc, file.path().string());
  });
  return 0;
}
