// Meshes read by VTK: .stl, .obj and .vtp vertices through readPoints, and
// .vtk (legacy) and .ply meshes through readMeshFile, as `articula sample`
// reads a mesh (.ply points have their own reader, fuzz_ply). The first byte
// picks the extension, the rest is the file.
#include <vtkObject.h>

#include "articula/points/mesh_file.hpp"
#include "articula/points/point_io.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // The reader collects VTK's errors itself; what VTK prints besides is noise here.
  vtkObject::GlobalWarningDisplayOff();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static const char* const kExtensions[] = {".stl", ".obj", ".vtp", ".vtk", ".ply"};
  const int kind = data[0] % 5;
  const articula::fuzz::InputFile file(kExtensions[kind], data + 1, size - 1);
  articula::fuzz::expectOnlyArticulaErrors([&] {
    if (kind < 3)
      articula::points::readPoints(file.path());
    else
      articula::points::readMeshFile(file.path());
  });
  return 0;
}
