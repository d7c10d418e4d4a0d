#include "dicom_check.hpp"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>
#include <stdexcept>

#include <gdcmDict.h>
#include <gdcmDicts.h>
#include <gdcmGlobal.h>
#include <gdcmVR.h>

#include "articula/core/error.hpp"
#include "articula/core/excerpt.hpp"

namespace articula::imaging {

std::vector<double> dicomNumbers(const std::string& text) {
  std::vector<double> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, '\\')) {
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (end == item.c_str() || !std::isfinite(v)) return {};
    out.push_back(v);
  }
  return out;
}

namespace {

// The groups of the elements GDCM reads to describe an image (the meta
// header, identity and modality, acquisition, position, pixels, dose grids,
// nuclear medicine), each through a typed attribute that asserts, and aborts
// the process, when the file's VR does not fit the dictionary's.
bool imageDescribingGroup(std::uint32_t tag) {
  const std::uint32_t group = tag >> 16;
  return group == 0x0002 || group == 0x0008 || group == 0x0018 || group == 0x0020 || group == 0x0028 ||
         group == 0x0054 || group == 0x3004 || group == 0x5200;
}

// The dictionary's VR (e.g. "US or SS") when an image-describing element's
// explicit VR `vr` does not fit it, as GDCM's attributes test it; empty when
// it fits or the element is not one of those. GDCM's own dictionary, so that
// the walk refuses what GDCM would abort on and nothing more.
std::string dictionaryVrRefusing(std::uint32_t tag, const std::string& vr) {
  if (!imageDescribingGroup(tag)) return {};
  const gdcm::Tag gdcm_tag(static_cast<std::uint16_t>(tag >> 16), static_cast<std::uint16_t>(tag & 0xFFFFu));
  const gdcm::DictEntry& entry = gdcm::Global::GetInstance().GetDicts().GetPublicDict().GetDictEntry(gdcm_tag);
  const gdcm::VR expected = entry.GetVR();
  if (expected == gdcm::VR::INVALID || expected == gdcm::VR::UN) return {};  // not in the dictionary
  if (expected.Compatible(gdcm::VR(gdcm::VR::GetVRTypeFromFile(vr.c_str())))) return {};
  std::string text = gdcm::VR::GetVRString(expected);
  for (size_t at = text.find('_'); at != std::string::npos; at = text.find('_')) text.replace(at, 1, " or ");
  return text;
}

// The value representations of the elements that describe an image, as the
// standard gives them: GDCM reads these through typed attributes and aborts
// the process on any other ("OB OW": either).
const char* standardVr(std::uint32_t tag) {
  switch (tag) {
    case 0x00020000u: return "UL";
    case 0x00020001u: return "OB";
    case 0x00020002u: case 0x00020003u: case 0x00020010u: case 0x00020012u: return "UI";
    case 0x00080016u: case 0x00080018u: case 0x0020000Du: case 0x0020000Eu: case 0x00200052u: return "UI";
    case 0x00080060u: case 0x00280004u: return "CS";
    case 0x0008103Eu: case 0x00281054u: return "LO";
    case 0x00180050u: case 0x00180088u: case 0x00200032u: case 0x00200037u: case 0x00280030u: case 0x00281050u:
    case 0x00281051u: case 0x00281052u: case 0x00281053u: return "DS";
    case 0x00200013u: case 0x00280008u: return "IS";
    case 0x00280002u: case 0x00280006u: case 0x00280010u: case 0x00280011u: case 0x00280100u: case 0x00280101u:
    case 0x00280102u: case 0x00280103u: return "US";
    case 0x7FE00010u: return "OB OW";
    default: return nullptr;
  }
}

constexpr std::uint32_t kUndefinedLength = 0xFFFFFFFFu;
constexpr std::uint32_t kPixelData = 0x7FE00010u;
constexpr std::uint32_t kRecognitionCode = 0x00080010u;
constexpr std::uint32_t kItem = 0xFFFEE000u, kItemEnd = 0xFFFEE00Du, kSequenceEnd = 0xFFFEE0DDu;
constexpr int kMaxNesting = 64;  // deeper is no real file, and would only grow the stack

struct Broken : std::runtime_error {
  using std::runtime_error::runtime_error;
};

std::string tagName(std::uint32_t tag) {
  char text[16];
  std::snprintf(text, sizeof text, "(%04X,%04X)", unsigned(tag >> 16), unsigned(tag & 0xFFFF));
  return text;
}

class Walker {
 public:
  Walker(std::ifstream& in, std::uint64_t size) : in_(in), size_(size) {}

