#include "dicom_check.hpp"

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <stdexcept>

namespace articula::imaging {

namespace {

constexpr std::uint32_t kUndefinedLength = 0xFFFFFFFFu;
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
      static const char* kLong[] = {"OB", "OD", "OF", "OL", "OV", "OW", "SQ", "UC", "UR", "UT", "UN", "SV", "UV"};
      bool long_form = false;
      for (const char* l : kLong) long_form = long_form || vr == l;
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
      items(depth + 1, tag, start);
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
  std::uint64_t pos_ = 0;

 public:
  void seek(std::uint64_t to) { pos_ = to; }
};

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
  if (size < 132 || !in.seekg(128) || !in.read(magic, 4) || std::string(magic, 4) != "DICM") return result;  // NotDicom
  try {
    Walker walk(in, size);
    walk.seek(132);
    // The meta header (group 0002) is explicit VR little endian; its transfer
    // syntax says how the data set after it is encoded.
    std::string syntax;
    bool any_meta = false;
    while (!walk.atEnd() && (walk.peekTag() >> 16) == 0x0002) {
      std::string value;
      if (walk.element(0, &value) == 0x00020010u) syntax = value;
      any_meta = true;
    }
    if (!any_meta) throw Broken("no meta header after the DICM preamble");
    while (!syntax.empty() && (syntax.back() == '\0' || syntax.back() == ' ')) syntax.pop_back();
    if (syntax == "1.2.840.10008.1.2.1.99") {  // deflated: the data set is a zlib stream, not walked
      result.kind = DicomFileKind::Complete;
      return result;
    }
    walk.explicit_vr = syntax != "1.2.840.10008.1.2";
    walk.big_endian = syntax == "1.2.840.10008.1.2.2";
    // Zero bytes after the last element are padding some writers leave; GDCM stops there too.
    while (!walk.atEnd() && !walk.restIsZero()) walk.element(0);
    result.kind = DicomFileKind::Complete;
  } catch (const Broken& e) {
    result.kind = DicomFileKind::Damaged;
    result.problem = e.what();
  }
  return result;
}

}  // namespace articula::imaging
