// PLY point files, hand-written rather than vtkPLYReader because VTK 9.1's reader
// (1) converts every vertex property to float, so double coordinates do not round-trip;
// (2) reports malformed headers and truncated data through VTK's error output, without the line.
// (3) (for meshes) reads a malformed ASCII record past its end: a face line with fewer
// items than its list length crashed it (a null token to strtod).
// Reading the header and the elements up to the vertex (and face) element is short code.
#include <algorithm>
#include <array>
#include <cerrno>
#include <cstddef>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <optional>
#include <sstream>
#include <vector>

#include "articula/core/error.hpp"
#include "readers.hpp"

namespace articula::points::detail {

namespace {

enum class PlyType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

std::optional<PlyType> plyType(const std::string& name) {
  static const std::array<std::pair<const char*, PlyType>, 16> kNames = {{
      {"char", PlyType::Int8},
      {"int8", PlyType::Int8},
      {"uchar", PlyType::UInt8},
      {"uint8", PlyType::UInt8},
      {"short", PlyType::Int16},
      {"int16", PlyType::Int16},
      {"ushort", PlyType::UInt16},
      {"uint16", PlyType::UInt16},
      {"int", PlyType::Int32},
      {"int32", PlyType::Int32},
      {"uint", PlyType::UInt32},
      {"uint32", PlyType::UInt32},
      {"float", PlyType::Float32},
      {"float32", PlyType::Float32},
      {"double", PlyType::Float64},
      {"float64", PlyType::Float64},
  }};
  for (const auto& [n, t] : kNames)
    if (name == n) return t;
  return std::nullopt;
}

std::size_t byteSize(PlyType type) {
  switch (type) {
    case PlyType::Int8:
    case PlyType::UInt8:
      return 1;
    case PlyType::Int16:
    case PlyType::UInt16:
      return 2;
    case PlyType::Int32:
    case PlyType::UInt32:
    case PlyType::Float32:
      return 4;
    case PlyType::Float64:
      return 8;
  }
  return 0;
}

struct Property {
  std::string name;
  PlyType type = PlyType::Float32;  // the item type for a list
  bool is_list = false;
  PlyType count_type = PlyType::UInt8;
};

struct Element {
  std::string name;
  std::size_t count = 0;
  std::vector<Property> properties;
};

enum class Format { Ascii, BinaryLittleEndian, BinaryBigEndian };

struct Header {
  Format format = Format::Ascii;
  std::vector<Element> elements;
  long line_count = 0;  // lines up to and including end_header
};

std::vector<std::string> words(const std::string& line) {
  std::istringstream in(line);
  return {std::istream_iterator<std::string>(in), std::istream_iterator<std::string>()};
}

Header readHeader(std::istream& in, const std::filesystem::path& path) {
  Header header;
  auto fail = [&](const std::string& expected, const std::string& found) {
    return InputError("PLY header of " + quoted(path) + ", line " + std::to_string(header.line_count) +
                      ": expected " + expected + ", found " + found);
  };
  std::string line;
  bool have_format = false;
  for (;;) {
    if (!std::getline(in, line)) throw fail("'end_header'", "the end of the file");
    ++header.line_count;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const auto w = words(line);
    if (header.line_count == 1) {
      if (w.size() != 1 || w[0] != "ply") throw fail("'ply' (the PLY magic line)", "'" + line.substr(0, 40) + "'");
      continue;
    }
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "end_header") break;
    if (w[0] == "format") {
      if (w.size() != 3 || w[2] != "1.0")
        throw fail("'format ascii|binary_little_endian|binary_big_endian 1.0'", "'" + line + "'");
      if (w[1] == "ascii")
        header.format = Format::Ascii;
      else if (w[1] == "binary_little_endian")
        header.format = Format::BinaryLittleEndian;
      else if (w[1] == "binary_big_endian")
        header.format = Format::BinaryBigEndian;
      else
        throw fail("format ascii, binary_little_endian or binary_big_endian", "'" + w[1] + "'");
      have_format = true;
    } else if (w[0] == "element") {
      if (w.size() != 3) throw fail("'element <name> <count>'", "'" + line + "'");
      char* end = nullptr;
      errno = 0;
      const unsigned long long count = std::strtoull(w[2].c_str(), &end, 10);
      if (*end != '\0' || errno != 0 || w[2][0] == '-')
        throw fail("a non-negative element count", "'" + w[2] + "'");
      header.elements.push_back({w[1], static_cast<std::size_t>(count), {}});
    } else if (w[0] == "property") {
      if (header.elements.empty()) throw fail("'element' before the first 'property'", "'" + line + "'");
      Property p;
      if (w.size() == 5 && w[1] == "list") {
        const auto count_type = plyType(w[2]);
        const auto item_type = plyType(w[3]);
        if (!count_type || !item_type) throw fail("PLY scalar types in 'property list'", "'" + line + "'");
        // A list length is a count: a float type would let 1e31 or NaN through as one.
        if (*count_type == PlyType::Float32 || *count_type == PlyType::Float64)
          throw fail("an integer type for the list length in 'property list'", "'" + w[2] + "'");
        p = {w[4], *item_type, true, *count_type};
      } else if (w.size() == 3) {
        const auto type = plyType(w[1]);
        if (!type)
          throw fail("a PLY type (char, uchar, short, ushort, int, uint, float, double)", "'" + w[1] + "'");
        p = {w[2], *type, false, PlyType::UInt8};
      } else {
        throw fail("'property <type> <name>' or 'property list <count type> <item type> <name>'",
                   "'" + line + "'");
      }
      header.elements.back().properties.push_back(p);
    } else {
      throw fail("a header keyword (format, element, property, comment, end_header)", "'" + line + "'");
    }
  }
  if (!have_format) throw fail("a 'format' line before 'end_header'", "none");
  return header;
}

// Binary data as a bounds-checked cursor that converts every scalar to double.
class BinaryCursor {
 public:
  BinaryCursor(std::vector<char> data, bool swap) : data_(std::move(data)), swap_(swap) {}
  std::size_t remaining() const { return data_.size() - pos_; }

