// Meshes (.stl, .obj, .vtp) through VTK's readers, and .ply and legacy .vtk through the
// project's own readers (ply_reader.cpp, vtk_legacy_reader.cpp: VTK 9.1's crashed on a short
// ASCII face record and on a malformed legacy header), whose meshes are handed to
// meshFromPolyData as VTK's would be. VTK reports problems through error events rather than
// exceptions, so an observer on the reader, its executive and (for XML) its parser collects
// them, keeps them off stderr, and we throw InputError with the first one.
#include <vtkVersion.h>
#include <vtkAlgorithm.h>
#include <vtkCommand.h>
#include <vtkDataArray.h>
#include <vtkDoubleArray.h>
#include <vtkIdTypeArray.h>
#include <vtkExecutive.h>
#include <vtkNew.h>
#include <vtkOBJReader.h>
#include <vtkTriangleFilter.h>
#include <vtkCellArray.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSTLReader.h>
#include <vtkSmartPointer.h>
#include <vtkXMLDataElement.h>
#include <vtkXMLDataParser.h>
#include <vtkXMLPolyDataReader.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include "articula/core/error.hpp"
#include "articula/points/mesh_file.hpp"
#include "articula/points/vtk_mesh.hpp"
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

// VTK 9.1 reads a truncated binary STL without complaint (it stops early), and
// allocates for the triangle count of the header before reading any, so check
// the size the header promises: 80 bytes of text, a uint32 triangle count, 50
// bytes per triangle. Which files are binary is decided as VTK decides it
// (vtksys DetectFileType): 5% or more of the first 256 bytes outside printable
// ASCII, tab, CR and LF; an ASCII header such as "solid" does not make it text.
void checkBinaryStlSize(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::array<char, 256> head{};
  in.read(head.data(), head.size());
  const auto got = static_cast<std::size_t>(in.gcount());
  const auto text = static_cast<std::size_t>(std::count_if(head.begin(), head.begin() + got, [](char c) {
    const auto u = static_cast<unsigned char>(c);
    return (u >= 0x20 && u <= 0x7F) || u == '\n' || u == '\r' || u == '\t';
  }));
  if (got > 0 && static_cast<double>(got - text) / static_cast<double>(got) < 0.05) return;  // ASCII: VTK checks it
  if (got < 84)
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

// VTK 9.1's OBJ reader trusts the file's indices: a face naming a vertex,
// texture coordinate or normal the file does not have is read out of bounds
// (a crash), and a material name of 100 characters or more overflows its
// buffer. So every index of 'f', 'l' and 'p' is checked here first, as VTK
// resolves it (1-based; negative counts back from the elements read so far),
// and anything VTK might read differently is refused rather than guessed.
void checkObjReferences(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("cannot open mesh file " + quoted(path) + " for reading");
  auto words = [](const std::string& line) {
    std::vector<std::string> out;
    std::size_t i = 0;
    for (;;) {
      while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
      if (i == line.size()) return out;
      const std::size_t start = i;
      while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
      out.push_back(line.substr(start, i - start));
    }
  };
  // First pass: how many of each the file holds (VTK reads positive indices against these totals).
  std::array<long, 3> total{0, 0, 0};  // v, vt, vn
  std::string line;
  long line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    line = line.substr(0, line.find('\0'));  // VTK reads each line as a C string
    const auto w = words(line);
    if (w.empty()) continue;
    if (w[0] == "v") ++total[0];
    if (w[0] == "vt") ++total[1];
    if (w[0] == "vn") ++total[2];
    if (w[0] == "usemtl" && w.size() > 1 && w[1].size() >= 100)
      throw InputError("mesh file " + quoted(path) + ", line " + std::to_string(line_number) +
                       ": expected a material name of fewer than 100 characters, found " +
                       std::to_string(w[1].size()));
  }
  in.clear();
  in.seekg(0);
  std::array<long, 3> so_far{0, 0, 0};  // negative indices count back from these
  const char* const kinds[3] = {"vertex", "texture coordinate", "normal"};
  const char* const plurals[3] = {"vertices", "texture coordinates", "normals"};
  line_number = 0;
  bool continued = false;  // a line ending in '\' continues the element on the next
  std::string command;
  while (std::getline(in, line)) {
    ++line_number;
    line = line.substr(0, line.find('\0'));
    auto w = words(line);
    if (!continued) {
      if (w.empty()) continue;
      command = w[0];
      w.erase(w.begin());
      if (command == "v") ++so_far[0];
      if (command == "vt") ++so_far[1];
      if (command == "vn") ++so_far[2];
      if (command != "f" && command != "l" && command != "p") continue;
    }
    continued = !w.empty() && w.back() == "\\";
    if (continued) w.pop_back();
    for (const std::string& word : w) {
      auto fail = [&](const std::string& expected) {
        return InputError("mesh file " + quoted(path) + ", line " + std::to_string(line_number) + ": expected " +
                          expected + " in '" + command + "', found '" + word.substr(0, 40) + "'");
      };
      // v, v/t, v//n or v/t/n; 'p' takes v only and 'l' v or v/t.
      std::vector<std::string> parts;
      std::size_t start = 0;
      for (std::size_t slash; (slash = word.find('/', start)) != std::string::npos; start = slash + 1)
        parts.push_back(word.substr(start, slash - start));
      parts.push_back(word.substr(start));
      const std::size_t max_parts = command == "f" ? 3 : command == "l" ? 2 : 1;
      if (parts.size() > max_parts || parts[0].empty() || (parts.size() == 2 && parts[1].empty()) ||
          (parts.size() == 3 && parts[2].empty()))
        throw fail(command == "f" ? "indices v, v/t, v//n or v/t/n" : command == "l" ? "indices v or v/t" : "indices v");
      for (std::size_t k = 0; k < parts.size(); ++k) {
        if (parts[k].empty()) continue;  // the t of v//n
        const std::string& text = parts[k];
        const std::size_t digits = text.find_first_not_of("+-") == 1 ? text.size() - 1 : text.size();
        if (digits == 0 || digits > 9 || text.find_first_not_of("0123456789", text.size() - digits) != std::string::npos)
          throw fail("integer indices of at most 9 digits");
        const long index = std::stol(text);
        const bool known = index > 0 ? index <= total[k] : index < 0 && -index <= so_far[k];
        if (!known)
          throw fail("a " + std::string(kinds[k]) + " index within the file's " + std::to_string(total[k]) + " " +
                     (total[k] == 1 ? kinds[k] : plurals[k]) + " (1-based, or negative counting back from the " +
                     std::to_string(so_far[k]) + " read so far)");
      }
    }
  }
}