  bool explicit_vr = true;
  bool big_endian = false;

  std::uint64_t position() const { return pos_; }
  bool atEnd() const { return pos_ == size_; }
  bool restIsZero() {
    in_.seekg(static_cast<std::streamoff>(pos_));
    for (std::uint64_t i = pos_; i < size_; ++i)
      if (in_.get() != 0) return false;
    return true;
  }

  std::uint32_t peekTag() {
    const std::uint64_t at = pos_;
    const std::uint32_t tag = readTag();
    pos_ = at;
    return tag;
  }

  /// One data element (and, for sequences and encapsulated data of undefined
  /// length, everything up to its delimiter). Returns the tag.
  std::uint32_t element(int depth, std::string* value = nullptr) {
    if (depth > kMaxNesting) throw Broken("sequences nested deeper than " + std::to_string(kMaxNesting));
    const std::uint64_t start = pos_;
    const std::uint32_t tag = readTag();
    if (tag == kItem || tag == kItemEnd || tag == kSequenceEnd)
      throw Broken("an item delimiter " + tagName(tag) + " outside a sequence at byte " + std::to_string(start));
    std::string vr;
    std::uint32_t length;
    if (explicit_vr) {
      vr = bytes(2);
      if (!(vr[0] >= 'A' && vr[0] <= 'Z' && vr[1] >= 'A' && vr[1] <= 'Z'))
        throw Broken("element " + tagName(tag) + " at byte " + std::to_string(start) + " has no value representation");
      // GDCM guesses at a VR it does not know (and at the encoding with it),
      // and aborted the process on such a file: only the standard's are read.
      static const std::string kKnown = "AE AS AT CS DA DS DT FL FD IS LO LT OB OD OF OL OV OW PN SH SL SQ SS ST SV TM UC UI UL UN UR US UT UV";
      if (kKnown.find(vr) == std::string::npos)  // two capitals match only a whole entry
        throw Broken("element " + tagName(tag) + " at byte " + std::to_string(start) + " has the unknown value representation '" + vr + "'");
      if (depth == 0)
        if (const char* expected = standardVr(tag); expected && !std::strstr(expected, vr.c_str()))
          throw Broken("element " + tagName(tag) + " at byte " + std::to_string(start) + " has the value representation '" +
                       vr + "', the standard's is " + expected);
      if (const std::string expected = dictionaryVrRefusing(tag, vr); !expected.empty())
        throw Broken("element " + tagName(tag) + " at byte " + std::to_string(start) + " has the value representation '" +
                     vr + "', the standard's is " + expected);
      // PS3.5 7.1.2: the VRs with a 2-byte length; any other has 2 reserved
      // bytes and a 4-byte length.
      static const char* kShort[] = {"AE", "AS", "AT", "CS", "DA", "DS", "DT", "FL", "FD", "IS", "LO",
                                     "LT", "PN", "SH", "SL", "SS", "ST", "TM", "UI", "UL", "US"};
      bool long_form = true;
      for (const char* l : kShort) long_form = long_form && vr != l;
      if (long_form) {
        skip(2, tag, start);
        length = read32();
      } else {
        length = read16();
      }
    } else {
      length = read32();
    }
    if (length == kUndefinedLength) {
      if (depth == 0 && tag == kRecognitionCode)
        throw Broken("element " + tagName(tag) + " (Recognition Code) at byte " + std::to_string(start) +
                     " has an undefined length; it holds a short text");
      if (depth == 0 && header && tag == kPixelData) header->pixel_data_bytes = DicomSliceHeader::kEncapsulated;
      items(depth + 1, tag, start);
    } else if (depth == 0 && header && capture(tag, length, start)) {
      // noted in the slice header
    } else {
      if (value && length <= 256) {
        need(length, tag, start);
        *value = bytes(length);
      } else {
        skip(length, tag, start);
      }
    }
    return tag;
  }

