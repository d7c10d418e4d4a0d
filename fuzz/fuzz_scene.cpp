// Simulation scenes as `articula simulate` reads them: dynamics::readScene.
#include "articula/dynamics/scene.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const articula::fuzz::InputFile file(".json", data, size);
  articula::fuzz::expectOnlyArticulaErrors([&] { articula::dynamics::readScene(file.path()); });
  return 0;
}
