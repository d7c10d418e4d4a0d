#include "articula/points/ply_writer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>

#include "articula/core/number_text.hpp"

namespace articula::points {
namespace {

// A comment must stay on its header line.
std::string oneLine(std::string text) {
  std::replace_if(
      text.begin(), text.end(), [](char c) { return c == '\n' || c == '\r'; }, ' ');
  return text;
}

template <typename T>
void appendLittleEndian(std::string& out, T value) {
  std::array<char, sizeof(T)> bytes;
  std::memcpy(bytes.data(), &value, sizeof(T));
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__
  std::reverse(bytes.begin(), bytes.end());
#endif
  out.append(bytes.data(), bytes.size());
}

std::uint8_t toUchar(double v) { return static_cast<std::uint8_t>(std::clamp(std::lround(v), 0L, 255L)); }

}  // namespace

std::string plyText(const PlyData& data, PlyFormat format) {
  const auto columns = static_cast<Eigen::Index>(data.vertex_properties.size());
  if (data.vertex_values.cols() != columns && data.vertex_values.rows() > 0)
    throw std::invalid_argument("plyText: " + std::to_string(data.vertex_values.cols()) + " value columns for " +
                                std::to_string(columns) + " properties");
  const bool binary = format == PlyFormat::BinaryLittleEndian;
  std::string out = binary ? "ply\nformat binary_little_endian 1.0\n" : "ply\nformat ascii 1.0\n";
  out += "comment SPACE=LPS\ncomment coordinates LPS, units mm\n";  // the first as 3D Slicer reads it
  for (const auto& comment : data.comments) out += "comment " + oneLine(comment) + "\n";
  out += "element vertex " + std::to_string(data.vertex_values.rows()) + "\n";
  for (const auto& p : data.vertex_properties) out += std::string("property ") + (p.uchar ? "uchar " : "double ") + p.name + "\n";
  if (data.faces.rows() > 0)
    out += "element face " + std::to_string(data.faces.rows()) + "\nproperty list uchar int vertex_indices\n";
  out += "end_header\n";
  out.reserve(out.size() + static_cast<size_t>(data.vertex_values.size()) * (binary ? 8 : 16) +
              static_cast<size_t>(data.faces.rows()) * 16);
  for (Eigen::Index i = 0; i < data.vertex_values.rows(); ++i) {
    for (Eigen::Index k = 0; k < columns; ++k) {
      const double v = data.vertex_values(i, k);
      const bool uchar = data.vertex_properties[static_cast<size_t>(k)].uchar;
      if (binary) {
        if (uchar) out += static_cast<char>(toUchar(v));
        else appendLittleEndian(out, v);
      } else {
        if (k > 0) out += ' ';
        if (uchar) out += std::to_string(toUchar(v));
        else appendNumber(out, v);
      }
    }
    if (!binary) out += '\n';
  }
  for (Eigen::Index i = 0; i < data.faces.rows(); ++i) {
    if (binary) {
      out += static_cast<char>(3);
      for (int k = 0; k < 3; ++k) appendLittleEndian(out, static_cast<std::int32_t>(data.faces(i, k)));
    } else {
      out += "3 " + std::to_string(data.faces(i, 0)) + ' ' + std::to_string(data.faces(i, 1)) + ' ' +
             std::to_string(data.faces(i, 2)) + '\n';
    }
  }
  return out;
}

}  // namespace articula::points
