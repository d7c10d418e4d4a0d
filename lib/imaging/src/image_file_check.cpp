#include "image_file_check.hpp"

#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <fstream>
#include <map>
#include <sstream>
#include <vector>

#include "articula/core/error.hpp"
#include "articula/core/excerpt.hpp"

namespace articula::imaging {
namespace {

namespace fs = std::filesystem;

bool endsWith(const std::string& name, const std::string& ext) {
  return name.size() > ext.size() && name.compare(name.size() - ext.size(), ext.size(), ext) == 0;
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::string trimmed(const std::string& s) {
  const auto first = s.find_first_not_of(" \t\r");
  if (first == std::string::npos) return "";
  return s.substr(first, s.find_last_not_of(" \t\r") - first + 1);
}

/// The bytes a zlib or gzip stream inflates to, read from `in` (to its end,
/// to `limit` bytes when that is not negative, or to where the stream ends);
/// -1 when it is damaged. Counted in chunks:
/// nothing of the image is kept.
long long inflatedLength(std::istream& in, long long limit) {
  z_stream z{};
  if (inflateInit2(&z, 15 + 32) != Z_OK) return -1;  // 15 + 32: zlib or gzip, by its header
  std::vector<unsigned char> input(1 << 16), output(1 << 16);
  long long total = 0;
  int rc = Z_OK;
  while (rc != Z_STREAM_END) {
    if (z.avail_in == 0) {
      long long want = static_cast<long long>(input.size());
      if (limit >= 0) want = std::min(want, limit);
      in.read(reinterpret_cast<char*>(input.data()), static_cast<std::streamsize>(want));
      if (limit >= 0) limit -= in.gcount();
      z.avail_in = static_cast<uInt>(in.gcount());
      z.next_in = input.data();
      if (z.avail_in == 0) break;  // the stream ends early
    }
    z.next_out = output.data();
    z.avail_out = static_cast<uInt>(output.size());
    rc = inflate(&z, Z_NO_FLUSH);
    if (rc != Z_OK && rc != Z_STREAM_END) break;
    total += static_cast<long long>(output.size() - z.avail_out);
  }
  inflateEnd(&z);
  return rc == Z_STREAM_END || rc == Z_OK || rc == Z_BUF_ERROR ? total : -1;
}

/// The image's data: how many bytes it must hold, where they are (this file
/// from `offset`, or another), and whether they are compressed.
struct DataLayout {
  unsigned long long expected = 0;
  fs::path file;
  std::streamoff offset = 0;
  bool compressed = false;
  long long compressed_size = -1;  // the header's word on it, when it says
};

void checkLength(const fs::path& header_file, const DataLayout& data) {
  std::ifstream in(data.file, std::ios::binary);
  if (!in) throw InputError(header_file.string() + ": its data file '" + data.file.string() + "' cannot be opened");
  long long found = 0;
  if (data.compressed) {
    in.seekg(data.offset);
    found = inflatedLength(in, data.compressed_size);
    if (found < 0) throw InputError(header_file.string() + ": its compressed voxel data is damaged");
  } else {
    in.seekg(0, std::ios::end);
    found = static_cast<long long>(in.tellg()) - data.offset;
  }
  if (found < 0 || static_cast<unsigned long long>(found) < data.expected)
    throw InputError(header_file.string() + ": the header announces " + std::to_string(data.expected) +
                     " bytes of voxel data, the file holds " + std::to_string(std::max(found, 0LL)) +
                     ": the file is cut short (an interrupted copy or download?)");
}

/// bytes x the sizes, saturating at 2^62 (a header may announce anything).
unsigned long long product(const std::vector<unsigned long long>& sizes, unsigned long long bytes) {
  constexpr unsigned long long kLimit = 1ULL << 62;
  unsigned long long n = bytes;
  for (unsigned long long s : sizes) {
    if (s == 0) return 0;
    if (n > kLimit / s) return kLimit;
    n *= s;
  }
  return n;
}

std::vector<unsigned long long> sizesOf(const std::string& text) {
  std::vector<unsigned long long> sizes;
  std::istringstream words(text);
  for (std::string w; words >> w;) {
    if (w.empty() || w.find_first_not_of("0123456789") != std::string::npos || w.size() > 18) return {};
    sizes.push_back(std::stoull(w));
  }
  return sizes;
}

// MetaImage (.mha, .mhd): "Key = Value" lines, ElementDataFile last; the
// data follows in the same file (LOCAL) or lies in the named file.
void checkMetaImage(const fs::path& path) {
  static const std::map<std::string, unsigned> kBytes = {
      {"MET_CHAR", 1}, {"MET_UCHAR", 1}, {"MET_SHORT", 2}, {"MET_USHORT", 2}, {"MET_INT", 4}, {"MET_UINT", 4},
      {"MET_LONG", 4}, {"MET_ULONG", 4}, {"MET_LONG_LONG", 8}, {"MET_ULONG_LONG", 8}, {"MET_FLOAT", 4}, {"MET_DOUBLE", 8}};
  std::ifstream in(path, std::ios::binary);
  if (!in) return;  // ITK says why
  std::map<std::string, std::string> fields;
  std::string line;
  while (std::getline(in, line) && in.tellg() < (1 << 20)) {
    // MetaIO reads each line as a C string: a NUL ends a key early ("Element
    // DataFile\0\0 =" was its data file's line), and no header holds control
    // characters.
    for (const char c : line)
      if (static_cast<unsigned char>(c) < 0x20 && c != '\t' && c != '\r')
        throw InputError(path.string() + ": the MetaImage header's line '" + excerpt(trimmed(line), 60) +
                         "' holds a control character (byte " + std::to_string(static_cast<unsigned char>(c)) +
                         "); expected text lines up to ElementDataFile");
    const auto eq = line.find('=');
    // MetaIO takes the words of a line without '=' for a key and reads on
    // into the next lines for its value: such a header spun it for ever.
    if (eq == std::string::npos) {
      if (trimmed(line).empty()) continue;
      throw InputError(path.string() + ": the MetaImage header's line '" + excerpt(trimmed(line), 60) +
                       "' has no '='; expected 'Key = Value' lines up to ElementDataFile");
    }
    const std::string key = trimmed(line.substr(0, eq));
    // MetaIO copies keys and values into fixed buffers (a 300-character key
    // overran one): its fields are short names and values.
    const bool named = !key.empty() && key.size() <= 64 &&
                       std::all_of(key.begin(), key.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
    if (!named || line.size() > 1024)
      throw InputError(path.string() + ": the MetaImage header's line '" + excerpt(trimmed(line), 60) +
                       "' is no field (a name of letters and digits, a value, 1,024 characters at most)");
    // MetaIO reads the fields in order, each sized by the NDims it has read
    // so far: a second NDims, or a second of any field, would make it read
    // other numbers than those judged here.
    if (!fields.emplace(key, trimmed(line.substr(eq + 1))).second)
      throw InputError(path.string() + ": the MetaImage header gives '" + excerpt(key) +
                       "' twice; expected each field once");
    if (key == "ElementDataFile") break;
  }
  // ITK's MetaIO reads NDims numbers for each of the sizes, spacings and
  // offsets, and NDims^2 for the matrix, trusting NDims: a negative one
  // spun it for ever. Only a 3-D volume is of use here.
  if (fields.count("NDims") && fields["NDims"] != "3")
    throw InputError(path.string() + ": the MetaImage header says NDims = " + excerpt(fields["NDims"]) +
                     "; expected NDims = 3 (a 3-D volume)");
  if (!fields.count("ElementDataFile") || !fields.count("DimSize") || !fields.count("ElementType")) return;  // ITK says why
  const std::string where = fields["ElementDataFile"];
  if (where != "LOCAL" && where != "LIST" && (where.find(' ') != std::string::npos || where.find('%') != std::string::npos))
    // A printf pattern with its first, last and step ("slice%03d.raw 1 40
    // 1"): MetaIO divided by a zero step and formatted garbled patterns past
    // their buffer. Such a series is rare; one file serves as well.
    throw InputError(path.string() + ": ElementDataFile = '" + excerpt(where, 60) +
                     "' names a pattern of slice files, which is not read here; expected LOCAL, LIST or one data "
                     "file (write the image as one .mha or .nrrd)");
  // MetaIO reads what it can of a garbled size or type: both are judged here.
  const auto type = kBytes.find(fields["ElementType"]);
  const std::vector<unsigned long long> sizes = sizesOf(fields["DimSize"]);
  if (sizes.size() != 3)
    throw InputError(path.string() + ": the MetaImage header says DimSize = '" + excerpt(fields["DimSize"], 60) +
                     "'; expected three whole numbers");
  if (type == kBytes.end())
    throw InputError(path.string() + ": the MetaImage header says ElementType = '" + excerpt(fields["ElementType"], 60) +
                     "'; expected a scalar type such as MET_SHORT or MET_FLOAT");
  DataLayout data;
  unsigned long long channels = 1;
  if (fields.count("ElementNumberOfChannels")) {
    const auto c = sizesOf(fields["ElementNumberOfChannels"]);
    if (c.size() == 1) channels = c[0];
  }
  data.expected = product(sizes, type->second * channels);
  data.compressed = lower(fields["CompressedData"]) == "true";
  if (where == "LOCAL") {
    data.file = path;
    data.offset = in.tellg();
  } else if (where == "LIST") {
    return;  // a list of slice files: ITK reads and checks them
  } else {
    data.file = fs::path(where).is_absolute() ? fs::path(where) : path.parent_path() / where;
  }
  if (data.compressed) {
    // ITK's MetaImage reader inflates exactly CompressedDataSize bytes: without
    // the field it fails and keeps zeros in the image, saying only
    // "Uncompress failed" on the terminal.
    const std::vector<unsigned long long> given = sizesOf(fields["CompressedDataSize"]);
    if (given.size() != 1) {
      std::error_code ec;
      const auto file_size = static_cast<long long>(fs::file_size(data.file, ec));
      const long long stored = ec ? -1 : file_size - (where == "LOCAL" ? static_cast<long long>(data.offset) : 0);
      throw InputError(path.string() + ": CompressedData = True without CompressedDataSize: ITK's reader cannot "
                       "inflate the voxels without it (it reads zeros); expected the line CompressedDataSize = " +
                       (stored >= 0 ? std::to_string(stored) : std::string("<bytes of compressed data>")) +
                       " before ElementDataFile");
    }
    data.compressed_size = static_cast<long long>(std::min(given[0], 1ULL << 62));
  }
  checkLength(path, data);
}

// NRRD (.nrrd, .nhdr): "field: value" lines to the first empty line; the
// data follows (attached) or lies in "data file".
void checkNrrd(const fs::path& path) {
  static const std::map<std::string, unsigned> kBytes = {
      {"signed char", 1}, {"int8", 1}, {"int8_t", 1}, {"uchar", 1}, {"unsigned char", 1}, {"uint8", 1}, {"uint8_t", 1},
      {"short", 2}, {"short int", 2}, {"signed short", 2}, {"signed short int", 2}, {"int16", 2}, {"int16_t", 2},
      {"ushort", 2}, {"unsigned short", 2}, {"unsigned short int", 2}, {"uint16", 2}, {"uint16_t", 2},
      {"int", 4}, {"signed int", 4}, {"int32", 4}, {"int32_t", 4}, {"uint", 4}, {"unsigned int", 4}, {"uint32", 4},
      {"uint32_t", 4}, {"longlong", 8}, {"long long", 8}, {"int64", 8}, {"int64_t", 8}, {"ulonglong", 8},
      {"unsigned long long", 8}, {"uint64", 8}, {"uint64_t", 8}, {"float", 4}, {"double", 8}};
  std::ifstream in(path, std::ios::binary);
  if (!in) return;
  std::map<std::string, std::string> fields;
  std::string line;
  while (std::getline(in, line) && in.tellg() < (1 << 20)) {
    if (trimmed(line).empty()) break;
    if (line[0] == '#') continue;
    const auto colon = line.find(':');
    if (colon == std::string::npos || line.compare(colon, 2, ":=") == 0) continue;
    fields[lower(trimmed(line.substr(0, colon)))] = trimmed(line.substr(colon + 1));
  }
  const auto type = kBytes.find(lower(fields["type"]));
  const std::vector<unsigned long long> sizes = sizesOf(fields["sizes"]);
  // ITK reads a size of more digits than any volume has by wrapping it, and
  // then allocates what the wrapped size asks for.
  if (!trimmed(fields["sizes"]).empty() && sizes.empty())
    throw InputError(path.string() + ": the NRRD header says sizes: '" + excerpt(fields["sizes"], 60) +
                     "'; expected whole numbers of at most 18 digits");
  const std::string encoding = lower(fields["encoding"]);
  if (type == kBytes.end() || sizes.empty() || fields.count("byte skip") || fields.count("line skip")) return;
  DataLayout data;
  data.expected = product(sizes, type->second);
  if (encoding == "gzip" || encoding == "gz") data.compressed = true;
  else if (encoding != "raw") return;  // text, hex, bzip2: ITK reads and checks them
  std::string detached = fields.count("data file") ? fields["data file"] : fields["datafile"];
  if (detached.empty()) {
    data.file = path;
    data.offset = in.tellg();
  } else if (detached.find(' ') == std::string::npos && detached != "LIST") {
    data.file = fs::path(detached).is_absolute() ? fs::path(detached) : path.parent_path() / detached;
  } else {
    return;
  }
  checkLength(path, data);
}

}  // namespace

void checkImageDataLength(const fs::path& path) {
  const std::string name = lower(path.filename().string());
  if (endsWith(name, ".mha") || endsWith(name, ".mhd")) checkMetaImage(path);
  else if (endsWith(name, ".nrrd") || endsWith(name, ".nhdr")) checkNrrd(path);
}

}  // namespace articula::imaging