 private:
  // Items up to the sequence delimiter: nested data sets, or the fragments
  // of encapsulated (compressed) pixel data.
  void items(int depth, std::uint32_t owner, std::uint64_t owner_start) {
    for (;;) {
      const std::uint64_t start = pos_;
      if (atEnd()) throw Broken("the file ends inside element " + tagName(owner) + " begun at byte " + std::to_string(owner_start));
      const std::uint32_t tag = readTag();
      const std::uint32_t length = read32();
      if (tag == kSequenceEnd) return;
      if (tag != kItem)
        throw Broken("expected an item in element " + tagName(owner) + " at byte " + std::to_string(start) + ", found " +
                     tagName(tag));
      if (length != kUndefinedLength) {
        // The fragments of the slice's compressed pixel data (the first item
        // is the offset table), kept to check the codestream they form.
        if (owner == kPixelData && depth == 1 && header) fragments.push_back({pos_, length});
        skip(length, owner, start);
        continue;
      }
      for (;;) {  // an item of undefined length: elements up to its delimiter
        if (atEnd()) throw Broken("the file ends inside an item of element " + tagName(owner));
        if (peekTag() == kItemEnd) {
          readTag();
          read32();
          break;
        }
        element(depth);
      }
    }
  }

  void need(std::uint64_t n, std::uint32_t tag, std::uint64_t start) const {
    if (n > size_ - pos_)
      throw Broken("element " + tagName(tag) + " at byte " + std::to_string(start) + " needs " + std::to_string(n) +
                   " bytes, " + std::to_string(size_ - pos_) + " remain");
  }
  void skip(std::uint64_t n, std::uint32_t tag, std::uint64_t start) {
    need(n, tag, start);
    pos_ += n;
  }
  std::string bytes(std::uint64_t n) {
    if (n > size_ - pos_) throw Broken("the file ends inside an element header at byte " + std::to_string(pos_));
    std::string out(n, '\0');
    in_.seekg(static_cast<std::streamoff>(pos_));
    in_.read(out.data(), static_cast<std::streamsize>(n));
    if (!in_) throw Broken("a read failed at byte " + std::to_string(pos_));
    pos_ += n;
    return out;
  }
  // The slice header's elements of the top-level data set (nested ones, in
  // sequences, describe other things).
  bool capture(std::uint32_t tag, std::uint32_t length, std::uint64_t start) {
    std::string* text = nullptr;
    long* count = nullptr;
    switch (tag) {
      case 0x00200032u: text = &header->position; break;
      case 0x00200037u: text = &header->orientation; break;
      case 0x00280030u: text = &header->pixel_spacing; break;
      case 0x00180050u: text = &header->slice_thickness; break;
      case 0x00281053u: text = &header->rescale_slope; break;
      case 0x00280008u: text = &header->frames; break;
      case 0x0020000Eu: text = &header->series_uid; break;
      case 0x00080060u: text = &header->modality; break;
      case 0x0008103Eu: text = &header->description; break;
      case 0x00280010u: count = &header->rows; break;
      case 0x00280011u: count = &header->columns; break;
      case 0x00280100u: count = &header->bits_allocated; break;
      case 0x00280002u: count = &header->samples_per_pixel; break;
      case 0x00280101u: count = &header->bits_stored; break;
      case 0x00280102u: count = &header->high_bit; break;
      case 0x00280103u: count = &header->pixel_representation; break;
      case kPixelData:
        header->pixel_data_bytes = length;
        skip(length, tag, start);
        return true;
      case kRecognitionCode: checkRecognitionCode(length, start); return true;
      default: return false;
    }
    if (text && length <= 256) {
      need(length, tag, start);
      *text = bytes(length);
      while (!text->empty() && (text->back() == ' ' || text->back() == '\0')) text->pop_back();
      return true;
    }
    if (count) {
      // One 16-bit number: GDCM reads another length its own way (and
      // aborted on the samples per pixel it made of one).
      if (length != 2)
        throw Broken("element " + tagName(tag) + " at byte " + std::to_string(start) + " holds " +
                     std::to_string(length) + " bytes; expected one 16-bit number (2 bytes)");
      *count = static_cast<long>(read16());
      return true;
    }
    return false;
  }

  // An ACR-NEMA data set's (0008,0010): GDCM takes any data set holding a
  // non-empty one for ACR-NEMA and aborts the process unless it begins as
  // those do.
  void checkRecognitionCode(std::uint32_t length, std::uint64_t start) {
    need(length, kRecognitionCode, start);
    if (length > 256)
      throw Broken("element " + tagName(kRecognitionCode) + " (Recognition Code) at byte " + std::to_string(start) +
                   " holds " + std::to_string(length) + " bytes; it holds a short text");
    std::string code = bytes(length);
    if (code.empty()) return;  // GDCM passes an empty one by
    for (const char* acr_nema : {"ACR-NEMA", "ACRNEMA", "MIPS 2.0"})
      if (code.rfind(acr_nema, 0) == 0) return;
    while (!code.empty() && (code.back() == ' ' || code.back() == '\0')) code.pop_back();  // the value's padding
    throw Broken("element " + tagName(kRecognitionCode) + " (Recognition Code, of ACR-NEMA files) at byte " +
                 std::to_string(start) + " holds '" + excerpt(code) +
                 "'; expected a code beginning with ACR-NEMA, ACRNEMA or MIPS 2.0");
  }

