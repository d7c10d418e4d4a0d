#include "articula/report/slice_image.hpp"

#include <cmath>
#include <stdexcept>

#include <zlib.h>

namespace articula::report {
namespace {

void appendBigEndian(std::string& out, std::uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) out += static_cast<char>((v >> shift) & 0xFF);
}

void appendChunk(std::string& out, const char* type, const std::string& data) {
  appendBigEndian(out, static_cast<std::uint32_t>(data.size()));
  const std::string body = std::string(type, 4) + data;
  out += body;
  appendBigEndian(out, static_cast<std::uint32_t>(
                           crc32(0L, reinterpret_cast<const Bytef*>(body.data()), static_cast<uInt>(body.size()))));
}

}  // namespace

std::string greyPng(const std::vector<std::uint8_t>& pixels, int width, int height) {
  if (width <= 0 || height <= 0 || pixels.size() != static_cast<size_t>(width) * static_cast<size_t>(height))
    throw std::invalid_argument("greyPng: expected width x height pixels");
  std::string raw;  // each row: filter type 0, then its pixels
  raw.reserve(static_cast<size_t>(height) * (static_cast<size_t>(width) + 1));
  for (int r = 0; r < height; ++r) {
    raw += '\0';
    raw.append(reinterpret_cast<const char*>(pixels.data()) + static_cast<size_t>(r) * static_cast<size_t>(width),
               static_cast<size_t>(width));
  }
  uLongf size = compressBound(static_cast<uLong>(raw.size()));
  std::string compressed(size, '\0');
  if (compress2(reinterpret_cast<Bytef*>(compressed.data()), &size, reinterpret_cast<const Bytef*>(raw.data()),
                static_cast<uLong>(raw.size()), Z_BEST_COMPRESSION) != Z_OK)
    throw std::runtime_error("greyPng: zlib could not compress the image");
  compressed.resize(size);
  std::string header;
  appendBigEndian(header, static_cast<std::uint32_t>(width));
  appendBigEndian(header, static_cast<std::uint32_t>(height));
  header += std::string("\x08\x00\x00\x00\x00", 5);  // 8 bits, grey, deflate, adaptive filters, no interlace
  std::string png = "\x89PNG\r\n\x1a\n";
  appendChunk(png, "IHDR", header);
  appendChunk(png, "IDAT", compressed);
  appendChunk(png, "IEND", "");
  return png;
}

std::string base64(const std::string& bytes) {
  static const char* kDigits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const std::uint32_t n = static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i])) << 16 |
                            (i + 1 < bytes.size() ? static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i + 1])) << 8 : 0) |
                            (i + 2 < bytes.size() ? static_cast<unsigned char>(bytes[i + 2]) : 0);
    out += kDigits[n >> 18 & 63];
    out += kDigits[n >> 12 & 63];
    out += i + 1 < bytes.size() ? kDigits[n >> 6 & 63] : '=';
    out += i + 2 < bytes.size() ? kDigits[n & 63] : '=';
  }
  return out;
}

std::vector<Segment2> contourSegments(const Eigen::MatrixXd& field, double level) {
  std::vector<Segment2> out;
  // Corners of a cell counter-clockwise from (row, column): 0 (r, c), 1 (r, c+1), 2 (r+1, c+1), 3 (r+1, c).
  const int dr[4] = {0, 0, 1, 1}, dc[4] = {0, 1, 1, 0};
  for (Eigen::Index r = 0; r + 1 < field.rows(); ++r)
    for (Eigen::Index c = 0; c + 1 < field.cols(); ++c) {
      double v[4];
      bool finite = true;
      for (int k = 0; k < 4; ++k) finite &= std::isfinite(v[k] = field(r + dr[k], c + dc[k]) - level);
      if (!finite) continue;
      // Where the level crosses edge k (corner k to k+1), in (column, row).
      const auto cross = [&](int k) {
        const int j = (k + 1) % 4;
        const double t = v[k] / (v[k] - v[j]);
        return Eigen::Vector2d(static_cast<double>(c) + dc[k] + t * (dc[j] - dc[k]),
                               static_cast<double>(r) + dr[k] + t * (dr[j] - dr[k]));
      };
      std::vector<int> edges;
      for (int k = 0; k < 4; ++k)
        if ((v[k] < 0) != (v[(k + 1) % 4] < 0)) edges.push_back(k);
      if (edges.size() == 2) {
        out.push_back({cross(edges[0]), cross(edges[1])});
      } else if (edges.size() == 4) {
        // A saddle: pair the edges so that the cell's mean side stays connected.
        const bool centre_below = (v[0] + v[1] + v[2] + v[3]) / 4 < 0;
        const bool first_below = v[0] < 0;
        if (centre_below == first_below) {
          out.push_back({cross(0), cross(1)});
          out.push_back({cross(2), cross(3)});
        } else {
          out.push_back({cross(3), cross(0)});
          out.push_back({cross(1), cross(2)});
        }
      }
    }
  return out;
}

}  // namespace articula::report
