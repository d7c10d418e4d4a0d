// Vertices of .stl, .obj and .vtp meshes through VTK's readers. VTK reports problems through
// error events rather than exceptions, so an observer on the reader, its executive and (for XML)
// its parser collects them, keeps them off stderr, and we throw InputError with the first one.
#include <vtkAlgorithm.h>
#include <vtkCommand.h>
#include <vtkDataArray.h>
#include <vtkExecutive.h>
#include <vtkNew.h>
#include <vtkOBJReader.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSTLReader.h>
#include <vtkSmartPointer.h>
#include <vtkXMLPolyDataReader.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdint>
#include <fstream>

#include "articula/core/error.hpp"
#include "readers.hpp"

namespace articula::points::detail {

namespace {

// Keeps the first error VTK reports (instead of printing it to the VTK output window).
class ErrorCollector : public vtkCommand {
 public:
  static ErrorCollector* New() { return new ErrorCollector; }
  void Execute(vtkObject*, unsigned long event, void* call_data) override {
    if (event != vtkCommand::ErrorEvent || !message.empty() || call_data == nullptr) return;
    message = static_cast<const char*>(call_data);
    // Drop VTK's "ERROR: In <source file>, line N\n<class> (<address>): " preamble.
    if (const auto colon = message.find("): "); colon != std::string::npos) message = message.substr(colon + 3);
    while (!message.empty() && std::isspace(static_cast<unsigned char>(message.back()))) message.pop_back();
  }
  std::string message;
};

// VTK 9.1 reads a truncated binary STL without complaint (it stops early), so check the size the
// header promises: 80 bytes of text, a uint32 triangle count, 50 bytes per triangle.
void checkBinaryStlSize(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::array<char, 84> head{};
  in.read(head.data(), head.size());
  const auto got = static_cast<std::size_t>(in.gcount());
  std::size_t start = 0;
  while (start < got && std::isspace(static_cast<unsigned char>(head[start]))) ++start;
  if (got - start >= 5 && std::string(head.data() + start, 5) == "solid") return;  // ASCII: VTK checks it
  if (got < head.size())
    throw InputError("mesh file " + quoted(path) +
                     ": expected an ASCII STL starting with 'solid' or a binary STL " +
                     "header of 84 bytes, found " + std::to_string(got) + " bytes of something else");
  std::uint32_t triangles = 0;
  for (int i = 3; i >= 0; --i) triangles = (triangles << 8) | static_cast<unsigned char>(head[80 + i]);
  const std::uintmax_t needed = 84 + 50 * static_cast<std::uintmax_t>(triangles);
  const std::uintmax_t size = std::filesystem::file_size(path);
  if (size < needed)
    throw InputError("mesh file " + quoted(path) + ": binary STL header declares " + std::to_string(triangles) +
                     " triangles (" + std::to_string(needed) + " bytes), found " + std::to_string(size) +
                     " bytes (truncated file?)");
}

vtkSmartPointer<vtkAlgorithm> makeReader(const std::filesystem::path& path, vtkCommand* errors) {
  const std::string ext = lowercase(path.extension().string());
  if (ext == ".stl") {
    checkBinaryStlSize(path);
    auto reader = vtkSmartPointer<vtkSTLReader>::New();
    reader->SetFileName(path.c_str());
    reader->MergingOn();  // STL repeats each vertex once per triangle
    return reader;
  }
  if (ext == ".obj") {
    auto reader = vtkSmartPointer<vtkOBJReader>::New();
    reader->SetFileName(path.c_str());
    return reader;
  }
  auto reader = vtkSmartPointer<vtkXMLPolyDataReader>::New();
  reader->SetFileName(path.c_str());
  reader->SetParserErrorObserver(errors);  // the XML parser's message names the line and column
  return reader;
}

}  // namespace

PointCloud readMeshVertices(const std::filesystem::path& path) {
  vtkNew<ErrorCollector> errors;
  vtkSmartPointer<vtkAlgorithm> reader = makeReader(path, errors);
  for (vtkObject* source : {static_cast<vtkObject*>(reader), static_cast<vtkObject*>(reader->GetExecutive())}) {
    source->AddObserver(vtkCommand::ErrorEvent, errors);
    source->AddObserver(vtkCommand::WarningEvent, errors);  // silences warnings; Execute keeps errors only
  }
  reader->Update();
  if (!errors->message.empty())
    throw InputError("mesh file " + quoted(path) + ": VTK could not read it: " + errors->message);

  vtkPolyData* mesh = vtkPolyData::SafeDownCast(reader->GetOutputDataObject(0));
  vtkPoints* points = mesh ? mesh->GetPoints() : nullptr;
  if (points == nullptr || points->GetNumberOfPoints() == 0)
    throw InputError("mesh file " + quoted(path) + ": expected vertices, found none");

  PointCloud cloud;
  const vtkIdType n = points->GetNumberOfPoints();
  cloud.positions.resize(n, 3);
  for (vtkIdType i = 0; i < n; ++i) {
    double p[3];
    points->GetPoint(i, p);
    cloud.positions.row(i) << p[0], p[1], p[2];
  }
  vtkDataArray* normals = mesh->GetPointData()->GetNormals();
  if (normals != nullptr && normals->GetNumberOfComponents() == 3 && normals->GetNumberOfTuples() == n) {
    cloud.normals.resize(n, 3);
    for (vtkIdType i = 0; i < n; ++i) {
      double v[3];
      normals->GetTuple(i, v);
      cloud.normals.row(i) << v[0], v[1], v[2];
    }
  }
  finishCloud(cloud, path, [](Eigen::Index i) { return "vertex " + std::to_string(i) + " (0-based)"; });
  return cloud;
}

}  // namespace articula::points::detail
