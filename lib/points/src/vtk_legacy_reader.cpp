// Legacy VTK meshes (.vtk, DATASET POLYDATA), hand-written rather than vtkPolyDataReader
// because VTK 9.1's reader trusts the file: a malformed header made it read out of bounds
// (a crash in vtkDataReader::ReadString, found by fuzzing (fuzz/fuzz_mesh)), and it
// allocates for whatever counts the file declares before reading any data. This reader
// checks every count against the bytes left before allocating and every cell index against
// the points, and names the line (ASCII) or byte (BINARY) of any problem.
// It reads what vtkPolyDataWriter writes, file versions 1.0 to 5.1 (cells as counts and ids
// before 5.0, as offsets and connectivity since), and keeps what a mesh needs: points,
// polygons, triangle strips, point normals and the point array CutThroughBone (SCALARS,
// COLOR_SCALARS or a FIELD array). Vertices,
// lines and every other attribute are read past.
#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "articula/core/error.hpp"
#include "articula/points/mesh_file.hpp"
#include "readers.hpp"

namespace articula::points::detail {

namespace {

enum class DataType { Bit, Int8, UInt8, Int16, UInt16, Int32, UInt32, Int64, UInt64, Float32, Float64, String };

// VTK's names of its data types (case-insensitive); vtkidtype is written as 32 bits.
std::optional<DataType> dataType(const std::string& lower_name) {
  static const std::array<std::pair<const char*, DataType>, 17> kNames = {{
      {"bit", DataType::Bit},
      {"char", DataType::Int8},
      {"signed_char", DataType::Int8},
      {"unsigned_char", DataType::UInt8},
      {"short", DataType::Int16},
      {"unsigned_short", DataType::UInt16},
      {"int", DataType::Int32},
      {"vtkidtype", DataType::Int32},
      {"vtktypeint32", DataType::Int32},
      {"unsigned_int", DataType::UInt32},
      {"long", DataType::Int64},
      {"vtktypeint64", DataType::Int64},
      {"unsigned_long", DataType::UInt64},
      {"vtktypeuint64", DataType::UInt64},
      {"float", DataType::Float32},
      {"double", DataType::Float64},
      {"string", DataType::String},
  }};
  for (const auto& [n, t] : kNames)
    if (lower_name == n) return t;
  if (lower_name == "utf8_string") return DataType::String;
  return std::nullopt;
}

std::size_t byteSize(DataType type) {
  switch (type) {
    case DataType::Int8:
    case DataType::UInt8:
      return 1;
    case DataType::Int16:
    case DataType::UInt16:
      return 2;
    case DataType::Int32:
    case DataType::UInt32:
    case DataType::Float32:
      return 4;
    case DataType::Int64:
    case DataType::UInt64:
    case DataType::Float64:
      return 8;
    case DataType::Bit:
    case DataType::String:
      return 0;  // read by their own rules
  }
  return 0;
}

bool isInteger(DataType type) {
  return type != DataType::Float32 && type != DataType::Float64 && type != DataType::String;
}

constexpr const char* kNumericTypes =
    "unsigned_char, char, unsigned_short, short, unsigned_int, int, unsigned_long, long, vtktypeint64, vtktypeuint64, "
    "float or double";

// Array names are written with %XX escapes for spaces and other bytes.
std::string decodeName(std::string_view encoded) {
  std::string out;
  for (std::size_t i = 0; i < encoded.size(); ++i) {
    if (encoded[i] == '%' && i + 2 < encoded.size() && std::isxdigit(static_cast<unsigned char>(encoded[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(encoded[i + 2]))) {
      out += static_cast<char>(std::stoi(std::string(encoded.substr(i + 1, 2)), nullptr, 16));
      i += 2;
    } else {
      out += encoded[i];
    }
  }
  return out;
}

// A file's word for a message: at most 40 characters, other bytes than printable ASCII as \xNN.
std::string printable(std::string_view text) {
  std::string out;
  for (std::size_t i = 0; i < std::min<std::size_t>(text.size(), 40); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c >= 0x20 && c < 0x7F) {
      out += static_cast<char>(c);
    } else {
      static const char* const kHex = "0123456789abcdef";
      out += std::string("\\x") + kHex[c >> 4] + kHex[c & 15];
    }
  }
  return out + (text.size() > 40 ? "..." : "");
}
std::string shown(std::string_view text) { return "'" + printable(text) + "'"; }

std::string lower(std::string_view text) { return lowercase(std::string(text)); }

// One section of cells as offsets into their point ids; `at`: where the section starts, for messages.
struct Cells {
  std::vector<std::int64_t> offsets{0}, connectivity;
  std::string keyword;
  std::size_t at = 0;
  std::size_t count() const { return offsets.size() - 1; }
};

class LegacyReader {
 public:
  LegacyReader(const std::filesystem::path& path, std::string data) : path_(path), data_(std::move(data)) {}

  VtkLegacyMesh read() {
    readHeader();
    // Sections in any order, as VTK reads them, until the attributes (which run to the end).
    for (;;) {
      const std::string_view word = token();
      if (word.empty()) break;
      const std::string key = lower(word);
      if (key == "field") {
        readField(false, 0);
      } else if (key == "points") {
        readPoints();
      } else if (key == "vertices" || key == "lines" || key == "polygons" || key == "triangle_strips") {
        Cells cells = readCells(std::string(word));
        (key == "polygons"          ? polygons_
         : key == "triangle_strips" ? strips_
         : key == "lines"           ? lines_
                                    : vertices_) = std::move(cells);
      } else if (key == "point_data" || key == "cell_data") {
        readAttributes(key == "point_data");
        break;
      } else {
        throw fail(
            "a POLYDATA section (POINTS, VERTICES, LINES, POLYGONS, TRIANGLE_STRIPS, POINT_DATA, CELL_DATA, "
            "FIELD)",
            shown(word));
      }
    }
    for (const Cells* cells : {&vertices_, &lines_, &polygons_, &strips_}) checkIndices(*cells);
    VtkLegacyMesh mesh;
    mesh.points = std::move(points_);
    mesh.normals = std::move(normals_);
    mesh.polygon_offsets = std::move(polygons_.offsets);
    mesh.polygon_connectivity = std::move(polygons_.connectivity);
    mesh.strip_offsets = std::move(strips_.offsets);
    mesh.strip_connectivity = std::move(strips_.connectivity);
    mesh.cut_through_bone = std::move(cut_through_bone_);
    return mesh;
  }

 private:
  // ---- where we are, and errors ----

  std::string where(std::size_t at) const {
    if (binary_) return "byte " + std::to_string(at);
    return "line " +
           std::to_string(1 + std::count(data_.begin(), data_.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
  }
  InputError fail(const std::string& expected, const std::string& found) const {
    return InputError("legacy VTK file " + quoted(path_) + ", " + where(mark_) + ": expected " + expected + ", found " +
                      found);
  }
  std::size_t remaining() const { return data_.size() - pos_; }

  // ---- words ----

  static bool isSpace(char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; }

  // The next whitespace-separated word, or an empty view at the end of the file.
  std::string_view token() {
    while (pos_ < data_.size() && isSpace(data_[pos_])) ++pos_;
    mark_ = pos_;
    while (pos_ < data_.size() && !isSpace(data_[pos_])) ++pos_;
    return std::string_view(data_).substr(mark_, pos_ - mark_);
  }
  std::string_view expect(const std::string& what) {
    const std::string_view word = token();
    if (word.empty()) throw fail(what, "the end of the file");
    return word;
  }
  void expectKeyword(const char* keyword, const std::string& context) {
    const std::string_view word = expect(std::string(keyword) + " " + context);
    if (lower(word) != lowercase(keyword)) throw fail(std::string(keyword) + " " + context, shown(word));
  }
  // A count: plain decimal digits (at most 18, so that products stay checkable).
  std::uint64_t count(const std::string& what) {
    const std::string_view word = expect(what);
    if (word.size() > 18 || word.find_first_not_of("0123456789") != std::string_view::npos)
      throw fail(what + " (a non-negative integer)", shown(word));
    return std::stoull(std::string(word));
  }
  DataType type(const std::string& what, bool numeric_only) {
    const std::string_view word = expect(what);
    const auto t = dataType(lower(word));
    if (!t || (numeric_only && (*t == DataType::Bit || *t == DataType::String)))
      throw fail(what + " (" + kNumericTypes + (numeric_only ? "" : ", bit or string") + ")", shown(word));
    return *t;
  }
  // The rest of the current line (VTK's getline before binary data and between lines of metadata).
  std::string_view line() {
    const std::size_t start = pos_;
    const std::size_t end = data_.find('\n', pos_);
    pos_ = end == std::string::npos ? data_.size() : end + 1;
    std::string_view text =
        std::string_view(data_).substr(start, (end == std::string::npos ? data_.size() : end) - start);
    if (!text.empty() && text.back() == '\r') text.remove_suffix(1);
    return text;
  }

  // ---- header ----

  void readHeader() {
    mark_ = 0;
    const std::string_view first = line();
    const std::string_view prefix = "# vtk DataFile Version";
    // The version: "x.y" between spaces, from 1.0 to 5.1.
    std::string_view version = first.substr(std::min(first.size(), prefix.size()));
    while (!version.empty() && (version.front() == ' ' || version.front() == '\t')) version.remove_prefix(1);
    while (!version.empty() && (version.back() == ' ' || version.back() == '\t')) version.remove_suffix(1);
    const std::size_t dot = version.find('.');
    const bool digits = dot != std::string_view::npos && dot >= 1 && dot <= 3 && version.size() - dot - 1 >= 1 &&
                        version.size() - dot - 1 <= 3 &&
                        version.substr(0, dot).find_first_not_of("0123456789") == std::string_view::npos &&
                        version.substr(dot + 1).find_first_not_of("0123456789") == std::string_view::npos;
    const int major = digits ? std::stoi(std::string(version.substr(0, dot))) : 0;
    const int minor = digits ? std::stoi(std::string(version.substr(dot + 1))) : 0;
    if (first.substr(0, prefix.size()) != prefix || !digits || major < 1 || major > 5 || (major == 5 && minor > 1))
      throw fail("'# vtk DataFile Version x.y' of 1.0 to 5.1", shown(first));
    cells_as_offsets_ = major >= 5;
    mark_ = pos_;
    const std::string_view title = line();
    if (title.size() > 256) throw fail("a title line of at most 256 characters", std::to_string(title.size()));
    const std::string_view format = expect("ASCII or BINARY");
    if (lower(format) == "binary")
      binary_ = true;
    else if (lower(format) != "ascii")
      throw fail("ASCII or BINARY", shown(format));
    const std::string_view dataset = expect("DATASET POLYDATA");
    if (lower(dataset) != "dataset") throw fail("DATASET POLYDATA", shown(dataset));
    const std::string_view kind = expect("DATASET POLYDATA");
    if (lower(kind) != "polydata") throw fail("DATASET POLYDATA", "DATASET " + printable(kind));
  }

  // ---- data ----

  // Checks that `items` values of `type` can fit in what is left, before anything is allocated for them:
  // an ASCII number takes at least two bytes (a digit and a separator, the last one none), a binary one its size.
  void checkRoom(std::uint64_t items, DataType type, const std::string& what) const {
    const std::uint64_t left = remaining();
    const bool fits = binary_ ? (type == DataType::Bit ? (items / 8) <= left
                                                       : items <= left / std::max<std::size_t>(byteSize(type), 1))
                              : items <= (left + 1) / 2;
    if (!fits)
      throw fail(std::to_string(items) + " values for " + what + " within the " + std::to_string(left) + " bytes left",
                 "too few bytes (truncated file?)");
  }
  // tuples x components, refused when it passes what any file holds.
  std::uint64_t product(std::uint64_t tuples, std::uint64_t components, const std::string& what) const {
    if (components != 0 && tuples > (std::uint64_t{1} << 62) / components)
      throw fail(what + " of a size within the file",
                 std::to_string(tuples) + " tuples of " + std::to_string(components) + " components");
    return tuples * components;
  }

  // Before binary data VTK skips the rest of the keyword's line.
  void startBinary(const std::string& what) {
    mark_ = pos_;
    const std::size_t end = data_.find('\n', pos_);
    if (end == std::string::npos) throw fail("a line end before the binary data of " + what, "the end of the file");
    pos_ = end + 1;
  }

  // One ASCII number of `type`: the whole word, in the range of the type (and finite); an
  // integer type's value also exactly in `integer`.
  double asciiValue(DataType type, const std::string& what, std::int64_t* integer = nullptr) {
    const bool is_integer = isInteger(type);
    const std::string_view word = token();  // messages are built on failure only: this runs per number
    if (word.empty()) throw fail((is_integer ? "an integer for " : "a number for ") + what, "the end of the file");
    const auto malformed = [&] {
      return fail((is_integer ? "an integer in the range of its type for " : "a finite number for ") + what,
                  shown(word));
    };
    if (word.size() > 60 ||
        word.find_first_not_of(is_integer ? "+-0123456789" : "+-.0123456789eE") != std::string_view::npos ||
        (type == DataType::UInt64 && word[0] == '-'))
      throw malformed();
    char text[64];
    std::memcpy(text, word.data(), word.size());
    text[word.size()] = '\0';
    char* end = nullptr;
    errno = 0;
    double value = 0;
    bool in_range = true;
    if (!is_integer) {
      value = type == DataType::Float32 ? static_cast<double>(std::strtof(text, &end)) : std::strtod(text, &end);
      in_range = std::isfinite(value);
    } else if (type == DataType::UInt64) {
      value = static_cast<double>(std::strtoull(text, &end, 10));
    } else {
      const long long i = std::strtoll(text, &end, 10);
      constexpr auto kInt32 = std::numeric_limits<std::int32_t>::max();
      in_range = type == DataType::Int8     ? i >= -128 && i <= 127
                 : type == DataType::UInt8  ? i >= 0 && i <= 255
                 : type == DataType::Int16  ? i >= -32768 && i <= 32767
                 : type == DataType::UInt16 ? i >= 0 && i <= 65535
                 : type == DataType::Int32  ? i >= -kInt32 - 1 && i <= kInt32
                 : type == DataType::UInt32 ? i >= 0 && i <= std::numeric_limits<std::uint32_t>::max()
                                            : true;  // Int64, and Bit (any integer, as VTK)
      value = static_cast<double>(i);
      if (integer) *integer = i;
    }
    // (ERANGE for integers only: a float's overflow is caught as not finite, its underflow is a value.)
    if (end != text + word.size() || (is_integer && errno == ERANGE) || !in_range) throw malformed();
    return value;
  }

  // One big-endian binary value of `type` (the caller has checked the room).
  template <typename T>
  T bigEndian() {
    std::array<unsigned char, sizeof(T)> bytes;
    for (std::size_t k = 0; k < sizeof(T); ++k) bytes[sizeof(T) - 1 - k] = static_cast<unsigned char>(data_[pos_ + k]);
    pos_ += sizeof(T);
    T value;
    std::memcpy(&value, bytes.data(), sizeof(T));
    return value;
  }
  double binaryValue(DataType type) {
    switch (type) {
      case DataType::Int8:
        return bigEndian<std::int8_t>();
      case DataType::UInt8:
        return bigEndian<std::uint8_t>();
      case DataType::Int16:
        return bigEndian<std::int16_t>();
      case DataType::UInt16:
        return bigEndian<std::uint16_t>();
      case DataType::Int32:
        return bigEndian<std::int32_t>();
      case DataType::UInt32:
        return bigEndian<std::uint32_t>();
      case DataType::Int64:
        return static_cast<double>(bigEndian<std::int64_t>());
      case DataType::UInt64:
        return static_cast<double>(bigEndian<std::uint64_t>());
      case DataType::Float32:
        return bigEndian<float>();
      case DataType::Float64:
        return bigEndian<double>();
      case DataType::Bit:
      case DataType::String:
        break;
    }
    return 0;
  }

  // An array of `items` values of `type` (as VTK's ReadArray), then any METADATA after it;
  // the values when `keep`, otherwise read past (ASCII numbers still checked).
  std::vector<double> array(DataType type, std::uint64_t items, std::uint64_t components, bool keep,
                            const std::string& what) {
    std::vector<double> values;
    if (type == DataType::String) {
      skipStrings(items, what);
    } else if (type == DataType::Bit && binary_) {
      if (items > 0) {
        startBinary(what);
        checkRoom(items, type, what);
        const std::uint64_t bytes = (items + 7) / 8;
        if (bytes > remaining())
          throw fail(std::to_string(bytes) + " bytes of bits for " + what, "fewer (truncated file?)");
        pos_ += bytes;
      }
    } else if (binary_) {
      if (items > 0) {
        startBinary(what);
        mark_ = data_start_ = pos_;
        checkRoom(items, type, what);
        if (keep) {
          values.resize(items);
          for (double& v : values) v = binaryValue(type);
        } else {
          pos_ += items * byteSize(type);
        }
      }
    } else {
      checkRoom(items, type, what);
      if (keep) values.resize(items);
      for (std::uint64_t i = 0; i < items; ++i) {
        const double v = asciiValue(type, what);
        if (keep) values[i] = v;
      }
    }
    skipMetadata(components);
    return values;
  }

  // Strings: in ASCII one per line after the type's line, in BINARY each after a length of 1 to 8 bytes
  // whose top two bits say how many.
  void skipStrings(std::uint64_t items, const std::string& what) {
    if (!binary_) {
      line();
      for (std::uint64_t i = 0; i < items; ++i) {
        mark_ = pos_;
        if (pos_ == data_.size()) throw fail(std::to_string(items) + " strings for " + what, "the end of the file");
        line();
      }
      return;
    }
    if (items == 0) return;
    startBinary(what);
    for (std::uint64_t i = 0; i < items; ++i) {
      mark_ = pos_;
      if (remaining() == 0) throw fail(std::to_string(items) + " strings for " + what, "the end of the file");
      const auto first = static_cast<unsigned char>(data_[pos_]);
      std::uint64_t length = 0;
      const int kind = first >> 6;
      const std::size_t header = kind == 3 ? 1 : kind == 2 ? 2 : kind == 1 ? 4 : 8;
      if (remaining() < header) throw fail("a string length for " + what, "the end of the file");
      for (std::size_t k = 0; k < header; ++k) length = (length << 8) | static_cast<unsigned char>(data_[pos_ + k]);
      if (kind != 0) length &= (std::uint64_t{1} << (8 * header - 2)) - 1;
      pos_ += header;
      if (length > remaining())
        throw fail("a string of " + std::to_string(length) + " bytes for " + what,
                   std::to_string(remaining()) + " bytes left");
      pos_ += length;
    }
  }

  // VTK 9 writes an array's component names and information keys after its data:
  // METADATA, then COMPONENT_NAMES (one line per component) and INFORMATION (lines of
  // NAME and DATA), up to a blank line.
  void skipMetadata(std::uint64_t components) {
    std::size_t p = pos_;
    while (p < data_.size() && (data_[p] == ' ' || data_[p] == '\r' || data_[p] == '\n')) ++p;
    if (data_.size() - p < 8 || lower(std::string_view(data_).substr(p, 8)) != "metadata") return;
    pos_ = p;
    line();
    while (pos_ < data_.size()) {
      const std::string entry = lower(line());
      if (entry.empty()) return;
      if (entry.rfind("component_names", 0) == 0) {
        for (std::uint64_t i = 0; i < components && pos_ < data_.size(); ++i) line();
      } else if (entry.rfind("information", 0) == 0) {
        while (pos_ < data_.size() && !line().empty()) {
        }
        return;
      }
    }
  }

  // Indices of cells: integers, exactly as the file has them.
  std::vector<std::int64_t> indices(DataType type, std::uint64_t items, const std::string& what) {
    std::vector<std::int64_t> out;
    if (binary_) {
      if (items == 0) return out;
      startBinary(what);
      mark_ = pos_;
      checkRoom(items, type, what);
      out.resize(items);
      for (auto& v : out) v = type == DataType::Int64 ? bigEndian<std::int64_t>() : bigEndian<std::int32_t>();
      return out;
    }
    checkRoom(items, type, what);
    out.resize(items);
    for (auto& v : out) asciiValue(type, what, &v);
    return out;
  }

  // ---- sections ----

  void readPoints() {
    if (have_points_) throw fail("one POINTS section", "a second");
    const std::uint64_t n = count("the number of points");
    const DataType t = type("a points type", true);
    const std::uint64_t items = product(n, 3, "POINTS");
    const std::vector<double> xyz = array(t, items, 3, true, "POINTS");
    points_.resize(static_cast<Eigen::Index>(n), 3);
    for (std::uint64_t i = 0; i < items; ++i) {
      if (!std::isfinite(xyz[i])) {  // binary only: ASCII numbers are checked as read
        mark_ = data_start_ + i * byteSize(t);
        throw fail("finite coordinates", std::to_string(xyz[i]) + " in point " + std::to_string(i / 3) + " (0-based)");
      }
      points_(static_cast<Eigen::Index>(i / 3), static_cast<Eigen::Index>(i % 3)) = xyz[i];
    }
    have_points_ = true;
  }

  Cells readCells(const std::string& keyword) {
    Cells cells;
    cells.keyword = keyword;
    cells.at = mark_;
    if (cells_as_offsets_) {
      const std::uint64_t n_offsets = count("the number of " + keyword + " offsets");
      const std::uint64_t n_ids = count("the size of the " + keyword + " connectivity");
      if (n_offsets == 0) return cells;  // VTK reads no OFFSETS then
      expectKeyword("OFFSETS", "after " + keyword);
      const DataType offsets_type = type("an offsets type (vtktypeint64 or vtktypeint32)", true);
      if (offsets_type != DataType::Int64 && offsets_type != DataType::Int32)
        throw fail("an offsets type vtktypeint64 or vtktypeint32",
                   shown(std::string_view(data_).substr(mark_, pos_ - mark_)));
      cells.offsets = indices(offsets_type, n_offsets, keyword + " offsets");
      skipMetadata(1);
      expectKeyword("CONNECTIVITY", "after " + keyword + " offsets");
      const DataType ids_type = type("a connectivity type (vtktypeint64 or vtktypeint32)", true);
      if (ids_type != DataType::Int64 && ids_type != DataType::Int32)
        throw fail("a connectivity type vtktypeint64 or vtktypeint32",
                   shown(std::string_view(data_).substr(mark_, pos_ - mark_)));
      cells.connectivity = indices(ids_type, n_ids, keyword + " connectivity");
      skipMetadata(1);
      const auto& o = cells.offsets;
      for (std::size_t i = 0; i < o.size(); ++i) {
        const std::int64_t previous = i == 0 ? 0 : o[i - 1];
        if ((i == 0 && o[0] != 0) || o[i] < previous || (i + 1 == o.size() && o[i] != static_cast<std::int64_t>(n_ids)))
          throw InputError("legacy VTK file " + quoted(path_) + ", " + where(cells.at) + " (" + keyword +
                           "): expected offsets rising from 0 to " + std::to_string(n_ids) +
                           " (the connectivity's size), found " + std::to_string(o[i]) + " at offset " +
                           std::to_string(i) + " (0-based)");
      }
      return cells;
    }
    // Before version 5: the number of cells, then `size` integers, each cell its point count and ids.
    const std::uint64_t n_cells = count("the number of " + keyword);
    const std::uint64_t size = count("the number of integers of " + keyword);
    const std::vector<std::int64_t> values = indices(DataType::Int32, size, keyword);
    for (std::size_t i = 0; i < values.size();) {
      const std::int64_t n = values[i];
      if (n < 0 || static_cast<std::uint64_t>(n) > values.size() - i - 1)
        throw InputError("legacy VTK file " + quoted(path_) + ", " + where(cells.at) + " (" + keyword +
                         "): expected cell " + std::to_string(cells.count()) + " (0-based) to list at most the " +
                         std::to_string(values.size() - i - 1) + " integers left of " + std::to_string(size) +
                         ", found a point count of " + std::to_string(n));
      cells.connectivity.insert(cells.connectivity.end(), values.begin() + static_cast<std::ptrdiff_t>(i + 1),
                                values.begin() + static_cast<std::ptrdiff_t>(i + 1 + static_cast<std::size_t>(n)));
      cells.offsets.push_back(static_cast<std::int64_t>(cells.connectivity.size()));
      i += 1 + static_cast<std::size_t>(n);
    }
    if (cells.count() != n_cells)
      throw InputError("legacy VTK file " + quoted(path_) + ", " + where(cells.at) + " (" + keyword + "): expected " +
                       std::to_string(n_cells) + " cells as declared, found " + std::to_string(cells.count()) +
                       " in its " + std::to_string(size) + " integers");
    return cells;
  }

  void checkIndices(const Cells& cells) const {
    const auto n = static_cast<std::int64_t>(points_.rows());
    for (std::size_t i = 0; i < cells.connectivity.size(); ++i) {
      const std::int64_t id = cells.connectivity[i];
      if (id >= 0 && id < n) continue;
      const auto cell = std::upper_bound(cells.offsets.begin(), cells.offsets.end(), static_cast<std::int64_t>(i)) -
                        cells.offsets.begin() - 1;
      throw InputError("legacy VTK file " + quoted(path_) + ", " + where(cells.at) + " (" + cells.keyword + ", cell " +
                       std::to_string(cell) + ", 0-based): expected point indices from 0 to " + std::to_string(n - 1) +
                       ", found " + std::to_string(id));
    }
  }

  std::uint64_t cellCount() const { return vertices_.count() + lines_.count() + polygons_.count() + strips_.count(); }

  // POINT_DATA or CELL_DATA and the attributes after it, to the end of the file (either may follow the other).
  void readAttributes(bool point_data) {
    for (;;) {
      const std::uint64_t n = count(point_data ? "the number of POINT_DATA values" : "the number of CELL_DATA values");
      const std::uint64_t expected = point_data ? static_cast<std::uint64_t>(points_.rows()) : cellCount();
      if (n != expected)
        throw fail(std::string(point_data ? "POINT_DATA " : "CELL_DATA ") + std::to_string(expected) +
                       (point_data ? " (the number of points)" : " (the number of cells)"),
                   std::to_string(n));
      std::optional<bool> next;
      for (;;) {
        const std::string_view word = token();
        if (word.empty()) return;
        const std::string key = lower(word);
        if (key == "point_data" || key == "cell_data") {
          next = key == "point_data";
          break;
        }
        readAttribute(key, word, point_data, n);
      }
      point_data = *next;
    }
  }

  void readAttribute(const std::string& key, std::string_view word, bool point_data, std::uint64_t n) {
    const std::string section = point_data ? "POINT_DATA" : "CELL_DATA";
    if (key == "scalars") {
      const std::string name = decodeName(expect("a SCALARS name"));
      const DataType t = type("a SCALARS type", false);
      std::uint64_t components = 1;
      std::string_view next = expect("LOOKUP_TABLE or a number of components after SCALARS " + name);
      if (lower(next) != "lookup_table") {
        mark_ = static_cast<std::size_t>(next.data() - data_.data());
        if (next.size() > 9 || next.find_first_not_of("0123456789") != std::string_view::npos ||
            std::stoul(std::string(next)) < 1)
          throw fail("a number of components (1 or more) or LOOKUP_TABLE after SCALARS " + name, shown(next));
        components = std::stoul(std::string(next));
        expectKeyword("LOOKUP_TABLE", "after SCALARS " + name);
      }
      expect("a lookup table name after SCALARS " + name);
      const bool keep = point_data && name == kCutThroughBoneArray && components == 1 && cut_through_bone_.empty();
      auto values = array(t, product(n, components, "SCALARS " + name), components, keep, "SCALARS " + name);
      if (keep) cut_through_bone_ = std::move(values);
    } else if (key == "vectors" || key == "normals" || key == "tensors" || key == "tensors6" || key == "global_ids" ||
               key == "pedigree_ids" || key == "edge_flags") {
      std::string upper = key;
      std::transform(upper.begin(), upper.end(), upper.begin(),
                     [](char c) { return static_cast<char>(std::toupper(static_cast<unsigned char>(c))); });
      const std::string name = decodeName(expect("a name after " + upper));
      const DataType t = type("a type for " + upper + " " + name, key != "pedigree_ids");
      const std::uint64_t components = key == "tensors"                       ? 9
                                       : key == "tensors6"                    ? 6
                                       : key == "vectors" || key == "normals" ? 3
                                                                              : 1;
      const bool keep = point_data && key == "normals" && normals_.rows() == 0;
      const auto values = array(t, product(n, components, upper), components, keep, upper + " " + name);
      if (keep) {
        normals_.resize(static_cast<Eigen::Index>(n), 3);
        for (std::size_t i = 0; i < values.size(); ++i)
          normals_(static_cast<Eigen::Index>(i / 3), static_cast<Eigen::Index>(i % 3)) = values[i];
      }
    } else if (key == "texture_coordinates") {
      const std::string name = decodeName(expect("a TEXTURE_COORDINATES name"));
      const std::uint64_t dimension = count("a dimension (1 to 3) for TEXTURE_COORDINATES " + name);
      if (dimension < 1 || dimension > 3)
        throw fail("a dimension of 1 to 3 for TEXTURE_COORDINATES " + name, std::to_string(dimension));
      const DataType t = type("a type for TEXTURE_COORDINATES " + name, true);
      array(t, product(n, dimension, "TEXTURE_COORDINATES"), dimension, false, "TEXTURE_COORDINATES " + name);
    } else if (key == "color_scalars") {
      const std::string name = decodeName(expect("a COLOR_SCALARS name"));
      const std::uint64_t components = count("a number of values per colour for COLOR_SCALARS " + name);
      if (components < 1) throw fail("1 or more values per colour for COLOR_SCALARS " + name, "0");
      // Floats from 0 to 1 in ASCII, bytes in BINARY (vtkPolyDataWriter writes active unsigned char scalars so).
      const bool keep = point_data && name == kCutThroughBoneArray && components == 1 && cut_through_bone_.empty();
      auto values = array(binary_ ? DataType::UInt8 : DataType::Float32, product(n, components, "COLOR_SCALARS"),
                          components, keep, "COLOR_SCALARS " + name);
      if (keep && !binary_)  // as VTK converts them to bytes
        for (double& v : values) v = std::clamp(std::trunc(255.0 * v + 0.5), 0.0, 255.0);
      if (keep) cut_through_bone_ = std::move(values);
    } else if (key == "lookup_table") {
      expect("a LOOKUP_TABLE name");
      const std::uint64_t size = count("a LOOKUP_TABLE size");
      // RGBA: floats in ASCII, bytes in BINARY; no metadata follows.
      const std::uint64_t items = product(size, 4, "LOOKUP_TABLE");
      if (binary_) {
        if (items == 0) return;
        startBinary("LOOKUP_TABLE");
        mark_ = pos_;
        checkRoom(items, DataType::UInt8, "LOOKUP_TABLE");
        pos_ += items;
      } else {
        checkRoom(items, DataType::Float32, "LOOKUP_TABLE");
        for (std::uint64_t i = 0; i < items; ++i) asciiValue(DataType::Float32, "LOOKUP_TABLE");
      }
    } else if (key == "field") {
      readField(point_data, n);
    } else {
      throw fail(section +
                     " attributes (SCALARS, COLOR_SCALARS, LOOKUP_TABLE, VECTORS, NORMALS, "
                     "TEXTURE_COORDINATES, TENSORS, FIELD, ...)",
                 shown(word));
    }
  }

  // FIELD name numArrays, then each array as `name components tuples type` and its data;
  // NULL_ARRAY stands for an absent array. Kept: a point array CutThroughBone of one component.
  void readField(bool point_data, std::uint64_t n) {
    expect("a FIELD name");
    const std::uint64_t arrays = count("a number of FIELD arrays");
    for (std::uint64_t a = 0; a < arrays; ++a) {  // each array takes a word at least: bounded by the file
      const std::string_view encoded =
          expect("FIELD array " + std::to_string(a) + " (0-based) of " + std::to_string(arrays));
      if (encoded == "NULL_ARRAY") continue;
      const std::string name = decodeName(encoded);
      const std::uint64_t components = count("a number of components of FIELD array " + name);
      const std::uint64_t tuples = count("a number of tuples of FIELD array " + name);
      const DataType t = type("a type of FIELD array " + name, false);
      const bool keep = point_data && name == kCutThroughBoneArray && components == 1 && tuples == n &&
                        t != DataType::String && cut_through_bone_.empty();
      auto values =
          array(t, product(tuples, components, "FIELD array " + name), components, keep, "FIELD array " + name);
      if (keep) cut_through_bone_ = std::move(values);
    }
  }

  const std::filesystem::path& path_;
  std::string data_;
  std::size_t pos_ = 0, mark_ = 0;  // mark_: where the word or data being read starts, for messages
  std::size_t data_start_ = 0;      // where the last binary array's values start
  bool binary_ = false, cells_as_offsets_ = false, have_points_ = false;
  Eigen::MatrixX3d points_, normals_;
  Cells vertices_, lines_, polygons_, strips_;
  std::vector<double> cut_through_bone_;
};

}  // namespace

VtkLegacyMesh readVtkLegacyMesh(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("cannot open mesh file " + quoted(path) + " for reading");
  std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw InputError("cannot read mesh file " + quoted(path));
  return LegacyReader(path, std::move(data)).read();
}

}  // namespace articula::points::detail