  std::uint32_t number(int n) {
    const std::string b = bytes(static_cast<std::uint64_t>(n));
    std::uint32_t v = 0;
    for (int i = 0; i < n; ++i) v |= std::uint32_t(static_cast<unsigned char>(b[big_endian ? n - 1 - i : i])) << (8 * i);
    return v;
  }
  std::uint32_t read16() { return number(2); }
  std::uint32_t read32() { return number(4); }
  std::uint32_t readTag() {
    const std::uint32_t group = read16();
    return group << 16 | read16();
  }

  std::ifstream& in_;
  std::uint64_t size_;

 public:
  DicomSliceHeader* header = nullptr;  // where to note the slice header, if anywhere
  std::vector<std::pair<std::uint64_t, std::uint32_t>> fragments;  // of the top-level pixel data: where, how long

 private:
  std::uint64_t pos_ = 0;

 public:
  void seek(std::uint64_t to) { pos_ = to; }
};

// What a decoder would not say of a compressed slice: OpenJPEG decodes a
// JPEG 2000 codestream cut short (or with a tile-part removed) from what is
// left, filling the rest with a coarser image, and libjpeg pads a JPEG cut
// short. Only the structure is checked (every marker segment and tile-part
// within the stream, the end marker last); damage inside the entropy-coded
// data has no marker to show it.
std::string jpeg2000Problem(const std::string& s) {
  const auto u16 = [&](size_t at) { return unsigned(static_cast<unsigned char>(s[at])) << 8 | static_cast<unsigned char>(s[at + 1]); };
  if (s.size() < 4 || u16(0) != 0xFF4F || u16(2) != 0xFF51)
    return "its JPEG 2000 codestream does not begin with the SOC and SIZ markers";
  size_t at = 2;
  while (at + 4 <= s.size() && u16(at) != 0xFF90) {  // the main header's marker segments, to the first tile-part
    if ((u16(at) & 0xFF00) != 0xFF00) return "its JPEG 2000 main header is broken at byte " + std::to_string(at);
    at += 2 + u16(at + 2);
  }
  for (;;) {
    if (at + 2 > s.size()) return "its JPEG 2000 codestream is cut short (no EOC marker after its last tile-part)";
    if (u16(at) == 0xFFD9) break;
    if (u16(at) != 0xFF90 || at + 12 > s.size())
      return "its JPEG 2000 codestream is broken at byte " + std::to_string(at) + " (expected a tile-part or EOC)";
    const std::uint64_t psot = std::uint64_t(u16(at + 6)) << 16 | u16(at + 8);
    if (psot == 0) return s.size() >= 2 && u16(s.size() - 2) == 0xFFD9 ? "" : "its JPEG 2000 codestream is cut short";
    if (at + psot > s.size())
      return "its JPEG 2000 codestream is cut short: a tile-part at byte " + std::to_string(at) + " announces " +
             std::to_string(psot) + " bytes, " + std::to_string(s.size() - at) + " remain";
    at += psot;
  }
  for (at += 2; at < s.size(); ++at)  // the fragment's even-length padding
    if (s[at] != '\0') return "its JPEG 2000 codestream has bytes after its EOC marker";
  return "";
}

std::string jpegProblem(const std::string& s) {
  size_t end = s.size();
  while (end > 0 && s[end - 1] == '\0') --end;  // padding to an even length
  if (end < 4 || static_cast<unsigned char>(s[0]) != 0xFF || static_cast<unsigned char>(s[1]) != 0xD8)
    return "its JPEG data does not begin with the SOI marker";
  if (static_cast<unsigned char>(s[end - 2]) != 0xFF || static_cast<unsigned char>(s[end - 1]) != 0xD9)
    return "its JPEG data is cut short (no EOI marker at its end)";
  return "";
}

// The codestream of a single-frame slice (its fragments after the offset
// table, joined), for the transfer syntaxes whose structure is checked.
std::string codestreamProblem(std::ifstream& in, const std::string& syntax,
                              const std::vector<std::pair<std::uint64_t, std::uint32_t>>& fragments) {
  const bool j2k = syntax == "1.2.840.10008.1.2.4.90" || syntax == "1.2.840.10008.1.2.4.91";
  const bool jpeg = syntax == "1.2.840.10008.1.2.4.50" || syntax == "1.2.840.10008.1.2.4.51" ||
                    syntax == "1.2.840.10008.1.2.4.57" || syntax == "1.2.840.10008.1.2.4.70";
  if ((!j2k && !jpeg) || fragments.size() < 2) return "";
  std::string stream;
  for (size_t f = 1; f < fragments.size(); ++f) {
    std::string part(fragments[f].second, '\0');
    in.clear();
    in.seekg(static_cast<std::streamoff>(fragments[f].first));
    in.read(part.data(), static_cast<std::streamsize>(part.size()));
    if (!in) return "a read of its pixel data failed";
    stream += part;
  }
  return j2k ? jpeg2000Problem(stream) : jpegProblem(stream);
}

}  // namespace