// VTK 9.1's XML readers take a DataArray's NumberOfComponents as they parse
// it: a number past the range of int is read as the largest int, and the
// reader then spends minutes (or all memory) on an array of that many
// components. So the file's XML is parsed first by VTK's own parser (which
// stops at the appended binary data and resolves character references as
// the reader will), and every NumberOfComponents must be plain digits within
// what a mesh's arrays hold; anything else is refused rather than guessed.
constexpr long kMaxVtpComponents = 4096;

void checkVtpComponentCounts(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("cannot open mesh file " + quoted(path) + " for reading");
  vtkNew<vtkXMLDataParser> parser;
  vtkNew<ErrorCollector> ignored;  // a malformed file: the reader's own parse reports it
  parser->AddObserver(vtkCommand::ErrorEvent, ignored);
  parser->SetStream(&in);
  if (!parser->Parse() || parser->GetRootElement() == nullptr) return;
  std::vector<vtkXMLDataElement*> pending{parser->GetRootElement()};  // a stack: nesting depth is the file's
  while (!pending.empty()) {
    vtkXMLDataElement* element = pending.back();
    pending.pop_back();
    for (int i = 0; i < element->GetNumberOfNestedElements(); ++i) pending.push_back(element->GetNestedElement(i));
    const char* value = element->GetAttribute("NumberOfComponents");
    if (value == nullptr) continue;
    std::string text(value);
    const auto first = text.find_first_not_of(" \t\r\n");
    const auto last = text.find_last_not_of(" \t\r\n");
    text = first == std::string::npos ? "" : text.substr(first, last - first + 1);
    const bool digits = !text.empty() && text.size() <= 9 && text.find_first_not_of("0123456789") == std::string::npos;
    const long components = digits ? std::stol(text) : 0;
    if (components < 1 || components > kMaxVtpComponents)
      throw InputError("mesh file " + quoted(path) + ": expected NumberOfComponents of 1 to " +
                       std::to_string(kMaxVtpComponents) + " on <" + element->GetName() + ">, found '" +
                       text.substr(0, 40) + (text.size() > 40 ? "...'" : "'"));
  }
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
    checkObjReferences(path);
    auto reader = vtkSmartPointer<vtkOBJReader>::New();
    reader->SetFileName(path.c_str());
    return reader;
  }
  if (ext != ".vtp")
    throw InputError("mesh file " + quoted(path) + ": expected extension .vtp, .stl, .ply, .vtk or .obj, found '" +
                     path.extension().string() + "'");
  checkVtpComponentCounts(path);
  auto reader = vtkSmartPointer<vtkXMLPolyDataReader>::New();
  reader->SetFileName(path.c_str());
  reader->SetParserErrorObserver(errors);  // the XML parser's message names the line and column
  return reader;
}