  // Reads one scalar; nullopt when the data ends first.
  std::optional<double> read(PlyType type) {
    const std::size_t size = byteSize(type);
    if (remaining() < size) return std::nullopt;
    std::array<char, 8> bytes{};
    std::memcpy(bytes.data(), data_.data() + pos_, size);
    pos_ += size;
    if (swap_) std::reverse(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(size));
    switch (type) {
      case PlyType::Int8:
        return as<std::int8_t>(bytes);
      case PlyType::UInt8:
        return as<std::uint8_t>(bytes);
      case PlyType::Int16:
        return as<std::int16_t>(bytes);
      case PlyType::UInt16:
        return as<std::uint16_t>(bytes);
      case PlyType::Int32:
        return as<std::int32_t>(bytes);
      case PlyType::UInt32:
        return as<std::uint32_t>(bytes);
      case PlyType::Float32:
        return as<float>(bytes);
      case PlyType::Float64:
        return as<double>(bytes);
    }
    return std::nullopt;
  }

 private:
  template <typename T>
  static double as(const std::array<char, 8>& bytes) {
    T value;
    std::memcpy(&value, bytes.data(), sizeof(T));
    return static_cast<double>(value);
  }
  std::vector<char> data_;
  std::size_t pos_ = 0;
  bool swap_;
};

bool hostIsLittleEndian() {
  const std::uint16_t one = 1;
  unsigned char first;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

// Where x, y, z (and nx, ny, nz) sit among the vertex element's properties.
struct VertexLayout {
  std::array<int, 3> position{-1, -1, -1};
  std::array<int, 3> normal{-1, -1, -1};
  bool has_normals = false;
};

VertexLayout vertexLayout(const Element& vertex, const std::filesystem::path& path) {
  VertexLayout layout;
  const std::array<const char*, 3> xyz{"x", "y", "z"}, nxyz{"nx", "ny", "nz"};
  for (int i = 0; i < static_cast<int>(vertex.properties.size()); ++i) {
    const Property& p = vertex.properties[static_cast<std::size_t>(i)];
    for (int k = 0; k < 3; ++k) {
      if (p.name != xyz[k] && p.name != nxyz[k]) continue;
      if (p.is_list)
        throw InputError("PLY header of " + quoted(path) + ": expected vertex property '" + p.name +
                         "' to be a scalar, found a list");
      (p.name == xyz[k] ? layout.position : layout.normal)[k] = i;
    }
  }
  if (*std::min_element(layout.position.begin(), layout.position.end()) < 0)
    throw InputError("PLY header of " + quoted(path) +
                     ": expected vertex properties x, y and z, found only those it lists");
  const int normals_found =
      static_cast<int>(std::count_if(layout.normal.begin(), layout.normal.end(), [](int i) { return i >= 0; }));
  if (normals_found != 0 && normals_found != 3)
    throw InputError("PLY header of " + quoted(path) + ": expected all of nx, ny, nz or none, found " +
                     std::to_string(normals_found) + " of them");
  layout.has_normals = normals_found == 3;
  return layout;
}

void store(PointCloud& cloud, const VertexLayout& layout, Eigen::Index row, const std::vector<double>& values) {
  for (int k = 0; k < 3; ++k) {
    cloud.positions(row, k) = values[static_cast<std::size_t>(layout.position[k])];
    if (layout.has_normals) cloud.normals(row, k) = values[static_cast<std::size_t>(layout.normal[k])];
  }
}

// Values of one ASCII record (one line) of `element`, scalars only kept for the vertex element;
// the items of the list property `list` (an index into the properties) go to `items`.
std::vector<double> parseAsciiRecord(const std::string& line, const Element& element,
                                     const std::filesystem::path& path, long line_number,
                                     std::size_t list = SIZE_MAX, std::vector<double>* items = nullptr) {
  auto fail = [&](const std::string& expected, const std::string& found) {
    return InputError(quoted(path) + ", line " + std::to_string(line_number) + " (" + element.name +
                      " record): expected " + expected + ", found " + found);
  };
  std::vector<double> values;
  values.reserve(element.properties.size());
  const char* cursor = line.c_str();
  auto next = [&](const std::string& what) {
    while (*cursor == ' ' || *cursor == '\t' || *cursor == '\r') ++cursor;
    if (*cursor == '\0') throw fail(what, "the end of the line");
    char* end = nullptr;
    const double value = std::strtod(cursor, &end);
    if (end == cursor || (*end != '\0' && *end != ' ' && *end != '\t' && *end != '\r')) {
      const char* stop = cursor;
      while (*stop != '\0' && *stop != ' ' && *stop != '\t' && *stop != '\r') ++stop;
      throw fail(what, "'" + std::string(cursor, stop) + "'");
    }
    cursor = end;
    return value;
  };
  for (std::size_t k = 0; k < element.properties.size(); ++k) {
    const Property& p = element.properties[k];
    if (!p.is_list) {
      values.push_back(next("a number for property '" + p.name + "'"));
      continue;
    }
    const double count = next("a list length for property '" + p.name + "'");
    // Negated so that NaN fails too, before any conversion to an integer.
    if (!(count >= 0 && count <= 1e9) || count != std::floor(count))
      throw fail("a non-negative integer list length", std::to_string(count));
    for (long j = 0; j < static_cast<long>(count); ++j) {
      const double item = next("item " + std::to_string(j) + " of list '" + p.name + "'");
      if (k == list) items->push_back(item);
    }
    values.push_back(0.0);  // lists are skipped; keep indices aligned with properties
  }
  while (*cursor == ' ' || *cursor == '\t' || *cursor == '\r') ++cursor;
  if (*cursor != '\0')
    throw fail(std::to_string(element.properties.size()) + " properties as the header declares",
               "more values: '" + std::string(cursor).substr(0, 40) + "'");
  return values;
}

// The face element's vertex index lists, read alongside the vertices (meshes only).
struct FaceLists {
  std::size_t element = 0, property = 0;  // the face element, and its vertex_indices list
  std::size_t vertex_count = 0;
  std::vector<std::int64_t> offsets{0}, indices;

  // Ends face `record`'s list: every item a vertex the file has.
  void close(const std::vector<double>& items, std::size_t record, const std::filesystem::path& path,
             const std::string& where) {
    for (const double item : items) {
      if (!(item >= 0 && item < static_cast<double>(vertex_count)) || item != std::floor(item)) {
        std::ostringstream found;
        found << item;
        throw InputError(quoted(path) + ", " + where + " (face " + std::to_string(record) +
                         ", 0-based): expected vertex indices from 0 to " + std::to_string(vertex_count - 1) +
                         ", found " + found.str());
      }
      indices.push_back(static_cast<std::int64_t>(item));
    }
    offsets.push_back(static_cast<std::int64_t>(indices.size()));
  }
};

// The last element a reading needs: the vertices', or the faces' if later.
std::size_t lastElement(std::size_t vertex_index, const FaceLists* faces) {
  return faces ? std::max(vertex_index, faces->element) : vertex_index;
}

PointCloud readAscii(std::istream& in, const Header& header, std::size_t vertex_index, const VertexLayout& layout,
                     const std::filesystem::path& path, std::uintmax_t data_bytes, FaceLists* faces) {
  const Element& vertex = header.elements[vertex_index];
  // Every ASCII record takes at least two bytes, which bounds an absurd declared count before allocating.
  if (vertex.count > data_bytes / 2)
    throw InputError(quoted(path) + ": header declares " + std::to_string(vertex.count) +
                     " vertices, but the data has only " + std::to_string(data_bytes) + " bytes");
  PointCloud cloud;
  const auto n = static_cast<Eigen::Index>(vertex.count);
  cloud.positions.resize(n, 3);
  cloud.normals.resize(layout.has_normals ? n : 0, 3);
  std::vector<long> lines(vertex.count);

  long line_number = header.line_count;
  std::string line;
  auto nextRecord = [&](const Element& element, std::size_t record) {
    for (;;) {
      if (!std::getline(in, line))
        throw InputError(quoted(path) + ": expected " + std::to_string(element.count) + " " + element.name +
                         " records, found the end of the file after " + std::to_string(record) + " (line " +
                         std::to_string(line_number) + ")");
      ++line_number;
      if (line.find_first_not_of(" \t\r") != std::string::npos) return;  // blank lines carry no record
    }
  };
  if (faces && header.elements[faces->element].count > data_bytes / 2)
    throw InputError(quoted(path) + ": header declares " + std::to_string(header.elements[faces->element].count) +
                     " faces, but the data has only " + std::to_string(data_bytes) + " bytes");
  std::vector<double> items;
  for (std::size_t e = 0; e <= lastElement(vertex_index, faces); ++e) {
    const Element& element = header.elements[e];
    const bool face = faces && e == faces->element;
    for (std::size_t r = 0; r < element.count; ++r) {
      nextRecord(element, r);
      items.clear();
      const auto values =
          parseAsciiRecord(line, element, path, line_number, face ? faces->property : SIZE_MAX, &items);
      if (face) faces->close(items, r, path, "line " + std::to_string(line_number));
      if (e != vertex_index) continue;
      store(cloud, layout, static_cast<Eigen::Index>(r), values);
      lines[r] = line_number;
    }
  }
  finishCloud(cloud, path,
              [&](Eigen::Index i) { return "line " + std::to_string(lines[static_cast<std::size_t>(i)]); });
  return cloud;
}

PointCloud readBinary(std::istream& in, const Header& header, std::size_t vertex_index, const VertexLayout& layout,
                      const std::filesystem::path& path, std::uintmax_t data_bytes, FaceLists* faces) {
  const Element& vertex = header.elements[vertex_index];
  std::size_t vertex_record_bytes = 0;
  for (const Property& p : vertex.properties)
    vertex_record_bytes += p.is_list ? byteSize(p.count_type) : byteSize(p.type);
  if (vertex_record_bytes > 0 && vertex.count > data_bytes / vertex_record_bytes)
    throw InputError(quoted(path) + ": header declares " + std::to_string(vertex.count) +
                     " vertices of at least " + std::to_string(vertex_record_bytes) +
                     " bytes, but the data has only " + std::to_string(data_bytes) + " bytes (truncated file?)");

  std::vector<char> data(static_cast<std::size_t>(data_bytes));
  in.read(data.data(), static_cast<std::streamsize>(data.size()));
  data.resize(static_cast<std::size_t>(in.gcount()));
  const bool file_little = header.format == Format::BinaryLittleEndian;
  BinaryCursor cursor(std::move(data), file_little != hostIsLittleEndian());

  PointCloud cloud;
  const auto n = static_cast<Eigen::Index>(vertex.count);
  cloud.positions.resize(n, 3);
  cloud.normals.resize(layout.has_normals ? n : 0, 3);
  std::vector<double> values, items;
  for (std::size_t e = 0; e <= lastElement(vertex_index, faces); ++e) {
    const Element& element = header.elements[e];
    const bool face = faces && e == faces->element;
    // Records without properties take no bytes: nothing to skip, and a declared
    // count of 10^19 of them must not be counted through one by one.
    if (element.properties.empty()) continue;
    for (std::size_t r = 0; r < element.count; ++r) {
      auto take = [&](PlyType type) {
        const auto value = cursor.read(type);
        if (!value)
          throw InputError(quoted(path) + ": binary data ends inside " + element.name + " " + std::to_string(r) +
                           " (0-based) of " + std::to_string(element.count) + " (truncated file?)");
        return *value;
      };
      values.clear();
      items.clear();
      for (std::size_t k = 0; k < element.properties.size(); ++k) {
        const Property& p = element.properties[k];
        if (!p.is_list) {
          values.push_back(take(p.type));
          continue;
        }
        const double count = take(p.count_type);
        if (count < 0)
          throw InputError(quoted(path) + ": " + element.name + " " + std::to_string(r) +
                           ": expected a non-negative list length, found " + std::to_string(count));
        for (long j = 0; j < static_cast<long>(count); ++j) {
          const double item = take(p.type);
          if (face && k == faces->property) items.push_back(item);
        }
        values.push_back(0.0);
      }
      if (face) faces->close(items, r, path, "binary data");
      if (e == vertex_index) store(cloud, layout, static_cast<Eigen::Index>(r), values);
    }
  }
  finishCloud(cloud, path, [](Eigen::Index i) { return "vertex " + std::to_string(i) + " (0-based)"; });
  return cloud;
}

}  // namespace

namespace {

// The vertices of a PLY file, and its face lists into `faces` unless null (point files).
PointCloud readPlyFile(const std::filesystem::path& path, FaceLists* faces) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("cannot open point file " + quoted(path) + " for reading");
  const Header header = readHeader(in, path);