DicomFileCheck checkDicomFile(const std::filesystem::path& file) {
  DicomFileCheck result;
  std::error_code ec;
  const std::uint64_t size = std::filesystem::file_size(file, ec);
  std::ifstream in(file, std::ios::binary);
  if (ec || !in) {
    result.kind = DicomFileKind::Damaged;
    result.problem = "cannot be read";
    return result;
  }
  char magic[4] = {};
  const bool preamble = size >= 132 && in.seekg(128) && in.read(magic, 4) && std::string(magic, 4) == "DICM";
  in.clear();
  // Without a preamble (as old writers and some archives store data sets),
  // GDCM reads a file whose first group is 0x0002 or 0x0008 (0x0800
  // byte-swapped, ACR-NEMA) as DICOM, and aborts the process on some it
  // cannot parse: such files are walked too. Any other is no DICOM file.
  unsigned char first[6] = {};
  if (!preamble && (size < 6 || !in.seekg(0) || !in.read(reinterpret_cast<char*>(first), 6))) return result;
  const unsigned first_group = first[0] | unsigned(first[1]) << 8;
  if (!preamble && first_group != 0x0002 && first_group != 0x0008 && first_group != 0x0800) return result;
  try {
    Walker walk(in, size);
    walk.header = &result.header;
    walk.seek(preamble ? 132 : 0);
    // The meta header (group 0002) is explicit VR little endian; its transfer
    // syntax says how the data set after it is encoded.
    std::string syntax;
    bool any_meta = false;
    while (!walk.atEnd() && (walk.peekTag() >> 16) == 0x0002) {
      std::string value;
      if (walk.element(0, &value) == 0x00020010u) syntax = value;
      any_meta = true;
    }
    if (preamble && !any_meta) throw Broken("no meta header after the DICM preamble");
    while (!syntax.empty() && (syntax.back() == '\0' || syntax.back() == ' ')) syntax.pop_back();
    if (syntax == "1.2.840.10008.1.2.1.99") {  // deflated: the data set is a zlib stream, not walked
      result.kind = DicomFileKind::Complete;
      return result;  // header.read stays false: the series check refuses it by name
    }
    if (any_meta) {
      walk.explicit_vr = syntax != "1.2.840.10008.1.2";
      walk.big_endian = syntax == "1.2.840.10008.1.2.2";
    } else {  // a bare data set: its first element shows how it is encoded
      walk.big_endian = first_group == 0x0800;
      walk.explicit_vr = !walk.big_endian && std::isupper(first[4]) && std::isupper(first[5]);
    }
    // Zero bytes after the last element are padding some writers leave; GDCM
    // stops there too, but in a big-endian data set it aborts on them.
    // PS3.5 7.1: each element once, in ascending order. GDCM keeps the first
    // of two alike (the walk noted the last), and aborted on what it kept.
    for (std::uint32_t last = 0; !walk.atEnd() && !walk.restIsZero();) {
      const std::uint64_t at = walk.position();
      const std::uint32_t tag = walk.element(0);
      if (tag <= last)
        throw Broken("element " + tagName(tag) + " at byte " + std::to_string(at) + " follows " + tagName(last) +
                     ": a data set holds each element once, in ascending order");
      last = tag;
    }
    if (!walk.atEnd() && walk.big_endian)
      throw Broken("zero bytes follow the last element of a big-endian data set, from byte " +
                   std::to_string(walk.position()));
    const std::vector<double> frames = dicomNumbers(result.header.frames);
    if (frames.size() <= 1 && (frames.empty() || frames[0] <= 1))
      if (const std::string problem = codestreamProblem(in, syntax, walk.fragments); !problem.empty()) throw Broken(problem);
    result.kind = DicomFileKind::Complete;
    result.header.read = true;
    result.header.bare = !preamble;
  } catch (const Broken& e) {
    result.kind = DicomFileKind::Damaged;
    result.problem = (preamble ? "" : "no DICOM preamble, and ") + std::string(e.what());
  }
  return result;
}

}  // namespace articula::imaging