// Vertices, their normals (none: 0 rows) and a per-vertex cut-through-bone mark (none:
// empty), and polygons as offsets into their vertex ids: a vtkPolyData for meshFromPolyData,
// which triangulates every mesh's polygons alike.
vtkSmartPointer<vtkPolyData> polyDataOf(const Eigen::MatrixX3d& vertices, const Eigen::MatrixX3d& normals,
                                        const std::vector<double>& cut_through_bone,
                                        const std::vector<std::int64_t>& offsets,
                                        const std::vector<std::int64_t>& connectivity) {
  const Eigen::Index n = vertices.rows();
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(n);
  for (Eigen::Index i = 0; i < n; ++i) points->SetPoint(i, vertices(i, 0), vertices(i, 1), vertices(i, 2));
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  poly->SetPoints(points);
  if (normals.rows() == n) {
    vtkNew<vtkDoubleArray> array;
    array->SetNumberOfComponents(3);
    array->SetNumberOfTuples(n);
    for (Eigen::Index i = 0; i < n; ++i) array->SetTuple3(i, normals(i, 0), normals(i, 1), normals(i, 2));
    poly->GetPointData()->SetNormals(array);
  }
  if (cut_through_bone.size() == static_cast<size_t>(n)) {
    vtkNew<vtkDoubleArray> cut;
    cut->SetName(kCutThroughBoneArray);
    cut->SetNumberOfValues(n);
    for (Eigen::Index i = 0; i < n; ++i) cut->SetValue(i, cut_through_bone[static_cast<size_t>(i)]);
    poly->GetPointData()->AddArray(cut);
  }
  vtkNew<vtkIdTypeArray> offset_array, connectivity_array;
  offset_array->SetNumberOfValues(static_cast<vtkIdType>(offsets.size()));
  for (size_t i = 0; i < offsets.size(); ++i) offset_array->SetValue(static_cast<vtkIdType>(i), offsets[i]);
  connectivity_array->SetNumberOfValues(static_cast<vtkIdType>(connectivity.size()));
  for (size_t i = 0; i < connectivity.size(); ++i)
    connectivity_array->SetValue(static_cast<vtkIdType>(i), connectivity[i]);
  vtkNew<vtkCellArray> polys;
  polys->SetData(offset_array, connectivity_array);
  poly->SetPolys(polys);
  return poly;
}

vtkSmartPointer<vtkPolyData> plyPolyData(const std::filesystem::path& path) {
  const PlyMesh ply = readPlyMesh(path);
  return polyDataOf(ply.cloud.positions, ply.cloud.normals, {}, ply.face_offsets, ply.face_indices);
}

// A legacy .vtk mesh, its triangle strips cut into triangles after its polygons
// (meshFromPolyData triangulates polygons only), winding alternating along each strip as VTK's.
vtkSmartPointer<vtkPolyData> legacyVtkPolyData(const std::filesystem::path& path) {
  const VtkLegacyMesh mesh = readVtkLegacyMesh(path);
  if (mesh.points.rows() == 0) throw InputError("mesh file " + quoted(path) + ": expected vertices, found none");
  std::vector<std::int64_t> offsets = mesh.polygon_offsets, connectivity = mesh.polygon_connectivity;
  for (size_t s = 0; s + 1 < mesh.strip_offsets.size(); ++s) {
    const std::int64_t* ids = mesh.strip_connectivity.data() + mesh.strip_offsets[s];
    const std::int64_t count = mesh.strip_offsets[s + 1] - mesh.strip_offsets[s];
    for (std::int64_t j = 0; j + 2 < count; ++j) {
      const bool odd = j % 2 == 1;
      connectivity.insert(connectivity.end(), {ids[odd ? j + 1 : j], ids[odd ? j : j + 1], ids[j + 2]});
      offsets.push_back(static_cast<std::int64_t>(connectivity.size()));
    }
  }
  return polyDataOf(mesh.points, mesh.normals, mesh.cut_through_bone, offsets, connectivity);
}

}  // namespace

