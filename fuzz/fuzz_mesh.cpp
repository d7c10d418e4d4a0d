// Mesh vertices (.stl, .obj, .vtp, read by VTK) through readPoints. The
// first byte picks the extension, the rest is the file.
#include <vtkObject.h>

#include "articula/points/point_io.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // The reader collects VTK's errors itself; what VTK prints besides is noise here.
  vtkObject::GlobalWarningDisplayOff();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static const char* const kExtensions[] = {".stl", ".obj", ".vtp"};
  const articula::fuzz::InputFile file(kExtensions[data[0] % 3], data + 1, size - 1);
  articula::fuzz::expectOnlyArticulaErrors([&] { articula::points::readPoints(file.path()); });
  return 0;
}