namespace articula::imaging {

namespace {

using Vec3 = std::array<double, 3>;

double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }


std::string number(double v) {
  std::ostringstream out;
  out << std::setprecision(7) << v;
  return out.str();
}

// A multi-valued element as numbers, "(1, 0, 0)": its text shows DICOM's
// backslash separators escaped.
std::string shown(const std::string& text) {
  const std::vector<double> values = dicomNumbers(text);
  if (values.empty()) return "'" + excerpt(text) + "'";
  if (values.size() == 1) return number(values[0]);
  std::ostringstream out;
  out << std::setprecision(7) << '(';
  for (size_t i = 0; i < values.size(); ++i) out << (i ? ", " : "") << values[i];
  out << ')';
  return out.str();
}

std::string name(const std::string& file) { return excerpt(std::filesystem::path(file).filename().string()); }

std::string gigabytes(double bytes) {
  std::ostringstream text;
  text << std::setprecision(3) << bytes / 1e9 << " GB";
  return text.str();
}

}  // namespace

void checkSeriesHeaders(const std::vector<std::string>& files, const std::vector<DicomSliceHeader>& headers) {
  const std::string series = "DICOM series in " + excerpt(std::filesystem::path(files.at(0)).parent_path().string());
  for (size_t k = 0; k < files.size(); ++k)
    if (!headers[k].read)
      throw InputError(series + ": the header of " + name(files[k]) +
                       " could not be checked (no DICOM preamble, or a deflated data set); expected a DICOM file "
                       "with a preamble: convert the series, for example with gdcmconv --raw");
  const DicomSliceHeader& first = headers[0];
  const auto where = [&](size_t k) { return name(files[k]) + " (slice " + std::to_string(k + 1) + " of " +
                                            std::to_string(files.size()) + ")"; };
  if (first.rows <= 0 || first.columns <= 0)
    throw InputError(series + ": " + where(0) + " has no Rows (0028,0010) or Columns (0028,0011); expected an image");
  const std::vector<double> orientation = dicomNumbers(first.orientation);
  if (orientation.size() != 6)
    throw InputError(series + ": expected six numbers in Image Orientation Patient (0020,0037) of " + where(0) +
                     ", found " + shown(first.orientation));
  const std::vector<double> spacing = dicomNumbers(first.pixel_spacing);
  if (spacing.size() != 2 || !(spacing[0] > 0 && spacing[1] > 0))
    throw InputError(series + ": expected two positive numbers in Pixel Spacing (0028,0030) of " + where(0) +
                     ", found " + shown(first.pixel_spacing));
  const Vec3 row{orientation[0], orientation[1], orientation[2]}, column{orientation[3], orientation[4], orientation[5]};
  Vec3 normal{row[1] * column[2] - row[2] * column[1], row[2] * column[0] - row[0] * column[2],
              row[0] * column[1] - row[1] * column[0]};
  const double length = std::sqrt(dot(normal, normal));
  if (!(length > 0.5)) throw InputError(series + ": the orientation of " + where(0) + " has parallel row and column");
  for (double& v : normal) v /= length;

  std::vector<Vec3> positions;
  double pixel_bytes = 0;
  for (size_t k = 0; k < files.size(); ++k) {
    const DicomSliceHeader& h = headers[k];
    // The pixel description as a CT stores it: GDCM aborts the process on
    // some others (more bits stored than allocated).
    const bool bits_ok = (h.bits_allocated == 8 || h.bits_allocated == 16 || h.bits_allocated == 32) &&
                         (h.bits_stored == -1 || (h.bits_stored >= 1 && h.bits_stored <= h.bits_allocated)) &&
                         (h.high_bit == -1 || (h.high_bit >= 0 && h.high_bit < h.bits_allocated)) &&
                         (h.pixel_representation == -1 || h.pixel_representation == 0 || h.pixel_representation == 1) &&
                         (h.samples_per_pixel == -1 || h.samples_per_pixel == 1);
    if (!bits_ok)
      throw InputError(series + ": " + where(k) + " describes its pixels as " + std::to_string(h.samples_per_pixel) +
                       " sample(s) of " + std::to_string(h.bits_allocated) + " bits allocated, " +
                       std::to_string(h.bits_stored) + " stored, high bit " + std::to_string(h.high_bit) +
                       ", representation " + std::to_string(h.pixel_representation) +
                       "; expected one sample of 8, 16 or 32 bits allocated, at most as many stored, signed (1) or "
                       "unsigned (0): a CT's grey values");
    if (h.rows != first.rows || h.columns != first.columns)
      throw InputError(series + ": " + where(k) + " is " + std::to_string(h.rows) + " x " + std::to_string(h.columns) +
                       " pixels (rows x columns), the first slice " + std::to_string(first.rows) + " x " +
                       std::to_string(first.columns) + ": a volume needs one size; remove the slices of another image");
    if (h.bits_allocated != first.bits_allocated || h.samples_per_pixel != first.samples_per_pixel)
      throw InputError(series + ": " + where(k) + " stores " + std::to_string(h.bits_allocated) + " bits x " +
                       std::to_string(h.samples_per_pixel) + " samples per pixel, the first slice " +
                       std::to_string(first.bits_allocated) + " x " + std::to_string(first.samples_per_pixel));
    const std::vector<double> o = dicomNumbers(h.orientation);
    double turn = o.size() == 6 ? 0 : 1;
    for (size_t i = 0; i < o.size() && i < 6; ++i) turn = std::max(turn, std::fabs(o[i] - orientation[i]));
    if (turn > 1e-4)
      throw InputError(series + ": " + where(k) + " has Image Orientation Patient " + shown(h.orientation) +
                       ", the first slice " + shown(first.orientation) +
                       ": ITK would place every slice in the first one's orientation; remove the slices of another "
                       "image or resample the series");
    const std::vector<double> s = dicomNumbers(h.pixel_spacing);
    if (s.size() != 2 || std::fabs(s[0] - spacing[0]) > 1e-4 * spacing[0] ||
        std::fabs(s[1] - spacing[1]) > 1e-4 * spacing[1])
      throw InputError(series + ": " + where(k) + " has Pixel Spacing " + shown(h.pixel_spacing) +
                       " mm, the first slice " + shown(first.pixel_spacing) +
                       ": ITK would use the first slice's spacing for all; remove the slices of another image");
    if (!h.rescale_slope.empty()) {
      const std::vector<double> slope = dicomNumbers(h.rescale_slope);
      if (slope.size() != 1 || slope[0] == 0)
        throw InputError(series + ": " + where(k) + " has Rescale Slope (0028,1053) " + shown(h.rescale_slope) +
                         "; expected a non-zero number (a slope of 0 makes every voxel of the slice one value)");
    }
    const std::vector<double> frames_text = dicomNumbers(h.frames);
    const double frames = frames_text.size() == 1 && frames_text[0] >= 1 ? frames_text[0] : 1;
    const double bytes = double(h.rows) * double(h.columns) * frames * std::max(1L, h.samples_per_pixel) *
                         std::max(1.0, double(h.bits_allocated) / 8);
    if (h.pixel_data_bytes == -1)
      throw InputError(series + ": " + where(k) + " holds no Pixel Data (7FE0,0010); expected an image in every slice");
    if (h.pixel_data_bytes >= 0 && double(h.pixel_data_bytes) < bytes)
      throw InputError(series + ": " + where(k) + " holds " + std::to_string(h.pixel_data_bytes) +
                       " bytes of pixel data, its header announces " + std::to_string(h.rows) + " x " +
                       std::to_string(h.columns) + " pixels of " + std::to_string(h.bits_allocated) + " bits (" +
                       std::to_string(static_cast<long long>(bytes)) +
                       " bytes): the slice is cut or damaged; replace it or export the series again");
    pixel_bytes += double(h.rows) * double(h.columns) * frames;
    const std::vector<double> p = dicomNumbers(h.position);
    if (p.size() != 3)
      throw InputError(series + ": expected three numbers in Image Position Patient (0020,0032) of " + where(k) +
                       ", found " + shown(h.position));
    positions.push_back({p[0], p[1], p[2]});
  }

  // The volume as ITK will hold it (float voxels, and a copy): refused before
  // ITK allocates it when this machine cannot, rather than swapping or dying.
  const double needed = pixel_bytes * sizeof(float) * 2;
  const double memory = double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGE_SIZE));
  if (memory > 0 && needed > memory)
    throw InputError(series + ": the slices announce " + std::to_string(static_cast<long long>(pixel_bytes)) +
                     " voxels (" + std::to_string(first.rows) + " x " + std::to_string(first.columns) + " x " +
                     std::to_string(files.size()) + "), " + gigabytes(needed) + " to read, more than this machine's " +
                     gigabytes(memory) + "; check the slices' Rows and Columns, or crop the series");

  // Each slice where the series' line puts it: ITK places slice k at the
  // first slice's position plus k gaps along the line to the last, and
  // ignores the position each slice states.
  if (positions.size() < 2) return;
  std::vector<std::pair<double, size_t>> along;
  for (size_t k = 0; k < positions.size(); ++k) along.emplace_back(dot(positions[k], normal), k);
  std::sort(along.begin(), along.end());
  for (size_t i = 1; i < along.size(); ++i)
    if (along[i].first - along[i - 1].first < 1e-3)
      throw InputError(series + ": " + where(along[i - 1].second) + " and " + where(along[i].second) +
                       " lie at one position along the slice normal (a duplicated slice?); keep one of them");
  const Vec3 span{positions.back()[0] - positions[0][0], positions.back()[1] - positions[0][1],
                  positions.back()[2] - positions[0][2]};
  const double along_span = dot(span, normal);
  const double tolerance = 0.25 * std::min(spacing[0], spacing[1]);
  for (size_t k = 1; k < positions.size(); ++k) {
    const Vec3 d{positions[k][0] - positions[0][0], positions[k][1] - positions[0][1], positions[k][2] - positions[0][2]};
    if (along_span == 0) continue;
    const double t = dot(d, normal) / along_span;
    const double off = std::hypot(dot(d, row) - t * dot(span, row), dot(d, column) - t * dot(span, column));
    if (off > tolerance) {
      std::ostringstream m;
      m << series << ": " << where(k) << " lies " << std::setprecision(3) << off
        << " mm beside the line from the first slice to the last (Image Position Patient " << shown(headers[k].position)
        << "); ITK would place it on that line. Slices shifted in-plane are no single volume: export the series again";
      throw InputError(m.str());
    }
  }
}