PointCloud readMeshVertices(const std::filesystem::path& path) {
  MeshFile mesh = readMeshFile(path);
  PointCloud cloud{std::move(mesh.vertices), std::move(mesh.normals)};
  finishCloud(cloud, path, [](Eigen::Index i) { return "vertex " + std::to_string(i) + " (0-based)"; });
  return cloud;
}

}  // namespace articula::points::detail

namespace articula::points {

MeshFile readMeshFile(const std::filesystem::path& path) {
  using detail::quoted;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError("mesh file " + quoted(path) + " not found");
  const std::string ext = detail::lowercase(path.extension().string());
  if (ext == ".ply") return meshFromPolyData(detail::plyPolyData(path));
  if (ext == ".vtk") return meshFromPolyData(detail::legacyVtkPolyData(path));
  vtkNew<detail::ErrorCollector> errors;
  vtkSmartPointer<vtkAlgorithm> reader = detail::makeReader(path, errors);
  for (vtkObject* source : {static_cast<vtkObject*>(reader), static_cast<vtkObject*>(reader->GetExecutive())}) {
    source->AddObserver(vtkCommand::ErrorEvent, errors);
    source->AddObserver(vtkCommand::WarningEvent, errors);  // silences warnings; Execute keeps errors only
  }
  reader->Update();
  if (!errors->message.empty())
    throw InputError("mesh file " + quoted(path) + ": VTK could not read it: " + errors->message);
  vtkPolyData* poly = vtkPolyData::SafeDownCast(reader->GetOutputDataObject(0));
  vtkPoints* points = poly ? poly->GetPoints() : nullptr;
  if (points == nullptr || points->GetNumberOfPoints() == 0)
    throw InputError("mesh file " + quoted(path) + ": expected vertices, found none");

  return meshFromPolyData(poly);
}

MeshFile meshFromPolyData(vtkPolyData* poly) {
  MeshFile out;
  vtkPoints* points = poly->GetPoints();
  const vtkIdType n = points ? points->GetNumberOfPoints() : 0;
  out.vertices.resize(n, 3);
  for (vtkIdType i = 0; i < n; ++i) {
    double p[3];
    points->GetPoint(i, p);
    out.vertices.row(i) << p[0], p[1], p[2];
  }
  vtkDataArray* normals = poly->GetPointData()->GetNormals();
  if (normals != nullptr && normals->GetNumberOfComponents() == 3 && normals->GetNumberOfTuples() == n) {
    out.normals.resize(n, 3);
    for (vtkIdType i = 0; i < n; ++i) {
      double v[3];
      normals->GetTuple(i, v);
      out.normals.row(i) << v[0], v[1], v[2];
    }
  }
  if (vtkDataArray* cut = poly->GetPointData()->GetArray(kCutThroughBoneArray);
      cut != nullptr && cut->GetNumberOfComponents() == 1 && cut->GetNumberOfTuples() == n) {
    out.cut_through_bone.resize(static_cast<size_t>(n));
    for (vtkIdType i = 0; i < n; ++i) out.cut_through_bone[static_cast<size_t>(i)] = cut->GetTuple1(i) != 0 ? 1 : 0;
  }
  if (poly->GetNumberOfPolys() > 0) {
    // Polygons as triangles (the filter keeps the points and their order);
    // triangles as they are, in their order.
    vtkCellArray* cells = poly->GetPolys();
    vtkNew<vtkTriangleFilter> triangulate;
    if (cells->IsHomogeneous() != 3) {
      triangulate->SetInputData(poly);
      triangulate->PassLinesOff();
      triangulate->PassVertsOff();
      triangulate->Update();
      cells = triangulate->GetOutput()->GetPolys();
    }
    out.triangles.resize(cells->GetNumberOfCells(), 3);
    vtkIdType row = 0, count = 0;
    const vtkIdType* ids = nullptr;
    for (cells->InitTraversal(); cells->GetNextCell(count, ids);)
      if (count == 3) out.triangles.row(row++) << static_cast<int>(ids[0]), static_cast<int>(ids[1]), static_cast<int>(ids[2]);
    out.triangles.conservativeResize(row, 3);
  }
  return out;
}

std::string vtkLibraryVersion() { return vtkVersion::GetVTKVersion(); }

}  // namespace articula::points