  const auto vertex = std::find_if(header.elements.begin(), header.elements.end(),
                                   [](const Element& e) { return e.name == "vertex"; });
  if (vertex == header.elements.end())
    throw InputError("PLY header of " + quoted(path) + ": expected an 'element vertex <count>' line, found none");
  const auto vertex_index = static_cast<std::size_t>(vertex - header.elements.begin());
  const VertexLayout layout = vertexLayout(*vertex, path);
  if (vertex->count == 0) throw InputError("point file " + quoted(path) + ": expected points, found 0 vertices");

  const auto face = std::find_if(header.elements.begin(), header.elements.end(),
                                 [](const Element& e) { return e.name == "face"; });
  if (faces && face == header.elements.end()) faces = nullptr;  // a point cloud: vertices only
  if (faces) {
    const auto list = std::find_if(face->properties.begin(), face->properties.end(), [](const Property& p) {
      return p.is_list && (p.name == "vertex_indices" || p.name == "vertex_index");
    });
    if (list == face->properties.end())
      throw InputError("PLY header of " + quoted(path) +
                       ": expected the face element to list 'vertex_indices' (or 'vertex_index'), found no such list");
    faces->element = static_cast<std::size_t>(face - header.elements.begin());
    faces->property = static_cast<std::size_t>(list - face->properties.begin());
    faces->vertex_count = vertex->count;
  }

  const auto data_start = static_cast<std::uintmax_t>(in.tellg());
  const std::uintmax_t file_bytes = std::filesystem::file_size(path);
  const std::uintmax_t data_bytes = file_bytes > data_start ? file_bytes - data_start : 0;
  return header.format == Format::Ascii
             ? readAscii(in, header, vertex_index, layout, path, data_bytes, faces)
             : readBinary(in, header, vertex_index, layout, path, data_bytes, faces);
}

}  // namespace

PointCloud readPly(const std::filesystem::path& path) {
  return readPlyFile(path, nullptr);
}

PlyMesh readPlyMesh(const std::filesystem::path& path) {
  FaceLists faces;
  PlyMesh mesh;
  mesh.cloud = readPlyFile(path, &faces);
  mesh.face_offsets = std::move(faces.offsets);
  mesh.face_indices = std::move(faces.indices);
  return mesh;
}

}  // namespace articula::points::detail