DicomFolder scanDicomFolder(const std::filesystem::path& folder) {
  DicomFolder out;
  std::vector<std::filesystem::path> paths;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(folder, ec))
    if (entry.is_regular_file(ec)) paths.push_back(entry.path());
  std::sort(paths.begin(), paths.end());
  std::map<std::string, DicomFolder::Series> by_uid;
  for (const auto& path : paths) {
    const std::string file_name = path.filename().string();
    DicomFileCheck check = checkDicomFile(path);
    if (check.kind == DicomFileKind::Damaged) {
      if (++out.damaged_count <= 5) out.damaged.push_back(excerpt(file_name) + ": " + check.problem);
      continue;
    }
    // A bare data set (no preamble and meta header, as Part 10 requires) is
    // walked but left out: GDCM guesses at its encoding, and aborted the
    // process on several whose walk passed.
    if (!check.header.read || check.header.bare || check.header.pixel_data_bytes == -1) {
      out.bare_files += check.header.read && check.header.bare;
      out.other_files.push_back(file_name);
      continue;
    }
    DicomFolder::Series& series = by_uid[check.header.series_uid];
    if (series.files.empty()) {
      series.uid = check.header.series_uid;
      series.modality = check.header.modality;
      series.description = check.header.description;
    }
    series.files.push_back(path.string());
    series.headers.push_back(std::move(check.header));
  }
  for (auto& [uid, series] : by_uid) {
    const std::vector<double> o = dicomNumbers(series.headers.front().orientation);
    if (o.size() == 6) {
      const Vec3 normal{o[1] * o[5] - o[2] * o[4], o[2] * o[3] - o[0] * o[5], o[0] * o[4] - o[1] * o[3]};
      std::vector<std::pair<double, size_t>> order;
      for (size_t k = 0; k < series.files.size(); ++k) {
        const std::vector<double> p = dicomNumbers(series.headers[k].position);
        order.emplace_back(p.size() == 3 ? dot({p[0], p[1], p[2]}, normal) : 0.0, k);
      }
      std::stable_sort(order.begin(), order.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
      DicomFolder::Series sorted = series;
      for (size_t k = 0; k < order.size(); ++k) {
        sorted.files[k] = series.files[order[k].second];
        sorted.headers[k] = series.headers[order[k].second];
      }
      series = std::move(sorted);
    }
    out.series.push_back(std::move(series));
  }
  return out;
}

}  // namespace articula::imaging
